//! The (u,v) unit: bisection of the hit patch's parameter square, one level per pipeline stage.
//!
//! This is the subdivision of paper §6.1 specialised to a flat patch, where the point is already
//! known (P = O + t d): a bilinear quad's iso-parameter lines are straight, so at each level the
//! cell is halved in u by the segment between its edge midpoints P(u_m, v₀)–P(u_m, v₁) and in v
//! by P(u₀, v_m)–P(u₁, v_m), and the side of each segment P lies on (one cross product dotted
//! with the normal each) picks the sub-cell. Midpoints of a bilinear map are averages of corners:
//! adds and a constant shift by 1. After D levels (u, v) is the centre of a 2^-D cell, within
//! 2^-(D+1) of the exact inverse. A triangle is the quad collapsed at v = 1, so it runs the same
//! stages. Bicubic patches will reuse the cell bookkeeping with bounding boxes instead of sides.

use crate::format::Unit;

/// One cell in flight: its four corners (v-major: P(u₀,v₀), P(u₁,v₀), P(u₁,v₁), P(u₀,v₁)),
/// raw Q8.24 in 64-bit registers, the point, the normal and the cell index so far.
#[derive(Clone, Copy, Debug, Default)]
pub struct Cell {
    /// Corners.
    pub q: [[i64; 3]; 4],
    /// The hit point.
    pub p: [i64; 3],
    /// The patch normal (raw Q2.30).
    pub n: [i64; 3],
    /// u cell index (level bits so far).
    pub iu: u32,
    /// v cell index.
    pub iv: u32,
}

fn mid(a: [i64; 3], b: [i64; 3]) -> [i64; 3] {
    [(a[0] + b[0]) >> 1, (a[1] + b[1]) >> 1, (a[2] + b[2]) >> 1]
}

/// (b − a) × (p − a) · n, the side of p relative to the segment a→b (positive: left, seen from
/// the front). 66-bit cross product, 98-bit dot product.
fn side(a: [i64; 3], b: [i64; 3], p: [i64; 3], n: [i64; 3]) -> i128 {
    let e = [
        (b[0] - a[0]) as i128,
        (b[1] - a[1]) as i128,
        (b[2] - a[2]) as i128,
    ];
    let w = [
        (p[0] - a[0]) as i128,
        (p[1] - a[1]) as i128,
        (p[2] - a[2]) as i128,
    ];
    let c = [
        e[1] * w[2] - e[2] * w[1],
        e[2] * w[0] - e[0] * w[2],
        e[0] * w[1] - e[1] * w[0],
    ];
    // the cross product is Q.48; drop 24 bits so the dot with the Q2.30 normal stays in 128.
    // (|e| < 2^32, |w| < 2^34, so |c| < 2^67 and c >> 24 fits 64 bits: the products below are
    // 64 × 64 → 128, which is what the narrowing tells the host compiler.)
    let c = c.map(|c| (c >> 24) as i64 as i128);
    c[0] * n[0] as i128 + c[1] * n[1] as i128 + c[2] * n[2] as i128
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
        let upper_u = side(bottom, top, c.p, c.n) < 0;
        let upper_v = side(left, right, c.p, c.n) > 0;
        // The sub-cell keeps corner k of the cell ((u, v) = (0,0), (1,0), (1,1), (0,1) for
        // k = 0..3), has the centre at the opposite corner, and between them the midpoints of
        // the two edges through corner k, mid(q_j, q_k) (mid is symmetric, and mid(q_k, q_k) =
        // q_k): one multiplexer per corner, no data-dependent branch in the simulation.
        let k = (upper_v as usize) << 1 | (upper_u ^ upper_v) as usize;
        let qk = c.q[k];
        for (j, q) in c.q.iter_mut().enumerate() {
            *q = if j == k ^ 2 { centre } else { mid(*q, qk) };
        }
        c.iu = (c.iu << 1) | upper_u as u32;
        c.iv = (c.iv << 1) | upper_v as u32;
    }
}

/// The cell centre after `depth` levels as Q2.30: (index + ½)·2^-depth.
pub fn centre(index: u32, depth: u32) -> Unit {
    Unit::from_bits((((index as i64) * 2 + 1) << (29 - depth)) as i32)
}
