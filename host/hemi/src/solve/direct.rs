//! A dense direct solve of (2.6): `(I − diag(ρ) F) B = E` by LU with partial pivoting (faer).
//!
//! It costs 2N³/3 flops per distinct matrix (one for grey scenes, three when coloured mirrors
//! make F differ per channel) and N² f64 of memory, whatever ρ(ρF) is: the remedy for ρ near 1
//! on small and medium scenes, and the reference the iterative solvers are charted against.
//!
//! The LU is faer's, behind the `faer` feature (on by default): faer is most of a first build's
//! compile time, so a build can leave it out, and then [`AVAILABLE`] is false, auto never picks
//! this solver and asking for it is an error.

use super::{Solution, System};
use anyhow::Result;
#[cfg(feature = "faer")]
use {super::Solver, faer::prelude::*, faer::Mat, std::time::Instant};

/// Whether this build has the dense LU (hemi's `faer` feature).
pub const AVAILABLE: bool = cfg!(feature = "faer");

/// Without the `faer` feature: the error that says how to get the dense LU.
#[cfg(not(feature = "faer"))]
pub fn solve(_: &System<'_>) -> Result<Solution> {
    anyhow::bail!(
        "--solver direct: this hemi was built without its dense LU (the `faer` feature); \
         rebuild with default features, or choose another solver"
    )
}

/// Solves `system` exactly (to rounding). `iterations` is 1: one factorisation.
#[cfg(feature = "faer")]
pub fn solve(system: &System<'_>) -> Result<Solution> {
    let t0 = Instant::now();
    let n = system.len();
    let mut radiosity = vec![[0.0f64; 3]; n];
    // With one F and one ρ for all channels a single factorisation serves the three right-hand
    // sides; otherwise one per channel.
    let shared = system.is_grey() && system.rho.iter().all(|r| r[0] == r[1] && r[1] == r[2]);
    let groups: Vec<Vec<usize>> = if shared {
        vec![vec![0, 1, 2]]
    } else {
        vec![vec![0], vec![1], vec![2]]
    };
    for cs in groups {
        let c0 = cs[0];
        let mut a = Mat::<f64>::identity(n, n);
        for (i, row) in system.f[c0].iter().enumerate() {
            for (j, fij) in row.entries() {
                a[(i, j)] -= system.rho[i][c0] * fij;
            }
        }
        let lu = a.partial_piv_lu();
        let mut rhs = Mat::<f64>::from_fn(n, cs.len(), |i, k| system.e[i][cs[k]]);
        lu.solve_in_place(&mut rhs);
        for (k, &c) in cs.iter().enumerate() {
            for (i, b) in radiosity.iter_mut().enumerate() {
                b[c] = rhs[(i, k)];
            }
        }
    }
    anyhow::ensure!(
        radiosity.iter().flatten().all(|x| x.is_finite()),
        "the dense solve gave non-finite radiosity: I − ρF is singular (a closed scene with ρ = 1?)"
    );
    let residual = system.residual(&radiosity);
    Ok(Solution {
        radiosity,
        iterations: 1,
        residual,
        solver: Solver::Direct,
        history: vec![(t0.elapsed().as_secs_f64(), residual)],
    })
}

#[cfg(all(test, feature = "faer"))]
mod tests {
    use super::super::grey;
    use super::*;

    #[test]
    fn two_patch_closed_form_per_channel() {
        let f = vec![vec![0.0, 0.4], vec![0.3, 0.0]].into();
        let rho = vec![[0.5, 0.6, 0.7], [0.8, 0.1, 0.2]];
        let e = vec![[1.0, 2.0, 0.5], [0.0; 3]];
        let s = solve(&System::new(grey(&f), &rho, &e).unwrap()).unwrap();
        for c in 0..3 {
            let b0 = e[0][c] / (1.0 - rho[0][c] * 0.4 * rho[1][c] * 0.3);
            assert!((s.radiosity[0][c] - b0).abs() < 1e-12);
            assert!((s.radiosity[1][c] - rho[1][c] * 0.3 * b0).abs() < 1e-12);
        }
        assert!(s.residual < 1e-14);
    }
}
