//! The (u,v) unit: bisection of the hit patch's parameter square, one level per pipeline stage.
//!
//! This is the subdivision of paper §6.1 specialised to a flat patch, where the point is already
//! known (P = O + t d): a bilinear quad's iso-parameter lines are straight, so at each level the
//! cell is halved in u by the segment between its edge midpoints P(u_m, v₀)–P(u_m, v₁) and in v
//! by P(u₀, v_m)–P(u₁, v_m), and the side of each segment P lies on picks the sub-cell. The side
//! is the sign of a 2D cross product in the plane of the two axes the patch normal is least
//! along (its dominant axis is chosen once per hit, from the normal's magnitudes): the patch
//! projects onto that plane without folding. The segment's direction enters the product in
//! 18 bits scaled by a power of two of its own ([`SEG_BITS`]), the point's offset whole, so the
//! test keeps its relative accuracy however small the cell gets. (A 3D cross product dotted
//! with the normal would need 98 bits; truncating it instead loses the side once the cell is
//! below ~2^-12 of the coordinate range, which an earlier version of this unit did.)
//! Midpoints of a bilinear map are averages of corners: adds and a constant shift by 1. After D
//! levels (u, v) is the centre of a 2^-D cell, within 2^-(D+1) of the exact inverse up to the
//! midpoints' rounding (up to ½ LSB of Q8.24 a level). A triangle is the quad collapsed at v = 1, so
//! it runs the same stages.

use crate::format::Unit;
use crate::intersect::coarse::{top_words, WORD_BITS};

/// One cell in flight, projected onto the plane of the two axes the patch normal is least along
/// (the third coordinate never enters a side test, so the unit has no registers for it): its
/// four corners (v-major: P(u₀,v₀), P(u₁,v₀), P(u₁,v₁), P(u₀,v₁)), raw Q8.24 in 64-bit
/// registers, the point and the cell index so far.
#[derive(Clone, Copy, Debug, Default)]
pub struct Cell {
    /// Corners (projected).
    pub q: [[i64; 2]; 4],
    /// The hit point (projected).
    pub p: [i64; 2],
    /// u cell index (level bits so far).
    pub iu: u32,
    /// v cell index.
    pub iv: u32,
}

fn mid(a: [i64; 2], b: [i64; 2]) -> [i64; 2] {
    [(a[0] + b[0]) >> 1, (a[1] + b[1]) >> 1]
}

impl Cell {
    /// The first cell, the whole patch with corners `q`, for the point `p` on it; `n` is the
    /// patch normal. The projection drops the normal's largest component (ties to the lower
    /// axis) and keeps the other two in cyclic order when that component is positive, swapped
    /// when it is negative, so a counter-clockwise turn seen from the front stays
    /// counter-clockwise in the plane.
    pub fn project(q: [[i64; 3]; 4], p: [i64; 3], n: [i64; 3]) -> Cell {
        let m = n.map(i64::unsigned_abs);
        let axis = if m[0] >= m[1] && m[0] >= m[2] {
            0
        } else if m[1] >= m[2] {
            1
        } else {
            2
        };
        let (i, j) = [(1, 2), (2, 0), (0, 1)][axis];
        let (i, j) = if n[axis] < 0 { (j, i) } else { (i, j) };
        let to2 = |v: [i64; 3]| [v[i], v[j]];
        Cell {
            q: q.map(to2),
            p: to2(p),
            iu: 0,
            iv: 0,
        }
    }
}

/// Bits of the segment's direction b − a in the side test's products: both components are
/// shifted right by the same power of two until the larger fits [`SEG_BITS`] signed bits (a
/// block floating point of the segment's own), so each product is 18 × 36 bits, two DSP tiles,
/// where the exact difference made it 36 × 36, four. The direction keeps a relative error under
/// √2 · 2^-16, so only a point within that fraction of |p − a| of the segment's line can be
/// given the wrong side, and then either sub-cell holds it to that distance (until session
/// 44 the difference went in whole). The coarse words' width, scaled as they are
/// ([`top_words`]; `rtl/uv_level.v` the same).
pub const SEG_BITS: u32 = WORD_BITS;

/// The side of p relative to the segment a→b (positive: left, seen from the front): the 2D
/// cross product ẽ × (p − a) of the segment's direction in [`SEG_BITS`] ([`top_words`],
/// floored) and the point's offset (a 36-bit point less a 34-bit corner: 37 bits), so each
/// product is exact in 55 bits and their difference in 56 (here a 128-bit container).
fn side(a: [i64; 2], b: [i64; 2], p: [i64; 2]) -> i128 {
    let (e, _) = top_words(&[b[0] - a[0], b[1] - a[1]]);
    e[0] as i128 * (p[1] - a[1]) as i128 - e[1] as i128 * (p[0] - a[0]) as i128
}

/// One bisection level.
#[derive(Clone, Copy, Debug, Default)]
pub struct UvStage;

impl UvStage {
    /// The stage's logic: halve the cell in u and in v, keep the sub-cell holding the point.
    #[inline]
    pub fn eval(&self, mut c: Cell) -> Cell {
        self.apply(&mut c);
        c
    }

    /// The stage's logic on the register in place.
    #[inline]
    pub fn apply(&self, c: &mut Cell) {
        let [q0, q1, q2, q3] = c.q;
        let bottom = mid(q0, q1);
        let top = mid(q3, q2);
        let left = mid(q0, q3);
        let right = mid(q1, q2);
        let centre = mid(bottom, top);
        // left of bottom→top means u < u_m; left of left→right means v > v_m
        let upper_u = side(bottom, top, c.p) < 0;
        let upper_v = side(left, right, c.p) > 0;
        // The sub-cell is one quarter of the 3 × 3 grid of corners, edge midpoints and centre:
        // each of its corners is a two-level multiplexer on the select bits (no data-dependent
        // branch or index in the simulation).
        // (AND-OR multiplexers on all-ones/all-zeros masks, as the gates would be)
        let (mu, mv) = (-(upper_u as i64), -(upper_v as i64));
        let sel = |m: i64, one: [i64; 2], zero: [i64; 2]| {
            [(one[0] & m) | (zero[0] & !m), (one[1] & m) | (zero[1] & !m)]
        };
        let pick = |[a, b, c, d]: [[i64; 2]; 4]| sel(mv, sel(mu, d, c), sel(mu, b, a));
        c.q = [
            pick([q0, bottom, left, centre]),
            pick([bottom, q1, centre, right]),
            pick([centre, right, top, q2]),
            pick([left, centre, q3, top]),
        ];
        c.iu = (c.iu << 1) | upper_u as u32;
        c.iv = (c.iv << 1) | upper_v as u32;
    }
}

/// The cell centre after `depth` levels as Q2.30: (index + ½)·2^-depth.
pub fn centre(index: u32, depth: u32) -> Unit {
    Unit::from_bits((((index as i64) * 2 + 1) << (29 - depth)) as i32)
}
