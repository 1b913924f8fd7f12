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
//! Where the gradient test passes, the new centre points are not shot but interpolated
//! bilinearly from the previous level (§4.3). Along one axis, child c of the 2k children lies at
//! x = c/2 − ¼ in units of the parent spacing (parent sample a sits at x = a), so its value is
//! ¾·(nearer parent) + ¼·(the other). At the border, beyond the outermost parent sample, the
//! line through the two outermost parents is extended (5/4 and −1/4): interpolation reproduces
//! any bilinear field on the whole patch, border strips included. (Holding the outermost value
//! instead, as this module first did, cost a first-order error of a quarter of the parent
//! spacing times the slope in every border strip, compounded level by level, and made the
//! surplus test shoot those strips on any smooth slope: 15 % more rows for the same error on
//! the Cornell box, docs/ACCURACY.md.) Interior weights are ≥ 0; per axis they sum to 1 for
//! every child, so every interpolated row still sums to what its parents' rows sum to, and
//! interpolating a level changes a patch form factor (4.3) only by a quarter of the second
//! difference of the two outermost parents' rows per border, zero for rows that vary linearly.
//! A border child's row may hold small negative entries where its outermost parent sees a
//! patch its neighbour does not; radiosity grids clamp at 0 (`crate::radiosity::Grid`).

/// The two parents of child `c` (of 2k) along one axis of a `k`-wide level, with their bilinear
/// weights (summing to 1; both ≥ 0 inside, 5/4 and −1/4 on a border child, which lies beyond
/// the outermost parent and is extrapolated; a level of one sample is held).
pub fn axis_stencil(k: usize, c: usize) -> [(usize, f64); 2] {
    assert!(k >= 1 && c < 2 * k, "child {c} of a level of {k}");
    if k == 1 {
        return [(0, 1.0), (0, 0.0)];
    }
    // x = c/2 − 1/4, exact in binary floating point; the span of the two parents that hold
    // it, the outermost span beyond the border
    let x = c as f64 * 0.5 - 0.25;
    let lo = (x.floor().max(0.0) as usize).min(k - 2);
    let t = x - lo as f64;
    [(lo, 1.0 - t), (lo + 1, t)]
}

/// The bilinear stencil of element (`a`, `b`) of the 2k×2k level from the k×k level: four
/// (v-major parent index, weight) pairs, summing to 1 (see [`axis_stencil`]).
pub fn stencil(k: usize, a: usize, b: usize) -> [(usize, f64); 4] {
    let [(u0, wu0), (u1, wu1)] = axis_stencil(k, a);
    let [(v0, wv0), (v1, wv1)] = axis_stencil(k, b);
    [
        (v0 * k + u0, wu0 * wv0),
        (v0 * k + u1, wu1 * wv0),
        (v1 * k + u0, wu0 * wv1),
        (v1 * k + u1, wu1 * wv1),
    ]
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
    fn children_sit_a_quarter_spacing_from_their_parents() {
        // k = 4: child 3 lies at x = 1.25, between parents 1 and 2, nearer 1
        assert_eq!(axis_stencil(4, 3), [(1, 0.75), (2, 0.25)]);
        assert_eq!(axis_stencil(4, 4), [(1, 0.25), (2, 0.75)]);
        // border children continue the line through the outermost two
        assert_eq!(axis_stencil(4, 0), [(0, 1.25), (1, -0.25)]);
        assert_eq!(axis_stencil(4, 7), [(2, -0.25), (3, 1.25)]);
        assert_eq!(axis_stencil(2, 0), [(0, 1.25), (1, -0.25)]);
        // a single sample: everything is that sample
        assert_eq!(axis_stencil(1, 1), [(0, 1.0), (0, 0.0)]);
    }

    #[test]
    fn every_child_is_an_affine_combination() {
        // weights sum to 1 for every child, so an interpolated row sums to what its parents'
        // rows sum to; a 2-sample level hands each parent exactly its share (2 per axis)
        for k in 1..=9 {
            for c in 0..2 * k {
                let [(_, w0), (_, w1)] = axis_stencil(k, c);
                assert!((w0 + w1 - 1.0).abs() < 1e-15, "k {k} child {c}");
            }
        }
        let mut got = [0.0; 2];
        for c in 0..4 {
            for (p, w) in axis_stencil(2, c) {
                got[p] += w;
            }
        }
        assert_eq!(got, [2.0, 2.0]);
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
