//! Successive over-relaxation and Jacobi sweeps: the iterative remedies when Gauss-Seidel is
//! slow (ρ(ρF) near 1) and N is too large for a dense LU.

use super::gauss_seidel::relaxed;
use super::{Solution, SolveSettings, Solver, System};
use anyhow::{bail, Result};
use std::time::Instant;

/// Young's optimal relaxation factor ω = 2 / (1 + √(1 − ρ_J²)) for a Jacobi spectral radius
/// ρ_J (Young 1971, Thm. 6-2.2). It is exact for consistently ordered matrices with real Jacobi
/// eigenvalues; radiosity matrices are not consistently ordered, so this is a good guess, not an
/// optimum: measured on the ρ = 0.99 furnace (docs/PERFORMANCE.md), it cuts the sweeps several
/// fold. ρ_J is clamped below 0.9999 so ω stays below 2 (SOR diverges at ω ≥ 2).
pub fn omega_for(radius: f64) -> f64 {
    let r = radius.clamp(0.0, 0.9999);
    2.0 / (1.0 + (1.0 - r * r).sqrt())
}

/// SOR: Gauss-Seidel updates blended as `B_i ← (1−ω) B_i + ω·GS_i`, with the same failure
/// detection (see the module [`super::gauss_seidel`](mod@super::gauss_seidel)).
pub fn sor(system: &System<'_>, omega: f64, settings: &SolveSettings) -> Result<Solution> {
    anyhow::ensure!(
        omega > 0.0 && omega < 2.0,
        "SOR needs 0 < ω < 2 (got {omega})"
    );
    relaxed(
        system,
        omega,
        settings,
        Solver::Sor,
        &format!("SOR (ω = {omega:.4})"),
    )
}

/// Jacobi sweeps: every patch updated from the previous sweep's values,
/// `B_i ← (E_i + ρ_i Σ_{j≠i} F_ij B_j) / (1 − ρ_i F_ii)`.
pub fn jacobi(system: &System<'_>, settings: &SolveSettings) -> Result<Solution> {
    let t0 = Instant::now();
    let n = system.len();
    let mut b: Vec<[f64; 3]> = system.e.to_vec();
    let mut next = b.clone();
    let mut history = Vec::new();
    let mut checkpoint = (0u32, f64::INFINITY);
    for it in 1..=settings.max_iterations {
        for i in 0..n {
            for c in 0..3 {
                let row = &system.f[c][i];
                let gathered: f64 = row
                    .entries()
                    .filter(|(j, _)| *j != i)
                    .map(|(j, f)| f * b[j][c])
                    .sum();
                next[i][c] = (system.e[i][c] + system.rho[i][c] * gathered)
                    / (1.0 - system.rho[i][c] * row[i]);
            }
        }
        std::mem::swap(&mut b, &mut next);
        let r = system.residual(&b);
        history.push((t0.elapsed().as_secs_f64(), r));
        if !r.is_finite() {
            bail!("Jacobi diverged at sweep {it}");
        }
        if r <= settings.tolerance {
            return Ok(Solution {
                radiosity: b,
                iterations: it,
                residual: r,
                solver: Solver::Jacobi,
                history,
            });
        }
        if it - checkpoint.0 >= 2000 {
            if r > 0.1 * checkpoint.1 {
                bail!("Jacobi stagnates: residual {r:.3e} after {it} sweeps");
            }
            checkpoint = (it, r);
        }
    }
    bail!(
        "Jacobi did not reach the tolerance {:.1e} in {} sweeps",
        settings.tolerance,
        settings.max_iterations
    )
}

#[cfg(test)]
mod tests {
    use super::super::{grey, tests::furnace};
    use super::*;

    #[test]
    fn sor_beats_gauss_seidel_near_one() {
        let f = furnace(12, 1.0);
        let rho = vec![[0.99; 3]; 12];
        let e: Vec<[f64; 3]> = (0..12).map(|i| [(i % 3) as f64; 3]).collect();
        let sys = System::new(grey(&f), &rho, &e).unwrap();
        let gs = super::super::gauss_seidel::solve(&sys, &SolveSettings::default()).unwrap();
        let s = sor(&sys, 1.3, &SolveSettings::default()).unwrap();
        assert!(
            s.iterations < gs.iterations,
            "SOR {} vs GS {}",
            s.iterations,
            gs.iterations
        );
        for (a, b) in s.radiosity.iter().zip(&gs.radiosity) {
            assert!((a[0] - b[0]).abs() < 1e-6 * b[0].abs().max(1.0));
        }
        assert!(sor(&sys, 2.0, &SolveSettings::default()).is_err());
    }

    #[test]
    fn omega_is_one_without_coupling_and_below_two() {
        assert_eq!(omega_for(0.0), 1.0);
        assert!(omega_for(1.5) < 2.0);
    }
}
