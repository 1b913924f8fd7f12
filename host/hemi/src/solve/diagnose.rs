//! Detection: what makes an iterative solve of (2.6) slow or impossible, measured before it runs.

pub use super::system::ROW_SLACK;
use super::System;

/// What [`diagnose`] measured.
#[derive(Clone, Debug, PartialEq)]
pub struct Diagnosis {
    /// N.
    pub patches: usize,
    /// Lower bound on the spectral radius of ρF (the largest over the channels).
    pub radius_low: f64,
    /// Upper bound on the spectral radius of ρF (the largest over the channels).
    pub radius_high: f64,
    /// Rows of F (any channel) summing above 1.
    pub rows_above_one: usize,
    /// The largest row sum of F.
    pub max_row_sum: f64,
    /// The largest ρ_i Σ_j F_ij: the spectral radius's Perron–Frobenius upper bound.
    pub max_reflected: f64,
    /// Power-iteration steps taken.
    pub steps: u32,
}

impl Diagnosis {
    /// About how many Jacobi sweeps reduce the error by `tol` at the upper radius; by the
    /// Stein–Rosenberg theorem Gauss-Seidel needs at most as many on these non-negative matrices.
    pub fn sweeps_estimate(&self, tol: f64) -> u64 {
        if self.radius_high >= 1.0 {
            return u64::MAX;
        }
        if self.radius_high <= 0.0 {
            return 1;
        }
        (tol.ln() / self.radius_high.ln()).ceil().max(1.0) as u64
    }
}

/// The row sums of F alone (no spectral radius): O(N²), for a warning before an explicit solver.
pub fn row_sums(system: &System<'_>) -> Diagnosis {
    let n = system.len();
    let mut d = Diagnosis {
        patches: n,
        radius_low: 0.0,
        radius_high: 0.0,
        rows_above_one: 0,
        max_row_sum: 0.0,
        max_reflected: 0.0,
        steps: 0,
    };
    let mut above = vec![false; n];
    for c in 0..3 {
        for (i, row) in system.f[c].iter().enumerate() {
            let s = row.sum();
            d.max_row_sum = d.max_row_sum.max(s);
            d.max_reflected = d.max_reflected.max(system.rho[i][c] * s);
            if s > 1.0 + ROW_SLACK {
                above[i] = true;
            }
        }
    }
    d.rows_above_one = above.iter().filter(|a| **a).count();
    d
}

/// Measures `system`: row sums of F, and the spectral radius of M = diag(ρ)F by power iteration
/// on M + I (the shift keeps the iteration from oscillating between the ±λ of a bipartite pair of
/// patches), bracketed by the Collatz–Wielandt bounds
/// `min_i (Mx)_i/x_i ≤ ρ(M) ≤ max_i (Mx)_i/x_i` for positive x (Perron–Frobenius; M ≥ 0).
/// Stops when the bracket is 10⁻⁴ wide or after 200 steps: at most 200 N² multiply-adds per
/// channel, about as much as 200 Gauss-Seidel sweeps of one channel — paid only by `auto`.
pub fn diagnose(system: &System<'_>) -> Diagnosis {
    let mut d = row_sums(system);
    let n = system.len();
    let channels: &[usize] =
        if system.is_grey() && system.rho.iter().all(|r| r[0] == r[1] && r[1] == r[2]) {
            &[0]
        } else {
            &[0, 1, 2]
        };
    if n == 0 {
        return d;
    }
    for &c in channels {
        let m = |i: usize, x: &[f64]| -> f64 {
            system.rho[i][c] * system.f[c][i].entries().map(|(j, f)| f * x[j]).sum::<f64>()
        };
        let mut x = vec![1.0f64; n];
        let mut y = vec![0.0f64; n];
        let (mut lo, mut hi) = (0.0, f64::INFINITY);
        for step in 1..=200u32 {
            let (mut l, mut h) = (f64::INFINITY, 0.0f64);
            for i in 0..n {
                let mx = m(i, &x);
                y[i] = mx + x[i];
                let ratio = mx / x[i];
                l = l.min(ratio);
                h = h.max(ratio);
            }
            lo = l;
            hi = h;
            let norm = y.iter().fold(0.0f64, |a, v| a.max(*v));
            if !(norm > 0.0 && norm.is_finite()) {
                break;
            }
            for (xi, yi) in x.iter_mut().zip(&y) {
                // keep x strictly positive so the bounds stay valid
                *xi = (yi / norm).max(1e-300);
            }
            d.steps = d.steps.max(step);
            if hi - lo < 1e-4 {
                break;
            }
        }
        d.radius_low = d.radius_low.max(lo);
        d.radius_high = d.radius_high.max(hi.min(d.max_reflected.max(lo)));
    }
    d
}

#[cfg(test)]
mod tests {
    use super::super::{grey, tests::furnace};
    use super::*;

    #[test]
    fn furnace_radius_is_rho() {
        let f = furnace(10, 1.0);
        let rho = vec![[0.7; 3]; 10];
        let e = vec![[1.0; 3]; 10];
        let d = diagnose(&System::new(grey(&f), &rho, &e).unwrap());
        assert!(
            d.radius_low <= 0.7 + 1e-12 && d.radius_high >= 0.7 - 1e-12,
            "{d:?}"
        );
        assert!(d.radius_high - d.radius_low < 1e-3, "{d:?}");
        assert_eq!(d.rows_above_one, 0);
    }

    #[test]
    fn bipartite_pair_converges() {
        // two opposed patches seeing each other by 0.2: eigenvalues ±ρ·0.2
        let f = vec![vec![0.0, 0.2], vec![0.2, 0.0]].into();
        let rho = vec![[0.5; 3]; 2];
        let e = vec![[1.0; 3]; 2];
        let d = diagnose(&System::new(grey(&f), &rho, &e).unwrap());
        assert!(
            (d.radius_high - 0.1).abs() < 1e-3 && (d.radius_low - 0.1).abs() < 1e-3,
            "{d:?}"
        );
    }
}
