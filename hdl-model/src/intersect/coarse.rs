//! The compact datapath's coarse edge test: a lane decides the sign of d · e from 18-bit words
//! (one DSP tile a product) where it can, and hands the rest to the shared exact unit.
//!
//! The words: d' = ⌊d / 2^t⌋ ([`COARSE_DIR_SHIFT`]) and, per edge, e' with e = 2^s (e' + δ),
//! |δ_c| < 2^κ, where κ is one small exponent a patch ([`Coarse::kappa`]).
//!
//! - The wide datapath forms e exactly, and its coarse word truncates it ([`coarse_edge`]):
//!   δ = the remainder, in [0, 1), so κ = 0.
//! - The compact datapath's set-up unit never forms the exact e (the exact unit recomputes it
//!   from patch memory when a pair needs it): it takes e' from the cross product of two
//!   18-bit words, a corner and the edge's vector ([`narrow_edge`]), six 18 × 18 products
//!   instead of six 34 × 34 ones, and bounds its error by κ. Since session 22.
//!
//! Why the test is exact where it answers ([`coarse_sign`]): with d = 2^t (d' + r),
//! 0 ≤ r_c < 1, each component of d · e / 2^(s+t) is d'e' + (d' + r) δ + r e', whose last
//! terms are below 2^κ (|d'| + 1) + |e'| in magnitude. So d · e = 2^(s+t) (A + ε) with
//! A = Σ d'_c e'_c and |ε| < B = 2^κ Σ (|d'_c| + 1) + Σ |e'_c|: A ≥ B means d · e > 0, A ≤ −B
//! means d · e < 0. The lane forms A with three 18 × 18 products, Σ (|d'_c| + 1) once a ray,
//! its shift by κ once a candidate, and B with adders.

/// Bits the coarse test drops from a direction component (Q2.30, |d_c| ≤ 2^30): what is left,
/// |d'_c| ≤ 2^16, is an 18-bit signed word.
pub const COARSE_DIR_SHIFT: u32 = 14;

/// Width of the coarse words and of the set-up's narrow operands (signed); also of the (u,v)
/// side test's segment directions and the Bezier slab test's reciprocals ([`top_words`]).
pub const WORD_BITS: u32 = 18;

/// The κ that says "the coarse words bound nothing": every pair of the patch goes to the exact
/// unit. A patch's κ is four bits of its lane word (its 284 bits become 288, eight block RAMs
/// wide as before).
pub const KAPPA_DECLINE: u8 = 15;

/// A patch's coarse edge words and their error exponent.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Coarse {
    /// e'_i of each edge (18-bit signed values).
    pub words: [[i32; 3]; 4],
    /// e = 2^s (e' + δ) with |δ_c| < 2^κ, each edge on its own scale 2^s;
    /// [`KAPPA_DECLINE`]: no bound.
    pub kappa: u8,
}

/// A vector as 18-bit signed words and a power of two of its own: v = 2^p (w + r) with
/// 0 ≤ r_c < 1. The largest component goes into [2^16, 2^17), by a floor when shifted down and
/// exactly when shifted up (then r = 0).
pub fn block18(v: &[i64; 3]) -> ([i64; 3], i32) {
    let m = v.iter().map(|c| c.unsigned_abs()).max().unwrap_or(0);
    if m == 0 {
        return ([0; 3], 0);
    }
    let bits = (64 - m.leading_zeros()) as i32;
    let p = bits - (WORD_BITS as i32 - 1);
    if p > 0 {
        (v.map(|c| c >> p), p)
    } else {
        (v.map(|c| c << -p), p)
    }
}

/// The wide datapath's coarse word of an exact edge normal: e' = ⌊e / 2^s⌋ with the least s
/// that brings every |e'_c| below 2^17 (κ = 0).
pub fn coarse_edge(e: &[i64; 3]) -> [i32; 3] {
    top18(e).0
}

/// ⌊v / 2^s⌋ as 18-bit words with the least s that brings every component below 2^17, and s.
fn top18(v: &[i64; 3]) -> ([i32; 3], u32) {
    let (w, s) = top_words(v);
    (w.map(|c| c as i32), s)
}

/// ⌊v / 2^s⌋ with the least s that brings every component of `v` below 2^17 in magnitude,
/// so into [`WORD_BITS`] signed bits (a block floating point of the vector's own), and s: the
/// set-up's coarse edge words, the (u,v) side test's segment direction and the Bezier slab
/// test's reciprocal. The shift is how far the bit length of the largest magnitude reaches
/// beyond WORD_BITS − 1, a leading one in the RTL (−2^17 itself takes one bit more than its
/// two's complement needs).
///
/// ```
/// use hemi_hdl_model::intersect::coarse::top_words;
/// assert_eq!(top_words(&[1 << 20, -3]), ([1 << 16, -1], 4));
/// assert_eq!(top_words(&[5, -7]), ([5, -7], 0));
/// ```
pub fn top_words<const N: usize>(v: &[i64; N]) -> ([i64; N], u32) {
    let m = v.iter().map(|c| c.unsigned_abs()).max().unwrap_or(0);
    let s = (u64::BITS - m.leading_zeros()).saturating_sub(WORD_BITS - 1);
    (v.map(|c| c >> s), s)
}

/// The compact set-up unit's coarse word of the edge normal e = trunc(±(u × v) / 2^shift) (the
/// set-up pass's exact edge: `negate` is its side's sign, `shift` the origin-wide truncation),
/// and the least κ that bounds it.
///
/// It uses u × v = u × Δ, Δ = v − u (exact in integers, and better conditioned for a small
/// patch, whose corners are nearly parallel). With u = 2^p (ũ + r), Δ = 2^q (Δ̃ + r')
/// ([`block18`]) and X = ũ × Δ̃ (six 18 × 18 products), u × Δ = 2^(p+q) (X + η) with
/// |η_x| < E_x = |ũ_y| + |ũ_z| + |Δ̃_y| + |Δ̃_z| + 1 (and so for y, z); E is the largest.
/// Then e' = ⌊±X / 2^m⌋ (m: X's top bits into 18), and e = 2^S (e' + δ) with S = p + q + m − shift and |δ| < 1 + E / 2^m + 2^-S (the floor, η,
/// and the set-up's truncation of e, below 1 in e's units).
pub fn narrow_edge(u: &[i64; 3], v: &[i64; 3], shift: u32, negate: bool) -> ([i32; 3], u8) {
    let delta = [0, 1, 2].map(|c| v[c] - u[c]);
    let ((wu, p), (wd, q)) = (block18(u), block18(&delta));
    let x = [
        wu[1] * wd[2] - wu[2] * wd[1],
        wu[2] * wd[0] - wu[0] * wd[2],
        wu[0] * wd[1] - wu[1] * wd[0],
    ];
    let x = if negate { x.map(|c| -c) } else { x };
    // E: the largest component's bound, over the other two components of each word
    let e_bound = (0..3)
        .map(|c| {
            let (j, k) = ((c + 1) % 3, (c + 2) % 3);
            wu[j].abs() + wu[k].abs() + wd[j].abs() + wd[k].abs() + 1
        })
        .fold(1, i64::max);
    let (words, m) = top18(&x);
    let s = p + q + m as i32 - shift as i32;
    // 2^κ ≥ 1 + E / 2^m + 2^-S, in sixteenths rounded up: rounding each of the bound's terms
    // up to a whole instead gives κ = 3 where sixteenths give 2 (most edges), and doubled the
    // undecided pairs
    let eta = ((e_bound << FRACTION) + (1 << m) - 1) >> m;
    // (past 2^20 sixteenths κ is 15 whatever the rest: the unit's shifter stops there)
    let trunc = 1i64 << (FRACTION as i32 - s).clamp(0, 20);
    let need = (1 << FRACTION) + eta + trunc;
    let kappa = (64 - (need - 1).leading_zeros()).saturating_sub(FRACTION);
    (words, kappa.min(KAPPA_DECLINE as u32) as u8)
}

/// A patch's coarse words from its corners `a` (a = v − O, three or four), edge k from corner
/// k to the next (the last to the first), each by [`narrow_edge`], as the set-up unit forms
/// them an edge a clock; with each edge's κ, of which the lanes keep the largest
/// ([`Coarse::kappa`]).
pub fn narrow_patch(a: &[[i64; 3]], shift: u32, negate: bool) -> (Coarse, [u8; 4]) {
    let mut c = Coarse::default();
    let mut kappas = [0u8; 4];
    for (k, (u, kappa_k)) in a.iter().zip(kappas.iter_mut()).enumerate() {
        let (words, kappa) = narrow_edge(u, &a[(k + 1) % a.len()], shift, negate);
        c.words[k] = words;
        *kappa_k = kappa;
        c.kappa = c.kappa.max(kappa);
    }
    (c, kappas)
}

/// Fraction bits of the set-up unit's κ arithmetic ([`narrow_edge`]).
const FRACTION: u32 = 4;

/// A ray's coarse direction d' with the bound's per-ray term Σ(|d'_c| + 1), formed once a ray
/// (module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CoarseRay {
    /// d' (the direction's Q2.30 words shifted down by [`COARSE_DIR_SHIFT`]).
    pub d: [i32; 3],
    dsum: i64,
}

impl CoarseRay {
    /// The ray of coarse direction `d`.
    pub fn new(d: [i32; 3]) -> CoarseRay {
        let dsum = d.iter().map(|&c| c.unsigned_abs() as i64 + 1).sum();
        CoarseRay { d, dsum }
    }
}

/// The sign of d · e from the words alone (`kappa` bounds e's words), or `None` when they
/// cannot tell (module doc).
pub fn coarse_sign(ray: &CoarseRay, e: &[i32; 3], kappa: u8) -> Option<bool> {
    if kappa >= KAPPA_DECLINE {
        return None;
    }
    let (mut a, mut esum) = (0i64, 0i64);
    for (&d, &e) in ray.d.iter().zip(e) {
        a += d as i64 * e as i64;
        esum += e.unsigned_abs() as i64;
    }
    let b = (ray.dsum << kappa) + esum;
    if a >= b {
        Some(true)
    } else if a <= -b {
        Some(false)
    } else {
        None
    }
}

/// What the coarse test makes of a (ray, patch) pair.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// Every edge certainly positive, or one certainly negative: `inside`.
    Decided(bool),
    /// No edge certainly negative, and these undecided (bit k: the edge from corner k to the
    /// next): the shared exact unit checks those edges only (the others are known positive),
    /// the mask coming with the pair from the lane.
    Undecided(u8),
}

/// The coarse test of a (ray, patch) pair over the patch's first `sides` words.
pub fn coarse_inside(ray: &CoarseRay, coarse: &Coarse, sides: usize) -> Verdict {
    if coarse.kappa >= KAPPA_DECLINE {
        return Verdict::Undecided((1 << sides) - 1);
    }
    let mut undecided = 0;
    for (k, e) in coarse.words[..sides].iter().enumerate() {
        match coarse_sign(ray, e, coarse.kappa) {
            Some(false) => return Verdict::Decided(false),
            Some(true) => {}
            None => undecided |= 1 << k,
        }
    }
    match undecided {
        0 => Verdict::Decided(true),
        mask => Verdict::Undecided(mask),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::intersect::tests::Rng;

    /// The (u,v) side test's segment directions (two components) fit their bits after the
    /// shift, and are shifted no further than the larger magnitude needs (moved here from
    /// `uv.rs` with the shift it tested).
    #[test]
    fn the_segment_fits_its_bits_after_the_shift() {
        let top = 1i64 << (WORD_BITS - 1);
        for e in [
            [0, 0],
            [top - 1, 5],
            [-top, 3],
            [top, 0],
            [-top - 1, 7],
            [(1 << 34) - 1, -(1 << 34)],
            [12_345_678_901, -3],
        ] {
            let (words, s) = top_words(&e);
            for x in words {
                assert!((-top..top).contains(&x), "{e:?} >> {s}: {x}");
            }
            // no more shift than the larger magnitude needs (−2^17 itself takes one bit more
            // than its two's complement would)
            if s > 0 {
                let m = e[0].unsigned_abs().max(e[1].unsigned_abs());
                assert!(m >> (s - 1) >= top as u64, "{e:?}");
            }
        }
    }

    fn exact_sign(d: &[i32; 3], e: &[i64; 3]) -> i128 {
        (0..3).map(|c| d[c] as i128 * e[c] as i128).sum()
    }

    /// A direction of Q2.30 words, nearly orthogonal to `e` one time in three (there the test
    /// must decline, or be right).
    fn direction(rng: &mut Rng, e: &[i64; 3], n: u32) -> [i32; 3] {
        let mut d = [0i32; 3].map(|_| (rng.signed(31)) as i32);
        if n.is_multiple_of(3) {
            // d − (d·e / e·e) e, rounded
            let ee: f64 = e.iter().map(|&c| (c as f64) * (c as f64)).sum();
            if ee > 0.0 {
                let de: f64 = (0..3).map(|c| d[c] as f64 * e[c] as f64).sum();
                for c in 0..3 {
                    d[c] = (d[c] as f64 - de / ee * e[c] as f64).round() as i32;
                }
            }
        }
        d
    }

    /// Checks one (d, e) pair against the coarse words; true when they decided it.
    fn agrees(d: &[i32; 3], e: &[i64; 3], words: &[i32; 3], kappa: u8) -> bool {
        let dc = CoarseRay::new(d.map(|c| c >> COARSE_DIR_SHIFT));
        match coarse_sign(&dc, words, kappa) {
            Some(positive) => {
                let s = exact_sign(d, e);
                assert_eq!(positive, s > 0, "d {d:?} e {e:?} words {words:?} κ {kappa}");
                assert_ne!(s, 0, "d {d:?} e {e:?}: decided a zero");
                true
            }
            None => false,
        }
    }

    /// Where the wide datapath's coarse test answers, it answers as the exact product: random
    /// edge normals of every magnitude up to 62 bits and unit-range directions, some within a
    /// few LSBs of the edge plane.
    #[test]
    fn the_coarse_edge_test_never_contradicts_the_exact_one() {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let (mut decided, mut declined) = (0u32, 0u32);
        for n in 0..200_000u32 {
            let bits = 2 + n % 61;
            let e = [rng.signed(bits), rng.signed(bits), rng.signed(bits)];
            let d = direction(&mut rng, &e, n);
            match agrees(&d, &e, &coarse_edge(&e), 0) {
                true => decided += 1,
                false => declined += 1,
            }
        }
        // the test is worth having: most random pairs are decided, the built ones often not
        assert!(
            decided > 120_000 && declined > 1_000,
            "{decided} decided, {declined} declined"
        );
    }

    /// Corners as the set-up pass sees them (Q8.24 differences, up to 2^34): near and far,
    /// patches from 2^-10 of a unit to 2^8, and edges that point at the origin.
    fn corners(rng: &mut Rng, n: u32) -> ([i64; 3], [i64; 3]) {
        let far = 10 + n % 24;
        let u = [0; 3].map(|_| rng.signed(far + 1));
        let size = 4 + (n / 7) % 30;
        let mut v = [0, 1, 2].map(|c| u[c] + rng.signed(size));
        if n.is_multiple_of(5) {
            // along u, give or take a few units: an edge seen end-on
            let k = 1 + (rng.next() % 3) as i64;
            v = [0, 1, 2].map(|c| u[c] + u[c] / (4 * k) + rng.signed(3));
        }
        (u, v)
    }

    /// Where the compact datapath's coarse test answers (words from the set-up's narrow
    /// products, [`narrow_edge`]), it answers as the exact edge the set-up pass would have
    /// formed, for origin-wide truncations up to 8 bits beyond the least and both sides.
    #[test]
    fn narrow_edge_words_never_contradict_the_exact_edge() {
        let mut rng = Rng(0x2545_f491_4f6c_dd1d);
        let (mut decided, mut declined) = (0u32, 0u32);
        let mut kappas = [0u32; 16];
        for n in 0..200_000u32 {
            let (u, v) = corners(&mut rng, n);
            // the set-up pass's origin-wide truncation keeps e within 62 bits; sometimes more
            let top = u
                .iter()
                .chain(&v)
                .map(|c| c.unsigned_abs())
                .max()
                .unwrap_or(0);
            let least = (2 * (64 - top.leading_zeros()) + 2).saturating_sub(62);
            let shift = least + if n.is_multiple_of(4) { n % 9 } else { 0 };
            let negate = n % 2 == 1;
            let cross = [
                u[1] as i128 * v[2] as i128 - u[2] as i128 * v[1] as i128,
                u[2] as i128 * v[0] as i128 - u[0] as i128 * v[2] as i128,
                u[0] as i128 * v[1] as i128 - u[1] as i128 * v[0] as i128,
            ];
            let sign = if negate { -1 } else { 1 };
            let e = cross.map(|c| crate::intersect::shift_toward_zero(c * sign, shift) as i64);
            let (words, kappa) = narrow_edge(&u, &v, shift, negate);
            assert!(words.iter().all(|w| (-(1 << 17)..(1 << 17)).contains(w)));
            kappas[kappa as usize] += 1;
            let d = direction(&mut rng, &e, n);
            match agrees(&d, &e, &words, kappa) {
                true => decided += 1,
                false => declined += 1,
            }
        }
        // a fifth of the edges are built end-on (most of those decline, κ = 15)
        assert!(
            decided > 100_000 && declined > 1_000 && kappas[KAPPA_DECLINE as usize] < 40_000,
            "{decided} decided, {declined} declined, κ {kappas:?}"
        );
    }

    /// The coarse words fit the 18-bit signed inputs of a DSP tile.
    #[test]
    fn coarse_words_are_18_bits() {
        for m in [0i64, 1, (1 << 17) - 1, 1 << 17, (1 << 61) - 1, -(1 << 61)] {
            for w in coarse_edge(&[m, -m, m / 3]) {
                assert!((-(1 << 17)..(1 << 17)).contains(&w), "{m}: {w}");
            }
        }
        let d = crate::format::Unit::ONE.to_bits() >> COARSE_DIR_SHIFT;
        assert!(d < 1 << 17);
    }
}
