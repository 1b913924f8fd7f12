//! The radiosity system (2.6), `B = E + ρ F B` per channel, and the solvers for it.
//!
//! The paper solves (2.6) by Gauss-Seidel (§6.4), which converges whenever the spectral radius of
//! `ρF` is below 1 — always, for a physical scene: every row of F sums to at most 1 (the fraction
//! of the hemisphere that sees something) and ρ < 1. Two things break that in practice:
//!
//! - **ρ close to 1.** A closed room of white walls has `ρ(ρF) ≈ ρ`; Gauss-Seidel then needs
//!   `ln(tol)/ln ρ(ρF)` sweeps or more (about 2000 at ρ = 0.99 for a residual of 1e-9), each
//!   costing `3N²`. A dense LU ([`direct`]) costs `2N³/3` once and does not care.
//! - **Rows above 1.** Pass 1 samples F (R circles, K×K points), so in a closed scene a row can sum
//!   to `1 + ε`. With ρ near 1, `ρ_i Σ_j F_ij ≥ 1` is then possible and the iteration diverges;
//!   energy conservation says the row cannot exceed 1, so [`System::conserving`] scales such
//!   rows back to 1.
//!
//! Which solver runs is [`Solver`]; [`Solver::Auto`] measures the system ([`diagnose()`]) and picks
//! ([`choose`]), saying why. Each solver has its own file; all take the same [`System`].

pub mod diagnose;
pub mod direct;
pub mod gauss_seidel;
pub mod progressive;
pub mod sor;
mod system;

pub use diagnose::{diagnose, Diagnosis};
pub use gauss_seidel::{gauss_seidel, gauss_seidel_scene};
pub use system::{
    coupled, coupled_entry, grey, system_reflectance_and_emission, Channels, SceneParts, System,
};

use anyhow::Result;

/// Result of a solve.
#[derive(Clone, Debug)]
pub struct Solution {
    /// Radiosity B per patch and channel.
    pub radiosity: Vec<[f64; 3]>,
    /// Sweeps (Gauss-Seidel, SOR, Jacobi), shots (progressive refinement), or 1 for a direct
    /// solve (one factorisation).
    pub iterations: u32,
    /// Final residual max |B − E − ρFB| / max |B| (progressive refinement: the unshot energy
    /// Σ ΔB_i A_i / Σ B_i A_i, the quantity it drives to zero).
    pub residual: f64,
    /// The solver that produced it.
    pub solver: Solver,
    /// (seconds since the start, residual) after every sweep or shot: the convergence charts of
    /// docs/PERFORMANCE.md.
    pub history: Vec<(f64, f64)>,
}

/// Solver settings.
#[derive(Clone, Copy, Debug)]
pub struct SolveSettings {
    /// Stop when the relative residual falls below this.
    pub tolerance: f64,
    /// Give up after this many sweeps (or shots).
    pub max_iterations: u32,
}

impl Default for SolveSettings {
    fn default() -> Self {
        SolveSettings {
            tolerance: 1e-9,
            max_iterations: 10_000,
        }
    }
}

/// Which solver to run (`--solver`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Solver {
    /// Measure the system and pick ([`choose`]).
    Auto,
    /// Gauss-Seidel sweeps, the paper's solver (§6.4).
    GaussSeidel,
    /// Successive over-relaxation with ω from the measured spectral radius.
    Sor,
    /// Jacobi sweeps (benchmarks only: never faster than Gauss-Seidel on these matrices, by the
    /// Stein–Rosenberg theorem, but it parallelises and is the textbook baseline).
    Jacobi,
    /// Dense LU with partial pivoting (faer; only in builds with hemi's `faer` feature).
    Direct,
    /// Progressive refinement shooting (Cohen et al. 1988).
    Progressive,
}

impl Solver {
    /// The name `--solver` takes.
    pub fn name(self) -> &'static str {
        match self {
            Solver::Auto => "auto",
            Solver::GaussSeidel => "gauss-seidel",
            Solver::Sor => "sor",
            Solver::Jacobi => "jacobi",
            Solver::Direct => "direct",
            Solver::Progressive => "progressive",
        }
    }
}

impl std::str::FromStr for Solver {
    type Err = anyhow::Error;
    fn from_str(s: &str) -> Result<Solver> {
        Ok(match s {
            "auto" => Solver::Auto,
            "gauss-seidel" | "gs" => Solver::GaussSeidel,
            "sor" => Solver::Sor,
            "jacobi" => Solver::Jacobi,
            "direct" => Solver::Direct,
            "progressive" => Solver::Progressive,
            _ => anyhow::bail!(
                "--solver {s}: expected auto, gauss-seidel, sor, jacobi, direct or progressive"
            ),
        })
    }
}

/// Largest N a dense LU is chosen for by `auto`: 2N³/3 flops per channel are about 6·10⁹ here,
/// a few seconds on one core, and the N×N copy it factors is 128 MiB.
pub const DIRECT_LIMIT: usize = 4096;

/// Spectral radius of ρF above which `auto` leaves Gauss-Seidel: at 0.9 it needs about
/// ln(1e-9)/ln 0.9 ≈ 200 sweeps, and every 0.01 closer to 1 costs more than the LU would.
pub const SLOW_RADIUS: f64 = 0.9;

/// What `auto` decided and why (one line for stderr).
#[derive(Clone, Debug)]
pub struct Choice {
    /// The solver picked.
    pub solver: Solver,
    /// Whether rows of F above 1 are to be scaled back to 1 first.
    pub conserve: bool,
    /// The reason, in words.
    pub why: String,
}

/// Picks a solver for a system that fits in memory, from its diagnosis: Gauss-Seidel when it
/// converges fast (the paper's choice, and the cheapest per sweep), a dense LU when ρ(ρF) is
/// near 1 and N is small enough, SOR when N is too large for the LU. Rows above 1 are scaled
/// back to 1 first (see [`System::conserving`]).
pub fn choose(d: &Diagnosis) -> Choice {
    let mut why = format!(
        "{} patches, spectral radius of ρF in [{:.4}, {:.4}], {} rows of F above 1 (largest sum {:.7})",
        d.patches, d.radius_low, d.radius_high, d.rows_above_one, d.max_row_sum
    );
    let conserve = d.rows_above_one > 0;
    if conserve {
        why += "; a row cannot exceed 1 (sampling and f32 rounding of pass 1): scaled back to 1";
    }
    let solver = if d.radius_high < SLOW_RADIUS {
        why += &format!(
            "; below {SLOW_RADIUS}, Gauss-Seidel converges in about {} sweeps",
            d.sweeps_estimate(1e-9)
        );
        Solver::GaussSeidel
    } else if direct::AVAILABLE && d.patches <= DIRECT_LIMIT {
        why += &format!(
            "; near 1, Gauss-Seidel would need about {} sweeps: a dense LU ({} ≤ {DIRECT_LIMIT} patches) instead",
            d.sweeps_estimate(1e-9),
            d.patches
        );
        Solver::Direct
    } else {
        why += &match direct::AVAILABLE {
            true => {
                format!("; near 1 and too large for a dense LU (> {DIRECT_LIMIT} patches): SOR")
            }
            false => "; near 1, and this build has no dense LU (the `faer` feature): SOR".into(),
        };
        Solver::Sor
    };
    Choice {
        solver,
        conserve,
        why,
    }
}

/// Solves `system` with `solver` (never [`Solver::Progressive`] here: it takes rows, see
/// [`progressive`]; [`Solver::Auto`] diagnoses and picks, and falls back to the direct solve
/// if an iterative one fails and N allows). `note` receives what auto decided.
pub fn solve(
    system: &System<'_>,
    solver: Solver,
    settings: &SolveSettings,
    note: &mut dyn FnMut(&str),
) -> Result<Solution> {
    match solver {
        Solver::GaussSeidel => gauss_seidel::solve(system, settings),
        Solver::Sor => {
            let d = diagnose(system);
            sor::sor(system, sor::omega_for(d.radius_high), settings)
        }
        Solver::Jacobi => sor::jacobi(system, settings),
        Solver::Direct => direct::solve(system),
        Solver::Progressive => progressive::solve_matrix(system, None, settings),
        Solver::Auto => {
            let d = diagnose(system);
            let choice = choose(&d);
            note(&format!("solver auto: {}", choice.why));
            let conserved;
            let sys = if choice.conserve {
                conserved = system.conserving().0;
                System {
                    f: [&conserved[0], &conserved[1], &conserved[2]],
                    ..*system
                }
            } else {
                *system
            };
            let first = match choice.solver {
                Solver::Direct => direct::solve(&sys),
                Solver::Sor => sor::sor(&sys, sor::omega_for(d.radius_high), settings),
                _ => gauss_seidel::solve(&sys, settings),
            };
            match first {
                Ok(s) => Ok(s),
                Err(e)
                    if direct::AVAILABLE
                        && choice.solver != Solver::Direct
                        && sys.len() <= DIRECT_LIMIT =>
                {
                    note(&format!(
                        "solver auto: {} failed ({e}); falling back to the dense LU",
                        choice.solver.name()
                    ));
                    direct::solve(&sys)
                }
                Err(e) => Err(e),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed "furnace" of n patches that all see each other equally: F_ij = 1/(n−1), j ≠ i.
    pub(crate) fn furnace(n: usize, scale: f64) -> crate::matrix::FormMatrix {
        let dense: Vec<Vec<f64>> = (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| if i == j { 0.0 } else { scale / (n - 1) as f64 })
                    .collect()
            })
            .collect();
        dense.into()
    }

    #[test]
    fn auto_picks_gauss_seidel_for_a_dark_room_and_direct_for_a_white_one() {
        let f = furnace(6, 1.0);
        let e = vec![[1.0; 3]; 6];
        let dark = vec![[0.5; 3]; 6];
        let white = vec![[0.99; 3]; 6];
        let d = diagnose(&System::new(grey(&f), &dark, &e).unwrap());
        assert_eq!(choose(&d).solver, Solver::GaussSeidel, "{d:?}");
        let d = diagnose(&System::new(grey(&f), &white, &e).unwrap());
        let near_one = if direct::AVAILABLE {
            Solver::Direct
        } else {
            Solver::Sor
        };
        assert_eq!(choose(&d).solver, near_one, "{d:?}");
    }

    #[test]
    fn every_solver_meets_the_furnace_closed_form() {
        // B = E / (1 − ρ) in a closed box where all rows sum to 1
        let f = furnace(8, 1.0);
        let e = vec![[1.0, 0.5, 0.25]; 8];
        let rho = vec![[0.9, 0.95, 0.8]; 8];
        let sys = System::new(grey(&f), &rho, &e).unwrap();
        for solver in [
            Solver::Auto,
            Solver::GaussSeidel,
            Solver::Sor,
            Solver::Jacobi,
            Solver::Direct,
            Solver::Progressive,
        ]
        .into_iter()
        .filter(|s| *s != Solver::Direct || direct::AVAILABLE)
        {
            let s = solve(&sys, solver, &SolveSettings::default(), &mut |_| {}).unwrap();
            for b in &s.radiosity {
                for c in 0..3 {
                    let want = e[0][c] / (1.0 - rho[0][c]);
                    assert!(
                        (b[c] - want).abs() < 1e-6 * want,
                        "{solver:?} channel {c}: {} vs {want}",
                        b[c]
                    );
                }
            }
        }
    }

    #[test]
    fn rows_above_one_are_scaled_back_by_auto() {
        // 2 % oversampled rows with ρ = 0.99: ρ ΣF = 1.0098 — no positive solution exists, and
        // the iteration grows without bound; auto scales the rows back and meets E/(1−ρ).
        let f = furnace(5, 1.02);
        let e = vec![[1.0; 3]; 5];
        let rho = vec![[0.99; 3]; 5];
        let sys = System::new(grey(&f), &rho, &e).unwrap();
        let err = gauss_seidel::solve(&sys, &SolveSettings::default()).unwrap_err();
        assert!(format!("{err}").contains("diverge"), "{err}");
        let mut said = String::new();
        let s = solve(&sys, Solver::Auto, &SolveSettings::default(), &mut |m| {
            said += m
        })
        .unwrap();
        assert!(said.contains("scaled back"), "{said}");
        assert!(
            (s.radiosity[0][0] - 100.0).abs() < 1e-6,
            "{:?}",
            s.radiosity[0]
        );
    }
}
