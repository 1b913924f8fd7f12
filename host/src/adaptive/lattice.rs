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
//! ¾·(nearer parent) + ¼·(the other), and at the border, beyond the outermost parent sample, the
//! outermost value is held (constant extension). Held, not extrapolated: with these weights every
//! parent hands out exactly the share it had (each parent's weights over its children sum to 2
//! per axis, 4 in all, and a child carries a quarter of its parent's area), so interpolating a
//! level changes no patch form factor (4.3), and every interpolated row is a convex combination
//! of computed rows — never negative, never summing to more than the rows it came from.

/// The two parents of child `c` (of 2k) along one axis of a `k`-wide level, with their bilinear
/// weights (≥ 0, summing to 1; the second weight is 0 where the child lies beyond the outermost
/// parent and the outermost value is held).
pub fn axis_stencil(k: usize, c: usize) -> [(usize, f64); 2] {
    assert!(k >= 1 && c < 2 * k, "child {c} of a level of {k}");
    // x = c/2 − 1/4, exact in binary floating point
    let x = c as f64 * 0.5 - 0.25;
    if x <= 0.0 {
        [(0, 1.0), (0, 0.0)]
    } else if x >= (k - 1) as f64 {
        [(k - 1, 1.0), (k - 1, 0.0)]
    } else {
        let lo = x.floor() as usize;
        let t = x - lo as f64;
        [(lo, 1.0 - t), (lo + 1, t)]
    }
}

/// The bilinear stencil of element (`a`, `b`) of the 2k×2k level from the k×k level: four
/// (v-major parent index, weight) pairs, the weights ≥ 0 and summing to 1.
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
        // border children hold the outermost value
        assert_eq!(axis_stencil(4, 0), [(0, 1.0), (0, 0.0)]);
        assert_eq!(axis_stencil(4, 7), [(3, 1.0), (3, 0.0)]);
        // a single sample: everything is that sample
        assert_eq!(axis_stencil(1, 1), [(0, 1.0), (0, 0.0)]);
    }

    #[test]
    fn every_parent_hands_out_exactly_its_share() {
        // Σ over children of a parent's weight = 2 per axis: interpolating a level keeps
        // Σ_q W_q F_q,j (4.3) on parallelograms.
        for k in 1..=9 {
            let mut got = vec![0.0; k];
            for c in 0..2 * k {
                for (p, w) in axis_stencil(k, c) {
                    got[p] += w;
                }
            }
            for (p, g) in got.iter().enumerate() {
                assert!((g - 2.0).abs() < 1e-12, "k {k} parent {p}: {g}");
            }
        }
    }

    #[test]
    fn interpolation_reproduces_a_bilinear_field_inside_the_windows() {
        let k = 4;
        let f = |x: f64, y: f64| 1.0 + 2.0 * x - 0.5 * y + 0.25 * x * y;
        let parents: Vec<f64> = (0..k * k)
            .map(|i| f((i % k) as f64, (i / k) as f64))
            .collect();
        for b in 1..2 * k - 1 {
            for a in 1..2 * k - 1 {
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
