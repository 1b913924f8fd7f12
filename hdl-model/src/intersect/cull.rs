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
//! 3. **full** (every sector) if the pyramid contains the axis or comes within 2^-10 of it (every
//!    e_i · w > −|e_i|∞ 2^-10, or every one < |e_i|∞ 2^-10), or if a corner lies within 2^-6 of
//!    the axis, where its azimuth is ill-conditioned;
//! 4. otherwise the azimuths φ_i = atan2(f_i.y, f_i.x) (a vectoring CORDIC of the unit's own,
//!    24 iterations on 32 bits), their smallest enclosing arc widened by [`MARGIN`] on each side,
//!    and the sectors its ends fall in.
//!
//! 5. **polar bands**: the corners' polar angles θ_i (a second vectoring, of (z, ρ)), and the
//!    polygon's θ range bounded from its boundary (θ has no extremum inside the polygon but at
//!    the pole): along an edge from p to q of length ℓ ≤ |θ_p − θ_q| + |φ_q − φ_p|, θ stays
//!    within (θ_p + θ_q ∓ ℓ)/2, so within [min − |Δφ|/2, max + |Δφ|/2] of its ends; with the
//!    pole inside, from 0. The range, widened by [`MARGIN`], gives the patch's bands among
//!    [`BANDS`] equal bands of θ over [0, π/2].
//!
//! A lane is handed the patches whose sector range holds the ray's sector and whose band range
//! holds its band (in hardware: a sector bitmap AND a band bitmap, walked by a priority
//! encoder). A ray's sector and band come from its reference direction by the same vectoring CORDIC (in parallel
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
/// Polar bands of θ over [0, π/2].
pub const BANDS: u32 = 16;
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

/// Where a patch can be met: its wedge and its polar bands `lo..=hi`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Reach {
    /// Azimuth sectors.
    pub wedge: Wedge,
    /// First polar band.
    pub band_lo: u8,
    /// Last polar band.
    pub band_hi: u8,
}

impl Reach {
    /// Every sector and band.
    pub const ALL: Reach = Reach {
        wedge: Wedge::Full,
        band_lo: 0,
        band_hi: BANDS as u8 - 1,
    };
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

    /// (atan2(y, x) in Q3.29 bits, |(x, y)|) for x, y in 32-bit containers (any common scale).
    fn vector(&self, x: i32, y: i32) -> (i64, i32) {
        let s = self.vector.eval(CordicSlot {
            x: Unit::from_bits(x),
            y: Unit::from_bits(y),
            z: Angle::ZERO,
            zero: x == 0 && y == 0,
            payload: (),
        });
        (s.z.to_bits() as i64, s.x.to_bits())
    }

    /// The band of a polar angle (Q3.29 bits), clamped to the bands.
    fn band_of(a: i64) -> u32 {
        (a.max(0) * BANDS as i64 * 2 / PI).min(BANDS as i64 - 1) as u32
    }

    /// The sector of an angle (Q3.29 bits, any turn).
    fn sector_of(&self, a: i64) -> u32 {
        let a = (a + PI).rem_euclid(2 * PI);
        ((a * self.sectors as i64) / (2 * PI)).min(self.sectors as i64 - 1) as u32
    }

    /// The sector and band of a hemisphere ray with reference direction `d` (Q2.30), if it is
    /// culled.
    pub fn ray_bin(&self, d: [Unit; 3]) -> Option<(u32, u32)> {
        let [x, y, z] = d.map(|c| c.to_bits());
        let rho = x.unsigned_abs().max(y.unsigned_abs());
        if self.sectors == 0 || z < 0 || rho < 1 << 25 {
            return None;
        }
        let (phi, r) = self.vector(x, y);
        let (theta, _) = self.vector(z, r);
        Some((self.sector_of(phi), Self::band_of(theta)))
    }

    /// The wedge of a planar patch with corner vectors `a` (Q8.24, relative to the origin) and
    /// edge normals `e` (inside iff d · e ≥ 0), in the frame with axes `axes` (u, v, w: Q2.30).
    pub fn reach(&self, a: &[[i64; 3]], e: &[[i64; 3]], axes: &[[Unit; 3]; 3]) -> Reach {
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
            return Reach {
                wedge: Wedge::Below,
                ..Reach::ALL
            };
        }
        // corners in spherical coordinates (a corner next to the axis: no useful bound)
        let (mut phi, mut theta) = ([0i64; 4], [0i64; 4]);
        for ((p, t), v) in phi.iter_mut().zip(theta.iter_mut()).zip(f) {
            let rho = v[0].unsigned_abs().max(v[1].unsigned_abs());
            if rho == 0 || rho < norm(v) >> 6 {
                return Reach::ALL;
            }
            // block floating point: the largest component into 27 bits (the angles ignore the
            // scale; the vectorings' gain of 1.65 on |v| ≤ √3 · 2^27 stays inside Q2.30)
            let shift = (128 - norm(v).leading_zeros()).saturating_sub(27);
            let (az, r) = self.vector((v[0] >> shift) as i32, (v[1] >> shift) as i32);
            *p = az;
            *t = self.vector((v[2] >> shift) as i32, r).0;
        }
        let (phi, theta) = (&phi[..f.len()], &theta[..f.len()]);
        let (mut lo_t, mut hi_t) = (i64::MAX, i64::MIN);
        for k in 0..f.len() {
            let j = (k + 1) % f.len();
            let bulge = wrap(phi[j] - phi[k]).abs() / 2;
            lo_t = lo_t.min(theta[k].min(theta[j]) - bulge);
            hi_t = hi_t.max(theta[k].max(theta[j]) + bulge);
        }
        // the axis (+z or −z) inside the pyramid, or within 2^-10 of it: every sector
        let (mut pos, mut neg) = (true, true);
        for ei in e {
            let s = dot(ei, &ax[2]);
            let m = (ei.iter().map(|c| c.unsigned_abs()).max().unwrap_or(0) as i128) << 20;
            pos &= s > -m;
            neg &= s < m;
        }
        if pos {
            lo_t = 0;
        }
        let band_lo = Self::band_of(lo_t - MARGIN) as u8;
        let band_hi = Self::band_of(hi_t + MARGIN) as u8;
        let full = Reach {
            wedge: Wedge::Full,
            band_lo,
            band_hi,
        };
        if pos || neg {
            return full;
        }
        let (mut lo, mut hi) = (0i64, 0i64);
        for p in &phi[1..] {
            let d = wrap(p - phi[0]);
            lo = lo.min(d);
            hi = hi.max(d);
        }
        if hi - lo + 2 * MARGIN >= PI {
            return full;
        }
        let s_lo = self.sector_of(phi[0] + lo - MARGIN);
        let s_hi = self.sector_of(phi[0] + hi + MARGIN);
        let len = (s_hi + self.sectors - s_lo) % self.sectors + 1;
        Reach {
            wedge: Wedge::Sectors {
                lo: s_lo as u8,
                len: len as u8,
            },
            ..full
        }
    }
}

/// An angle difference (Q3.29 bits) into (−π, π].
fn wrap(d: i64) -> i64 {
    if d > PI {
        d - 2 * PI
    } else if d <= -PI {
        d + 2 * PI
    } else {
        d
    }
}
