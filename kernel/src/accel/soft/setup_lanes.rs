//! Sixteen polygons set up at once for one hemisphere (hosts' patch-by-patch walk).
//!
//! On the Cornell box cut 16 × 16 a hemisphere sets up about 3,200 patches for 2,500 rays, and
//! [`LocalPatch::setup`] was 37 % of pass 1: a few hundred operations a patch, with the square
//! roots, divisions and branches of the cone between them. The same operations written lane
//! by lane over [`LANES`] patches (one `[f32; 16]` a quantity) become one AVX-512 instruction
//! each, or two AVX2 ones, where [`super::super::simd::Vectorizer`] compiles them. Every lane does
//! what the scalar set-up does, in the same order, without fused multiply-adds, so each patch
//! gets the same bits (`the_lanes_set_up_what_setup_does` holds every field); the branches
//! become selections made after the arithmetic, which costs nothing where lanes agree.

use super::{ceil_to_int, fast_acos, fast_atan2, floor_to_int, LocalPatch};
use crate::geometry::{sqrt, Polygon, Vec3};
use crate::hemisphere::Ring;
use crate::rotation::Rotation;
use core::ops::Range;

/// Polygons a set-up takes at once: sixteen, one AVX-512 register of f32. Eight (one AVX2
/// register) took 11 % longer on the Cornell box cut 16 × 16 and 7 % on its 8 × 8 cut;
/// thirty-two gained 4 % more at 16 × 16 and lost 4 % on the 10k room (docs/PERFORMANCE.md).
pub(super) const LANES: usize = 16;

/// One quantity of [`LANES`] patches.
type Lane = [f32; LANES];

/// `f` of every index: a plain loop over a fixed array, which the compiler turns into vector
/// instructions over lanes (`core::array::from_fn`'s guard against a panicking `f` kept them
/// scalar, and tripled the set-up's time).
#[inline(always)]
fn each<T: Copy + Default, const N: usize>(f: impl Fn(usize) -> T) -> [T; N] {
    let mut out = [T::default(); N];
    for (k, x) in out.iter_mut().enumerate() {
        *x = f(k);
    }
    out
}

/// [`LANES`] vectors, coordinate by coordinate: lane k's is (x[k], y[k], z[k]).
#[derive(Clone, Copy, Default)]
struct Vec3s {
    x: Lane,
    y: Lane,
    z: Lane,
}

impl Vec3s {
    #[inline(always)]
    fn gather(v: impl Fn(usize) -> Vec3) -> Vec3s {
        Vec3s {
            x: each(|k| v(k).x),
            y: each(|k| v(k).y),
            z: each(|k| v(k).z),
        }
    }

    #[inline(always)]
    fn lane(&self, k: usize) -> Vec3 {
        Vec3::new(self.x[k], self.y[k], self.z[k])
    }

    /// `v - o` in every lane, as `Vec3`'s `Sub`.
    #[inline(always)]
    fn minus(self, o: Vec3) -> Vec3s {
        Vec3s {
            x: each(|k| self.x[k] - o.x),
            y: each(|k| self.y[k] - o.y),
            z: each(|k| self.z[k] - o.z),
        }
    }

    /// [`Rotation::invert`] in every lane, operation for operation.
    #[inline(always)]
    fn invert(self, r: &Rotation) -> Vec3s {
        let x1: Lane = each(|k| self.x[k] * r.cos_phi + self.y[k] * r.sin_phi);
        let y: Lane = each(|k| -self.x[k] * r.sin_phi + self.y[k] * r.cos_phi);
        let x: Lane = each(|k| x1[k] * r.cos_theta - self.z[k] * r.sin_theta);
        Vec3s {
            x: each(|k| x[k] * r.cos_psi + y[k] * r.sin_psi),
            y: each(|k| -x[k] * r.sin_psi + y[k] * r.cos_psi),
            z: each(|k| x1[k] * r.sin_theta + self.z[k] * r.cos_theta),
        }
    }

    /// `Vec3::dot` in every lane.
    #[inline(always)]
    fn dot(&self, o: &Vec3s) -> Lane {
        each(|k| self.x[k] * o.x[k] + self.y[k] * o.y[k] + self.z[k] * o.z[k])
    }

    /// `Vec3::cross` in every lane (never fused: shared edges stay exact negations).
    #[inline(always)]
    fn cross(&self, o: &Vec3s) -> Vec3s {
        Vec3s {
            x: each(|k| self.y[k] * o.z[k] - self.z[k] * o.y[k]),
            y: each(|k| self.z[k] * o.x[k] - self.x[k] * o.z[k]),
            z: each(|k| self.x[k] * o.y[k] - self.y[k] * o.x[k]),
        }
    }

    /// Each lane's vector times that lane's `s`.
    #[inline(always)]
    fn times(&self, s: &Lane) -> Vec3s {
        Vec3s {
            x: each(|k| self.x[k] * s[k]),
            y: each(|k| self.y[k] * s[k]),
            z: each(|k| self.z[k] * s[k]),
        }
    }
}

/// [`LANES`] patches set up, and how far each reaches on the rings.
pub(super) struct SetUp {
    /// What [`LocalPatch::setup`] gives each.
    pub(super) patches: [LocalPatch; LANES],
    /// Where each patch's rays are, for the patch-by-patch walk.
    pub(super) reach: [Reach; LANES],
}

/// What the patch-by-patch walk needs of a patch besides its set-up, computed with it in lanes
/// where the walk had computed it patch by patch (a square root, a division and an arc cosine
/// or two each, 8 % of the cut 16 × 16 box's pass 1).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Reach {
    /// Where on the shot's rings rays can fall inside the patch, by its box in polar angle and
    /// azimuth (see [`Span`]).
    pub(super) runs: Runs,
    /// The ring nearest the cone's axis, where the search for the rings it meets starts.
    pub(super) nearest: usize,
    /// The widest azimuth half-width the cone spans on any ring, when it holds neither pole:
    /// sin Δφ = sin α / sin θ_c (the great circle through the pole tangent to the cone), widened
    /// by 3e-4 rad (fast_acos errs by 6.7e-5, fast_atan2 by 2e-6, the roundings by less). A
    /// cone round a pole has sin α ≥ sin θ_c and keeps the per-ring intervals.
    pub(super) widest: Option<f32>,
}

/// Where a patch's rays can be, from its [`Span`].
#[derive(Clone, Copy, Debug, Default)]
pub(super) enum Runs {
    /// Not known: the walk searches the rings the cone meets.
    #[default]
    Unknown,
    /// On no ring: the walk skips the patch.
    None,
    /// Only in these runs of ray indices.
    Some(RingRuns),
}

/// Runs of ray indices on up to [`SPAN_RINGS`] consecutive rings: ring `first + i` holds the
/// run `lo[i]..=hi[i]` where bit i of `kept` is set (indices may run past either end of the
/// ring, as the azimuths wrap). Kept small (40 bytes, and [`Runs`] 44, where a list of
/// `(ring, first, last)` in 64 bits made `Runs` 104): sixteen of them are moved about with
/// every set-up, and moving the larger ones was a tenth of the cut 16 × 16 box's pass 1.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct RingRuns {
    first: u32,
    kept: u8,
    lo: [i32; SPAN_RINGS],
    hi: [i32; SPAN_RINGS],
}

impl RingRuns {
    /// Run `i` as (ring, first index, last index), if kept.
    #[inline(always)]
    pub(super) fn get(&self, i: usize) -> Option<(usize, i64, i64)> {
        let (lo, hi) = (*self.lo.get(i)?, *self.hi.get(i)?);
        (self.kept >> i & 1 == 1).then_some((self.first as usize + i, lo as i64, hi as i64))
    }
}

/// Sets up `polys` (all of `SIDES` sides) from `origin` in the frame of `rot` for the shot's
/// `rings` of `table`: the edges and the plane that decide the hits, then the bounding cone,
/// then the reach.
#[inline(always)]
pub(super) fn setup_lanes<const SIDES: usize>(
    polys: &[&Polygon; LANES],
    origin: Vec3,
    rot: &Rotation,
    (table, rings): (&[Ring], &Range<usize>),
) -> SetUp {
    // (plain loops, not closures: a closure the compiler does not inline is compiled for the
    // baseline and called, outside the vector code)
    let normals = Vec3s::gather(|k| polys[k].normal);
    let mut h = [0.0; LANES];
    let mut local = [Vec3s::default(); SIDES];
    let mut length = [[0.0; LANES]; SIDES];
    for (c, (l, n)) in local.iter_mut().zip(&mut length).enumerate() {
        let corner = Vec3s::gather(|k| polys[k].v[c]).minus(origin);
        if c == 0 {
            h = normals.dot(&corner);
        }
        *l = corner.invert(rot);
        let squared = l.dot(l);
        *n = each(|k| sqrt(squared[k]));
    }
    let seen = seen_lanes(&h, &local, &length);
    let sign: Lane = each(|k| if h[k] > 0.0 { 1.0 } else { -1.0 });
    let mut edges = [Vec3s::default(); SIDES];
    for (c, e) in edges.iter_mut().enumerate() {
        *e = local[c].cross(&local[(c + 1) % SIDES]).times(&sign);
    }
    let thin = thin_lanes(&edges, &length);
    let cone = Cone::of(&local, &length);
    let normal = normals.invert(rot);
    let mut set_up = [LocalPatch::default(); LANES];
    for (k, lp) in set_up.iter_mut().enumerate() {
        if !seen[k] {
            continue;
        }
        *lp = LocalPatch {
            sides: polys[k].sides,
            normal: normal.lane(k),
            h: h[k],
            active: true,
            ..LocalPatch::default()
        };
        for (e, edge) in lp.edges.iter_mut().zip(&edges) {
            *e = edge.lane(k);
        }
        cone.bound(lp, k);
    }
    let reach = cone.reach(&set_up, &thin, (table, rings));
    SetUp {
        patches: set_up,
        reach,
    }
}

/// Whether each lane's patch has a [`thin_edge`].
#[inline(always)]
fn thin_lanes<const SIDES: usize>(edges: &[Vec3s; SIDES], length: &[Lane; SIDES]) -> [bool; LANES] {
    let mut thin = [false; LANES];
    for (c, e) in edges.iter().enumerate() {
        let (squared, next) = (e.dot(e), &length[(c + 1) % SIDES]);
        for (k, t) in thin.iter_mut().enumerate() {
            *t |= thin_edge(squared[k], length[c][k], next[k]);
        }
    }
    thin
}

/// Whether each lane's patch can be seen at all: not from its own plane (a NaN distance counts
/// as in the plane), and not wholly below the horizon, as `setup_sides` returns early.
#[inline(always)]
fn seen_lanes<const SIDES: usize>(
    h: &Lane,
    local: &[Vec3s; SIDES],
    length: &[Lane; SIDES],
) -> [bool; LANES] {
    each(|k| {
        let scale = length.iter().fold(0.0f32, |m, n| m.max(n[k]));
        let in_plane = h[k].abs().is_nan() || h[k].abs() <= 1e-6 * scale;
        let below = local.iter().all(|l| l.z[k] <= 0.0);
        !in_plane && !below
    })
}

/// [`LANES`] bounding cones: the axis, the sum of the vertices' directions normalised, and the
/// widest vertex's angle from it.
struct Cone {
    /// Whether the directions' sum could be normalised (else the patch tests every ray).
    some: [bool; LANES],
    axis: Vec3s,
    cos_alpha: Lane,
    axis_rho: Lane,
    axis_phi: Lane,
    span: Span,
}

impl Cone {
    /// The cone of each lane's vertices, as `setup_sides` bounds them.
    #[inline(always)]
    fn of<const SIDES: usize>(local: &[Vec3s; SIDES], length: &[Lane; SIDES]) -> Cone {
        let mut unit = [Vec3s::default(); SIDES];
        let mut sum = Vec3s::default();
        for (u, (l, n)) in unit.iter_mut().zip(local.iter().zip(length)) {
            let inverse: Lane = each(|k| 1.0 / n[k]);
            *u = l.times(&inverse);
            sum = Vec3s {
                x: each(|k| sum.x[k] + u.x[k]),
                y: each(|k| sum.y[k] + u.y[k]),
                z: each(|k| sum.z[k] + u.z[k]),
            };
        }
        let squared = sum.dot(&sum);
        let l: Lane = each(|k| sqrt(squared[k]));
        let some = each(|k| l[k].is_finite() && l[k] > 1e-30);
        let axis = Vec3s {
            x: each(|k| sum.x[k] / l[k]),
            y: each(|k| sum.y[k] / l[k]),
            z: each(|k| sum.z[k] / l[k]),
        };
        let mut widest = [1.0f32; LANES];
        for u in &unit {
            let d = axis.dot(u);
            widest = each(|k| widest[k].min(d[k]));
        }
        let cos_alpha: Lane = each(|k| widest[k] - 1e-4);
        let axis_phi = each(|k| fast_atan2(axis.y[k], axis.x[k]));
        Cone {
            some,
            axis,
            cos_alpha,
            axis_rho: each(|k| sqrt(axis.x[k] * axis.x[k] + axis.y[k] * axis.y[k])),
            axis_phi,
            span: Span::of(&unit, &widest, &axis_phi),
        }
    }

    /// Lane `k`'s cone into `lp`, and its verdict on a patch wholly below the horizon.
    #[inline(always)]
    fn bound(&self, lp: &mut LocalPatch, k: usize) {
        if !self.some[k] {
            lp.full = true;
            return;
        }
        let (axis, cos_alpha) = (self.axis.lane(k), self.cos_alpha[k]);
        lp.axis = axis;
        lp.cos_alpha = cos_alpha;
        lp.axis_rho = self.axis_rho[k];
        lp.axis_phi = self.axis_phi[k];
        lp.full = cos_alpha < 0.05;
        if !lp.full && axis.z < 0.0 {
            let sin_alpha = sqrt((1.0 - cos_alpha * cos_alpha).max(0.0));
            if axis.z * cos_alpha + lp.axis_rho * sin_alpha < -1e-4 {
                lp.active = false;
            }
        }
    }
}

impl Cone {
    /// Each lane's [`Reach`] on the shot's `rings` of `table`, beside its set-up.
    #[inline(always)]
    fn reach(
        &self,
        set_up: &[LocalPatch; LANES],
        thin: &[bool; LANES],
        (table, rings): (&[Ring], &Range<usize>),
    ) -> [Reach; LANES] {
        let r_all = table.len();
        let dtheta = core::f32::consts::FRAC_PI_2 / r_all.max(1) as f32;
        let nearest: Lane = each(|k| nearest_ring(self.axis.z[k], dtheta));
        let (cos_alpha, rho) = (&self.cos_alpha, &self.axis_rho);
        let x: Lane = each(|k| sin_over_rho(cos_alpha[k], rho[k]));
        let half: Lane = each(|k| widest_half(x[k]));
        let rings_in = self.span.rings(1.0 / dtheta, rings);
        let mut reach = [Reach::default(); LANES];
        for (k, (r, lp)) in reach.iter_mut().zip(set_up).enumerate() {
            // a patch the cone bounds (else it is scanned on every ring, as before), and not
            // thin (else it is scanned on each ring's own interval, as boards scan it)
            let bounded = lp.cone_bounds(r_all) && !thin[k];
            *r = Reach {
                runs: match bounded {
                    true => self.span.runs(k, rings_in[k], table),
                    false => Runs::Unknown,
                },
                nearest: (nearest[k] as usize).min(r_all.saturating_sub(1)),
                widest: (bounded && x[k] < 0.999).then_some(half[k]),
            };
        }
        reach
    }
}

impl Reach {
    /// `lp`'s reach on `table`, where the walk sets patches up one at a time (it keeps every
    /// patch: the box of [`Span`] is computed in lanes only); `thin` as [`thin_polygon`] says.
    #[inline(always)]
    pub(super) fn of(lp: &LocalPatch, table: &[Ring], thin: bool) -> Reach {
        let r_all = table.len();
        let dtheta = core::f32::consts::FRAC_PI_2 / r_all.max(1) as f32;
        let nearest = nearest_ring(lp.axis.z, dtheta);
        let x = sin_over_rho(lp.cos_alpha, lp.axis_rho);
        let bounded = lp.cone_bounds(r_all) && !thin;
        Reach {
            runs: Runs::Unknown,
            nearest: (nearest as usize).min(r_all.saturating_sub(1)),
            widest: (bounded && x < 0.999).then(|| widest_half(x)),
        }
    }
}

/// Whether an edge whose normal has squared length `squared`, between corners `a` and `b` away
/// from the origin, is too short in angle γ for a bound narrower than the boards' per-ring
/// interval: its normal, rounded to 2⁻²⁴·ab a component, tilts its plane by about 6e-8 / sin γ
/// rad, which passes [`SPAN_MARGIN`] below sin γ ≈ 2e-4 (a review's slivers lost hits there).
/// Under sin γ = 1e-2 (a tilt under 6e-6 rad) a patch keeps the boards' intervals: the box and
/// the widest bound are for the rest.
#[inline(always)]
fn thin_edge(squared: f32, a: f32, b: f32) -> bool {
    let scale = a * b;
    // (a NaN, from an infinite corner, counts as thin)
    let wide = squared >= 1e-4 * scale * scale;
    !wide
}

/// [`thin_edge`] for any edge of `poly`, set up from `origin` as `lp` (one patch at a time).
pub(super) fn thin_polygon(lp: &LocalPatch, poly: &Polygon, origin: Vec3) -> bool {
    let sides = lp.sides as usize;
    let length = |c: usize| (poly.v[c % sides] - origin).length();
    (0..sides).any(|c| thin_edge(lp.edges[c].dot(lp.edges[c]), length(c), length(c + 1)))
}

/// The index of the ring nearest a cone's axis of height `z`, + ½ (rings Δθ apart).
#[inline(always)]
fn nearest_ring(z: f32, dtheta: f32) -> f32 {
    fast_acos(z.clamp(-1.0, 1.0)) / dtheta + 0.5
}

/// sin α / ρ of a cone's axis (the sine of its widest azimuth half-width, below 1).
#[inline(always)]
fn sin_over_rho(cos_alpha: f32, rho: f32) -> f32 {
    sqrt((1.0 - cos_alpha * cos_alpha).max(0.0)) / rho
}

/// [`Reach::widest`] from [`sin_over_rho`]'s x.
#[inline(always)]
fn widest_half(x: f32) -> f32 {
    core::f32::consts::FRAC_PI_2 - fast_acos(x) + 3e-4
}

/// [`LANES`] boxes in polar angle θ and azimuth φ, each holding every direction from the origin
/// into its patch: the corners' range, widened for the arcs between them. A direction into a
/// convex polygon is a convex combination Σ μᵢvᵢ of its corners' directions, normalised, and
/// |Σ μᵢvᵢ| ≥ (Σ μᵢvᵢ)·a ≥ cos α for the cone's axis a: so its z lies within min zᵢ and max zᵢ,
/// each divided by cos α where that widens it (the arcs bulge toward a pole); and while the
/// corners' azimuths span less than a half-turn (the pole outside), its azimuth lies between
/// theirs. Most of a finely cut box's patches fall between the rays (60 % at 16 × 16, docs/
/// PERFORMANCE.md): a box on one to [`SPAN_RINGS`] rings that holds no ray index drops the
/// patch before its rings are searched, and one that holds some gives the runs to scan. (A
/// thin patch, [`thin_edge`], gets no box: its rounded edges reach past any margin.)
struct Span {
    theta_lo: Lane,
    theta_hi: Lane,
    phi_lo: Lane,
    phi_hi: Lane,
    /// The azimuth bounds hold (the corners lie within less than a half-turn, none at a pole).
    known: [bool; LANES],
}

/// What each bound of a [`Span`] is widened by, in radians: fast_acos errs by 6.7e-5 and
/// fast_atan2 by 2e-6, the corners' directions by a few ulps, a patch's edge planes (rounded)
/// by under 6e-6 where no edge is thin ([`thin_edge`]; thin ones have no box).
const SPAN_MARGIN: f32 = 3e-4;

/// What a [`Span`]'s z bounds are widened by before the arc cosine, whose slope is unbounded at
/// the poles: a few ulps of z there are 1e-3 rad.
const SPAN_MARGIN_Z: f32 = 1e-5;

/// Rings a box may cover and still be tested ray index by ray index; wider boxes are kept.
pub(super) const SPAN_RINGS: usize = 4;

impl Span {
    /// The box of each lane's corner directions `unit` about its cone (axis azimuth `axis_phi`,
    /// cos α = `cos_alpha`, unwidened: every corner's cosine from the axis is at least it).
    #[inline(always)]
    fn of<const SIDES: usize>(unit: &[Vec3s; SIDES], cos_alpha: &Lane, axis_phi: &Lane) -> Span {
        let (mut z_lo, mut z_hi) = ([f32::INFINITY; LANES], [f32::NEG_INFINITY; LANES]);
        let (mut d_lo, mut d_hi) = ([f32::INFINITY; LANES], [f32::NEG_INFINITY; LANES]);
        let mut rho_min = [f32::INFINITY; LANES];
        for u in unit {
            z_lo = each(|k| z_lo[k].min(u.z[k]));
            z_hi = each(|k| z_hi[k].max(u.z[k]));
            let d: Lane = each(|k| half_turn(fast_atan2(u.y[k], u.x[k]) - axis_phi[k]));
            d_lo = each(|k| d_lo[k].min(d[k]));
            d_hi = each(|k| d_hi[k].max(d[k]));
            rho_min = each(|k| rho_min[k].min(u.x[k] * u.x[k] + u.y[k] * u.y[k]));
        }
        let top: Lane = each(|k| match z_hi[k] >= 0.0 {
            true => z_hi[k] / cos_alpha[k],
            false => z_hi[k],
        });
        let bottom: Lane = each(|k| match z_lo[k] < 0.0 {
            true => z_lo[k] / cos_alpha[k],
            false => z_lo[k],
        });
        let wedge = core::f32::consts::PI - 2.0 * SPAN_MARGIN;
        Span {
            theta_lo: each(|k| fast_acos((top[k] + SPAN_MARGIN_Z).min(1.0)) - SPAN_MARGIN),
            theta_hi: each(|k| fast_acos((bottom[k] - SPAN_MARGIN_Z).max(-1.0)) + SPAN_MARGIN),
            phi_lo: each(|k| axis_phi[k] + d_lo[k] - SPAN_MARGIN),
            phi_hi: each(|k| axis_phi[k] + d_hi[k] + SPAN_MARGIN),
            known: each(|k| rho_min[k] > 1e-8 && d_hi[k] - d_lo[k] < wedge),
        }
    }

    /// The rings of `rings` each lane's box covers, θ_j = j·Δθ within its θ bounds
    /// (`ring_of` = 1/Δθ), as (first, last): last < first when it covers none.
    #[inline(always)]
    fn rings(&self, ring_of: f32, rings: &Range<usize>) -> [(i64, i64); LANES] {
        let first: Lane = each(|k| self.theta_lo[k] * ring_of);
        let last: Lane = each(|k| self.theta_hi[k] * ring_of);
        let (start, end) = (rings.start as i64, rings.end as i64 - 1);
        each(|k| {
            let first = ceil_to_int(first[k]).max(start);
            (first, floor_to_int(last[k]).min(end))
        })
    }

    /// Lane `k`'s box on its rings `first..=last` of `table`: on none of them, or on each of at
    /// most [`SPAN_RINGS`] of them the ray indices k with (k + ½)·2π/N_j within its azimuths
    /// (as `ring_interval` places them). (Patch by patch: the same in lanes, for all of a
    /// lane's four rings at once, was 5–15 % slower on the cut 16 × 16 box than this loop,
    /// which most patches leave early.)
    #[inline(always)]
    fn runs(&self, k: usize, (first, last): (i64, i64), table: &[Ring]) -> Runs {
        if last < first {
            return Runs::None;
        }
        if first <= 0 || !self.known[k] || last - first >= SPAN_RINGS as i64 {
            return Runs::Unknown;
        }
        let mut runs = RingRuns {
            first: first as u32,
            ..RingRuns::default()
        };
        // (a plain loop: `(first..=last).all(…)` stayed a call, 6 % of the cut 16 × 16 box)
        for (i, j) in (first..last + 1).enumerate() {
            let Some(ring) = table.get(j as usize) else {
                return Runs::Unknown;
            };
            let per_radian = ring.count as f32 * (1.0 / core::f32::consts::TAU);
            // (the azimuths lie within a turn and a half, so the ends are within a few ring
            // lengths: 32 bits hold what `ceil_to_int` gives, and saturate past them)
            let lo = to_i32(ceil_to_int(self.phi_lo[k] * per_radian - 0.5));
            let hi = to_i32(floor_to_int(self.phi_hi[k] * per_radian - 0.5));
            runs.kept |= ((hi >= lo) as u8) << i;
            (runs.lo[i], runs.hi[i]) = (lo, hi);
        }
        match runs.kept {
            0 => Runs::None,
            _ => Runs::Some(runs),
        }
    }
}

/// `x` in 32 bits, saturating.
#[inline(always)]
fn to_i32(x: i64) -> i32 {
    x.clamp(i32::MIN.into(), i32::MAX.into()) as i32
}

/// An angle difference in (−π, π] (both angles in (−π, π], so one turn at most corrects it).
#[inline(always)]
fn half_turn(d: f32) -> f32 {
    use core::f32::consts::{PI, TAU};
    match d {
        _ if d > PI => d - TAU,
        _ if d <= -PI => d + TAU,
        _ => d,
    }
}

#[cfg(test)]
mod tests {
    use super::{setup_lanes, Runs, LANES, SPAN_RINGS};
    use crate::accel::soft::tests::uniform;
    use crate::accel::soft::LocalPatch;
    use crate::geometry::{Polygon, Vec3};
    use crate::rotation::Rotation;

    /// Every field's bits, so that NaN and −0 count.
    fn bits(lp: &LocalPatch) -> ([u32; 12], [u32; 10], u8, [bool; 3]) {
        let e: [u32; 12] = core::array::from_fn(|i| {
            let v = lp.edges[i / 3];
            [v.x, v.y, v.z][i % 3].to_bits()
        });
        let f = [
            lp.normal.x,
            lp.normal.y,
            lp.normal.z,
            lp.h,
            lp.axis.x,
            lp.axis.y,
            lp.axis.z,
            lp.cos_alpha,
            lp.axis_rho,
            lp.axis_phi,
        ]
        .map(f32::to_bits);
        (e, f, lp.sides, [lp.full, lp.active, lp.curved])
    }

    /// Random quads and triangles around random origins and frames, with the cases that
    /// return early (an origin in the plane, a patch below the horizon, one seen edge-on) and
    /// degenerate ones: each lane gets every bit of the one-patch set-up, the cone's azimuth
    /// included. Changing one operation's order in the lanes fails it.
    #[test]
    fn the_lanes_set_up_what_setup_does() {
        let mut unit = uniform(0x9e37_79b9_7f4a_7c15u64);
        let mut next = move || unit() * 2.0 - 1.0;
        let mut checked = 0;
        for round in 0..4000 {
            let origin = Vec3::new(next(), next(), next()) * 3.0;
            let normal = Vec3::new(next(), next(), next())
                .try_normalize()
                .unwrap_or(Vec3::Z);
            let rot = Rotation::onto_spun(normal, next() * 3.0);
            let polys: [Polygon; LANES] = core::array::from_fn(|k| {
                let c = Vec3::new(next(), next(), next()) * 4.0;
                let (a, b) = (
                    Vec3::new(next(), next(), next()),
                    Vec3::new(next(), next(), next()),
                );
                let v = [c, c + a, c + a + b, c + b];
                let built = if (round + k) % 3 == 0 {
                    Polygon::triangle([v[0], v[1], v[2]])
                } else {
                    Polygon::quad(v)
                };
                let unit = || {
                    Polygon::quad(
                        [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
                            .map(|(x, y)| Vec3::new(x, y, 0.0)),
                    )
                };
                let mut p = match built.or_else(|_| unit()) {
                    Ok(p) => p,
                    Err(e) => panic!("{e:?}"),
                };
                match (round + k) % 7 {
                    // the origin in the plane, or next to a vertex
                    0 => p.v[0] = origin,
                    1 => p.v[1] = origin + Vec3::new(1e-7, 0.0, 0.0),
                    _ => {}
                }
                p
            });
            for sides in [3u8, 4] {
                let group: std::vec::Vec<&Polygon> =
                    polys.iter().filter(|p| p.sides == sides).collect();
                let Some(&spare) = group.first() else {
                    continue;
                };
                let lanes: [&Polygon; LANES] =
                    core::array::from_fn(|k| group.get(k).copied().unwrap_or(spare));
                let table = (&[][..], &(0..0));
                let set_up = match sides {
                    4 => setup_lanes::<4>(&lanes, origin, &rot, table),
                    _ => setup_lanes::<3>(&lanes, origin, &rot, table),
                };
                for (p, lp) in lanes.iter().zip(&set_up.patches) {
                    let one = LocalPatch::setup(p, origin, &rot);
                    assert_eq!(bits(lp), bits(&one), "{p:?} from {origin:?}");
                    checked += 1;
                }
            }
        }
        assert!(checked >= 4000 * LANES);
    }

    /// The span's runs hold every ray that hits the patch, and a patch it drops holds none:
    /// small quads (most between the rays, some on them), near and far, many near the pole,
    /// from random frames, every ray of a 32-ring hemisphere tested against each patch. The
    /// test must drop many and bound many by runs; a margin below zero, the arcs not widened by
    /// cos α, or a box round the pole taken for a wedge of azimuth (in a window of rings
    /// without the pole) fails it.
    #[test]
    fn the_spans_runs_hold_every_ray_that_hits() {
        use crate::hemisphere::{DeltaRule, OwnedHemisphere};
        let owned = OwnedHemisphere::new(32, DeltaRule::Band).unwrap();
        let hemi = owned.view();
        let table = hemi.rings();
        let mut next = uniform(0x2545_f491_4f6c_dd1du64);
        let (mut dropped, mut bounded) = (0, 0);
        for round in 0..3000 {
            let origin = Vec3::new(next(), next(), next());
            let normal = Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5)
                .try_normalize()
                .unwrap_or(Vec3::Z);
            let rot = Rotation::onto_spun(normal, next() * 6.0);
            let polys: [Polygon; LANES] = core::array::from_fn(|_| {
                // a direction above the horizon, toward the pole on some rounds
                let lift = if round % 4 == 0 { 0.999 } else { next() };
                let dir = rot.apply(
                    Vec3::new(next() - 0.5, next() - 0.5, lift)
                        .try_normalize()
                        .unwrap_or(Vec3::Z),
                );
                let c = origin + dir * (0.5 + 4.0 * next());
                let size = 0.005 + 0.2 * next();
                let a = Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5) * size;
                let b = Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5) * size;
                let quad = Polygon::quad([c, c + a, c + a + b, c + b]);
                let x = Vec3::new(1.0, 0.0, 0.0);
                let square = [Vec3::ZERO, x, x + Vec3::Z, Vec3::Z];
                quad.or_else(|_| Polygon::quad(square))
                    .expect("a unit square is a quad")
            });
            let lanes: [&Polygon; LANES] = core::array::from_fn(|k| &polys[k]);
            // every ring, or a window without the pole (where a box round the pole must not
            // be taken for a wedge of azimuth)
            let window = [0, 1, 5][round % 3]..table.len();
            let set_up = setup_lanes::<4>(&lanes, origin, &rot, (table, &window));
            for (k, (lp, reach)) in set_up.patches.iter().zip(&set_up.reach).enumerate() {
                if !lp.active {
                    continue;
                }
                let hits: std::vec::Vec<(usize, u32)> = (0..table.len())
                    .flat_map(|j| (0..table[j].count).map(move |i| (j, i)))
                    .filter(|&(j, i)| window.contains(&j) && lp.hit(hemi.direction(j, i)).is_some())
                    .collect();
                let held = |&(j, i): &(usize, u32)| match reach.runs {
                    Runs::Unknown => true,
                    Runs::None => false,
                    Runs::Some(runs) => (0..SPAN_RINGS).filter_map(|r| runs.get(r)).any(|r| {
                        let n = table[j].count as i64;
                        let from = (i as i64 - r.1).rem_euclid(n);
                        r.0 == j && from <= r.2 - r.1
                    }),
                };
                if let Some(missed) = hits.iter().find(|h| !held(h)) {
                    panic!("{:?}: ray {missed:?} outside {:?}", polys[k], reach.runs);
                }
                dropped += matches!(reach.runs, Runs::None) as usize;
                bounded += (matches!(reach.runs, Runs::Some(_)) && !hits.is_empty()) as usize;
            }
        }
        assert!(
            dropped > 3000 && bounded > 1000,
            "{dropped} dropped, {bounded} hit within runs"
        );
    }
}
