//! Progressive refinement shooting (Cohen, Chen, Wallace & Greenberg 1988), for scenes whose
//! matrix does not fit, and for an image early (the paper's §9 suggests it for exactly that).
//!
//! Every patch keeps its radiosity B_i and its unshot radiosity ΔB_i (both start at E_i). A step
//! picks the patch with the most unshot power ΔB_i A_i, and shoots it: every receiver j gets
//!
//! ```text
//! ΔB_j += ρ_j F_ji ΔB_i,   B_j += ρ_j F_ji ΔB_i,   then ΔB_i = 0          (Cohen 1988, fig. 3)
//! ```
//!
//! which is Southwell's iteration on (2.6): ΔB is at every step exactly the residual
//! `E + ρFB − B` of the system the F_ji come from, so the stopping rule max|ΔB| / max|B| is the
//! same relative residual the other solvers stop on. Memory is O(N) beyond the column of F_ji
//! that one step needs, which [`progressive`] asks for one shooter at a time: from a stored
//! matrix ([`solve_matrix`]: the column, exact), or computed on demand by shooting the shooter's
//! hemispheres ([`crate::on_demand`]: its row F_ij turned into the column by reciprocity,
//! F_ji = F_ij A_i / A_j, as Cohen et al. do with their hemicube at the shooter).
//!
//! With translucent sheets the system is `B = E + KB` with K = ρF + τF_twin
//! ([`crate::solve::coupled`]): the columns are then K_ji, which carry ρ and τ, and ρ is
//! passed as 1 (`on_demand::solve_streaming`, `on_demand::RowShooter::coupled_column`).

use super::{Solution, SolveSettings, Solver, System};
use anyhow::{bail, Result};
use std::time::Instant;

/// `column(i, out)`: fills `out[j]` with F_ji per channel for shooter i.
pub type ColumnSource<'a> = dyn FnMut(usize, &mut [[f64; 3]]) -> Result<()> + 'a;

/// Progressive refinement over N patches with reflectances `rho`, emissions `e` and areas
/// `areas`. `column(i, out)` fills `out[j]` with F_ji per channel for shooter i. `on_shot(step,
/// b)` sees the radiosity after every shot (the early image). Stops at the relative residual
/// `settings.tolerance`, or fails after `settings.max_iterations` shots.
pub fn progressive(
    rho: &[[f64; 3]],
    e: &[[f64; 3]],
    areas: &[f64],
    column: &mut ColumnSource<'_>,
    settings: &SolveSettings,
    on_shot: &mut dyn FnMut(u32, &[[f64; 3]]),
) -> Result<Solution> {
    let n = e.len();
    anyhow::ensure!(
        rho.len() == n && areas.len() == n,
        "progressive refinement: {n} emissions, {} reflectances, {} areas",
        rho.len(),
        areas.len()
    );
    let t0 = Instant::now();
    let mut b = e.to_vec();
    let mut unshot = e.to_vec();
    let mut col = vec![[0.0f64; 3]; n];
    let mut history = Vec::new();
    let residual = |b: &[[f64; 3]], unshot: &[[f64; 3]]| {
        let worst = unshot.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
        let scale = b.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
        if scale > 0.0 {
            worst / scale
        } else {
            worst
        }
    };
    let mut r = residual(&b, &unshot);
    if r <= settings.tolerance {
        return Ok(Solution {
            radiosity: b,
            iterations: 0,
            residual: r,
            solver: Solver::Progressive,
            history,
        });
    }
    for step in 1..=settings.max_iterations {
        // the shooter: most unshot power, summed over channels
        let (i, _) = unshot
            .iter()
            .zip(areas)
            .map(|(u, a)| (u[0].abs() + u[1].abs() + u[2].abs()) * a)
            .enumerate()
            .fold(
                (0, -1.0),
                |best, (i, p)| if p > best.1 { (i, p) } else { best },
            );
        let shot = unshot[i];
        unshot[i] = [0.0; 3];
        col.fill([0.0; 3]);
        column(i, &mut col)?;
        for j in 0..n {
            for c in 0..3 {
                let d = rho[j][c] * col[j][c] * shot[c];
                unshot[j][c] += d;
                b[j][c] += d;
            }
        }
        r = residual(&b, &unshot);
        history.push((t0.elapsed().as_secs_f64(), r));
        on_shot(step, &b);
        if !r.is_finite() {
            bail!("progressive refinement diverged at shot {step} (is ρ·ΣF ≥ 1 for some patch?)");
        }
        if r <= settings.tolerance {
            return Ok(Solution {
                radiosity: b,
                iterations: step,
                residual: r,
                solver: Solver::Progressive,
                history,
            });
        }
    }
    bail!(
        "progressive refinement did not reach the tolerance {:.1e} in {} shots (residual {r:.3e})",
        settings.tolerance,
        settings.max_iterations
    )
}

/// Progressive refinement on a stored system: the column F_·i is read from the matrix, so this
/// converges to the same B as the other solvers. `areas` orders the shooters by power (without
/// them, by unshot radiosity).
pub fn solve_matrix(
    system: &System<'_>,
    areas: Option<&[f64]>,
    settings: &SolveSettings,
) -> Result<Solution> {
    let n = system.len();
    let ones = vec![1.0; n];
    let areas = areas.unwrap_or(&ones);
    // Southwell needs one shot per patch and per decade or so: allow N times the sweeps
    let settings = SolveSettings {
        max_iterations: settings.max_iterations.saturating_mul(n.max(1) as u32),
        ..*settings
    };
    progressive(
        system.rho,
        system.e,
        areas,
        &mut |i, out| {
            for (j, o) in out.iter_mut().enumerate() {
                *o = [0, 1, 2].map(|c| system.f[c][j][i]);
            }
            Ok(())
        },
        &settings,
        &mut |_, _| {},
    )
}

#[cfg(test)]
mod tests {
    use super::super::{direct, grey};
    use super::*;

    #[test]
    fn matches_the_direct_solve_on_an_open_scene() {
        let f = vec![
            vec![0.0, 0.3, 0.2],
            vec![0.1, 0.0, 0.4],
            vec![0.25, 0.05, 0.0],
        ]
        .into();
        let rho = vec![[0.7; 3], [0.5, 0.6, 0.4], [0.9; 3]];
        let e = vec![[1.0; 3], [0.0; 3], [0.2; 3]];
        let sys = System::new(grey(&f), &rho, &e).unwrap();
        let want = direct::solve(&sys).unwrap();
        let got = solve_matrix(&sys, Some(&[1.0, 2.0, 0.5]), &SolveSettings::default()).unwrap();
        for (a, b) in got.radiosity.iter().zip(&want.radiosity) {
            for c in 0..3 {
                assert!((a[c] - b[c]).abs() < 1e-8, "{a:?} vs {b:?}");
            }
        }
        // ΔB is the residual: the reported one agrees with the system's
        assert!(sys.residual(&got.radiosity) <= 2.0 * got.residual + 1e-15);
    }
}
