//! Hemisphere culling: per origin and frame, the azimuth sectors in which a planar patch can be
//! hit, so that a lane is handed only the patches a hemisphere ray can meet.
//!
//! The hardware counterpart of the soft engine's per-ring cone intervals (`accel/soft.rs`): a
//! hemisphere ray is the reference direction d_ref turned by the frame R, and d = R d_ref is in
//! a patch's pyramid (spanned by a_i = v_i − O) only if d_ref is in the pyramid of Rᵀ a_i. Seen
//! down the frame's axis, that pyramid covers an azimuth wedge: if it contains neither +z nor
//! −z (its edge normals e_i do not all have the same sign along the axis w = R ẑ), every
//! direction in it lies between the azimuths of its corners, which span less than π. So per
//! patch, in the set-up pass:
//!
//! 1. the corners in the frame: f_i = (a_i · u, a_i · v, a_i · w) with u, v, w = R x̂, R ŷ, R ẑ,
//!    the frame's axes as the rotator turns them (three directions through the rotator per
//!    frame; three dot products per corner);
//! 2. **below the horizon** if every corner has f_i · ẑ < −|f_i|∞ 2^-10: a hemisphere ray
//!    (d_ref · ẑ ≥ 0) cannot reach it;
//! 3. **full** (every sector) if the pyramid contains the axis (all e_i · w of one sign), if an
//!    edge plane nearly contains it (|e_i · w| ≤ |e_i|∞ 2^-10), or if a corner lies within
//!    2^-6 of the axis, where its azimuth is ill-conditioned;
//! 4. otherwise the azimuths φ_i = atan2(f_i.y, f_i.x) (a vectoring CORDIC of the unit's own,
//!    24 iterations on 32 bits), their smallest enclosing arc widened by [`MARGIN`] on each side,
//!    and the sectors its ends fall in.
//!
//! A ray's sector comes from its reference direction by the same vectoring CORDIC (in parallel
//! with the rotator, so it adds no latency). Rays within 2^-5 of the pole (sin θ < 2^-5), rays
//! below the horizon and rays not rotated by a frame (TRACE entries) are not culled: they are
//! handed every active patch.
//!
//! Why the margin is safe: everything the test compares is within about 2^-21 rad of exact (the
//! rotator's truncation, the axes' and the vectoring's), and an azimuth error is at most the
//! direction error over sin θ, so within 2^-16 rad for the rays that are culled; [`MARGIN`] is
//! 2^-9 rad, and culling is applied only with CORDIC words of at least
//! [`MIN_CULL_WIDTH`] bits. Culling therefore only removes patches the edge test would reject:
//! every hit is the one the full scan finds, which the tests check against the unculled model.

use crate::cordic::{CordicConfig, CordicPipe, CordicSlot, Mode};
use crate::format::{Angle, Unit};

/// The widening of a wedge on each side, in Q3.29 radians: 2^-9 rad.
pub const MARGIN: i64 = 1 << 20;
/// π in Q3.29.
const PI: i64 = 1_686_629_713;
/// Narrowest CORDIC word (CONFIG.WIDTH) with which the unit culls: below it, the rotator's own
/// error would approach the margin, so every ray is handed every patch.
pub const MIN_CULL_WIDTH: u32 = 24;

/// Where a patch can be met by culled rays.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Wedge {
    /// Below the frame's horizon: never by a culled ray.
    Below,
    /// In every sector.
    #[default]
    Full,
    /// In sectors `lo, lo + 1, …, lo + len − 1` (modulo the sector count).
    Sectors {
        /// First sector.
        lo: u8,
        /// Number of sectors.
        len: u8,
    },
}

/// The culling unit's vectoring CORDIC (azimuths of corners and rays) and sector count.
#[derive(Clone, Debug)]
pub struct CullUnit {
    sectors: u32,
    vector: CordicPipe<()>,
}

impl CullUnit {
    /// A unit with `sectors` azimuth sectors (0: culling off).
    pub fn new(sectors: u32) -> Self {
        CullUnit {
            sectors,
            vector: CordicPipe::new(Mode::Vector, CordicConfig::DEFAULT),
        }
    }

    /// Sectors (0: off).
    pub fn sectors(&self) -> u32 {
        self.sectors
    }

    /// atan2(y, x) in Q3.29 bits, for x, y in 32-bit containers (any common scale).
    fn azimuth(&self, x: i32, y: i32) -> i64 {
        let s = self.vector.eval(CordicSlot {
            x: Unit::from_bits(x),
            y: Unit::from_bits(y),
            z: Angle::ZERO,
            zero: x == 0 && y == 0,
            payload: (),
        });
        s.z.to_bits() as i64
    }

    /// The sector of an angle (Q3.29 bits, any turn).
    fn sector_of(&self, a: i64) -> u32 {
        let a = (a + PI).rem_euclid(2 * PI);
        ((a * self.sectors as i64) / (2 * PI)).min(self.sectors as i64 - 1) as u32
    }

    /// The sector of a hemisphere ray with reference direction `d` (Q2.30), if it is culled.
    pub fn ray_sector(&self, d: [Unit; 3]) -> Option<u32> {
        let [x, y, z] = d.map(|c| c.to_bits());
        let rho = x.unsigned_abs().max(y.unsigned_abs());
        if self.sectors == 0 || z < 0 || rho < 1 << 25 {
            return None;
        }
        Some(self.sector_of(self.azimuth(x, y)))
    }

    /// The wedge of a planar patch with corner vectors `a` (Q8.24, relative to the origin) and
    /// edge normals `e` (inside iff d · e ≥ 0), in the frame with axes `axes` (u, v, w: Q2.30).
    pub fn wedge(&self, a: &[[i64; 3]], e: &[[i64; 3]], axes: &[[Unit; 3]; 3]) -> Wedge {
        let ax = axes.map(|v| v.map(|c| c.to_bits() as i128));
        let dot = |p: &[i64; 3], q: &[i128; 3]| -> i128 {
            (0..3).map(|c| p[c] as i128 * q[c]).sum::<i128>()
        };
        // corners in the frame (Q8.24, the products shifted back by the axes' 30 bits)
        let mut f = [[0i128; 3]; 4];
        for (fi, ai) in f.iter_mut().zip(a) {
            *fi = [0, 1, 2].map(|k| dot(ai, &ax[k]) >> 30);
        }
        let f = &f[..a.len()];
        let norm = |v: &[i128; 3]| v.iter().map(|c| c.unsigned_abs()).max().unwrap_or(0);
        if f.iter().all(|v| v[2] < -((norm(v) >> 10) as i128)) {
            return Wedge::Below;
        }
        // the axis inside the pyramid, or nearly on an edge plane: every sector
        let (mut pos, mut neg) = (true, true);
        for ei in e {
            let s = dot(ei, &ax[2]);
            let m = ei.iter().map(|c| c.unsigned_abs()).max().unwrap_or(0) as i128;
            if s.abs() <= m << 20 {
                return Wedge::Full;
            }
            pos &= s > 0;
            neg &= s < 0;
        }
        if pos || neg {
            return Wedge::Full;
        }
        let mut phi = [0i64; 4];
        for (p, v) in phi.iter_mut().zip(f) {
            let rho = v[0].unsigned_abs().max(v[1].unsigned_abs());
            if rho == 0 || rho < norm(v) >> 6 {
                return Wedge::Full;
            }
            // block floating point: the larger of x, y into 29 bits (atan2 ignores the scale;
            // the vectoring's gain of 1.65 then stays inside Q2.30)
            let shift = (128 - rho.leading_zeros()).saturating_sub(29);
            *p = self.azimuth((v[0] >> shift) as i32, (v[1] >> shift) as i32);
        }
        let phi = &phi[..f.len()];
        let wrap = |d: i64| {
            if d > PI {
                d - 2 * PI
            } else if d <= -PI {
                d + 2 * PI
            } else {
                d
            }
        };
        let (mut lo, mut hi) = (0i64, 0i64);
        for p in &phi[1..] {
            let d = wrap(p - phi[0]);
            lo = lo.min(d);
            hi = hi.max(d);
        }
        if hi - lo + 2 * MARGIN >= PI {
            return Wedge::Full;
        }
        let s_lo = self.sector_of(phi[0] + lo - MARGIN);
        let s_hi = self.sector_of(phi[0] + hi + MARGIN);
        let len = (s_hi + self.sectors - s_lo) % self.sectors + 1;
        Wedge::Sectors {
            lo: s_lo as u8,
            len: len as u8,
        }
    }
}
