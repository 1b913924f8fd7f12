//! The software accelerator: f32 arithmetic on whatever CPU runs the kernel.
//!
//! Hemisphere rays share their origin and come from a fixed direction table, and the engine
//! exploits both (the general-purpose casters it is compared with cannot):
//!
//! 1. Instead of turning 10⁴ rays onto the normal, it turns the few patch vertices the other way
//!    (`Rotation::invert`): the same rotation, applied where it is cheap.
//! 2. Seen from the shared origin a convex polygon is the pyramid spanned by its edges; a ray hits
//!    it iff `d · (a × b) ≥ 0` for every edge (a,b) of its vertices relative to the origin (signs
//!    flipped for a polygon seen from behind). No plane intersection is needed to decide a hit,
//!    and two patches sharing an edge use exactly negated edge normals, so a ray through the edge
//!    hits one of them: closed boxes do not leak.
//! 3. Each patch gets a bounding cone (axis c, half-angle α). Ring j only meets the cone over an
//!    azimuth interval, from `sinθ_j ρ_c cos(φ−φ_c) + cosθ_j c_z ≥ cos α`; only rays in that
//!    interval are tested against the patch. Work then grows with the solid angle the patches
//!    cover, not with rays × patches.
//!
//! Bezier patches take the same cone culling, with the cone of their control points (the
//! surface lies in their convex hull); the rays that survive it are intersected one by one by
//! the subdivision of paper §6.1 ([`Bezier::intersect`]). A patch is never intersected with the
//! hemispheres placed on it (F_ii = 0, see [`Accelerator::set_origin_patch`]).

#[cfg(not(target_os = "none"))]
use super::bvh::Bvh;
#[cfg(not(target_os = "none"))]
use super::simd::{SimdLoop, Vectorizer};
use super::{Accelerator, Hit, Ray};
use crate::geometry::{sqrt, Bezier, Polygon, Subdivision, Vec3};
#[cfg(not(target_os = "none"))]
use crate::geometry::{BezierTree, UvFrame};
use crate::hemisphere::{Hemisphere, Ring};
use crate::patch::{Patch, Shape};
use crate::rotation::Rotation;
use core::ops::Range;
#[cfg(not(target_os = "none"))]
use setup_lanes::{setup_lanes, thin_polygon, Reach, Runs, LANES as LANES_SET_UP, SPAN_RINGS};

#[cfg(not(target_os = "none"))]
mod setup_lanes;

/// Per-patch data for one origin and frame, rebuilt for every hemisphere.
#[derive(Clone, Copy, Debug, Default)]
pub struct LocalPatch {
    edges: [Vec3; 4],
    sides: u8,
    normal: Vec3,
    /// n · (v0 − origin): the signed distance of the plane (its sign says which side we are on).
    h: f32,
    axis: Vec3,
    cos_alpha: f32,
    axis_rho: f32,
    axis_phi: f32,
    /// The cone is too wide to bound usefully: test every ray.
    full: bool,
    active: bool,
    /// A curved patch: rays that pass the cone go to the subdivision intersection.
    curved: bool,
}

impl LocalPatch {
    /// Sets up `poly` as seen from `origin`, in the frame of `rot` (identity frame: pass a
    /// rotation onto +z), with the bounding cone used to cull bundles of rays.
    pub fn setup(poly: &Polygon, origin: Vec3, rot: &Rotation) -> LocalPatch {
        Self::setup_with(poly, origin, Some(rot), true, true)
    }

    /// Sets up any patch as seen from `origin` in the frame of `rot`: polygons as above, Bezier
    /// patches by the cone of their control points.
    pub fn setup_patch(patch: &Patch, origin: Vec3, rot: &Rotation) -> LocalPatch {
        match &patch.shape {
            Shape::Polygon(p) => Self::setup(p, origin, rot),
            Shape::Bezier(b) => Self::setup_curved(b, origin, Some(rot)),
        }
    }

    /// Sets up any patch for rays in every direction from `origin` (the scene's own frame), as
    /// `cast_from` casts them: the same cone, but no cull of patches below the frame's
    /// horizon, which only a hemisphere above +z may skip.
    pub fn setup_patch_any(patch: &Patch, origin: Vec3) -> LocalPatch {
        match &patch.shape {
            Shape::Polygon(p) => Self::setup_with(p, origin, None, true, false),
            Shape::Bezier(b) => Self::setup_curved(b, origin, None),
        }
    }

    fn setup_curved(b: &Bezier, origin: Vec3, rot: Option<&Rotation>) -> LocalPatch {
        let mut lp = LocalPatch {
            active: true,
            curved: true,
            full: true,
            ..LocalPatch::default()
        };
        let turn = |v: Vec3| match rot {
            Some(r) => r.invert(v),
            None => v,
        };
        let mut sum = Vec3::ZERO;
        let mut dirs = [Vec3::ZERO; 16];
        let size = b.bounds().size();
        for (d, p) in dirs.iter_mut().zip(b.cp.iter()) {
            match turn(*p - origin).try_normalize() {
                // an origin on (or next to) the hull: no useful cone
                Some(u) if (*p - origin).length() > 1e-4 * size => *d = u,
                _ => return lp,
            }
            sum += *d;
        }
        if let Some(axis) = sum.try_normalize() {
            let cos_alpha = dirs.iter().fold(1.0f32, |m, d| m.min(axis.dot(*d))) - 1e-4;
            if cos_alpha >= 0.05 {
                lp.full = false;
                lp.axis = axis;
                lp.cos_alpha = cos_alpha;
                lp.axis_rho = sqrt(axis.x * axis.x + axis.y * axis.y);
                lp.axis_phi = libm::atan2f(axis.y, axis.x);
            }
        }
        lp
    }

    /// The set-up for a single ray: edges and plane only (the cone would cost more than it saves).
    pub fn setup_single(poly: &Polygon, origin: Vec3) -> LocalPatch {
        Self::setup_with(poly, origin, None, false, false)
    }

    /// `rot: None` is the scene's own frame (no rotation at all).
    fn setup_with(
        poly: &Polygon,
        origin: Vec3,
        rot: Option<&Rotation>,
        cone: bool,
        horizon: bool,
    ) -> LocalPatch {
        // the vertex loops unrolled for quads and triangles apart (polygons have no other
        // sides): 2-4 % of the cut boxes' pass 1 by `hemi bench rays`
        match poly.sides {
            4 => Self::setup_sides::<4>(poly, origin, rot, cone, horizon),
            _ => Self::setup_sides::<3>(poly, origin, rot, cone, horizon),
        }
    }

    /// [`LocalPatch::setup_with`] for a polygon of `SIDES` sides.
    fn setup_sides<const SIDES: usize>(
        poly: &Polygon,
        origin: Vec3,
        rot: Option<&Rotation>,
        cone: bool,
        horizon: bool,
    ) -> LocalPatch {
        let turn = |v: Vec3| match rot {
            Some(r) => r.invert(v),
            None => v,
        };
        let mut lp = LocalPatch::default();
        let h = poly.normal.dot(poly.v[0] - origin);
        let sides = SIDES;
        let mut local = [Vec3::ZERO; 4];
        let mut length = [0.0f32; 4];
        for ((l, n), v) in local.iter_mut().zip(&mut length).zip(&poly.v).take(sides) {
            *l = turn(*v - origin);
            *n = l.length();
        }
        let scale = length.iter().fold(0.0f32, |m, &n| m.max(n));
        // An origin in the patch's plane (its own patch, coplanar neighbours) can only graze it.
        // (written so that a NaN distance also counts as "in the plane")
        if h.abs().is_nan() || h.abs() <= 1e-6 * scale {
            return lp;
        }
        // Nothing of the patch above the horizon: a hemisphere's rays (all rising) cannot reach
        // it. This catches what the cone test below cannot: a neighbour sharing an edge or a
        // vertex with the origin's patch, whose cone is too wide to bound (on a tessellated
        // sphere, every hemisphere has a dozen).
        if horizon && local.iter().take(sides).all(|l| l.z <= 0.0) {
            return lp;
        }
        let s = if h > 0.0 { 1.0 } else { -1.0 };
        for i in 0..sides {
            lp.edges[i] = local[i].cross(local[(i + 1) % sides]) * s;
        }
        lp.sides = poly.sides;
        lp.normal = turn(poly.normal);
        lp.h = h;
        lp.active = true;
        if !cone {
            lp.full = true;
            return lp;
        }
        // Bounding cone: a convex polygon lies in the cone of its vertex directions when α < 90°.
        // (each vertex's direction computed once, by a reciprocal and three products: the
        // directions bound the cone only, whose margin below dwarfs their rounding; the edges
        // and the plane, which decide the hits, are from `local`)
        let mut unit = [Vec3::ZERO; 4];
        let mut sum = Vec3::ZERO;
        for ((u, l), n) in unit.iter_mut().zip(&local).zip(&length).take(sides) {
            *u = *l * (1.0 / *n);
            sum += *u;
        }
        match sum.try_normalize() {
            Some(axis) => {
                let mut cos_alpha = 1.0f32;
                for u in unit.iter().take(sides) {
                    cos_alpha = cos_alpha.min(axis.dot(*u));
                }
                // widen a little so that rounding never culls a ray the exact test would accept
                cos_alpha -= 1e-4;
                lp.axis = axis;
                lp.cos_alpha = cos_alpha;
                lp.axis_rho = sqrt(axis.x * axis.x + axis.y * axis.y);
                lp.axis_phi = fast_atan2(axis.y, axis.x);
                lp.full = cos_alpha < 0.05;
                if horizon && !lp.full && axis.z < 0.0 {
                    // entirely below the horizon: polar angle of the cone's top edge > 90°
                    let sin_alpha = sqrt((1.0 - cos_alpha * cos_alpha).max(0.0));
                    // max z over the cone = cos(θc − α) = cz cosα + ρ sinα
                    if axis.z * cos_alpha + lp.axis_rho * sin_alpha < -1e-4 {
                        lp.active = false;
                    }
                }
            }
            None => lp.full = true,
        }
        lp
    }

    /// Whether the patch can be hit at all from this origin.
    pub fn is_active(&self) -> bool {
        self.active
    }

    /// The distance to the patch along the local direction `d`, if the ray hits it.
    #[inline(always)]
    pub fn hit(&self, d: Vec3) -> Option<f32> {
        for e in &self.edges[..self.sides as usize] {
            if d.dot(*e) < 0.0 {
                return None;
            }
        }
        let t = self.h / self.normal.dot(d);
        if t > 0.0 && t < f32::INFINITY {
            Some(t)
        } else {
            None
        }
    }

    /// The edge and plane tests of this patch for the rays of quarter `q` of `ring`, as
    /// coefficients of the stored azimuth (c, s): `e·d = A c + B s + C` with
    /// d = (sinθ c', sinθ s', cosθ) and (c', s') = (c, s) turned by q right angles. Unused
    /// edges of a triangle are zero and always pass. Exact negation of an edge carries over to its
    /// coefficients, so shared edges stay watertight.
    #[inline]
    fn coefficients(&self, ring: &Ring, q: u32) -> Coefficients {
        let turn = |v: Vec3| -> [f32; 3] {
            let (a, b) = match q & 3 {
                0 => (v.x, v.y),
                1 => (v.y, -v.x),
                2 => (-v.x, -v.y),
                _ => (-v.y, v.x),
            };
            [ring.sin_theta * a, ring.sin_theta * b, ring.cos_theta * v.z]
        };
        let mut edges = [[0.0f32; 3]; 4];
        for (out, e) in edges.iter_mut().zip(&self.edges[..self.sides as usize]) {
            *out = turn(*e);
        }
        Coefficients {
            edges,
            normal: turn(self.normal),
        }
    }

    /// Which side the rays from this origin see.
    pub fn front(&self) -> bool {
        self.h < 0.0
    }

    /// The indices k of ring `ring` whose rays may hit the patch, as a (possibly wrapping) range
    /// `start..start+len` modulo N_j; `None` when the ring misses the cone. With `widest`
    /// ([`Reach::widest`], one bound a patch) the azimuths are bounded by it rather
    /// than by this ring's own half-width (an arc cosine a ring): a superset of that interval.
    fn ring_interval(&self, ring: &Ring, j: usize, widest: Option<f32>) -> Option<(i64, i64)> {
        let n = ring.count as i64;
        if self.full || j == 0 {
            return Some((0, n));
        }
        let best = ring.sin_theta * self.axis_rho + ring.cos_theta * self.axis.z;
        if best < self.cos_alpha {
            return None;
        }
        if self.axis_rho < 1e-6 {
            return Some((0, n));
        }
        let half = match widest {
            Some(half) => half,
            None => {
                let q = (self.cos_alpha - ring.cos_theta * self.axis.z)
                    / (ring.sin_theta * self.axis_rho);
                if q <= -1.0 {
                    return Some((0, n));
                }
                // fast_acos errs by at most 6.7e-5 rad; the margin keeps the interval
                // conservative
                fast_acos(q.min(1.0)) + 2e-4
            }
        };
        // rays per radian, multiplied where dividing by the spacing cost two divisions a ring:
        // the rounding moves an end by a few ulps of the ray index (under 1e-5 rad), far inside
        // the margin above, and a ray the interval leaves out is outside the widened cone, so
        // it cannot hit the patch
        let per_radian = n as f32 * (1.0 / core::f32::consts::TAU);
        let lo = ceil_to_int((self.axis_phi - half) * per_radian - 0.5);
        let hi = floor_to_int((self.axis_phi + half) * per_radian - 0.5);
        if hi < lo {
            return None;
        }
        let len = (hi - lo + 1).min(n);
        Some((wrap(lo, n), len))
    }
}

#[cfg(not(target_os = "none"))]
impl LocalPatch {
    /// Whether the patch's cone bounds its rays on a table of `r_all` rings: not too wide, its
    /// axis off the pole (else every ring's rays are its candidates).
    #[inline(always)]
    fn cone_bounds(&self, r_all: usize) -> bool {
        !self.full && self.axis_rho >= 1e-6 && r_all > 0
    }

    /// The rings of `rings` (of a table of `r_all` rings, θ_j = j·π/(2R)) whose
    /// [`LocalPatch::ring_interval`] is not empty: contiguous, since cos(θ_j − θ_c) ≥ cos α
    /// holds on one interval of θ around the cone's axis θ_c. Found from the ring `nearest`
    /// the axis ([`Reach::nearest`]) outwards, so a patch costs the rings it spans, not all R.
    #[inline(always)]
    fn ring_span(&self, table: &[Ring], rings: Range<usize>, nearest: usize) -> Range<usize> {
        let r_all = table.len();
        if !self.cone_bounds(r_all) {
            return rings;
        }
        let passes = |j: usize| {
            table.get(j).is_some_and(|ring| {
                ring.sin_theta * self.axis_rho + ring.cos_theta * self.axis.z >= self.cos_alpha
            })
        };
        let seed = [nearest, nearest.wrapping_sub(1), nearest + 1]
            .into_iter()
            .find(|&j| passes(j));
        let Some(seed) = seed else {
            return 0..0;
        };
        let mut lo = seed;
        while lo > 0 && passes(lo - 1) {
            lo -= 1;
        }
        let mut hi = seed + 1;
        while hi < r_all && passes(hi) {
            hi += 1;
        }
        lo.max(rings.start)..hi.min(rings.end)
    }
}

/// Where ring j's rays start in a whole-hemisphere buffer: the pole, then each ring's N_j
/// (four quarters of `first`'s table).
#[cfg(not(target_os = "none"))]
#[inline]
fn ring_offset(ring: &Ring, j: usize) -> usize {
    if j == 0 {
        0
    } else {
        1 + 4 * ring.first as usize
    }
}

/// `libm::ceilf(x) as i64` for every x (NaN to 0, saturating at the ends) without libm's
/// software rounding, which was a tenth of the ring intervals' time: the cast truncates
/// toward zero, and one comparison corrects it.
#[inline]
fn ceil_to_int(x: f32) -> i64 {
    let i = x as i64;
    if (i as f32) < x {
        i.saturating_add(1)
    } else {
        i
    }
}

/// `libm::floorf(x) as i64` for every x, as [`ceil_to_int`].
#[inline]
fn floor_to_int(x: f32) -> i64 {
    let i = x as i64;
    if (i as f32) > x {
        i.saturating_sub(1)
    } else {
        i
    }
}

/// `k.rem_euclid(n)` for n > 0 without a 64-bit division where k is within a turn of the ring
/// (the ring intervals' starts always are): a division was a fifth of their time.
#[inline]
fn wrap(k: i64, n: i64) -> i64 {
    match k {
        _ if (0..n).contains(&k) => k,
        _ if (-n..0).contains(&k) => k + n,
        _ if (n..2 * n).contains(&k) => k - n,
        _ => k.rem_euclid(n),
    }
}

/// `(start / quarter, start % quarter)` for a ray index of a ring of four quarters (`start`
/// below 4 · `quarter`), by comparisons instead of two 64-bit divisions per patch and ring.
#[inline(always)]
fn quarter_and_offset(start: i64, quarter: i64) -> (i64, i64) {
    if !(0..4 * quarter).contains(&start) {
        return (start / quarter, start % quarter);
    }
    let q =
        (start >= quarter) as i64 + (start >= 2 * quarter) as i64 + (start >= 3 * quarter) as i64;
    (q, start - q * quarter)
}

/// arccos by Abramowitz & Stegun 4.4.45, |error| ≤ 6.7·10⁻⁵ rad on [−1, 1]: the cone culling only
/// needs a bound, and libm's correctly rounded `acosf` was a tenth of the pass-1 time.
#[inline]
fn fast_acos(x: f32) -> f32 {
    let a = x.abs();
    let r = sqrt((1.0 - a).max(0.0))
        * (1.570_728_8 + a * (-0.212_114_4 + a * (0.074_261_0 + a * -0.018_729_3)));
    if x < 0.0 {
        core::f32::consts::PI - r
    } else {
        r
    }
}

/// atan2(y, x) in (−π, π] within 2e-6 rad of libm's (a test holds it), 0 at the origin: the
/// cone's azimuth, which only places the ring intervals, whose margin (2e-4 rad, of which
/// fast_acos takes 6.7e-5) covers the difference. libm's was 5 % of a hemisphere's time on
/// the Cornell box cut 16 × 16, a call for every patch set up.
#[inline(always)]
fn fast_atan2(y: f32, x: f32) -> f32 {
    // written as selections after the arithmetic, not branches, so that sixteen set-ups at once
    // (`setup_lanes`) vectorise it
    let (ax, ay) = (x.abs(), y.abs());
    let steep = ay > ax;
    let (lo, hi) = if steep { (ax, ay) } else { (ay, ax) };
    let a = lo / hi;
    let s = a * a;
    // a minimax polynomial of atan on [0, 1] (odd, degree 11)
    let r = a
        * (0.999_977_26
            + s * (-0.332_623_47
                + s * (0.193_543_46
                    + s * (-0.116_432_87 + s * (0.052_653_32 + s * -0.011_721_2)))));
    let r = if steep {
        core::f32::consts::FRAC_PI_2 - r
    } else {
        r
    };
    let r = if x < 0.0 {
        core::f32::consts::PI - r
    } else {
        r
    };
    let r = if y < 0.0 { -r } else { r };
    // the zero vector (whose division above gave NaN) and NaN vectors: 0
    if hi.is_nan() || hi <= 0.0 {
        0.0
    } else {
        r
    }
}

/// A patch's tests for one ring quarter (see [`LocalPatch::coefficients`]).
struct Coefficients {
    edges: [[f32; 3]; 4],
    normal: [f32; 3],
}

#[cfg(test)]
mod tests {
    use super::{ceil_to_int, fast_acos, fast_atan2, floor_to_int, quarter_and_offset, wrap};

    /// A xorshift generator of f32s in [0, 1) from `seed`: the kernel's random tests are
    /// reproducible and need no crate for it.
    pub(super) fn uniform(mut seed: u64) -> impl FnMut() -> f32 {
        move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 40) as f32 / (1u64 << 24) as f32
        }
    }

    /// Every f32 bit pattern of a sweep, the ends and NaN round as libm's do.
    #[test]
    fn rounding_to_int_is_libms() {
        let special = [
            0.0f32,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::MAX,
            f32::MIN,
            9.3e18,
            -9.3e18,
            8_388_609.0,
        ];
        let sweep = (0..2_000_000u32).map(|i| f32::from_bits(i.wrapping_mul(2_147_483_647)));
        for x in special.into_iter().chain(sweep) {
            assert_eq!(ceil_to_int(x), libm::ceilf(x) as i64, "ceil {x:e}");
            assert_eq!(floor_to_int(x), libm::floorf(x) as i64, "floor {x:e}");
        }
    }

    #[test]
    fn wrapping_and_quarters_are_the_divisions() {
        for n in [1i64, 4, 8, 12, 256] {
            for k in -3 * n..3 * n {
                assert_eq!(wrap(k, n), k.rem_euclid(n), "wrap {k} {n}");
                let quarter = (n / 4).max(1);
                assert_eq!(
                    quarter_and_offset(k, quarter),
                    (k / quarter, k % quarter),
                    "quarter {k} {quarter}"
                );
            }
        }
    }

    #[test]
    fn fast_atan2_stays_within_its_bound() {
        let mut worst = 0.0f32;
        for i in 0..=4000 {
            let phi = -core::f32::consts::PI + i as f32 * (core::f32::consts::TAU / 4000.0);
            for r in [1e-3f32, 0.3, 1.0] {
                let (y, x) = (r * libm::sinf(phi), r * libm::cosf(phi));
                let e = (fast_atan2(y, x) - libm::atan2f(y, x)).abs();
                // ±π are the same azimuth
                worst = worst.max(e.min((e - core::f32::consts::TAU).abs()));
            }
        }
        assert!(worst <= 2e-6, "{worst}");
        assert_eq!(fast_atan2(0.0, 0.0), 0.0);
    }

    /// The eight-lane scan keeps every bit of the one-ray-at-a-time scan, in the run and around
    /// it: runs of every length from every offset of a short buffer (so that groups reach past
    /// the run and past the buffer's end), rays inside and outside, ties, misses and
    /// infinities, and directions that end (as a quarter does) before the buffers (as the ring
    /// does). Writing a lane past the run fails it.
    #[cfg(not(target_os = "none"))]
    #[test]
    fn eight_lanes_keep_the_scalar_scans_bits() {
        use super::{scan_in_lanes, scan_segment, Coefficients};
        let mut unit = uniform(0x2545_f491_4f6c_dd1du64);
        let mut next = move || unit() * 2.0 - 1.0;
        let mut changed = 0;
        for trial in 0..400 {
            let total = 1 + trial % 37;
            let mut coefficient = || [next(), next(), next() * 0.3];
            let co = Coefficients {
                edges: [coefficient(), coefficient(), coefficient(), coefficient()],
                normal: [next(), next(), next()],
            };
            let (h, id) = (next(), (trial % 5) as u32);
            let dirs: std::vec::Vec<[f32; 2]> = (0..total).map(|_| [next(), next()]).collect();
            let best_t: std::vec::Vec<f32> = (0..total)
                .map(|k| {
                    if k % 3 == 0 {
                        f32::INFINITY
                    } else {
                        next().abs() * 4.0
                    }
                })
                .collect();
            let best_id: std::vec::Vec<u32> = (0..total as u32).map(|k| k % 4 + 1).collect();
            for start in 0..total {
                for len in 0..=total - start {
                    let (mut t1, mut i1) = (best_t.clone(), best_id.clone());
                    let run = start..start + len;
                    let (d, t, i) = (&dirs[run.clone()], &mut t1[run.clone()], &mut i1[run]);
                    scan_segment(&co, h, id, d, t, i);
                    // the directions end between the run's end and the buffers' (a quarter's
                    // end inside the ring)
                    let quarter_end = start + len + (trial + start) % (total - start - len + 1);
                    let (mut t2, mut i2) = (best_t.clone(), best_id.clone());
                    let window = (
                        &dirs[start..quarter_end],
                        &mut t2[start..],
                        &mut i2[start..],
                    );
                    scan_in_lanes(&co, h, id, len, window);
                    let bits =
                        |t: &[f32]| t.iter().map(|x| x.to_bits()).collect::<std::vec::Vec<_>>();
                    assert_eq!(bits(&t1), bits(&t2), "trial {trial}, rays {start}+{len}");
                    assert_eq!(i1, i2, "trial {trial}, rays {start}+{len}");
                    changed += usize::from(t1 != best_t);
                }
            }
        }
        // the workload hits: most runs change some ray
        assert!(changed > 1000, "{changed}");
    }

    #[test]
    fn fast_acos_stays_within_its_bound() {
        for i in 0..=20_000 {
            let x = -1.0 + i as f32 / 10_000.0;
            assert!((fast_acos(x) - libm::acosf(x)).abs() <= 8e-5, "x = {x}");
        }
    }
}

/// Polygon `lp` (patch `id`) against the rays `start..start+len` (modulo N_j) of ring `j`,
/// keeping the nearest hit per ray in `best_t`/`best_id` (the ring's N_j entries), ties to the
/// lowest id. The interval is walked quarter by quarter: within quarter q a ray's direction is
/// the stored (c, s) turned by q right angles, so each edge test folds into A·c + B·s + C ≥ 0
/// with per-(patch, ring, quarter) coefficients and the loop runs branch-free over a contiguous
/// slice of the quarter table. The one ring scan of both hemisphere walks.
#[expect(
    clippy::too_many_arguments,
    reason = "one patch, one ring, one interval, the buffers"
)]
#[inline(always)]
fn scan_ring(
    lp: &LocalPatch,
    id: u32,
    hemi: &Hemisphere<'_>,
    ring: &Ring,
    j: usize,
    (start, len): (i64, i64),
    best_t: &mut [f32],
    best_id: &mut [u32],
) {
    if j == 0 {
        if let Some(t) = lp.hit(Vec3::Z) {
            if t < best_t[0] || (t == best_t[0] && id < best_id[0]) {
                best_t[0] = t;
                best_id[0] = id;
            }
        }
        return;
    }
    let quarter = hemi.quarter_of(ring);
    let quarter_n = (ring.count / 4).max(1) as i64;
    let mut remaining = len;
    let (mut q, mut r) = quarter_and_offset(start, quarter_n);
    while remaining > 0 {
        let seg = remaining.min(quarter_n - r);
        let k0 = (q * quarter_n + r) as usize;
        let co = lp.coefficients(ring, q as u32);
        let (r0, n) = (r as usize, seg as usize);
        let window = (&quarter[r0..], &mut best_t[k0..], &mut best_id[k0..]);
        scan_run(&co, lp.h, id, n, window);
        remaining -= seg;
        r = 0;
        q = (q + 1) % 4;
    }
}

/// One run of `len` rays of a ring quarter; `window` holds its directions (to the end of its
/// quarter) and buffers (to the end of its ring) from its first ray on. Hosts take runs of
/// [`LANES_FROM`] rays or more in groups of eight ([`scan_in_lanes`]); boards, whose cores have
/// no vector unit, ray by ray.
#[inline(always)]
fn scan_run(
    co: &Coefficients,
    h: f32,
    id: u32,
    len: usize,
    (dirs, best_t, best_id): (&[[f32; 2]], &mut [f32], &mut [u32]),
) {
    #[cfg(not(target_os = "none"))]
    if len >= LANES_FROM {
        return scan_in_lanes(co, h, id, len, (dirs, best_t, best_id));
    }
    scan_segment(
        co,
        h,
        id,
        &dirs[..len],
        &mut best_t[..len],
        &mut best_id[..len],
    );
}

/// Tests one patch against a run of rays of one ring quarter and keeps the nearest hits.
/// Written without branches in the loop body so that it vectorises.
#[inline(always)]
fn scan_segment(
    co: &Coefficients,
    h: f32,
    id: u32,
    dirs: &[[f32; 2]],
    best_t: &mut [f32],
    best_id: &mut [u32],
) {
    let e = &co.edges;
    let n = &co.normal;
    for ((cs, bt), bi) in dirs.iter().zip(best_t.iter_mut()).zip(best_id.iter_mut()) {
        let (c, s) = (cs[0], cs[1]);
        let inside = (e[0][0] * c + e[0][1] * s + e[0][2] >= 0.0)
            & (e[1][0] * c + e[1][1] * s + e[1][2] >= 0.0)
            & (e[2][0] * c + e[2][1] * s + e[2][2] >= 0.0)
            & (e[3][0] * c + e[3][1] * s + e[3][2] >= 0.0);
        let t = h / (n[0] * c + n[1] * s + n[2]);
        // nearer, or as near and a lower id: the winner does not depend on the order in which
        // patches are scanned (in id order, the second clause never fires)
        let closer =
            inside & (t > 0.0) & (t < f32::INFINITY) & ((t < *bt) | ((t == *bt) & (id < *bi)));
        *bt = if closer { t } else { *bt };
        *bi = if closer { id } else { *bi };
    }
}

/// Runs of this many rays or more go through [`scan_in_lanes`]; a single ray is tested
/// alone (eight lanes for one cost the cut 16 × 16 box 1–2 %).
#[cfg(not(target_os = "none"))]
const LANES_FROM: usize = 2;

/// [`scan_run`] on hosts, for a run of `len` rays, in groups of [`LANES`] of fixed width.
/// A small patch's run is a few rays of a ring quarter, which the compiler's vector loop over a
/// slice of any length left to its scalar tail (a division a ray); a fixed group is one vector
/// pass whatever the run (on the cut 8 × 8 Cornell box 7–9 % of pass 1, on the box itself 2–6 %,
/// docs/PERFORMANCE.md). A group reaching past the run reads and writes back the rays after it
/// unchanged (they are not live), or, past the end of `window`, works on a padded copy. The
/// same operations on each ray as [`scan_segment`], so the same bits.
#[cfg(not(target_os = "none"))]
#[inline(always)]
fn scan_in_lanes(
    co: &Coefficients,
    h: f32,
    id: u32,
    len: usize,
    (dirs, best_t, best_id): (&[[f32; 2]], &mut [f32], &mut [u32]),
) {
    for at in (0..len).step_by(LANES) {
        let live = len - at;
        let whole = (dirs.get(at..at + LANES), best_t.get_mut(at..at + LANES));
        if let (Some(d), Some(bt)) = whole {
            if let Some(bi) = best_id.get_mut(at..at + LANES) {
                scan_lanes(co, h, id, live, d, bt, bi);
                continue;
            }
        }
        let mut d = [[0.0f32; 2]; LANES];
        let (mut bt, mut bi) = ([0.0f32; LANES], [0u32; LANES]);
        let m = live.min(LANES);
        d[..m].copy_from_slice(&dirs[at..at + m]);
        bt[..m].copy_from_slice(&best_t[at..at + m]);
        bi[..m].copy_from_slice(&best_id[at..at + m]);
        scan_lanes(co, h, id, live, &d, &mut bt, &mut bi);
        best_t[at..at + m].copy_from_slice(&bt[..m]);
        best_id[at..at + m].copy_from_slice(&bi[..m]);
    }
}

/// Lanes of [`scan_in_lanes`]: the first `live` of `LANES` rays (all, when `live` ≥ LANES).
#[cfg(not(target_os = "none"))]
const LANES: usize = 8;

/// [`scan_segment`]'s test on exactly [`LANES`] rays, of which the first `live` count.
#[cfg(not(target_os = "none"))]
#[inline(always)]
fn scan_lanes(
    co: &Coefficients,
    h: f32,
    id: u32,
    live: usize,
    dirs: &[[f32; 2]],
    best_t: &mut [f32],
    best_id: &mut [u32],
) {
    let (Ok(dirs), Ok(best_t), Ok(best_id)) = (
        <&[[f32; 2]; LANES]>::try_from(dirs),
        <&mut [f32; LANES]>::try_from(best_t),
        <&mut [u32; LANES]>::try_from(best_id),
    ) else {
        // (the callers pass exactly LANES of each)
        debug_assert!(false, "scan_lanes takes {LANES} rays");
        return;
    };
    let e = &co.edges;
    let n = &co.normal;
    for k in 0..LANES {
        let [c, s] = dirs[k];
        let inside = (e[0][0] * c + e[0][1] * s + e[0][2] >= 0.0)
            & (e[1][0] * c + e[1][1] * s + e[1][2] >= 0.0)
            & (e[2][0] * c + e[2][1] * s + e[2][2] >= 0.0)
            & (e[3][0] * c + e[3][1] * s + e[3][2] >= 0.0);
        let t = h / (n[0] * c + n[1] * s + n[2]);
        let (bt, bi) = (best_t[k], best_id[k]);
        let closer = (k < live)
            & inside
            & (t > 0.0)
            & (t < f32::INFINITY)
            & ((t < bt) | ((t == bt) & (id < bi)));
        best_t[k] = if closer { t } else { bt };
        best_id[k] = if closer { id } else { bi };
    }
}

/// Scratch memory the software accelerator works in; sized by the caller so that the kernel
/// never allocates (the firmware hands it static buffers, the host a `Vec` per thread).
pub struct SoftScratch<'s> {
    /// One entry per loaded patch.
    pub local: &'s mut [LocalPatch],
    /// At least the largest ring's ray count (4R).
    pub best_t: &'s mut [f32],
    /// Same length as `best_t`.
    pub best_id: &'s mut [u32],
}

/// The f32 ray engine over a slice of patches.
pub struct SoftAccelerator<'p, 's> {
    patches: &'p [Patch],
    scratch: SoftScratch<'s>,
    subdivision: Subdivision,
    origin_patch: u32,
    /// A tree over the patches for rays that share nothing (see [`super::bvh`]). Hosts only: a
    /// board's rays are hemisphere rays and its scenes small, and its flash has no room for
    /// code it would never run.
    #[cfg(not(target_os = "none"))]
    bvh: Option<Bvh<'s>>,
    /// Each patch's (u,v) frame, computed once by the host ([`SoftAccelerator::with_uv_frames`])
    /// instead of per hit: the same (u,v), bit for bit, for a fraction of the work.
    #[cfg(not(target_os = "none"))]
    uv_frames: Option<&'s [Option<UvFrame>]>,
    /// Hemispheres patch by patch ([`SoftAccelerator::with_patch_major`]); hosts only.
    #[cfg(not(target_os = "none"))]
    patch_major: Option<PatchMajor<'s>>,
    /// Each curved patch's stored subdivision ([`SoftAccelerator::with_bezier_trees`]); hosts
    /// only (a board's RAM holds its stack, not the trees).
    #[cfg(not(target_os = "none"))]
    bezier_trees: Option<&'s [Option<BezierTree<'s>>]>,
}

/// How a host casts hemispheres patch by patch: every patch's rays of the whole hemisphere
/// at once, over the patches a tree says are above the horizon (or all of them).
#[cfg(not(target_os = "none"))]
#[derive(Clone, Copy, Debug)]
struct PatchMajor<'s> {
    tree: Option<Bvh<'s>>,
    /// The ring scans run with the widest SIMD the CPU has.
    simd: Vectorizer,
}

const NO_HIT: u32 = u32::MAX;
/// Marks a best id whose hit is on a curved patch's back side (front/back varies per ray there).
const BACK: u32 = 1 << 31;

/// Why a software accelerator could not be set up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SoftError {
    /// The scratch has fewer `local` entries than there are patches.
    ScratchTooSmall,
    /// More patches than ids (2³¹).
    TooManyPatches,
}

/// Hits of a curved patch closer than this fraction of its size to the ray's origin are the
/// surface the ray starts on (a neighbouring patch at a shared seam), not a new hit.
const CURVED_T_MIN: f32 = 1e-4;

impl<'p, 's> SoftAccelerator<'p, 's> {
    /// An engine over `patches` (the patch memory) working in `scratch`.
    pub fn new(patches: &'p [Patch], scratch: SoftScratch<'s>) -> Result<Self, SoftError> {
        if scratch.local.len() < patches.len() || scratch.best_t.len() != scratch.best_id.len() {
            return Err(SoftError::ScratchTooSmall);
        }
        if patches.len() >= BACK as usize {
            return Err(SoftError::TooManyPatches);
        }
        Ok(SoftAccelerator {
            patches,
            scratch,
            subdivision: Subdivision::default(),
            origin_patch: NO_HIT,
            #[cfg(not(target_os = "none"))]
            bvh: None,
            #[cfg(not(target_os = "none"))]
            uv_frames: None,
            #[cfg(not(target_os = "none"))]
            patch_major: None,
            #[cfg(not(target_os = "none"))]
            bezier_trees: None,
        })
    }

    /// Casts hemispheres patch by patch instead of ring by ring, when the scratch holds a whole
    /// hemisphere (`best_t` of at least [`Hemisphere::ray_count`] entries; else the ring scan
    /// runs as before): each patch is tested on the rings its cone spans only, and with `tree`
    /// (a [`Bvh`] over these patches) only the patches above the hemisphere's horizon are set
    /// up at all ([`Bvh::visit_above`]). Every ray keeps the nearest hit, ties to the lowest
    /// id, so the hits are the ring scan's, bit for bit, whatever order the patches come in.
    /// For patch memories without curved patches only (the caller checks): a curved patch's
    /// subdivision is bounded by the best distance so far, which would then depend on the
    /// order.
    #[cfg(not(target_os = "none"))]
    pub fn with_patch_major(mut self, tree: Option<Bvh<'s>>) -> Self {
        self.patch_major = Some(PatchMajor {
            tree,
            simd: Vectorizer::detect(),
        });
        self
    }

    /// Answers single rays and `cast_from` bundles through `bvh`, a tree over these patches,
    /// instead of testing every patch: the same hits, in time that grows with log N.
    #[cfg(not(target_os = "none"))]
    pub fn with_bvh(mut self, bvh: Bvh<'s>) -> Self {
        self.bvh = Some(bvh);
        self
    }

    /// The tree given by [`SoftAccelerator::with_bvh`], if any.
    #[cfg(not(target_os = "none"))]
    pub fn bvh(&self) -> Option<Bvh<'s>> {
        self.bvh
    }

    /// The nearest hit of `origin + t dir` below `t_max` through the tree: per patch the same
    /// tests as the linear scan of `nearest_hit`, and ties to the lowest id as there.
    #[cfg(not(target_os = "none"))]
    fn nearest_in_tree(
        &self,
        bvh: &Bvh<'_>,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        want_uv: bool,
    ) -> Option<Hit> {
        let found = bvh.nearest(origin, dir, t_max, |id, best_t| {
            if id == self.origin_patch {
                return None;
            }
            match &self.patches[id as usize].shape {
                Shape::Polygon(poly) => {
                    let lp = LocalPatch::setup_single(poly, origin);
                    if !lp.active {
                        return None;
                    }
                    let t = lp.hit(dir)?;
                    (t < t_max && t <= best_t).then_some((t, (lp.front(), None)))
                }
                Shape::Bezier(b) => {
                    let (t, u, v, front) = self.curved_hit(id as usize, b, origin, dir, best_t)?;
                    Some((t, (front, Some((u, v)))))
                }
            }
        });
        let (t, id, (front, uv)) = found?;
        let (u, v) = match uv {
            Some(uv) => uv,
            None if want_uv => self.patches[id as usize]
                .as_polygon()
                .map_or((0.0, 0.0), |poly| {
                    self.polygon_uv(id as usize, poly, origin + dir * t)
                }),
            None => (0.0, 0.0),
        };
        Some(Hit {
            patch: id,
            t,
            u,
            v,
            front,
        })
    }

    /// Inverts hits on patch `id`'s polygon to (u,v) through `frames[id]` (from
    /// [`Polygon::uv_frame`]), one per patch, instead of rebuilding the frame per hit.
    #[cfg(not(target_os = "none"))]
    pub fn with_uv_frames(mut self, frames: &'s [Option<UvFrame>]) -> Self {
        self.uv_frames = Some(frames);
        self
    }

    /// The (u,v) of point `p` on patch `id`'s polygon `poly` ([`Polygon::uv_of`]).
    fn polygon_uv(&self, id: usize, poly: &Polygon, p: Vec3) -> (f32, f32) {
        #[cfg(not(target_os = "none"))]
        if let Some(Some(frame)) = self.uv_frames.and_then(|f| f.get(id)) {
            return frame.uv_of(p);
        }
        let _ = id;
        poly.uv_of(p)
    }

    /// Intersects curved patch `id` starting from `trees[id]` ([`Bezier::build_tree`], built
    /// for this engine's [`Subdivision`]) instead of splitting its first levels again for every
    /// ray: the same hits, bit for bit.
    #[cfg(not(target_os = "none"))]
    pub fn with_bezier_trees(mut self, trees: &'s [Option<BezierTree<'s>>]) -> Self {
        self.bezier_trees = Some(trees);
        self
    }

    /// Sets the termination of the Bezier subdivision (depth, minimum box).
    pub fn with_subdivision(mut self, sub: Subdivision) -> Self {
        self.subdivision = sub;
        self
    }

    /// The loaded patches.
    pub fn patches(&self) -> &'p [Patch] {
        self.patches
    }

    /// Nearest hit of one ray on curved patch `id`, `b`, as (t, u, v, front).
    fn curved_hit(
        &self,
        id: usize,
        b: &Bezier,
        o: Vec3,
        d: Vec3,
        t_max: f32,
    ) -> Option<(f32, f32, f32, bool)> {
        #[cfg(not(target_os = "none"))]
        let tree = self.bezier_trees.and_then(|t| t.get(id)?.as_ref());
        #[cfg(target_os = "none")]
        let tree: Option<&crate::geometry::BezierTree<'_>> = {
            let _ = id;
            None
        };
        // (the tree keeps the patch's box: computing it was a tenth of a teapot's pass 1)
        let size = tree
            .and_then(|t| t.size())
            .unwrap_or_else(|| b.bounds().size());
        let t_min = CURVED_T_MIN * size;
        let h = b.intersect_in(tree, o, d, t_min, t_max, &self.subdivision)?;
        // at a pole the normal is the limit from inside the patch
        let front = b
            .normal_near(h.u, h.v)
            .map(|n| n.dot(d) < 0.0)
            .unwrap_or(true);
        Some((h.t, h.u, h.v, front))
    }

    /// The full hit for a winning (id, t) of a bundle; (u,v) only when asked for. Inlined for
    /// pass 1's every ray (a polygon, no (u,v): the side is the set-up's), the rest called.
    #[inline(always)]
    fn resolve(&self, tagged: u32, t: f32, origin: Vec3, dir: Vec3, want_uv: bool) -> Hit {
        if !want_uv && tagged & BACK == 0 {
            if let Some(Shape::Polygon(_)) = self.patches.get(tagged as usize).map(|p| &p.shape) {
                return Hit {
                    patch: tagged,
                    t,
                    u: 0.0,
                    v: 0.0,
                    front: self.scratch.local[tagged as usize].front(),
                };
            }
        }
        self.resolve_in_full(tagged, t, origin, dir, want_uv)
    }

    /// [`SoftAccelerator::resolve`]'s general case.
    #[inline(never)]
    fn resolve_in_full(&self, tagged: u32, t: f32, origin: Vec3, dir: Vec3, want_uv: bool) -> Hit {
        let id = tagged & !BACK;
        let patch = &self.patches[id as usize];
        let (mut u, mut v) = (0.0, 0.0);
        let front = match &patch.shape {
            Shape::Polygon(poly) => {
                if want_uv {
                    (u, v) = self.polygon_uv(id as usize, poly, origin + dir * t);
                }
                self.scratch.local[id as usize].front()
            }
            Shape::Bezier(b) => {
                if want_uv {
                    if let Some((_, hu, hv, _)) =
                        self.curved_hit(id as usize, b, origin, dir, t * (1.0 + 1e-4) + 1e-30)
                    {
                        (u, v) = (hu, hv);
                    }
                }
                tagged & BACK == 0
            }
        };
        Hit {
            patch: id,
            t,
            u,
            v,
            front,
        }
    }
}

impl Accelerator for SoftAccelerator<'_, '_> {
    fn rotate(&mut self, rot: &Rotation, d: Vec3) -> Vec3 {
        rot.apply(d)
    }

    fn set_origin_patch(&mut self, patch: Option<u32>) {
        self.origin_patch = patch.unwrap_or(NO_HIT);
    }

    fn nearest_hit(&mut self, ray: &Ray, t_max: f32) -> Option<Hit> {
        #[cfg(not(target_os = "none"))]
        if let Some(bvh) = self.bvh {
            return self.nearest_in_tree(&bvh, ray.origin, ray.dir, t_max, true);
        }
        let mut best: Option<Hit> = None;
        let mut best_t = t_max;
        for (i, p) in self.patches.iter().enumerate() {
            if i as u32 == self.origin_patch {
                continue;
            }
            match &p.shape {
                Shape::Polygon(poly) => {
                    let lp = LocalPatch::setup_single(poly, ray.origin);
                    if !lp.active {
                        continue;
                    }
                    if let Some(t) = lp.hit(ray.dir) {
                        if t < best_t {
                            best_t = t;
                            let (u, v) = self.polygon_uv(i, poly, ray.origin + ray.dir * t);
                            best = Some(Hit {
                                patch: i as u32,
                                t,
                                u,
                                v,
                                front: lp.front(),
                            });
                        }
                    }
                }
                Shape::Bezier(b) => {
                    if let Some((t, u, v, front)) =
                        self.curved_hit(i, b, ray.origin, ray.dir, best_t)
                    {
                        best_t = t;
                        best = Some(Hit {
                            patch: i as u32,
                            t,
                            u,
                            v,
                            front,
                        });
                    }
                }
            }
        }
        best
    }

    fn cast_from<F: FnMut(usize, Option<Hit>)>(
        &mut self,
        origin: Vec3,
        dirs: &[Vec3],
        want_uv: bool,
        mut sink: F,
    ) {
        #[cfg(not(target_os = "none"))]
        if let Some(bvh) = self.bvh {
            for (i, &d) in dirs.iter().enumerate() {
                sink(
                    i,
                    self.nearest_in_tree(&bvh, origin, d, f32::INFINITY, want_uv),
                );
            }
            return;
        }
        // One set-up per patch for the shared origin, in the scene's own frame; each ray is
        // first checked against the patch's bounding cone (3 multiply-adds) before the edges.
        // The rays go in any direction, so nothing is culled by a horizon.
        for (id, (lp, p)) in self
            .scratch
            .local
            .iter_mut()
            .zip(self.patches.iter())
            .enumerate()
        {
            *lp = if id as u32 == self.origin_patch {
                LocalPatch::default()
            } else {
                LocalPatch::setup_patch_any(p, origin)
            };
        }
        for (i, &d) in dirs.iter().enumerate() {
            let mut best_t = f32::INFINITY;
            let mut best_id = NO_HIT;
            for (id, lp) in self.scratch.local[..self.patches.len()].iter().enumerate() {
                if !lp.active || (!lp.full && d.dot(lp.axis) < lp.cos_alpha) {
                    continue;
                }
                if lp.curved {
                    if let Shape::Bezier(b) = &self.patches[id].shape {
                        if let Some((t, _, _, front)) = self.curved_hit(id, b, origin, d, best_t) {
                            best_t = t;
                            best_id = id as u32 | if front { 0 } else { BACK };
                        }
                    }
                } else if let Some(t) = lp.hit(d) {
                    if t < best_t {
                        best_t = t;
                        best_id = id as u32;
                    }
                }
            }
            if best_id == NO_HIT {
                sink(i, None);
            } else {
                sink(i, Some(self.resolve(best_id, best_t, origin, d, want_uv)));
            }
        }
    }

    fn cast_rings<F: FnMut(usize, u32, Option<Hit>)>(
        &mut self,
        origin: Vec3,
        rot: &Rotation,
        hemi: &Hemisphere<'_>,
        rings: Range<usize>,
        want_uv: bool,
        mut sink: F,
    ) {
        // no_std builds (the firmware) keep one copy of the ring scan for every caller
        // (hemisphere, frustums, gather, pass 2) and call the sink through a pointer: a call
        // per ray, against ~7 KiB of flash per closure, which a 128 KiB part cannot spare. The
        // host keeps a scan per closure, the sink inlined. Same code, same bits.
        #[cfg(not(feature = "std"))]
        self.scan_rings::<dyn FnMut(usize, u32, Option<Hit>)>(
            origin, rot, hemi, rings, want_uv, &mut sink,
        );
        #[cfg(feature = "std")]
        self.scan_rings(origin, rot, hemi, rings, want_uv, &mut sink);
    }
}

impl SoftAccelerator<'_, '_> {
    #[cfg_attr(not(feature = "std"), inline(never))]
    fn scan_rings<F: FnMut(usize, u32, Option<Hit>) + ?Sized>(
        &mut self,
        origin: Vec3,
        rot: &Rotation,
        hemi: &Hemisphere<'_>,
        rings: Range<usize>,
        want_uv: bool,
        sink: &mut F,
    ) {
        #[cfg(not(target_os = "none"))]
        if let Some(walk) = self.patch_major {
            if self.scratch.best_t.len() >= hemi.ray_count() as usize {
                self.scan_patch_major(walk, origin, rot, hemi, rings, want_uv, sink);
                return;
            }
        }
        let n_patches = self.patches.len();
        for (id, (lp, p)) in self
            .scratch
            .local
            .iter_mut()
            .zip(self.patches.iter())
            .enumerate()
        {
            *lp = if id as u32 == self.origin_patch {
                LocalPatch::default()
            } else {
                LocalPatch::setup_patch(p, origin, rot)
            };
        }
        let max_ring = hemi
            .rings()
            .iter()
            .map(|r| r.count as usize)
            .max()
            .unwrap_or(0);
        if max_ring > self.scratch.best_t.len() {
            // Scratch too small for this table: fall back to the ray-by-ray path, which is
            // slower but needs no scratch (never a silent wrong answer).
            for j in rings {
                let ring = hemi.rings()[j];
                for k in 0..ring.count {
                    let dir = rot.apply(hemi.direction(j, k));
                    let hit = self
                        .nearest_hit(&Ray { origin, dir }, f32::INFINITY)
                        .filter(|h| h.patch != self.origin_patch);
                    sink(j, k, hit);
                }
            }
            return;
        }
        for j in rings {
            let ring = hemi.rings()[j];
            let n = ring.count as usize;
            self.scratch.best_t[..n].fill(f32::INFINITY);
            self.scratch.best_id[..n].fill(NO_HIT);
            for id in 0..n_patches {
                let lp = self.scratch.local[id];
                if !lp.active {
                    continue;
                }
                let Some((start, len)) = lp.ring_interval(&ring, j, None) else {
                    continue;
                };
                if lp.curved {
                    // Rays that pass the cone go through the subdivision one by one.
                    let Shape::Bezier(b) = &self.patches[id].shape else {
                        continue;
                    };
                    for i in 0..len {
                        let k = ((start + i) % n as i64) as usize;
                        let d = rot.apply(hemi.direction(j, k as u32));
                        if let Some((t, _, _, front)) =
                            self.curved_hit(id, b, origin, d, self.scratch.best_t[k])
                        {
                            self.scratch.best_t[k] = t;
                            self.scratch.best_id[k] = id as u32 | if front { 0 } else { BACK };
                        }
                    }
                    continue;
                }
                let best_t = &mut self.scratch.best_t[..n];
                let best_id = &mut self.scratch.best_id[..n];
                scan_ring(
                    &lp,
                    id as u32,
                    hemi,
                    &ring,
                    j,
                    (start, len),
                    best_t,
                    best_id,
                );
            }
            for k in 0..n {
                let id = self.scratch.best_id[k];
                if id == NO_HIT {
                    sink(j, k as u32, None);
                } else {
                    let t = self.scratch.best_t[k];
                    let dir = if want_uv {
                        rot.apply(hemi.direction(j, k as u32))
                    } else {
                        Vec3::ZERO
                    };
                    sink(j, k as u32, Some(self.resolve(id, t, origin, dir, want_uv)));
                }
            }
        }
    }
}

#[cfg(not(target_os = "none"))]
impl<'p> SoftAccelerator<'p, '_> {
    /// [`SoftAccelerator::with_patch_major`]'s hemisphere: every patch above the horizon is set
    /// up once and scanned over the rings it spans into a whole-hemisphere buffer, then the rays
    /// are reported ring by ring as the ring scan reports them.
    #[expect(
        clippy::too_many_arguments,
        reason = "cast_rings' arguments, and the walk"
    )]
    fn scan_patch_major<F: FnMut(usize, u32, Option<Hit>) + ?Sized>(
        &mut self,
        walk: PatchMajor<'_>,
        origin: Vec3,
        rot: &Rotation,
        hemi: &Hemisphere<'_>,
        rings: Range<usize>,
        want_uv: bool,
        sink: &mut F,
    ) {
        let table = hemi.rings();
        let Some(last) = rings.end.checked_sub(1).filter(|_| rings.start < rings.end) else {
            return;
        };
        let from = ring_offset(&table[rings.start], rings.start);
        let to = ring_offset(&table[last], last) + table[last].count as usize;
        self.scratch.best_t[from..to].fill(f32::INFINITY);
        self.scratch.best_id[from..to].fill(NO_HIT);
        let shot = Shot {
            simd: walk.simd,
            origin,
            rot,
            hemi,
            rings: rings.clone(),
        };
        match self.patches.len() < LANES_FROM_PATCHES as usize {
            true => self.scan_one_by_one(walk.tree, &shot),
            false => self.scan_in_batches(walk.tree, &shot),
        }
        for j in rings {
            let ring = table[j];
            let at = ring_offset(&ring, j);
            for k in 0..ring.count as usize {
                let id = self.scratch.best_id[at + k];
                if id == NO_HIT {
                    sink(j, k as u32, None);
                    continue;
                }
                let t = self.scratch.best_t[at + k];
                let hit = if want_uv {
                    let dir = rot.apply(hemi.direction(j, k as u32));
                    self.resolve(id, t, origin, dir, want_uv)
                } else {
                    // `resolve`'s answer for a polygon (the walk is for polygons only), without
                    // looking the patch up again
                    Hit {
                        patch: id,
                        t,
                        u: 0.0,
                        v: 0.0,
                        front: self.scratch.local[id as usize].front(),
                    }
                };
                sink(j, k as u32, Some(hit));
            }
        }
    }

    /// Sets up polygon `id` alone and scans it over the shot's rings.
    fn scan_patch(&mut self, id: u32, shot: &Shot<'_, '_>) {
        if id == self.origin_patch {
            return;
        }
        let Some(Shape::Polygon(poly)) = self.patches.get(id as usize).map(|p| &p.shape) else {
            return;
        };
        let lp = LocalPatch::setup(poly, shot.origin, shot.rot);
        self.scratch.local[id as usize] = lp;
        if !lp.active {
            return;
        }
        shot.simd.run(PatchScan {
            lp: &lp,
            reach: &Reach::of(&lp, shot.hemi.rings(), thin_polygon(&lp, poly, shot.origin)),
            id,
            hemi: shot.hemi,
            rings: shot.rings.clone(),
            best_t: &mut *self.scratch.best_t,
            best_id: &mut *self.scratch.best_id,
        })
    }

    /// The walk's polygons set up and scanned one at a time.
    fn scan_one_by_one(&mut self, tree: Option<Bvh<'_>>, shot: &Shot<'_, '_>) {
        let count = self.patches.len() as u32;
        let mut scan = |id| self.scan_patch(id, shot);
        match tree {
            Some(tree) => tree.visit_above(shot.origin, shot.rot.apply(Vec3::Z), &mut scan),
            None => (0..count).for_each(scan),
        }
    }

    /// The walk's polygons set up [`LANES_SET_UP`] at a time, each then scanned.
    fn scan_in_batches(&mut self, tree: Option<Bvh<'_>>, shot: &Shot<'_, '_>) {
        let mut waiting = Waiting::default();
        match tree {
            Some(tree) => tree.visit_above(shot.origin, shot.rot.apply(Vec3::Z), |id| {
                self.offer(&mut waiting, id, shot)
            }),
            None => {
                (0..self.patches.len() as u32).for_each(|id| self.offer(&mut waiting, id, shot))
            }
        }
        self.set_up_and_scan::<4>(&waiting.quads, shot);
        self.set_up_and_scan::<3>(&waiting.triangles, shot);
    }

    /// Queues polygon `id` for a set-up of [`LANES_SET_UP`] of its kind, and sets up and scans
    /// the queue when it is full. (The order in which patches are scanned does not change a
    /// ray's winner: ties go to the lower id.)
    #[inline(always)]
    fn offer(&mut self, waiting: &mut Waiting<'p>, id: u32, shot: &Shot<'_, '_>) {
        if id == self.origin_patch {
            return;
        }
        let Some(Shape::Polygon(poly)) = self.patches.get(id as usize).map(|p| &p.shape) else {
            return;
        };
        let quad = poly.sides == 4;
        let queue = if quad {
            &mut waiting.quads
        } else {
            &mut waiting.triangles
        };
        queue.push(id, poly);
        if queue.len < LANES_SET_UP {
            return;
        }
        let full = core::mem::take(queue);
        match quad {
            true => self.set_up_and_scan::<4>(&full, shot),
            false => self.set_up_and_scan::<3>(&full, shot),
        }
    }

    /// Sets up `queue`'s polygons of `SIDES` sides at once and scans each over the shot's rings.
    fn set_up_and_scan<const SIDES: usize>(&mut self, queue: &Queue<'_>, shot: &Shot<'_, '_>) {
        let ids = &queue.ids[..queue.len];
        // lanes past the queue set up its first polygon again, and are dropped
        let Some(spare) = queue.polys[0] else {
            return;
        };
        let polys = core::array::from_fn(|k| queue.polys[k].unwrap_or(spare));
        shot.simd.run(SetUpAndScan::<SIDES> {
            polys,
            ids,
            shot,
            local: &mut *self.scratch.local,
            best_t: &mut *self.scratch.best_t,
            best_id: &mut *self.scratch.best_id,
        })
    }
}

/// Patch memories of fewer patches are set up one patch at a time. Eight at once (the lanes'
/// width when measured) cost the Cornell box (20 patches, big ones: its time is in the scans)
/// 6 % of pass 1 (before the runs of [`Runs`]) and, with the runs, its 2 × 2 cut (80) 4 %, and
/// gain 3 % at 4 × 4 (320), 14 % at 8 × 8 (1,280) and 20 % at 16 × 16 (`hemi bench rays`, one
/// thread). Sixteen at once, re-measured with thresholds of 64 and 512: batches cost the 2 × 2
/// cut 2 % and gain the 4 × 4 cut 9 %.
#[cfg(not(target_os = "none"))]
const LANES_FROM_PATCHES: u32 = 256;

/// What a hemisphere's patch-by-patch walk hands each set-up: its rays and where they start.
#[cfg(not(target_os = "none"))]
struct Shot<'a, 'h> {
    simd: Vectorizer,
    origin: Vec3,
    rot: &'a Rotation,
    hemi: &'a Hemisphere<'h>,
    rings: Range<usize>,
}

/// Polygons the walk has reached and not yet set up, quads and triangles apart (a set-up of
/// several takes one kind).
#[cfg(not(target_os = "none"))]
#[derive(Default)]
struct Waiting<'p> {
    quads: Queue<'p>,
    triangles: Queue<'p>,
}

/// Up to [`LANES_SET_UP`] polygons and their ids.
#[cfg(not(target_os = "none"))]
#[derive(Default)]
struct Queue<'p> {
    ids: [u32; LANES_SET_UP],
    polys: [Option<&'p Polygon>; LANES_SET_UP],
    len: usize,
}

#[cfg(not(target_os = "none"))]
impl<'p> Queue<'p> {
    fn push(&mut self, id: u32, poly: &'p Polygon) {
        if let (Some(i), Some(p)) = (self.ids.get_mut(self.len), self.polys.get_mut(self.len)) {
            (*i, *p) = (id, Some(poly));
            self.len += 1;
        }
    }
}

/// One set-up of several polygons and their scans, as [`SoftAccelerator::set_up_and_scan`]
/// hands them to the [`Vectorizer`].
#[cfg(not(target_os = "none"))]
struct SetUpAndScan<'a, 'h, const SIDES: usize> {
    polys: [&'a Polygon; LANES_SET_UP],
    ids: &'a [u32],
    shot: &'a Shot<'a, 'h>,
    local: &'a mut [LocalPatch],
    best_t: &'a mut [f32],
    best_id: &'a mut [u32],
}

#[cfg(not(target_os = "none"))]
impl<const SIDES: usize> SimdLoop for SetUpAndScan<'_, '_, SIDES> {
    type Output = ();

    #[inline(always)]
    fn run(self) {
        let shot = self.shot;
        let table = (shot.hemi.rings(), &shot.rings);
        let set_up = setup_lanes::<SIDES>(&self.polys, shot.origin, shot.rot, table);
        let each = set_up.patches.iter().zip(&set_up.reach);
        for (&id, (lp, reach)) in self.ids.iter().zip(each) {
            // only a patch a ray can be inside can win one, and only a winner's set-up is read
            // again (by the report): the others' copies are skipped (1 % of the cut 16 × 16)
            if !lp.active || matches!(reach.runs, Runs::None) {
                continue;
            }
            if let Some(slot) = self.local.get_mut(id as usize) {
                *slot = *lp;
            }
            PatchScan {
                lp,
                reach,
                id,
                hemi: shot.hemi,
                rings: shot.rings.clone(),
                best_t: &mut *self.best_t,
                best_id: &mut *self.best_id,
            }
            .run();
        }
    }
}

/// One polygon's rays of a whole-hemisphere buffer, after its set-up.
#[cfg(not(target_os = "none"))]
struct PatchScan<'a, 'h> {
    lp: &'a LocalPatch,
    reach: &'a Reach,
    id: u32,
    hemi: &'a Hemisphere<'h>,
    rings: Range<usize>,
    best_t: &'a mut [f32],
    best_id: &'a mut [u32],
}

#[cfg(not(target_os = "none"))]
impl SimdLoop for PatchScan<'_, '_> {
    type Output = ();

    #[inline(always)]
    fn run(mut self) {
        let table = self.hemi.rings();
        if let Runs::Some(runs) = self.reach.runs {
            // the box's runs, on one to four rings, where the cone's search would look on more
            for i in 0..SPAN_RINGS {
                if let Some((j, first, last)) = runs.get(i) {
                    let n = table[j].count as i64;
                    let run = (wrap(first, n), (last - first + 1).min(n));
                    self.scan_on(j, run);
                }
            }
            return;
        }
        let widest = self.reach.widest;
        for j in self
            .lp
            .ring_span(table, self.rings.clone(), self.reach.nearest)
        {
            if let Some(run) = self.lp.ring_interval(&table[j], j, widest) {
                self.scan_on(j, run);
            }
        }
    }
}

#[cfg(not(target_os = "none"))]
impl PatchScan<'_, '_> {
    /// The patch's test on `run` (start, length) of ring `j`'s rays.
    #[inline(always)]
    fn scan_on(&mut self, j: usize, run: (i64, i64)) {
        let ring = self.hemi.rings()[j];
        let at = ring_offset(&ring, j);
        let n = ring.count as usize;
        let best_t = &mut self.best_t[at..at + n];
        let best_id = &mut self.best_id[at..at + n];
        scan_ring(self.lp, self.id, self.hemi, &ring, j, run, best_t, best_id);
    }
}
