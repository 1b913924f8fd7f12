//! The (u,v) hierarchy of sample points on one patch (paper §4.2), and how a level is filled
//! from the one before it where no form factors are computed (§4.3).
//!
//! Level n of a patch whose initial guess is K×K is the uniform lattice of k = K·2^n cells per
//! side: element (a, b) is the cell `[a/k, (a+1)/k] × [b/k, (b+1)/k]` of the unit (u,v) square
//! with its sample point at the centre, stored v-major (index b·k + a), exactly as the uniform
//! K×K sampling of pass 1 lays out k×k. Subdividing one level splits every element into four
//! (the "binary subdivision" of §4.2), so an element's (u,v) weight is 2^-2n of its level-0
//! parent's — on a polygon the weight carried into (4.3) is the true area share (see
//! `hemi_kernel::sampling`), which is the same thing on parallelograms.
//!
//! Where the gradient test passes, the new centre points are not shot but interpolated from
//! the previous level (§4.3: "bi-linear interpolation of the intensities of the previous step").
//! Along one axis, child c of the 2k children lies a quarter of the parent spacing left or
//! right of its parent a = c/2, so it gets p_a ∓ s/4, s the slope of the level at a: centred,
//! (p_{a+1} − p_{a−1})/2, inside, and one-sided at the two outermost parents; in 2D the
//! product of the two axes. This is linear interpolation along the slope through each parent,
//! and it is what we use instead of the plain bilinear stencil between neighbouring parents
//! (¾, ¼), for three reasons measured on the Cornell box (docs/ACCURACY.md):
//!
//! - it reproduces any bilinear field on the whole patch, border strips included; the plain
//!   stencil had to hold the outermost value beyond the border (a first-order error of a
//!   quarter spacing times the slope in every border strip, compounded level by level, which
//!   also made the surplus test shoot those strips on smooth slopes) or extrapolate it;
//! - the two children of a parent average to the parent exactly, so interpolating a level
//!   changes no patch form factor (4.3) whatever the rows (extrapolating the plain stencil moved
//!   F by 2–3 % on a curved falloff);
//! - on a curved field its error at a child is f''h²/32 against 3f''h²/32 for the plain one.
//!
//! The price: weights of ±1/8 (±1/4 at the border), so an interpolated row is an affine, not a
//! convex, combination of shot rows. It sums to what they sum to, but may hold small negative
//! entries where a parent sees a patch its neighbour does not; radiosity grids clamp at 0
//! (`crate::radiosity::Grid`).

/// The conservative stencil along one axis: child `c` (of 2k) of parent a = c/2 is
/// p_a ∓ s/4 (− for the left child), s the slope at a — centred, (p_{a+1} − p_{a−1})/2,
/// inside, one-sided at the border, 0 on a level of one sample. Up to three (parent, weight)
/// pairs, summing to 1; the two children of a parent average to it.
pub fn axis_slope_stencil(k: usize, c: usize) -> Vec<(usize, f64)> {
    assert!(k >= 1 && c < 2 * k, "child {c} of a level of {k}");
    let a = c / 2;
    let sign = if c.is_multiple_of(2) { -0.25 } else { 0.25 };
    if k == 1 {
        return vec![(0, 1.0)];
    }
    // slope s as weights on parents
    let s: [(usize, f64); 2] = if a == 0 {
        [(1, 1.0), (0, -1.0)]
    } else if a == k - 1 {
        [(k - 1, 1.0), (k - 2, -1.0)]
    } else {
        [(a + 1, 0.5), (a - 1, -0.5)]
    };
    let mut out = vec![(a, 1.0)];
    for (p, w) in s {
        match out.iter_mut().find(|(q, _)| *q == p) {
            Some(e) => e.1 += sign * w,
            None => out.push((p, sign * w)),
        }
    }
    out
}

/// The stencil of element (`a`, `b`) of the 2k×2k level from the k×k level: (v-major parent
/// index, weight) pairs, summing to 1 (see [`axis_slope_stencil`]).
pub fn stencil(k: usize, a: usize, b: usize) -> Vec<(usize, f64)> {
    let (su, sv) = (axis_slope_stencil(k, a), axis_slope_stencil(k, b));
    sv.iter()
        .flat_map(|&(v, wv)| su.iter().map(move |&(u, wu)| (v * k + u, wu * wv)))
        .collect()
}

/// The 4-sample window of a `k`-wide level whose part of the patch holds child `c` (of 2k) along
/// one axis. Window w spans the parents w and w+1 (0 ≤ w ≤ k−2) and holds the children between
/// them (2w+1 and 2w+2); the border children (0 and 2k−1), outside every window's span, belong
/// to the outermost window. `k` must be at least 2 (a window needs two samples per axis).
pub fn owner(k: usize, c: usize) -> usize {
    assert!(k >= 2 && c < 2 * k, "child {c} of a level of {k}");
    (c.saturating_sub(1) / 2).min(k - 2)
}

/// A sparse element row: (patch j, F_iq,j per channel), ascending j.
pub type Row = Vec<(u32, [f32; 3])>;

/// One weighted term of [`blend`]: a row and its weight.
pub type Part<'a> = (&'a [(u32, [f32; 3])], f64);

/// Σ w·row over `parts`, sparse, ascending j, accumulated in f64; zero weights are skipped.
pub fn blend(parts: &[Part<'_>]) -> Row {
    let mut all: Vec<(u32, [f64; 3])> = Vec::new();
    for &(row, w) in parts {
        if w == 0.0 {
            continue;
        }
        all.extend(
            row.iter()
                .map(|&(j, f)| (j, [0, 1, 2].map(|c| w * f[c] as f64))),
        );
    }
    all.sort_by_key(|&(j, _)| j);
    let mut out: Row = Vec::new();
    let mut acc: Option<(u32, [f64; 3])> = None;
    for (j, f) in all {
        match &mut acc {
            Some((aj, af)) if *aj == j => {
                for c in 0..3 {
                    af[c] += f[c];
                }
            }
            _ => {
                if let Some((aj, af)) = acc.take() {
                    out.push((aj, af.map(|x| x as f32)));
                }
                acc = Some((j, f));
            }
        }
    }
    if let Some((aj, af)) = acc {
        out.push((aj, af.map(|x| x as f32)));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn children_sit_a_quarter_spacing_along_the_slope() {
        // k = 4, parent 1: its children get p1 ∓ (p2 − p0)/8
        assert_eq!(
            axis_slope_stencil(4, 2),
            [(1, 1.0), (2, -0.125), (0, 0.125)]
        );
        assert_eq!(
            axis_slope_stencil(4, 3),
            [(1, 1.0), (2, 0.125), (0, -0.125)]
        );
        // border parents use the one-sided slope: the outer child continues the line
        assert_eq!(axis_slope_stencil(4, 0), [(0, 1.25), (1, -0.25)]);
        assert_eq!(axis_slope_stencil(4, 1), [(0, 0.75), (1, 0.25)]);
        assert_eq!(axis_slope_stencil(4, 7), [(3, 1.25), (2, -0.25)]);
        // a single sample: everything is that sample
        assert_eq!(axis_slope_stencil(1, 1), [(0, 1.0)]);
    }

    #[test]
    fn children_average_to_their_parent() {
        // per axis the two children of parent a hold 2 on a and 0 on every other parent, so
        // interpolating a level keeps Σ_q W_q F_q,j (4.3) whatever the rows; every child's
        // weights sum to 1, so rows keep their sums
        for k in 1..=9 {
            for a in 0..k {
                let mut got = vec![0.0; k];
                for c in [2 * a, 2 * a + 1] {
                    let st = axis_slope_stencil(k, c);
                    let sum: f64 = st.iter().map(|&(_, w)| w).sum();
                    assert!((sum - 1.0).abs() < 1e-15, "k {k} child {c}");
                    for (p, w) in st {
                        got[p] += w;
                    }
                }
                for (p, g) in got.iter().enumerate() {
                    let want = if p == a { 2.0 } else { 0.0 };
                    assert!((g - want).abs() < 1e-12, "k {k} parent {a}: {p} gets {g}");
                }
            }
        }
    }

    #[test]
    fn interpolation_reproduces_a_bilinear_field_on_the_whole_patch() {
        let k = 4;
        let f = |x: f64, y: f64| 1.0 + 2.0 * x - 0.5 * y + 0.25 * x * y;
        let parents: Vec<f64> = (0..k * k)
            .map(|i| f((i % k) as f64, (i / k) as f64))
            .collect();
        for b in 0..2 * k {
            for a in 0..2 * k {
                let got: f64 = stencil(k, a, b).iter().map(|&(p, w)| w * parents[p]).sum();
                let want = f(a as f64 * 0.5 - 0.25, b as f64 * 0.5 - 0.25);
                assert!((got - want).abs() < 1e-12, "({a},{b}): {got} vs {want}");
            }
        }
    }

    #[test]
    fn windows_own_the_children_between_their_samples() {
        let k = 4;
        let owners: Vec<usize> = (0..2 * k).map(|c| owner(k, c)).collect();
        assert_eq!(owners, [0, 0, 0, 1, 1, 2, 2, 2]);
        assert_eq!((0..4).map(|c| owner(2, c)).collect::<Vec<_>>(), [0; 4]);
    }

    #[test]
    fn blending_merges_sparse_rows() {
        let r1: Row = vec![(0, [0.5; 3]), (3, [0.25, 0.5, 0.75])];
        let r2: Row = vec![(1, [1.0; 3]), (3, [0.25; 3])];
        let got = blend(&[(&r1, 0.75), (&r2, 0.25), (&r2, 0.0)]);
        assert_eq!(
            got,
            vec![(0, [0.375; 3]), (1, [0.25; 3]), (3, [0.25, 0.4375, 0.625])]
        );
    }
}
