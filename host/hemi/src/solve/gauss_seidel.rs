//! Gauss-Seidel sweeps (paper §6.4): the paper's solver, and the one `auto` keeps when the
//! system converges fast.

use super::{Channels, Solution, SolveSettings, Solver, System};
use anyhow::{bail, Result};
use std::time::Instant;

/// Why an iteration at relaxation `omega` diverged, as the rows of the system say: only rows
/// with ρ·ΣF ≥ 1 are blamed if there are any; otherwise it is the over-relaxation.
fn why_diverged(system: &System<'_>, omega: f64) -> String {
    let d = super::diagnose::row_sums(system);
    if d.max_reflected >= 1.0 {
        format!(
            "a row has ρ·ΣF = {:.4} ≥ 1, which makes the system unsolvable by iteration",
            d.max_reflected
        )
    } else if omega > 1.0 {
        format!(
            "no row has ρ·ΣF ≥ 1 (the largest is {:.4}), so the over-relaxation ω = {omega:.3} \
             is what diverges: --solver gauss-seidel or auto",
            d.max_reflected
        )
    } else {
        format!(
            "no row has ρ·ΣF ≥ 1 (the largest is {:.4})",
            d.max_reflected
        )
    }
}

/// Solves `B_i = E_i + ρ_i Σ_j F_ij B_j` for every channel by Gauss-Seidel sweeps, stopping on
/// the relative residual. The existing entry point; [`solve`] takes a [`System`].
pub fn gauss_seidel(
    f: Channels<'_>,
    rho: &[[f64; 3]],
    e: &[[f64; 3]],
    settings: &SolveSettings,
) -> Result<Solution> {
    solve(&System::new(f, rho, e)?, settings)
}

/// Gauss-Seidel on `system` (SOR with ω = 1).
pub fn solve(system: &System<'_>, settings: &SolveSettings) -> Result<Solution> {
    relaxed(system, 1.0, settings, Solver::GaussSeidel, "Gauss-Seidel")
}

/// One relaxed Gauss-Seidel update of patch i, channel c: the Gauss-Seidel value
/// `(E_i + ρ_i Σ_{j≠i} F_ij B_j) / (1 − ρ_i F_ii)` blended as `B_i ← (1−ω) B_i + ω·GS`.
/// The sums run over each row's non-zeros, in column order as a dense row's would.
#[inline]
#[expect(
    clippy::needless_range_loop,
    reason = "B_i is read through the row and written in place"
)]
pub(crate) fn sweep(system: &System<'_>, omega: f64, b: &mut [[f64; 3]]) {
    for i in 0..b.len() {
        for c in 0..3 {
            let row = &system.f[c][i];
            let mut gathered = 0.0;
            let mut fii = 0.0;
            for (j, fij) in row.entries() {
                if j != i {
                    gathered += fij * b[j][c];
                } else {
                    fii = fij;
                }
            }
            let denom = 1.0 - system.rho[i][c] * fii;
            let gs = (system.e[i][c] + system.rho[i][c] * gathered) / denom;
            b[i][c] = (1.0 - omega) * b[i][c] + omega * gs;
        }
    }
}

/// Gauss-Seidel sweeps relaxed by `omega` (1 = plain Gauss-Seidel; see [`super::sor`]), with the
/// failure detection every iterative solver here shares:
/// - **divergence**: the residual is not finite, or its absolute value grew for 20 sweeps in a
///   row (an eigenvalue of the iteration at or above 1: some ρ_i Σ_j F_ij ≥ 1);
/// - **stagnation**: no tenfold drop of the residual in 2000 sweeps (ρ(ρF) within 10⁻³ of 1).
pub(crate) fn relaxed(
    system: &System<'_>,
    omega: f64,
    settings: &SolveSettings,
    solver: Solver,
    name: &str,
) -> Result<Solution> {
    let t0 = Instant::now();
    let mut b: Vec<[f64; 3]> = system.e.to_vec();
    let mut history = Vec::new();
    let mut last = f64::INFINITY;
    let mut last_abs = f64::INFINITY;
    let mut growing = 0;
    let mut checkpoint = (0u32, f64::INFINITY);
    for it in 1..=settings.max_iterations {
        sweep(system, omega, &mut b);
        let r = system.residual(&b);
        let scale = b
            .iter()
            .flat_map(|x| x.iter())
            .fold(0.0f64, |m, x| m.max(x.abs()));
        let abs = r * scale.max(f64::MIN_POSITIVE);
        history.push((t0.elapsed().as_secs_f64(), r));
        if !r.is_finite() || !scale.is_finite() {
            bail!(
                "{name} diverged at sweep {it}: the residual is not finite; {}",
                why_diverged(system, omega)
            );
        }
        if r <= settings.tolerance {
            return Ok(Solution {
                radiosity: b,
                iterations: it,
                residual: r,
                solver,
                history,
            });
        }
        growing = if abs > last_abs { growing + 1 } else { 0 };
        if growing >= 20 {
            bail!(
                "{name} diverges: the residual grew for 20 sweeps in a row (now {abs:.3e}, \
                 radiosity {scale:.3e}); {}",
                why_diverged(system, omega)
            );
        }
        last = r;
        last_abs = abs;
        if it - checkpoint.0 >= 2000 {
            if r > 0.1 * checkpoint.1 {
                bail!("{name} stagnates: residual {r:.3e} after {it} sweeps fell less than tenfold in the last 2000 (ρ close to 1?)");
            }
            checkpoint = (it, r);
        }
    }
    bail!(
        "{name} did not reach the tolerance {:.1e} in {} sweeps (residual {last:.3e})",
        settings.tolerance,
        settings.max_iterations
    )
}

/// The system of `scene` over `f` (assembled by [`super::SceneParts`]) solved by Gauss-Seidel,
/// the paper's solver (§6.4).
pub fn gauss_seidel_scene(
    scene: &crate::scene::Scene,
    f: Channels<'_>,
    settings: &SolveSettings,
) -> Result<Solution> {
    let parts = super::SceneParts::new(scene, f);
    let system = parts.system(f)?;
    gauss_seidel(system.f, system.rho, system.e, settings)
}

#[cfg(test)]
mod tests {
    use super::super::grey;
    use super::*;

    #[test]
    fn two_patch_system_matches_closed_form() {
        // B0 = 1 + 0.5·0.4·B1, B1 = 0 + 0.8·0.3·B0
        let f = vec![vec![0.0, 0.4], vec![0.3, 0.0]].into();
        let rho = vec![[0.5; 3], [0.8; 3]];
        let e = vec![[1.0; 3], [0.0; 3]];
        let s = gauss_seidel(grey(&f), &rho, &e, &SolveSettings::default()).unwrap();
        let b0 = 1.0 / (1.0 - 0.5 * 0.4 * 0.8 * 0.3);
        assert!((s.radiosity[0][0] - b0).abs() < 1e-9);
        assert!((s.radiosity[1][0] - 0.24 * b0).abs() < 1e-9);
        assert!(s.residual <= 1e-9);
        assert_eq!(s.history.len() as u32, s.iterations);
    }

    #[test]
    fn divergence_is_reported() {
        let f = vec![vec![0.0, 1.0], vec![1.0, 0.0]].into();
        let rho = vec![[1.5; 3], [1.5; 3]];
        let e = vec![[1.0; 3], [0.0; 3]];
        let err = gauss_seidel(grey(&f), &rho, &e, &SolveSettings::default()).unwrap_err();
        assert!(format!("{err}").contains("diverge"), "{err}");
        assert!(
            format!("{err}").contains("a row has ρ·ΣF = 1.5000 ≥ 1"),
            "{err}"
        );
    }

    #[test]
    fn over_relaxation_that_diverges_blames_omega_not_rows_that_are_fine() {
        let f = vec![vec![0.0, 0.9], vec![0.9, 0.0]].into();
        let rho = vec![[0.9; 3], [0.9; 3]];
        let e = vec![[1.0; 3], [0.0; 3]];
        let system = System::new(grey(&f), &rho, &e).unwrap();
        let settings = SolveSettings::default();
        let err = relaxed(&system, 2.5, &settings, Solver::Sor, "SOR").unwrap_err();
        let err = format!("{err}");
        assert!(
            err.contains("no row has ρ·ΣF ≥ 1 (the largest is 0.8100)"),
            "{err}"
        );
        assert!(err.contains("ω = 2.500 is what diverges"), "{err}");
    }
}
