//! The radiosity system (2.6), `B = E + ρ F B` per channel, solved by Gauss-Seidel (paper §6.4).

use anyhow::{bail, Result};

/// Result of a solve.
#[derive(Clone, Debug)]
pub struct Solution {
    /// Radiosity B per patch and channel.
    pub radiosity: Vec<[f64; 3]>,
    /// Gauss-Seidel sweeps done.
    pub iterations: u32,
    /// Final residual max |B − E − ρFB| / max |B|.
    pub residual: f64,
}

/// Solver settings.
#[derive(Clone, Copy, Debug)]
pub struct SolveSettings {
    /// Stop when the relative residual falls below this.
    pub tolerance: f64,
    /// Give up after this many sweeps.
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

/// Form factors per channel: `f[c][i][j]`. Without coloured mirrors the three are one matrix
/// ([`grey`]); with them, indirect form factors S_ij differ per channel (paper §3.3).
pub type Channels<'a> = [&'a [Vec<f64>]; 3];

/// The same matrix for every channel.
pub fn grey(f: &[Vec<f64>]) -> Channels<'_> {
    [f, f, f]
}

fn residual(f: Channels<'_>, rho: &[[f64; 3]], e: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    let mut worst = 0.0f64;
    let mut scale = 0.0f64;
    for i in 0..b.len() {
        for c in 0..3 {
            let gathered: f64 = f[c][i].iter().zip(b).map(|(fij, bj)| fij * bj[c]).sum();
            let r = b[i][c] - e[i][c] - rho[i][c] * gathered;
            worst = worst.max(r.abs());
            scale = scale.max(b[i][c].abs());
        }
    }
    if scale > 0.0 {
        worst / scale
    } else {
        worst
    }
}

/// Solves `B_i = E_i + ρ_i Σ_j F_ij B_j` for every channel by Gauss-Seidel sweeps, stopping on
/// the relative residual. Divergence (the residual grows for 20 sweeps in a row, or goes
/// non-finite) and stagnation (no tenfold drop in 2000 sweeps) are errors that say so.
pub fn gauss_seidel(
    f: Channels<'_>,
    rho: &[[f64; 3]],
    e: &[[f64; 3]],
    settings: &SolveSettings,
) -> Result<Solution> {
    let n = e.len();
    anyhow::ensure!(
        rho.len() == n
            && f.iter()
                .all(|m| m.len() == n && m.iter().all(|r| r.len() == n)),
        "the system's sizes disagree: {n} emissions, {} reflectances, an F that is not {n}×{n}",
        rho.len()
    );
    let mut b: Vec<[f64; 3]> = e.to_vec();
    let mut last = f64::INFINITY;
    let mut growing = 0;
    let mut checkpoint = (0u32, f64::INFINITY);
    for it in 1..=settings.max_iterations {
        for i in 0..n {
            for c in 0..3 {
                let mut gathered = 0.0;
                for (j, fij) in f[c][i].iter().enumerate() {
                    if j != i {
                        gathered += fij * b[j][c];
                    }
                }
                let denom = 1.0 - rho[i][c] * f[c][i][i];
                b[i][c] = (e[i][c] + rho[i][c] * gathered) / denom;
            }
        }
        let r = residual(f, rho, e, &b);
        if !r.is_finite() {
            bail!("Gauss-Seidel diverged at sweep {it}: the residual is not finite (is ρ·ΣF ≥ 1 for some patch?)");
        }
        if r <= settings.tolerance {
            return Ok(Solution {
                radiosity: b,
                iterations: it,
                residual: r,
            });
        }
        growing = if r > last { growing + 1 } else { 0 };
        if growing >= 20 {
            bail!("Gauss-Seidel diverges: the residual grew for 20 sweeps in a row (now {r:.3e}); rows with ρ·ΣF ≥ 1 make the system unsolvable by iteration");
        }
        last = r;
        if it - checkpoint.0 >= 2000 {
            if r > 0.1 * checkpoint.1 {
                bail!("Gauss-Seidel stagnates: residual {r:.3e} after {it} sweeps fell less than tenfold in the last 2000 (ρ close to 1?)");
            }
            checkpoint = (it, r);
        }
    }
    bail!(
        "Gauss-Seidel did not reach the tolerance {:.1e} in {} sweeps (residual {last:.3e})",
        settings.tolerance,
        settings.max_iterations
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_patch_system_matches_closed_form() {
        // B0 = 1 + 0.5·0.4·B1, B1 = 0 + 0.8·0.3·B0
        let f = vec![vec![0.0, 0.4], vec![0.3, 0.0]];
        let rho = vec![[0.5; 3], [0.8; 3]];
        let e = vec![[1.0; 3], [0.0; 3]];
        let s = gauss_seidel(grey(&f), &rho, &e, &SolveSettings::default()).unwrap();
        let b0 = 1.0 / (1.0 - 0.5 * 0.4 * 0.8 * 0.3);
        assert!((s.radiosity[0][0] - b0).abs() < 1e-9);
        assert!((s.radiosity[1][0] - 0.24 * b0).abs() < 1e-9);
        assert!(s.residual <= 1e-9);
    }

    #[test]
    fn divergence_is_reported() {
        let f = vec![vec![0.0, 1.0], vec![1.0, 0.0]];
        let rho = vec![[1.5; 3], [1.5; 3]];
        let e = vec![[1.0; 3], [0.0; 3]];
        let err = gauss_seidel(grey(&f), &rho, &e, &SolveSettings::default()).unwrap_err();
        assert!(format!("{err}").contains("diverge"), "{err}");
    }
}
