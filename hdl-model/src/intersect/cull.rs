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
//!    frame; three dot products per corner, on narrow words: below);
//! 2. **below the horizon** if every corner has f_i · ẑ < −|f_i|∞ 2^-9: a hemisphere ray
//!    (d_ref · ẑ ≥ 0) cannot reach it;
//! 3. **full** (every sector) if the pyramid contains the axis or comes within 2^-10 of it (every
//!    e_i · w > −|e_i|∞ 2^-10, or every one < |e_i|∞ 2^-10), or if a corner may lie within 2^-4
//!    of the axis, where its azimuth is ill-conditioned (its bands then from the first);
//! 4. otherwise the azimuths φ_i = atan2(f_i.y, f_i.x) (a vectoring CORDIC of the unit's own,
//!    14 iterations on 20 bits, its input normalised: [`NORM_TOP`]), their smallest enclosing
//!    arc widened by [`MARGIN`] on each side, and the sectors its ends fall in.
//!
//! 5. **polar bands**: the corners' polar angles θ_i (a second vectoring, of (z, ρ)), and the
//!    polygon's θ range bounded from its boundary (θ has no extremum inside the polygon but at
//!    the poles): along an edge from p to q of length ℓ ≤ |θ_p − θ_q| + |φ_q − φ_p|, θ stays
//!    above (θ_p + θ_q − ℓ)/2, so above min − |Δφ|/2 of its ends (an arc bulges towards the
//!    pole); with the pole inside, from 0. Above, θ is at most the corners' largest (since
//!    issue 19's fourth round; before, max + |Δφ|/2): along an arc between directions above the
//!    horizon θ stays at or below the larger θ of its ends (`polar_range`). The range, widened
//!    by [`MARGIN`], gives the patch's bands among [`BANDS`] equal bands of θ over [0, π/2].
//!
//! A lane is handed the patches whose sector range holds the ray's sector and whose band range
//! holds its band (in hardware: a sector bitmap AND a band bitmap, walked word by word by a
//! priority encoder, [`super::bitmap_walk`]). A ray's sector and band come from its reference
//! direction by the same vectoring CORDIC (in parallel with the rotator, so it adds no
//! latency). Rays within 2^-5 of the pole (sin θ < 2^-5), rays below the horizon and rays not
//! rotated by a frame (TRACE entries) are not culled: they are handed every active patch.
//!
//! **Narrow arithmetic.** Culling only has to be conservative: a lane's candidates may be a
//! superset of the patches a ray can meet, since the edge test decides the hits. So the set-up
//! units form the corner transform and the axis test from 18-bit signed words (one 18 × 18
//! product each, a DSP tile or 324 LUT4s, instead of 34 × 32 and 62 × 32 ones): each corner
//! vector by a power of two of its own (only its direction matters), the axes as Q2.16
//! (`>> 14`), the edge normals as the lanes' coarse words. With floor truncation the exact
//! value (scaled) is within B = Σ(|x'| + |y'| + 1) of the narrow dot product (as for the coarse
//! edge test, [`super::coarse`]; for the edge words, whose error is below 2^κ rather than 1,
//! B = 2^κ Σ(|w̃| + 1) + Σ|e'|), and every decision is widened by that bound: a patch is
//! below the horizon only if certainly so (and by 2^-9 instead of 2^-10), a corner counts as
//! next to the axis if it may be within 2^-4 of it plus B, the axis test's thresholds are moved
//! out by B. The corners' direction error is then at most B/ρ ≤ 2^-7.8 rad in azimuth (|ã|∞ ≥
//! 2^16, ρ ≥ 2^-4 |f|∞) and less in θ, the vectorings (14 iterations on 20 bits, [`CULL_CORDIC`],
//! each input scaled by a power of two of its own, [`NORM_TOP`]) add at most [`VECTOR_ERROR`]
//! = 2^-12 each, a corner's and a ray's 2^-11, the wrap of a wedge across ±π by the word's 2π
//! (`PI`) at most 2^-17, and [`MARGIN`] is 2^-7 rad: 2^-9 (the exact products' margin, which
//! covers the rotator) + 2^-7.8 + 2^-11 + 2^-17 = 6.9·10⁻³ < 7.8·10⁻³. (Until session 26 the
//! vectorings were 18 iterations on 24 bits, fed the corner scaled by its largest component, so
//! that a corner 2^-4 from the axis lost 4 bits: 14 on 20 did not fit the margin that way.) A
//! test (`narrow_reach_holds_the_wide_one`) checks on random patches, origins and frames that
//! the reach holds the one the exact products and the 32-bit vectorings give (with the same
//! polar bound and near-axis bands, at the old margin and near-axis threshold), and
//! (`culled_rays_inside_a_patch_are_handed_it`) that a ray inside a patch's pyramid is in its
//! reach.
//!
//! Why the margin is safe against the rotator: everything the test compares is within about
//! 2^-21 rad of exact (the rotator's truncation, the axes'), and an azimuth error is at most the
//! direction error over sin θ, so within 2^-16 rad for the rays that are culled (rays within
//! 2^-5 of the pole are not), and culling is applied only with CORDIC words of at least
//! [`MIN_CULL_WIDTH`] bits. Culling therefore only removes patches the edge test would reject:
//! every hit is the one the full scan finds, which the tests check against the unculled model.

use super::angle_memo::AngleMemo;
use super::coarse::{block18, Coarse, KAPPA_DECLINE};
use crate::cordic::rom::HALF_PI_Q62;
use crate::cordic::{CordicConfig, CordicPipe, CordicSlot, Mode};
use crate::format::{Angle, Unit};

/// The widening of a wedge (and a band range) on each side, in Q3.29 radians: 2^-7 rad (see
/// the module doc, "Narrow arithmetic").
pub const MARGIN: i64 = 1 << 22;
/// The culling unit's vectoring CORDIC (corners' and rays' azimuths and polar angles): 14
/// iterations on 20-bit words, fed [`NORM_TOP`]-normalised vectors (18 iterations on 24 bits
/// until session 26, fed vectors normalised by the corner's largest component, so that a
/// corner next to the axis reached the vectoring with 4 bits fewer).
pub const CULL_CORDIC: CordicConfig = CordicConfig {
    iterations: 14,
    width: 20,
};
/// Clocks from a patch's last corner to its reach, as the RTL (`hdl-model/rtl/cull_reach.v`)
/// pipelines them for 100 MHz: the corner's block scaling (3), its products and bounds (2), its
/// decisions (3), the two vectorings ([`CULL_CORDIC`]) each after a normalisation of 3 clocks
/// (`cull_angles.v`), the patch gathered (1), its wedge and polar range (7), the ends' sectors
/// and bands (4: one `cull_bin.v`'s 3 for both ends, the high end a clock after the low) and
/// the answer's register (1): 63. (62 until session 45, with a bin unit for each end; until
/// session 27 the model charged two vectorings and 5 clocks, 41 in all, before the RTL
/// existed.) In the compact set-up unit a corner first waits for its edge's words:
/// `intersect::CULL_SETUP_LATENCY`.
pub const REACH_LATENCY: u32 = 2 * crate::cordic::pipe_latency(CULL_CORDIC.iterations) + 27;
/// Clocks from a reference direction to its sector and band, as the RTL (`cull_ray.v`) takes
/// them: the two vectorings ([`CULL_CORDIC`]) each after a normalisation of 3 clocks, and the
/// bins (3): 45. The unit runs beside the rotator from the clock the direction enters it, so a
/// culled ray waits only where the rotator is shorter (CONFIG.ITER below 11).
pub const RAY_LATENCY: u32 = 2 * crate::cordic::pipe_latency(CULL_CORDIC.iterations) + 9;
/// Every vectoring's input is scaled by a power of two (either way: a leading-one detector and
/// shifters) so that its larger component is in [2^(NORM_TOP − 1), 2^NORM_TOP): the most a
/// Q2.30 container holds after the vectoring's gain of 1.65 on up to √2 times that. Its error
/// is then that of the word, whatever the vector's length (measured: at most 1.7·10⁻⁴ rad,
/// 2^-12.5, `normalised_vectorings_stay_within_their_budget`).
pub const NORM_TOP: u32 = 29;
/// The bound a test holds a normalised vectoring's angle error to: 2^-12 rad (Q3.29 bits).
pub const VECTOR_ERROR: i64 = 1 << 17;
/// Bits dropped from the frame's axes (Q2.30) for the corner transform and the axis test:
/// Q2.16 words of 18 bits.
const AXIS_SHIFT: u32 = 14;
/// A corner that may lie within 2^-NEAR_AXIS (of |f|∞) of the axis puts the patch in every
/// sector.
const NEAR_AXIS: u32 = 4;
/// π in Q3.29 rounded to the vectorings' grid (Q3.17 at [`CULL_CORDIC`]'s 20 bits): every
/// angle the reach and the bins meet is then on that grid (the vectorings' angles are, and so
/// are [`MARGIN`], this and the bulges, [`ANGLE_GRID`]), so the RTL takes them in 23 bits, not
/// 35 (session 45; π to the container's last bit before). Rays and patches are binned by the
/// same π, so the sectors and bands still partition the circle; the wrap's 2π is off the true
/// one by under 2^-17 rad, which the margin's account covers.
const PI: i64 = crate::format::rom_round(2 * HALF_PI_Q62, CULL_CORDIC.width - 3, 29) as i64;
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

impl Wedge {
    /// Its sector rows at `sectors` sectors, in the order the set-up writes them: none below
    /// the horizon, every one for a wedge of every sector, else `lo, lo + 1, …` modulo
    /// `sectors`.
    pub fn sectors(self, sectors: u32) -> impl Iterator<Item = u32> {
        let (lo, len) = match self {
            Wedge::Below => (0, 0),
            Wedge::Full => (0, sectors),
            Wedge::Sectors { lo, len } => (lo as u32, len as u32),
        };
        (0..len).map(move |k| (lo + k) % sectors)
    }

    /// Its words as the RTL's ports and the co-simulation's vectors carry them: kind (0 below
    /// the horizon, 1 every sector, 2 a wedge), first sector and length.
    pub fn words(self) -> (u8, u8, u8) {
        match self {
            Wedge::Below => (0, 0, 0),
            Wedge::Full => (1, 0, 0),
            Wedge::Sectors { lo, len } => (2, lo, len),
        }
    }
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
            vector: CordicPipe::new(Mode::Vector, CULL_CORDIC),
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

    /// atan2(y, x) of any (x, y) (Q3.29 bits), normalised ([`NORM_TOP`]) into the vectoring,
    /// with the magnitude it returns and the shift s it was taken at (the magnitude is
    /// |(x, y)|·2^s).
    fn azimuth(&self, x: i128, y: i128) -> (i64, i128, i32) {
        let s = norm_shift(x, y);
        let (a, r) = self.vector(scale(x, s) as i32, scale(y, s) as i32);
        (a, r as i128, s)
    }

    /// A corner's azimuth and polar angle (Q3.29 bits) from its frame coordinates `v`, each
    /// vectoring's input normalised on its own (the angles ignore the scale).
    fn angles(&self, v: [i64; 3]) -> (i64, i64) {
        let (az, r, s) = self.azimuth(v[0] as i128, v[1] as i128);
        (az, self.polar(v[2] as i128, r, s))
    }

    /// The polar angle atan2(r, z) of a vector whose azimuth vectoring returned magnitude `r` at
    /// shift `s` (so z is taken at that scale, then the pair normalised for the second vectoring).
    fn polar(&self, z: i128, r: i128, s: i32) -> i64 {
        self.azimuth(scale(z, s), r).0
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
        self.ray_bin_remembering(d, &mut AngleMemo::none())
    }

    /// [`CullUnit::ray_bin`], taking the ray's angles from `memo` where it has them (a
    /// hemisphere's reference directions are the same at every origin: [`AngleMemo`]).
    pub fn ray_bin_remembering(&self, d: [Unit; 3], memo: &mut AngleMemo) -> Option<(u32, u32)> {
        let [x, y, z] = d.map(|c| c.to_bits());
        let rho = x.unsigned_abs().max(y.unsigned_abs());
        if self.sectors == 0 || z < 0 || rho < 1 << 25 {
            return None;
        }
        let (phi, theta) = memo.angles([x, y, z].map(i64::from), |v| self.angles(v));
        Some((self.sector_of(phi), Self::band_of(theta)))
    }

    /// The wedge of a planar patch with corner vectors `a` (Q8.24, relative to the origin) and
    /// coarse edge normals `coarse` (the lanes' 18-bit words: e = 2^s·(ce + δ), |δ_c| < 2^κ,
    /// inside iff d · e ≥ 0), in the frame with axes `axes` (u, v, w: Q2.30).
    ///
    /// Every product is of two 18-bit signed words (module doc, "Narrow arithmetic"), and every
    /// decision is widened by the bound on its error, so the reach holds the reach the exact
    /// products would give (`narrow_reach_holds_the_wide_one`).
    pub fn reach(&self, a: &[[i64; 3]], coarse: &Coarse, axes: &[[Unit; 3]; 3]) -> Reach {
        self.reach_remembering(a, coarse, axes, &mut AngleMemo::none())
    }

    /// [`CullUnit::reach`], taking the corners' angles from `memo` where it has them (the same
    /// answer: [`AngleMemo`]).
    pub fn reach_remembering(
        &self,
        a: &[[i64; 3]],
        coarse: &Coarse,
        axes: &[[Unit; 3]; 3],
        memo: &mut AngleMemo,
    ) -> Reach {
        let ax = axes.map(|v| v.map(|c| (c.to_bits() >> AXIS_SHIFT) as i64));
        // corners in the frame, each on its own scale: f = ã · x̃ within b of the exact
        // (a · x) / 2^(k + AXIS_SHIFT), componentwise
        let mut f = [[0i64; 3]; 4];
        let mut b = [[0i64; 3]; 4];
        for ((fi, bi), ai) in f.iter_mut().zip(b.iter_mut()).zip(a) {
            let (w, _) = block18(ai);
            for k in 0..3 {
                fi[k] = (0..3).map(|c| w[c] * ax[k][c]).sum();
                bi[k] = (0..3).map(|c| w[c].abs() + ax[k][c].abs() + 1).sum();
            }
        }
        let (f, b) = (&f[..a.len()], &b[..a.len()]);
        let norm = |v: &[i64; 3]| v.iter().map(|c| c.abs()).max().unwrap_or(0);
        // below the horizon only if certainly so: z + b < −(|f|∞ + b) 2^-9
        if f.iter()
            .zip(b)
            .all(|(v, e)| v[2] + e[2] < -((norm(v) + norm(e)) >> 9))
        {
            return Reach {
                wedge: Wedge::Below,
                ..Reach::ALL
            };
        }
        // corners in spherical coordinates (a corner that may be within 2^-NEAR_AXIS of the
        // axis has no useful azimuth: every sector, bands from 0)
        let (mut phi, mut theta) = ([0i64; 4], [0i64; 4]);
        let mut near = false;
        for (((p, t), v), e) in phi.iter_mut().zip(theta.iter_mut()).zip(f).zip(b) {
            let rho = v[0].abs().max(v[1].abs());
            let (n, eb) = (norm(v), norm(e));
            near |= rho < eb + ((n + eb) >> NEAR_AXIS);
            (*p, *t) = memo.angles(*v, |v| self.angles(v));
        }
        let phi = &phi[..f.len()];
        let (lo_t, hi_t) = polar_range(phi, &theta[..f.len()]);
        let (pos, neg) = axis_sides(coarse, a.len(), &ax[2]);
        let lo_t = if pos || near { 0 } else { lo_t };
        self.reach_of(phi, (lo_t, hi_t), pos || neg || near, MARGIN)
    }

    /// The reach of a patch whose corners lie at azimuths `phi` and between polar angles
    /// `lo_t..hi_t`, each widened by `margin`: its bands, and its sectors unless the patch
    /// surrounds the axis (`around`) or spans half a turn or more.
    fn reach_of(&self, phi: &[i64], (lo_t, hi_t): (i64, i64), around: bool, margin: i64) -> Reach {
        let full = Reach {
            wedge: Wedge::Full,
            band_lo: Self::band_of(lo_t - margin) as u8,
            band_hi: Self::band_of(hi_t + margin) as u8,
        };
        if around {
            return full;
        }
        let (mut lo, mut hi) = (0i64, 0i64);
        for p in &phi[1..] {
            let d = wrap(p - phi[0]);
            lo = lo.min(d);
            hi = hi.max(d);
        }
        if hi - lo + 2 * margin >= PI {
            return full;
        }
        let s_lo = self.sector_of(phi[0] + lo - margin);
        let s_hi = self.sector_of(phi[0] + hi + margin);
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

/// The shift that brings the larger of |x|, |y| into [2^(NORM_TOP − 1), 2^NORM_TOP) (0 for a
/// zero vector).
fn norm_shift(x: i128, y: i128) -> i32 {
    let m = x.unsigned_abs().max(y.unsigned_abs());
    if m == 0 {
        return 0;
    }
    NORM_TOP as i32 - (128 - m.leading_zeros()) as i32
}

/// v·2^s, truncated (towards −∞) when s < 0.
fn scale(v: i128, s: i32) -> i128 {
    if s >= 0 {
        v << s
    } else {
        v >> -s
    }
}

/// Whether the axis +z (`pos`) or −z (`neg`) may lie in the pyramid of the patch's first
/// `sides` coarse edges, or within 2^-10 of it: then it is in every sector. From the words and
/// w̃ = w / 2^AXIS_SHIFT: with e = 2^s (ce + δ), |δ_c| < 2^κ, e · w / 2^(s + AXIS_SHIFT) is
/// within B = 2^κ Σ(|w̃| + 1) + Σ|ce| of A = ce · w̃, and |e|∞ 2^-10 / 2^(s + AXIS_SHIFT) is below
/// (|ce|∞ + 2^κ) 2^6, so the exact test's pos (neg) implies A + B > −(|ce|∞ + 2^κ) 2^6
/// (A − B < (|ce|∞ + 2^κ) 2^6). Words that bound nothing ([`KAPPA_DECLINE`]) allow both.
fn axis_sides(coarse: &Coarse, sides: usize, w: &[i64; 3]) -> (bool, bool) {
    if coarse.kappa >= KAPPA_DECLINE {
        return (true, true);
    }
    let wsum: i64 = w.iter().map(|c| c.abs() + 1).sum();
    let (mut pos, mut neg) = (true, true);
    for ei in &coarse.words[..sides] {
        let e = ei.map(|c| c as i64);
        let dot: i64 = (0..3).map(|c| e[c] * w[c]).sum();
        let bound = (wsum << coarse.kappa) + e.iter().map(|c| c.abs()).sum::<i64>();
        let norm = e.iter().map(|c| c.abs()).max().unwrap_or(0);
        let m = (norm + (1 << coarse.kappa)) << 6;
        pos &= dot + bound > -m;
        neg &= dot - bound < m;
    }
    (pos, neg)
}

/// The polar range of a patch from its corners' azimuths and polar angles (Q3.29 bits). Below:
/// along an edge from p to q (a great-circle arc of length ℓ ≤ |θ_p − θ_q| + |φ_q − φ_p|) θ
/// stays above (θ_p + θ_q − ℓ)/2, so above min − |Δφ|/2 (the arc bulges towards the pole);
/// the pole itself is the axis test's. Above: if every corner is above the horizon, so is the
/// whole pyramid (its directions are the corners' positive combinations), and on a great circle
/// z = A cos(s − s0) has no minimum inside an arc shorter than π whose ends have z ≥ 0, nor z a
/// minimum inside the polygon but at −z: θ is at most the corners' largest; if a corner is below
/// the horizon, that largest is above π/2 and the band is the last anyway. An azimuth of a
/// corner next to the axis is unreliable, which widens only the lower bound (the caller takes
/// it from 0 then).
fn polar_range(phi: &[i64], theta: &[i64]) -> (i64, i64) {
    let (mut lo_t, mut hi_t) = (i64::MAX, i64::MIN);
    for k in 0..phi.len() {
        let j = (k + 1) % phi.len();
        let bulge = half_up(wrap(phi[j] - phi[k]).abs());
        lo_t = lo_t.min(theta[k].min(theta[j]) - bulge);
        hi_t = hi_t.max(theta[k]);
    }
    (lo_t, hi_t)
}

/// Bits of Q3.29 below the culling vectorings' angle word ([`CULL_CORDIC`]'s Q3.17): the grid
/// every angle of the reach is on.
const ANGLE_GRID: u32 = 32 - CULL_CORDIC.width;
// the RTL carries the reach's angles without these bits: its constants must be on the grid
const _: () = assert!(MARGIN % (1 << ANGLE_GRID) == 0 && PI % (1 << ANGLE_GRID) == 0);

/// Half of a nonnegative angle (Q3.29 bits), rounded up to the vectorings' grid
/// ([`ANGLE_GRID`]): ⌈⌈a⌉/2⌉ in the grid's units, at least a/2, so a bulge stays conservative
/// and the RTL's halving of a word (`cull_reach.v`, (|e| + 1) >>> 1) is the same. (a/2 on
/// Q3.29, half a word's LSB below it for an odd word, until the review of session 45.)
fn half_up(a: i64) -> i64 {
    let words = (a + (1 << ANGLE_GRID) - 1) >> ANGLE_GRID;
    ((words + 1) >> 1) << ANGLE_GRID
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

#[cfg(test)]
pub(crate) mod tests {
    extern crate std;
    use super::*;
    use crate::intersect::coarse::{coarse_edge, narrow_edge};
    use crate::intersect::tests::Rng;
    use std::vec;
    use std::vec::Vec;

    /// The exact products' margin (2^-9 rad), before the narrow arithmetic.
    const WIDE_MARGIN: i64 = 1 << 20;

    /// The reach as the exact products (34 × 32 and 62 × 32) and 32-bit vectorings of 24
    /// iterations gave it before the narrow arithmetic (its margin 2^-9, a corner next to the
    /// axis within 2^-6), with the same polar bound and near-axis bands as the narrow unit:
    /// the reference the narrow unit must hold.
    #[allow(
        clippy::needless_range_loop,
        reason = "the reference is the code it replaced, as it was"
    )]
    fn reach_wide(unit: &CullUnit, a: &[[i64; 3]], e: &[[i64; 3]], axes: &[[Unit; 3]; 3]) -> Reach {
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
        // corners in spherical coordinates (a corner next to the axis: no useful azimuth)
        let (mut phi, mut theta) = ([0i64; 4], [0i64; 4]);
        let mut near = false;
        for ((p, t), v) in phi.iter_mut().zip(theta.iter_mut()).zip(f) {
            let rho = v[0].unsigned_abs().max(v[1].unsigned_abs());
            near |= rho == 0 || rho < norm(v) >> 6;
            // block floating point: the largest component into 27 bits (the angles ignore the
            // scale; the vectorings' gain of 1.65 on |v| ≤ √3 · 2^27 stays inside Q2.30)
            let shift = (128 - norm(v).leading_zeros()).saturating_sub(27);
            let (az, r) = unit.vector((v[0] >> shift) as i32, (v[1] >> shift) as i32);
            *p = az;
            *t = unit.vector((v[2] >> shift) as i32, r).0;
        }
        let phi = &phi[..f.len()];
        let (mut lo_t, hi_t) = polar_range(phi, &theta[..f.len()]);
        // the axis (+z or −z) inside the pyramid, or within 2^-10 of it: every sector
        let (mut pos, mut neg) = (true, true);
        for ei in e {
            let s = dot(ei, &ax[2]);
            let m = (ei.iter().map(|c| c.unsigned_abs()).max().unwrap_or(0) as i128) << 20;
            pos &= s > -m;
            neg &= s < m;
        }
        if pos || near {
            lo_t = 0;
        }
        unit.reach_of(phi, (lo_t, hi_t), pos || neg || near, WIDE_MARGIN)
    }

    type V = [f64; 3];
    fn cross(u: V, v: V) -> V {
        [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ]
    }
    fn dot(u: V, v: V) -> f64 {
        u[0] * v[0] + u[1] * v[1] + u[2] * v[2]
    }
    fn unit(v: V) -> V {
        let l = dot(v, v).sqrt();
        v.map(|c| c / l)
    }

    /// A random case: corner vectors (Q8.24, from the origin), exact edge normals (inside iff
    /// d · e ≥ 0), the frame's axes (Q2.30 and f64), the corners in f64; `None` when the origin
    /// is (nearly) in the patch's plane.
    #[allow(clippy::type_complexity, reason = "a test case, destructured at once")]
    fn case(
        rng: &mut Rng,
    ) -> Option<(Vec<[i64; 3]>, Vec<[i64; 3]>, [[Unit; 3]; 3], [V; 3], Vec<V>)> {
        // a random rotation (unit quaternion) for the frame
        let rot = rotation([rng.sym(), rng.sym(), rng.sym(), rng.sym()]);
        let axes = rot.map(|r| r.map(Unit::from_num));
        // an origin and a patch of any size from 2^-9 to 2 units, near or far
        let o: V = [rng.sym(), rng.sym(), rng.sym()];
        let c: V = [rng.sym(), rng.sym(), rng.sym()].map(|v| 2.0 * v);
        let size = (2.0f64).powf(-9.0 + 10.0 * rng.unit());
        let p: V = [rng.sym(), rng.sym(), rng.sym()].map(|v| v * size);
        let r: V = [rng.sym(), rng.sym(), rng.sym()].map(|v| v * size);
        let corners: Vec<V> = if rng.next().is_multiple_of(3) {
            vec![c, add(c, p), add(c, r)]
        } else {
            vec![
                sub(sub(c, p), r),
                sub(add(c, p), r),
                add(add(c, p), r),
                add(sub(c, p), r),
            ]
        };
        let fix = |v: f64| (v * (1u64 << 24) as f64).round() as i64;
        let oi = o.map(fix);
        let a: Vec<[i64; 3]> = corners
            .iter()
            .map(|v| core::array::from_fn(|k| fix(v[k]) - oi[k]))
            .collect();
        let n = cross(sub(corners[1], corners[0]), sub(corners[2], corners[0]));
        let h = dot(unit(n), sub(corners[0], o));
        if h.abs() < 1e-6 {
            return None;
        }
        let s = if h > 0.0 { 1i128 } else { -1 };
        let m = a.len();
        let e: Vec<[i64; 3]> = (0..m)
            .map(|k| {
                let (u, v) = (a[k].map(|c| c as i128), a[(k + 1) % m].map(|c| c as i128));
                [
                    u[1] * v[2] - u[2] * v[1],
                    u[2] * v[0] - u[0] * v[2],
                    u[0] * v[1] - u[1] * v[0],
                ]
                .map(|c| (c * s) as i64)
            })
            .collect();
        // the inside is where d · e ≥ 0: flip all if the centroid is outside
        let g: [i128; 3] = core::array::from_fn(|k| a.iter().map(|v| v[k] as i128).sum());
        let ge: i128 = (0..3).map(|k| g[k] * e[0][k] as i128).sum();
        let e = if ge < 0 {
            e.iter().map(|v| v.map(|c| -c)).collect()
        } else {
            e
        };
        let rel: Vec<V> = corners.iter().map(|v| sub(*v, o)).collect();
        Some((a, e, axes, rot, rel))
    }
    fn add(u: V, v: V) -> V {
        [u[0] + v[0], u[1] + v[1], u[2] + v[2]]
    }
    fn sub(u: V, v: V) -> V {
        [u[0] - v[0], u[1] - v[1], u[2] - v[2]]
    }
    /// The rows of the rotation of quaternion `q` (normalised first): a frame's axes.
    pub(crate) fn rotation(q: [f64; 4]) -> [[f64; 3]; 3] {
        let [w0, x, y, z] = unit4(q);
        [
            [
                1.0 - 2.0 * (y * y + z * z),
                2.0 * (x * y + w0 * z),
                2.0 * (x * z - w0 * y),
            ],
            [
                2.0 * (x * y - w0 * z),
                1.0 - 2.0 * (x * x + z * z),
                2.0 * (y * z + w0 * x),
            ],
            [
                2.0 * (x * z + w0 * y),
                2.0 * (y * z - w0 * x),
                1.0 - 2.0 * (x * x + y * y),
            ],
        ]
    }

    fn unit4(q: [f64; 4]) -> [f64; 4] {
        let l = q.iter().map(|c| c * c).sum::<f64>().sqrt();
        q.map(|c| c / l)
    }

    /// The lanes' words of a case's edges as the wide datapath truncates them (`narrow`
    /// false) or as the compact set-up unit forms them from the corners (true).
    fn coarse_of(a: &[[i64; 3]], e: &[[i64; 3]], narrow: bool) -> Coarse {
        let mut c = Coarse::default();
        for k in 0..a.len() {
            if !narrow {
                c.words[k] = coarse_edge(&e[k]);
                continue;
            }
            // the case's e is ±(a_k × a_k+1): negated where it points against the product
            let (u, v) = (a[k], a[(k + 1) % a.len()]);
            let (ui, vi) = (u.map(|c| c as i128), v.map(|c| c as i128));
            let cross = [
                ui[1] * vi[2] - ui[2] * vi[1],
                ui[2] * vi[0] - ui[0] * vi[2],
                ui[0] * vi[1] - ui[1] * vi[0],
            ];
            let along: i128 = (0..3).map(|c| cross[c] * e[k][c] as i128).sum();
            let (w, kappa) = narrow_edge(&u, &v, 0, along < 0);
            c.words[k] = w;
            c.kappa = c.kappa.max(kappa);
        }
        c
    }

    fn sector_mask(r: &Reach, sectors: u32) -> u64 {
        r.wedge.sectors(sectors).fold(0, |m, s| m | 1u64 << s)
    }

    /// The narrow unit's reach holds the exact products' on random patches (triangles and
    /// quads of every size, near and far), origins and frames: never below the horizon where
    /// that one is not, every sector and band of it.
    #[test]
    fn narrow_reach_holds_the_wide_one() {
        let mut rng = Rng(0x2545_f491_4f6c_dd1d);
        let (mut cases, mut sectored) = (0u32, 0u32);
        for sectors in [8u32, 32, 64] {
            let narrow = CullUnit::new(sectors);
            let wide = CullUnit {
                sectors,
                vector: CordicPipe::new(Mode::Vector, CordicConfig::DEFAULT),
            };
            for _ in 0..40_000 {
                let Some((a, e, axes, _, _)) = case(&mut rng) else {
                    continue;
                };
                let ce = coarse_of(&a, &e, cases % 2 == 1);
                let w = reach_wide(&wide, &a, &e, &axes);
                let n = narrow.reach(&a, &ce, &axes);
                cases += 1;
                if w.wedge == Wedge::Below {
                    continue;
                }
                sectored += matches!(w.wedge, Wedge::Sectors { .. }) as u32;
                let (mw, mn) = (sector_mask(&w, sectors), sector_mask(&n, sectors));
                assert_eq!(mw & !mn, 0, "sectors: wide {w:?} narrow {n:?} a {a:?}");
                assert!(
                    n.band_lo <= w.band_lo && n.band_hi >= w.band_hi,
                    "bands: wide {w:?} narrow {n:?} a {a:?}"
                );
            }
        }
        assert!(
            cases > 100_000 && sectored > 20_000,
            "{cases} cases, {sectored} in sectors"
        );
    }

    /// Every vectoring is normalised before the CORDIC, so its angle is within [`VECTOR_ERROR`]
    /// of atan2 whatever the vector's length: the budget the module doc's margin counts, for
    /// vectors of every length from one bit to 2^40 and every direction.
    #[test]
    fn normalised_vectorings_stay_within_their_budget() {
        let unit = CullUnit::new(32);
        let mut rng = Rng(0x5851_f42d_4c95_7f2d);
        let mut worst = 0f64;
        for k in 0..300_000u32 {
            let a = (rng.unit() * 2.0 - 1.0) * core::f64::consts::PI;
            let len = (2.0f64).powf(1.0 + 39.0 * rng.unit());
            let (x, y) = ((a.cos() * len) as i128, (a.sin() * len) as i128);
            if x == 0 && y == 0 {
                continue;
            }
            let (got, _, _) = unit.azimuth(x, y);
            let want = (y as f64).atan2(x as f64);
            let mut d = (got as f64 / (1u64 << 29) as f64 - want).abs();
            if d > core::f64::consts::PI {
                d = 2.0 * core::f64::consts::PI - d;
            }
            worst = worst.max(d);
            // the polar vectoring of the same vector's z against its magnitude
            if k % 2 == 0 {
                let z = ((rng.unit() * 2.0 - 1.0) * len * 4.0) as i128;
                let (_, r, s) = unit.azimuth(x, y);
                let got = unit.polar(z, r, s) as f64 / (1u64 << 29) as f64;
                let want = ((x * x + y * y) as f64).sqrt().atan2(z as f64);
                worst = worst.max((got - want).abs());
            }
        }
        let bound = VECTOR_ERROR as f64 / (1u64 << 29) as f64;
        assert!(worst <= bound, "worst {worst:e} rad, budget {bound:e}");
        std::println!("worst vectoring error {worst:e} rad");
    }

    /// A culled ray through a point of a patch is handed the patch: its sector and band are in
    /// the patch's reach (points near the edges and corners included).
    #[test]
    fn culled_rays_inside_a_patch_are_handed_it() {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let unit32 = CullUnit::new(32);
        let mut culled = 0u32;
        for _ in 0..20_000 {
            let Some((a, e, axes, rot, rel)) = case(&mut rng) else {
                continue;
            };
            let ce = coarse_of(&a, &e, rng.next() % 2 == 1);
            let reach = unit32.reach(&a, &ce, &axes);
            let mask = sector_mask(&reach, 32);
            for _ in 0..8 {
                // a point of the patch: weights of the corners, some of them tiny
                let mut wts: Vec<f64> = rel
                    .iter()
                    .map(|_| {
                        let u = rng.unit();
                        if rng.next().is_multiple_of(3) {
                            u * 1e-4
                        } else {
                            u
                        }
                    })
                    .collect();
                let sum: f64 = wts.iter().sum();
                wts.iter_mut().for_each(|w| *w /= sum);
                let p: V = (0..3)
                    .map(|k| rel.iter().zip(&wts).map(|(v, w)| v[k] * w).sum())
                    .collect::<Vec<f64>>()
                    .try_into()
                    .unwrap();
                let d = unit(p);
                // the exact edge test on d as the rotator hands it (Q2.30)
                let dq = d.map(|c| (c * (1u64 << 30) as f64).round() as i128);
                let inside = e
                    .iter()
                    .all(|v| (0..3).map(|k| dq[k] * v[k] as i128).sum::<i128>() >= 0);
                // the ray's reference direction: d in the frame
                let d_ref = rot.map(|axis| Unit::from_num(dot(axis, d)));
                let Some((s, b)) = unit32.ray_bin(d_ref) else {
                    continue;
                };
                if !inside {
                    continue;
                }
                culled += 1;
                assert!(
                    mask & 1 << s != 0
                        && (reach.band_lo as u32..=reach.band_hi as u32).contains(&b),
                    "ray in sector {s} band {b}, reach {reach:?}, a {a:?}"
                );
            }
        }
        assert!(culled > 20_000, "{culled} culled rays inside");
    }
}
