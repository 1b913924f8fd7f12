//! The Bezier unit: ray against one bicubic Bezier patch by bounding-box subdivision with an
//! on-chip stack (paper §6.1, §7), the algorithm of the kernel's `Bezier::intersect` in fixed
//! point:
//!
//! ```text
//!  REPEAT UNTIL STACK IS EMPTY:
//!    node := working register, or POP              (STACK_WORDS clocks when popped)
//!    IF node.enter ≥ best_t: drop it                            (1 clock)
//!    ELSE IF depth = D or (depth ≥ 2 and flat within tol): LEAF  (LEAF_CLOCKS)
//!    ELSE split into four by midpoint de Casteljau, box and slab-test each child,
//!         keep the nearest hit child in the working register,
//!         PUSH the others far-to-near       (STEP_CLOCKS + STACK_WORDS per push)
//! ```
//!
//! The state machine ([`BezierEngine`]) is sequential: one node per step, as in Pulleyblank &
//! Kapenga's chip and the paper's fig. 7. Each step's combinational logic is evaluated at once
//! on the clock the step begins and the engine then waits out the step's clocks (the way the
//! planar path models its divider): the counts are those of the datapath described at each
//! constant below, not of the model's own work.
//!
//! Formats and widths:
//! - control points: the configured coordinate width Wc, Q2.(Wc−2), held in the Q8.24 containers
//!   of patch memory (the low 26 − Wc bits are cleared on load and after every midpoint; values
//!   wrap at ±2, which the driver's normalisation into [−1, 1] never reaches). Midpoints are an
//!   add and a shift by the constant 1, truncating.
//! - ray: origin Q8.24, direction Q2.30, and per ray the reciprocals 1/d as Q32.32 (computed by
//!   the ray's reciprocal unit before it starts, see [`RECIP_LATENCY`]).
//! - slab distances: (box − origin) · 1/d, products by the reciprocal's leading [`RECIP_BITS`]
//!   bits truncated to Q8.24 (64-bit saturating registers), widened on each side by
//!   [`SLAB_MARGIN`] LSBs and 2^-[`SLAB_REL_SHIFT`] of the distance, so that neither the
//!   truncation nor the reciprocal's rounding rejects a box the exact test would accept.
//! - flatness: 9·P_rc − Σ w·corners with the integer weights of the bilinear map at (c/3, r/3),
//!   compared with 9·tol: exact, no rounding.
//! - leaf: the corner quad as two triangles, Möller–Trumbore in exact integer arithmetic
//!   (products up to 103 bits, i128 registers); t, s and r come out of dividers as truncated
//!   quotients (t as Q8.24, s and r as Q.30) after normalising the denominator to 62 bits.
//! - (u, v) = cell origin (the depth bits of the cell index) + (s, r) · 2^-depth, Q2.30.
//!
//! Values with a binary point are `fixed` types (`crate::format`): the ray, reciprocals, boxes,
//! distances, numerators and (s, r), so a product or quotient realigns by what its formats say
//! (`wide_mul`, `format::quotient`) rather than by a shift written beside a comment. The
//! control-point banks stay raw words: the midpoint adders, masks and min/max trees do not
//! depend on where the point is, and the host runs them lane by lane.

use crate::format::{quotient, width_mask, Coord, Coord64, Recip, Unit, Unit64};
use crate::intersect::coarse::{top_words, WORD_BITS};
use fixed::types::extra::{LeEqU128, U24, U30, U72, U78};
use fixed::FixedI128;

/// Coordinate words of one patch's control points in control-point memory: 16 points × (x, y, z).
pub const CP_WORDS: usize = 48;
/// Rows of control-point memory (one patch each): the 32-patch teapot with room to spare.
pub const BEZIER_ROWS: usize = 64;
/// Entries of the on-chip subdivision stack (each 16 points × 3 × Wc bits plus the cell index,
/// depth and entry distance: about 1.35 kbit at Wc = 26, 54 kbit in all). A depth-first descent
/// that keeps the nearest child in the working register leaves at most three siblings pending
/// per level, so a depth D needs 3·D entries: D ≤ 13 fits.
pub const STACK_ENTRIES: usize = 40;
/// Deepest subdivision: the (u,v) cell index registers are 16 bits per axis.
pub const MAX_DEPTH: u32 = 16;
/// Narrowest control-point datapath.
pub const MIN_COORD_WIDTH: u32 = 12;
/// Widest control-point datapath: Q2.24, exactly the memory's Q8.24 fraction.
pub const MAX_COORD_WIDTH: u32 = 26;
/// Clocks of a subdivision step besides its pushes: (1) the de Casteljau midpoint network (three
/// levels of adders along u, then three along v, all 49 points of the 7×7 grid at once) and the
/// flatness test; (2) the four children's boxes (16-input min/max trees) and their slab tests
/// (24 multipliers against 1/d), then the near-to-far sort of four entry distances.
pub const STEP_CLOCKS: u32 = 2;
/// Clocks of a leaf test: two for the cross and dot products of both triangles (p = d × e2,
/// q = s × e1, then the four dot products), 32 for radix-2 restoring dividers (t, s, r of both
/// triangles in parallel, 32 quotient bits each).
pub const LEAF_CLOCKS: u32 = 34;
/// Clocks of the reciprocal unit that computes 1/d (three radix-2 dividers, 32 quotient bits,
/// plus one to load): pipelined, at the input of the ray queue.
pub const RECIP_LATENCY: u64 = 33;
/// Clocks the compact datapath's slab tester adds to a step: one tester for the four children
/// and two multipliers in it, an axis's two bounds (box − origin) · 1/d a clock, so three clocks
/// a child and twelve a step where four testers of six take one. Why two: each 26 × 64
/// multiplier is eight DSP tiles of the part's 156 (or, without tiles, an array of about 3,400
/// LUT4s; 10,000 as Yosys maps `a * b`), for a unit only Bezier patches use. Until session 24
/// six multipliers, a child a clock (3 more).
pub const SERIAL_SLAB_CLOCKS: u32 = 4 * 3 - 1;

/// Clocks the compact datapath's leaf adds to [`LEAF_CLOCKS`]: its products on two 34 × 34
/// multipliers, two a clock. A triangle is p = d × e2 (six products), det = e1 · p and
/// b1 = s · p (six), q = s × e1 (six), b2 = d · q and t = e2 · q (six): 24 products, twelve
/// clocks, the second triangle after the first, so 24 clocks where eighteen multipliers take
/// two. Until session 24 six multipliers, eight clocks (6 more).
pub const SERIAL_LEAF_CLOCKS: u32 = 2 * 24 / 2 - 2;

/// Words of the stack memory a node takes, one a clock: its 1,300 bits (16 control points of
/// three 26-bit words, the cell, depth and entry distance) as two words of 650, so the 40-entry
/// stack is 19 block RAMs of 512 × 36 where a 1,300-bit word took 37 (one until session 44).
pub const STACK_WORDS: u32 = 2;

/// Each slab interval is widened by this (two LSBs of Q8.24), and by its distance's own
/// 2^-[`SLAB_REL_SHIFT`] for the reciprocal's rounding ([`RECIP_BITS`]).
pub const SLAB_MARGIN: Coord64 = Coord64::from_bits(2);
/// Significant bits of a reciprocal 1/d in the slab test: the divider's Q32.32 quotient is
/// floored to its leading [`RECIP_BITS`] signed bits (a block floating point of its own), so
/// a slab product is 26 × 18 bits, two DSP tiles, where the whole word made it 26 × 64, eight
/// (until session 44). The reciprocal is then off by under 2^-16 of itself, and so is every
/// distance formed with it. The coarse words' width, scaled as they are ([`top_words`]).
pub const RECIP_BITS: u32 = WORD_BITS;
/// A distance t formed with a rounded reciprocal is within |t| · 2^-16 / (1 − 2^-16) plus the
/// product's truncation (an LSB) of the exact one, which |t̃| >> 15, one LSB for that shift's
/// floor and [`SLAB_MARGIN`] cover, with |t̃| the distance as formed.
pub const SLAB_REL_SHIFT: u32 = 15;
/// The barycentric tolerance of the leaf test as a shift of the determinant: 2^-20 ≈ 1e-6, the
/// kernel's `EPS`, so rays through a leaf edge are not lost between two leaves.
const BARY_EPS_SHIFT: u32 = 20;

/// A control point: x, y, z as raw words of the Q8.24 containers (holding Q2.(Wc−2)).
pub type Point = [i32; 3];

/// The 16 control points of a (sub-)patch as the datapath's registers hold them: one bank per
/// axis, point r·4 + c (row r along v, column c along u) in each. Each bank is its own 16-word
/// register file in hardware; on the host, a contiguous array the min/max trees and midpoint
/// adders run over lane by lane.
pub type Net = [[i32; 16]; 3];

/// Point `i` of a net.
#[inline]
fn point(net: &Net, i: usize) -> Point {
    [net[0][i], net[1][i], net[2][i]]
}

/// The subdivision parameters (the BZ_CONFIG register).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SubdivConfig {
    /// Maximum subdivision depth D.
    pub depth: u32,
    /// Control-point datapath width Wc in bits.
    pub coord_width: u32,
}

impl SubdivConfig {
    /// Depth 10 (the kernel's default) on the full 26-bit datapath.
    pub const DEFAULT: SubdivConfig = SubdivConfig {
        depth: 10,
        coord_width: 26,
    };

    /// Whether a unit with a `stack`-entry stack can run it: D within the cell index and its
    /// worst case of 3·D pending siblings within the stack, Wc within the datapath.
    pub fn is_valid_for(&self, stack: usize) -> bool {
        (1..=MAX_DEPTH).contains(&self.depth)
            && 3 * self.depth as usize <= stack
            && (MIN_COORD_WIDTH..=MAX_COORD_WIDTH).contains(&self.coord_width)
    }

    /// The mask that keeps Wc bits of a Q8.24 container as Q2.(Wc−2).
    pub fn mask(&self) -> i32 {
        width_mask(self.coord_width + 6)
    }
}

/// A coordinate word as the Wc-bit datapath holds it: wrapped to Q2.24 (±2), low bits cleared.
#[inline]
pub fn to_datapath(raw: i32, mask: i32) -> i32 {
    ((raw << 6) >> 6) & mask
}

/// The per-ray inputs of the unit, in its 64-bit registers.
#[derive(Clone, Copy, Debug, Default)]
pub struct RaySetup {
    /// Origin.
    pub origin: [Coord64; 3],
    /// Direction.
    pub dir: [Unit64; 3],
    /// 1/d per axis (zero where `parallel`).
    pub inv: [Recip; 3],
    /// d is zero on this axis.
    pub parallel: [bool; 3],
}

impl RaySetup {
    /// The ray with its reciprocals 1/d, truncated: 2^(32 + 30) / d's bits, the Q32.32
    /// quotient of the constant 1 by a Q2.30 divisor, floored to [`RECIP_BITS`] significant
    /// bits.
    pub fn new(origin: [Coord; 3], dir: [Unit; 3]) -> Self {
        let d = dir.map(Unit64::from);
        RaySetup {
            origin: origin.map(Coord64::from),
            dir: d,
            inv: d.map(|c| match c.to_bits() {
                0 => Recip::ZERO,
                bits => Recip::from_bits(significant((1i64 << 62) / bits)),
            }),
            parallel: d.map(|c| c == Unit64::ZERO),
        }
    }
}

/// An axis-aligned box.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Box3 {
    /// Minimum corner.
    pub lo: [Coord64; 3],
    /// Maximum corner.
    pub hi: [Coord64; 3],
}

impl Box3 {
    /// The box of 16 control points (three 16-input min/max trees).
    pub fn of(net: &Net) -> Box3 {
        // on the datapath words themselves (i32), a bank at a time, so the host can run the
        // trees as vector min/max; the box registers are the 64-bit slab inputs
        let lo = net.map(|bank| bank.into_iter().fold(i32::MAX, i32::min));
        let hi = net.map(|bank| bank.into_iter().fold(i32::MIN, i32::max));
        // the words are Q8.24 containers (holding Q2.(Wc−2))
        let word = |w: i32| Coord64::from(Coord::from_bits(w));
        Box3 {
            lo: lo.map(word),
            hi: hi.map(word),
        }
    }

    /// The slab test of §6.1: the entry distance (at least `t_min`) if the ray meets the box
    /// with entry ≤ exit, exit ≥ `t_min` and entry < `t_max`.
    #[inline]
    pub fn slab(&self, ray: &RaySetup, t_min: Coord64, t_max: Coord64) -> Option<Coord64> {
        let mut enter = Coord64::MIN;
        let mut exit = Coord64::MAX;
        for k in 0..3 {
            let o = ray.origin[k];
            if ray.parallel[k] {
                if o < self.lo[k] || o > self.hi[k] {
                    return None;
                }
                continue;
            }
            let a = mul_q32(self.lo[k] - o, ray.inv[k]);
            let b = mul_q32(self.hi[k] - o, ray.inv[k]);
            let (a, b) = if a < b { (a, b) } else { (b, a) };
            enter = enter.max(a - margin(a));
            exit = exit.min(b + margin(b));
        }
        (enter <= exit && exit >= t_min && enter < t_max).then_some(enter.max(t_min))
    }
}

/// `x` floored to its leading [`RECIP_BITS`] signed bits, the bits below them cleared
/// ([`top_words`] and back: a leading one and a mask).
fn significant(x: i64) -> i64 {
    let ([w], s) = top_words(&[x]);
    w << s
}

/// What a slab bound formed with a rounded reciprocal is widened by: its own magnitude shifted
/// by [`SLAB_REL_SHIFT`], an LSB and [`SLAB_MARGIN`] (a magnitude and an adder a bound).
#[inline]
fn margin(t: Coord64) -> Coord64 {
    let rel = (t.to_bits().unsigned_abs() >> SLAB_REL_SHIFT) as i64 + 1;
    Coord64::from_bits(rel) + SLAB_MARGIN
}

/// A distance along the ray: `delta` · 1/d, the 128-bit product truncated back to Q8.24 and
/// saturated to a quarter of the 64-bit range so that the margins cannot wrap.
#[inline]
fn mul_q32(delta: Coord64, inv: Recip) -> Coord64 {
    /// The saturation bounds, in the product's container.
    const LO: FixedI128<U24> = FixedI128::from_bits(i64::MIN as i128 / 4);
    const HI: FixedI128<U24> = FixedI128::from_bits(i64::MAX as i128 / 4);
    let t: FixedI128<U24> = delta.wide_mul(inv).wrapping_to_num();
    t.clamp(LO, HI).wrapping_to_num()
}

/// Midpoints of four pairs of datapath words (one adder per lane): a 1-bit-wider add and the
/// constant shift 1, truncated to Wc. Datapath words are within ±2^25 ([`to_datapath`]), so the
/// 27-bit sum fits the i32 the host computes it in.
#[inline]
fn mid4(a: [i32; 4], b: [i32; 4], mask: i32) -> [i32; 4] {
    core::array::from_fn(|l| ((a[l] + b[l]) >> 1) & mask)
}

/// Four cubics split at ½ at once by de Casteljau's midpoints, lane l being cubic l: `p[i]` is
/// control point i of every lane. Returns the left and right halves, in the same form.
#[inline]
fn split4(p: [[i32; 4]; 4], mask: i32) -> ([[i32; 4]; 4], [[i32; 4]; 4]) {
    let p01 = mid4(p[0], p[1], mask);
    let p12 = mid4(p[1], p[2], mask);
    let p23 = mid4(p[2], p[3], mask);
    let a = mid4(p01, p12, mask);
    let b = mid4(p12, p23, mask);
    let c = mid4(a, b, mask);
    ([p[0], p01, a, c], [c, b, p23, p[3]])
}

/// The split stage: the four children at the parametric midpoints (index bit 0 = upper u half,
/// bit 1 = upper v half, the kernel's order), rows along u first, then columns along v. Each
/// axis bank splits on its own: the four rows along u as four lanes, then the four columns of
/// each half along v as four lanes.
#[derive(Clone, Copy, Debug, Default)]
pub struct SplitStage;

impl SplitStage {
    /// The stage's logic.
    pub fn eval(&self, net: &Net, mask: i32) -> [Net; 4] {
        let mut out = [[[0; 16]; 3]; 4];
        for (k, bank) in net.iter().enumerate() {
            // along u: lane r is row r, p[c] its column c
            let cols: [[i32; 4]; 4] =
                core::array::from_fn(|c| core::array::from_fn(|r| bank[4 * r + c]));
            let (left, right) = split4(cols, mask);
            for (h, half) in [left, right].iter().enumerate() {
                // along v: lane c is column c of the half, p[r] its row r
                let rows: [[i32; 4]; 4] =
                    core::array::from_fn(|r| core::array::from_fn(|c| half[c][r]));
                let (low, high) = split4(rows, mask);
                for r in 0..4 {
                    for c in 0..4 {
                        out[h][k][4 * r + c] = low[r][c];
                        out[2 + h][k][4 * r + c] = high[r][c];
                    }
                }
            }
        }
        out
    }
}

/// The flatness test: every control point within `tol` (max norm) of the bilinear map of the
/// four corners at (c/3, r/3). Scaled by 9 so that the weights are integers: the sums are in
/// the control points' own format (Q8.24 containers), so they compare with 9 · `tol` exactly.
#[derive(Clone, Copy, Debug, Default)]
pub struct FlatnessStage;

impl FlatnessStage {
    /// The stage's logic.
    pub fn eval(&self, cp: &Net, tol: Coord64) -> bool {
        let (p00, p10, p01, p11) = (point(cp, 0), point(cp, 3), point(cp, 12), point(cp, 15));
        let lim = (tol * 9).to_bits();
        for r in 0..4i64 {
            for c in 0..4i64 {
                let p = point(cp, 4 * r as usize + c as usize);
                for k in 0..3 {
                    let bilinear = (3 - r) * (3 - c) * p00[k] as i64
                        + (3 - r) * c * p10[k] as i64
                        + r * (3 - c) * p01[k] as i64
                        + r * c * p11[k] as i64;
                    if (9 * p[k] as i64 - bilinear).abs() > lim {
                        return false;
                    }
                }
            }
        }
        true
    }
}

fn sub(a: Point, b: Point) -> [i128; 3] {
    core::array::from_fn(|k| a[k] as i128 - b[k] as i128)
}

fn cross(a: [i128; 3], b: [i128; 3]) -> [i128; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot(a: [i128; 3], b: [i128; 3]) -> i128 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Möller–Trumbore numerators of one triangle, sign-normalised so that det > 0: (det, b1·det,
/// b2·det, t·det), and the side (det > 0 before normalisation: the ray meets the side
/// ∂P/∂u × ∂P/∂v points away from). They are exact integer products, and their formats follow
/// from the factors': edges and s = O − a are Q.24 and d is Q.30, so det = e1 · (d × e2),
/// b1n = s · (d × e2) and b2n = d · (s × e1) are Q.78, tn = e2 · (s × e1) is Q.72.
struct Numerators {
    det: FixedI128<U78>,
    b1n: FixedI128<U78>,
    b2n: FixedI128<U78>,
    tn: FixedI128<U72>,
    front: bool,
}

fn triangle(ray: &RaySetup, a: Point, b: Point, c: Point) -> Option<Numerators> {
    let d = ray.dir.map(|x| x.to_bits() as i128);
    let e1 = sub(b, a);
    let e2 = sub(c, a);
    let p = cross(d, e2);
    let det = dot(e1, p);
    if det == 0 {
        // degenerate (a collapsed edge at a pole) or parallel: the other triangle answers
        return None;
    }
    let s: [i128; 3] = core::array::from_fn(|k| ray.origin[k].to_bits() as i128 - a[k] as i128);
    let q = cross(s, e1);
    let (mut b1n, mut b2n, mut tn) = (dot(s, p), dot(d, q), dot(e2, q));
    let front = det > 0;
    let mut det = det;
    if det < 0 {
        (det, b1n, b2n, tn) = (-det, -b1n, -b2n, -tn);
    }
    let eps = det >> BARY_EPS_SHIFT;
    if b1n < -eps || b1n > det + eps || b2n < -eps || b1n + b2n > det + eps {
        return None;
    }
    Some(Numerators {
        det: FixedI128::from_bits(det),
        b1n: FixedI128::from_bits(b1n),
        b2n: FixedI128::from_bits(b2n),
        tn: FixedI128::from_bits(tn),
        front,
    })
}

/// A leaf divider's truncated quotient n / det with `F` fraction bits (32-bit results, F + 2
/// bits significant at most), det normalised to 62 bits first: both are shifted by the same
/// amount, so the formats and the quotient's 30+ significant bits stay.
fn leaf_quotient<F: LeEqU128, N: LeEqU128>(n: FixedI128<N>, det: FixedI128<U78>) -> i64 {
    let k = (128 - det.to_bits().leading_zeros()).saturating_sub(62);
    quotient::<F, _, _>(n >> k, det >> k).map_or(0, |q| q.to_bits() as i64)
}

/// The leaf stage: the ray against the leaf's corner quad as the triangles (P00, P10, P11) and
/// (P00, P11, P01), two-sided. Returns t, the leaf-local (s, r) in [0, 1], and the side, for the
/// nearer hit with `t_min < t < t_max`.
#[derive(Clone, Copy, Debug, Default)]
pub struct LeafStage;

impl LeafStage {
    /// The stage's logic.
    pub fn eval(
        &self,
        cp: &Net,
        ray: &RaySetup,
        t_min: Coord64,
        t_max: Coord64,
    ) -> Option<(Coord64, Unit64, Unit64, bool)> {
        let (p00, p10, p01, p11) = (point(cp, 0), point(cp, 3), point(cp, 12), point(cp, 15));
        let mut best: Option<(Coord64, Unit64, Unit64, bool)> = None;
        let mut best_t = t_max;
        for (tri, (a, b, c)) in [(p00, p10, p11), (p00, p11, p01)].into_iter().enumerate() {
            let Some(n) = triangle(ray, a, b, c) else {
                continue;
            };
            // t = tn / det ≤ 0, or beyond Q8.24's 128: no hit (in the bits, Q.72 against Q.78,
            // t ≤ 128 is tn ≤ 2 · det)
            if !n.tn.is_positive() || n.tn.to_bits() > 2 * n.det.to_bits() {
                continue;
            }
            let t = Coord64::from_bits(leaf_quotient::<U24, _>(n.tn, n.det));
            if t <= t_min || t >= best_t {
                continue;
            }
            // triangle A maps (s, r) = (b1 + b2, b2), triangle B (b1, b1 + b2); clamped to the leaf
            let (sn, rn) = if tri == 0 {
                (n.b1n + n.b2n, n.b2n)
            } else {
                (n.b1n, n.b1n + n.b2n)
            };
            let zero = FixedI128::ZERO;
            let s = Unit64::from_bits(leaf_quotient::<U30, _>(sn.clamp(zero, n.det), n.det));
            let r = Unit64::from_bits(leaf_quotient::<U30, _>(rn.clamp(zero, n.det), n.det));
            best_t = t;
            best = Some((t, s, r, n.front));
        }
        best
    }
}

/// A sub-patch in the working register or on the stack.
#[derive(Clone, Copy, Debug, Default)]
pub struct Node {
    /// Control points (Wc-bit datapath words).
    pub cp: Net,
    /// Cell index along u (`depth` bits).
    pub iu: u32,
    /// Cell index along v.
    pub iv: u32,
    /// Subdivision level.
    pub depth: u32,
    /// Entry distance of its box.
    pub enter: Coord64,
}

/// The on-chip stack: `cap` entries of a single-port memory.
#[derive(Clone, Debug)]
pub struct Stack {
    mem: [Node; STACK_ENTRIES],
    len: usize,
    cap: usize,
    high_water: usize,
}

impl Stack {
    /// An empty stack of `cap` (≤ [`STACK_ENTRIES`]) entries.
    pub fn new(cap: usize) -> Self {
        assert!(cap <= STACK_ENTRIES);
        Stack {
            mem: [Node::default(); STACK_ENTRIES],
            len: 0,
            cap,
            high_water: 0,
        }
    }

    /// Pushes; false (and nothing stored) when full.
    pub fn push(&mut self, n: Node) -> bool {
        if self.len == self.cap {
            return false;
        }
        self.mem[self.len] = n;
        self.len += 1;
        self.high_water = self.high_water.max(self.len);
        true
    }

    /// Pops the top.
    pub fn pop(&mut self) -> Option<Node> {
        self.len = self.len.checked_sub(1)?;
        Some(self.mem[self.len])
    }

    /// Most entries held at once since built.
    pub fn high_water(&self) -> usize {
        self.high_water
    }

    /// Empties it.
    pub fn clear(&mut self) {
        self.len = 0;
    }
}

/// One patch test's inputs besides the control points.
#[derive(Clone, Copy, Debug, Default)]
pub struct Job {
    /// The ray.
    pub ray: RaySetup,
    /// Hits at or below this t are the surface the ray starts on.
    pub t_min: Coord64,
    /// Only hits nearer than this count (the ray's nearest Bezier hit so far).
    pub t_max: Coord64,
    /// Flatness tolerance (0: subdivide to the maximum depth).
    pub tol: Coord64,
}

/// What the engine returns for one patch.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BezierOut {
    /// The nearest hit: t, u, v, front side.
    pub hit: Option<(Coord64, Unit, Unit, bool)>,
    /// A push found the stack full: a subtree was dropped and the hit may be missing.
    pub overflow: bool,
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
enum State {
    #[default]
    Idle,
    /// Take the next node: the working register if it holds one, else pop.
    Fetch,
    /// The working register holds a node to test.
    Eval,
}

/// Counters of the work done (for measurements).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BezierStats {
    /// Patch tests run.
    pub jobs: u64,
    /// Subdivision steps (splits).
    pub steps: u64,
    /// Leaf tests.
    pub leaves: u64,
    /// Nodes dropped because a nearer hit was already known.
    pub pruned: u64,
    /// Clocks spent.
    pub clocks: u64,
}

/// The subdivision state machine.
#[derive(Clone, Debug)]
pub struct BezierEngine {
    cfg: SubdivConfig,
    mask: i32,
    state: State,
    wait: u32,
    work: Option<Node>,
    stack: Stack,
    job: Job,
    best: Option<(Coord64, Unit, Unit, bool)>,
    best_t: Coord64,
    overflow: bool,
    stats: BezierStats,
    /// clocks a step adds for its child boxes' slab tests beyond the first: 0 with four slab
    /// testers, [`SERIAL_SLAB_CLOCKS`] with the compact datapath's one
    serial_slabs: u32,
    /// clocks a leaf adds beyond [`LEAF_CLOCKS`]: 0 with both triangles' products at once,
    /// [`SERIAL_LEAF_CLOCKS`] with the compact datapath's two multipliers
    serial_leaf: u32,
}

impl BezierEngine {
    /// An idle engine for `cfg` with a stack of `stack` entries (the device builds it with
    /// [`STACK_ENTRIES`]; smaller stacks are for tests of the overflow report).
    pub fn new(cfg: SubdivConfig, stack: usize) -> Self {
        BezierEngine {
            cfg,
            mask: cfg.mask(),
            state: State::Idle,
            wait: 0,
            work: None,
            stack: Stack::new(stack),
            job: Job::default(),
            best: None,
            best_t: Coord64::ZERO,
            overflow: false,
            stats: BezierStats::default(),
            serial_slabs: 0,
            serial_leaf: 0,
        }
    }

    /// The engine with one slab tester for the four children of a step instead of four, and
    /// that tester with two multipliers instead of six ([`SERIAL_SLAB_CLOCKS`]): the compact
    /// datapath's engine.
    pub fn with_serial_slabs(mut self) -> Self {
        self.serial_slabs = SERIAL_SLAB_CLOCKS;
        self
    }

    /// The engine whose leaf test has two 34 × 34 multipliers instead of eighteen
    /// ([`SERIAL_LEAF_CLOCKS`]): the compact datapath's engine.
    pub fn with_serial_leaf(mut self) -> Self {
        self.serial_leaf = SERIAL_LEAF_CLOCKS;
        self
    }

    /// The configuration.
    pub fn config(&self) -> SubdivConfig {
        self.cfg
    }

    /// Whether a patch test is running.
    pub fn busy(&self) -> bool {
        self.state != State::Idle
    }

    /// Work counters since built.
    pub fn stats(&self) -> BezierStats {
        self.stats
    }

    /// Most stack entries in use at once since built.
    pub fn stack_high_water(&self) -> usize {
        self.stack.high_water()
    }

    /// Drops the test in flight.
    pub fn flush(&mut self) {
        self.state = State::Idle;
        self.work = None;
        self.stack.clear();
    }

    /// The control points as the datapath holds them.
    pub fn load(&self, words: &[u32]) -> Net {
        core::array::from_fn(|k| {
            core::array::from_fn(|i| to_datapath(words[3 * i + k] as i32, self.mask))
        })
    }

    /// Starts a test of the patch `cp` (datapath words, see [`BezierEngine::load`]) whose root
    /// box the ray enters at `enter`: the root goes into the working register.
    pub fn start(&mut self, cp: Net, enter: Coord64, job: Job) {
        debug_assert!(!self.busy());
        self.job = job;
        self.best = None;
        self.best_t = job.t_max;
        self.overflow = false;
        self.stack.clear();
        self.work = Some(Node {
            cp,
            iu: 0,
            iv: 0,
            depth: 0,
            enter,
        });
        self.state = State::Eval;
        self.wait = 0;
        self.stats.jobs += 1;
    }

    /// One clock; the result on the clock the test ends.
    pub fn tick(&mut self) -> Option<BezierOut> {
        if self.state == State::Idle {
            return None;
        }
        self.stats.clocks += 1;
        if self.wait > 0 {
            self.wait -= 1;
            return None;
        }
        match self.state {
            State::Idle => None,
            State::Fetch => match self.stack.pop() {
                Some(n) => {
                    self.work = Some(n);
                    self.state = State::Eval;
                    // the node's other words
                    self.wait = STACK_WORDS - 1;
                    None
                }
                None => {
                    self.state = State::Idle;
                    Some(BezierOut {
                        hit: self.best,
                        overflow: self.overflow,
                    })
                }
            },
            State::Eval => {
                let node = self.work.take().expect("Eval holds a node");
                self.state = State::Fetch;
                if node.enter >= self.best_t {
                    self.stats.pruned += 1;
                    return None;
                }
                let leaf = node.depth >= self.cfg.depth
                    || (node.depth >= 2
                        && self.job.tol.is_positive()
                        && FlatnessStage.eval(&node.cp, self.job.tol));
                if leaf {
                    self.stats.leaves += 1;
                    self.wait = LEAF_CLOCKS - 1 + self.serial_leaf;
                    if let Some((t, s, r, front)) =
                        LeafStage.eval(&node.cp, &self.job.ray, self.job.t_min, self.best_t)
                    {
                        // the cell's corner i · 2^-depth plus the leaf-local x · 2^-depth
                        let at = |i: u32, x: Unit64| -> Unit {
                            let corner = Unit64::from_bits(i64::from(i) << (30 - node.depth));
                            (corner + (x >> node.depth)).wrapping_to_num()
                        };
                        self.best_t = t;
                        self.best = Some((t, at(node.iu, s), at(node.iv, r), front));
                    }
                    return None;
                }
                self.step(node);
                None
            }
        }
    }

    /// A subdivision step: split, slab-test the children, keep the nearest, push the others.
    fn step(&mut self, node: Node) {
        self.stats.steps += 1;
        let children = SplitStage.eval(&node.cp, self.mask);
        let mut hit: [(Coord64, usize); 4] = [(Coord64::ZERO, 0); 4];
        let mut n = 0;
        for (k, child) in children.iter().enumerate() {
            if let Some(e) = Box3::of(child).slab(&self.job.ray, self.job.t_min, self.best_t) {
                hit[n] = (e, k);
                n += 1;
            }
        }
        // a four-input sorting network on the entry distances (ties: lower index nearer)
        let hit = &mut hit[..n];
        hit.sort_unstable();
        let child = |(e, k): (Coord64, usize)| Node {
            cp: children[k],
            iu: (node.iu << 1) | (k & 1) as u32,
            iv: (node.iv << 1) | (k >> 1) as u32,
            depth: node.depth + 1,
            enter: e,
        };
        let mut pushes = 0;
        for &h in hit.iter().skip(1).rev() {
            pushes += 1;
            if !self.stack.push(child(h)) {
                self.overflow = true;
            }
        }
        if let Some(&h) = hit.first() {
            self.work = Some(child(h));
            self.state = State::Eval;
        }
        self.wait = STEP_CLOCKS - 1 + STACK_WORDS * pushes + self.serial_slabs;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ONE: f64 = (1u64 << 24) as f64;

    fn q(x: f64) -> i32 {
        (x * ONE).round() as i32
    }

    /// The slab test on rounded reciprocals keeps every box the exact interval meets, and
    /// begins no later than it: random boxes and rays (a small generator of its own), against
    /// the interval computed in f64 from the same words.
    #[test]
    fn rounded_reciprocals_never_reject_a_box_the_exact_test_meets() {
        let mut x = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = |span: f64| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            ((x >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0) * span
        };
        let (mut met, mut tested) = (0, 0);
        while tested < 20_000 {
            let o: [Coord; 3] = core::array::from_fn(|_| Coord::from_num(next(1.0)));
            let (c, h): ([f64; 3], [f64; 3]) = (
                core::array::from_fn(|_| next(1.0)),
                core::array::from_fn(|_| next(0.3).abs()),
            );
            // aimed near the box, one component of every size, some tiny (1/d then has many
            // bits)
            let scale = [1.0, 1e-3, 1e-6][tested % 3];
            let aim: [f64; 3] =
                core::array::from_fn(|k| c[k] + 1.5 * next(h[k]) - o[k].to_num::<f64>());
            let len = aim.iter().map(|a| a * a).sum::<f64>().sqrt().max(1e-9);
            let d: [Unit; 3] = core::array::from_fn(|k| {
                Unit::from_num(aim[k] / len * if k == tested % 3 { scale } else { 1.0 })
            });
            let word = |v: f64| Coord64::from(Coord::from_num(v));
            let b = Box3 {
                lo: core::array::from_fn(|k| word(c[k] - h[k])),
                hi: core::array::from_fn(|k| word(c[k] + h[k])),
            };
            let ray = RaySetup::new(o, d);
            let (mut enter, mut exit) = (f64::MIN, f64::MAX);
            for k in 0..3 {
                let (ok, dk) = (o[k].to_num::<f64>(), d[k].to_num::<f64>());
                let (lo, hi) = (b.lo[k].to_num::<f64>(), b.hi[k].to_num::<f64>());
                if dk == 0.0 {
                    if ok < lo || ok > hi {
                        (enter, exit) = (1.0, 0.0);
                    }
                    continue;
                }
                let (t0, t1) = ((lo - ok) / dk, (hi - ok) / dk);
                enter = enter.max(t0.min(t1));
                exit = exit.min(t0.max(t1));
            }
            tested += 1;
            // within the saturated range the model's registers hold
            if enter > exit || exit < 0.0 || enter.abs() > 1e9 || exit.abs() > 1e9 {
                continue;
            }
            met += 1;
            let got = b.slab(&ray, Coord64::ZERO, Coord64::MAX);
            let got = got.unwrap_or_else(|| panic!("{o:?} {d:?} {b:?}: exact [{enter}, {exit}]"));
            assert!(got.to_num::<f64>() <= enter.max(0.0), "{got} > {enter}");
        }
        assert!(met > 1_000, "only {met} boxes met");
    }

    /// A patch from a function of (u, v) sampled at thirds (a bilinear or flat map is exact).
    fn patch(f: impl Fn(f64, f64) -> [f64; 3]) -> [u32; CP_WORDS] {
        let mut w = [0u32; CP_WORDS];
        for r in 0..4 {
            for c in 0..4 {
                let p = f(c as f64 / 3.0, r as f64 / 3.0);
                for k in 0..3 {
                    w[3 * (4 * r + c) + k] = q(p[k]) as u32;
                }
            }
        }
        w
    }

    /// Runs one test to completion: (result, clocks).
    fn run(
        e: &mut BezierEngine,
        words: &[u32],
        o: [f64; 3],
        d: [f64; 3],
        tol: i64,
    ) -> (BezierOut, u32) {
        let ray = RaySetup::new(
            o.map(|x| Coord::from_bits(q(x))),
            d.map(|x| Unit::from_bits((x * (1u64 << 30) as f64).round() as i32)),
        );
        let cp = e.load(words);
        let far = Coord64::from_bits(i32::MAX as i64);
        let Some(enter) = Box3::of(&cp).slab(&ray, Coord64::ZERO, far) else {
            return (BezierOut::default(), 0);
        };
        e.start(
            cp,
            enter,
            Job {
                ray,
                t_min: Coord64::ZERO,
                t_max: far,
                tol: Coord64::from_bits(tol),
            },
        );
        let mut clocks = 0;
        loop {
            clocks += 1;
            assert!(clocks < 100_000, "engine hangs");
            if let Some(r) = e.tick() {
                return (r, clocks);
            }
        }
    }

    fn f(x: Coord64) -> f64 {
        x.to_num()
    }

    fn uv(x: Unit) -> f64 {
        x.to_num()
    }

    #[test]
    fn a_flat_patch_gives_exact_t_and_uv() {
        // the unit square at z = 0.25, hit from above
        let w = patch(|u, v| [u - 0.5, v - 0.5, 0.25]);
        let mut e = BezierEngine::new(SubdivConfig::DEFAULT, STACK_ENTRIES);
        let (r, clocks) = run(
            &mut e,
            &w,
            [0.3 - 0.5, 0.8 - 0.5, 0.75],
            [0.0, 0.0, -1.0],
            0,
        );
        let (t, u, v, front) = r.hit.expect("hit");
        assert!((f(t) - 0.5).abs() < 2.0 / ONE, "t {}", f(t));
        // (u,v) of a flat unit patch is the hit point: limited by the Q.30 quotient
        assert!(
            (uv(u) - 0.3).abs() < 1e-6 && (uv(v) - 0.8).abs() < 1e-6,
            "{} {}",
            uv(u),
            uv(v)
        );
        // ∂P/∂u × ∂P/∂v = +z: hit from above is the front
        assert!(front);
        // ten levels of one step each, then one leaf
        assert!(clocks >= 10 * STEP_CLOCKS + LEAF_CLOCKS, "{clocks}");
        assert!(!r.overflow);
        // from below: the back side
        let (r, _) = run(&mut e, &w, [-0.2, 0.3, -0.5], [0.0, 0.0, 1.0], 0);
        assert!(!r.hit.expect("hit").3);
    }

    #[test]
    fn a_miss_beside_the_patch_ends_without_a_hit() {
        let w = patch(|u, v| [u, v, 0.1 * (u * 6.0).sin()]);
        let mut e = BezierEngine::new(SubdivConfig::DEFAULT, STACK_ENTRIES);
        let (r, _) = run(&mut e, &w, [1.2, 0.5, 1.0], [0.0, 0.0, -1.0], 0);
        assert_eq!(r.hit, None);
    }

    #[test]
    fn a_small_stack_reports_overflow() {
        // a ray along the plane's diagonal through a wavy sheet touches many boxes per level
        let w = patch(|u, v| [u, v, 0.3 * (u - 0.5) * (v - 0.5)]);
        let cfg = SubdivConfig {
            depth: 8,
            coord_width: 26,
        };
        let d: [f64; 3] = [1.0, 1.0, -0.02];
        let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        let d = d.map(|x| x / n);
        let mut big = BezierEngine::new(cfg, STACK_ENTRIES);
        let (r, _) = run(&mut big, &w, [-0.5, -0.5, 0.02], d, 0);
        assert!(
            !r.overflow && big.stack_high_water() >= 2,
            "{}",
            big.stack_high_water()
        );
        let mut small = BezierEngine::new(cfg, 1);
        let (r, _) = run(&mut small, &w, [-0.5, -0.5, 0.02], d, 0);
        assert!(r.overflow);
    }

    #[test]
    fn configurations_beyond_the_stack_are_invalid() {
        assert!(SubdivConfig::DEFAULT.is_valid_for(STACK_ENTRIES));
        let deep = SubdivConfig {
            depth: 14,
            coord_width: 26,
        };
        assert!(!deep.is_valid_for(STACK_ENTRIES) && deep.is_valid_for(42));
        assert!(!SubdivConfig {
            depth: 8,
            coord_width: 27
        }
        .is_valid_for(STACK_ENTRIES));
        assert!(!SubdivConfig {
            depth: 0,
            coord_width: 20
        }
        .is_valid_for(STACK_ENTRIES));
    }

    #[test]
    fn flatness_is_exact_on_bilinear_patches() {
        // a twisted bilinear patch: its control points lie exactly on the bilinear map
        let w = patch(|u, v| [u, v, 0.5 * u * v]);
        let e = BezierEngine::new(SubdivConfig::DEFAULT, STACK_ENTRIES);
        let cp = e.load(&w);
        // thirds are rounded to the LSB: within 9 LSBs
        assert!(FlatnessStage.eval(&cp, Coord64::DELTA));
        let w = patch(|u, v| [u, v, 0.5 * u * u * v]);
        assert!(!FlatnessStage.eval(&e.load(&w), Coord64::from_bits(1 << 12)));
    }
}
