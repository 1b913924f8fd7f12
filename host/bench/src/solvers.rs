//! `hemi bench solvers`: the solvers' convergence (residual against work) on the Cornell box and
//! on a closed ρ = 0.99 furnace, the regime where Gauss-Seidel crawls (docs/PERFORMANCE.md).

use crate::chart::{log_log, Series};
use anyhow::Result;
use hemi::pass1::form_factors;
use hemi::scene::Scene;
use hemi::settings::Pass1Settings;
use hemi::solve::{
    diagnose, direct, gauss_seidel, progressive, sor, SceneParts, Solution, SolveSettings, System,
};
use std::io::Write;
use std::path::Path;
use std::time::Instant;

/// A closed box `[0,1]³` of 6·n² inward quads, every one emitting 1 and reflecting `rho`: the
/// furnace, whose radiosity is E/(1−ρ) everywhere when F's rows sum to 1.
pub fn furnace_scene(n: usize, rho: f64) -> String {
    let mut s = format!(
        "[[material]]\nname = \"m\"\ndiffuse = [{rho}, {rho}, {rho}]\nemission = [1, 1, 1]\n\n"
    );
    let faces = [
        (0usize, 0.0, 1.0),
        (0, 1.0, -1.0),
        (1, 0.0, 1.0),
        (1, 1.0, -1.0),
        (2, 0.0, 1.0),
        (2, 1.0, -1.0),
    ];
    for (f, &(axis, value, sign)) in faces.iter().enumerate() {
        let (a1, a2) = ((axis + 1) % 3, (axis + 2) % 3);
        for i in 0..n {
            for j in 0..n {
                let corner = |di: usize, dj: usize| {
                    let mut p = [0.0; 3];
                    p[axis] = value;
                    p[a1] = (i + di) as f64 / n as f64;
                    p[a2] = (j + dj) as f64 / n as f64;
                    p
                };
                let v = if sign > 0.0 {
                    [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)]
                } else {
                    [corner(0, 0), corner(0, 1), corner(1, 1), corner(1, 0)]
                };
                let vs: Vec<String> = v
                    .iter()
                    .map(|p| format!("[{}, {}, {}]", p[0], p[1], p[2]))
                    .collect();
                s += &format!(
                    "[[quad]]\nname = \"f{f}_{i}_{j}\"\nmaterial = \"m\"\nvertices = [{}]\n\n",
                    vs.join(", ")
                );
            }
        }
    }
    s
}

struct Run {
    name: String,
    sol: Result<Solution>,
    secs: f64,
    /// Work per history entry, in sweep equivalents (3N² multiply-adds).
    work_per_step: f64,
    /// Work before the first entry (the LU's factorisation).
    work_fixed: f64,
}

fn runs(system: &System<'_>, areas: &[f64], settings: &SolveSettings) -> Vec<Run> {
    let n = system.len() as f64;
    let d = diagnose(system);
    let omega = sor::omega_for(d.radius_high);
    let time = |f: &dyn Fn() -> Result<Solution>| {
        let t0 = Instant::now();
        let s = f();
        (s, t0.elapsed().as_secs_f64())
    };
    let mut out = Vec::new();
    let (sol, secs) = time(&|| gauss_seidel::solve(system, settings));
    out.push(Run {
        name: "Gauss-Seidel".into(),
        sol,
        secs,
        work_per_step: 1.0,
        work_fixed: 0.0,
    });
    let (sol, secs) = time(&|| sor::sor(system, omega, settings));
    out.push(Run {
        name: format!("SOR ω = {omega:.3}"),
        sol,
        secs,
        work_per_step: 1.0,
        work_fixed: 0.0,
    });
    let (sol, secs) = time(&|| sor::jacobi(system, settings));
    out.push(Run {
        name: "Jacobi".into(),
        sol,
        secs,
        work_per_step: 1.0,
        work_fixed: 0.0,
    });
    let (sol, secs) = time(&|| progressive::solve_matrix(system, Some(areas), settings));
    out.push(Run {
        name: "progressive (shots / N)".into(),
        sol,
        secs,
        work_per_step: 1.0 / n,
        work_fixed: 0.0,
    });
    let (sol, secs) = time(&|| direct::solve(system));
    // LU: N³/3 multiply-adds per factorisation (one for a grey system)
    let groups = if system.is_grey() { 1.0 } else { 3.0 };
    out.push(Run {
        name: "dense LU (faer)".into(),
        sol,
        secs,
        work_per_step: 0.0,
        work_fixed: groups * n * n * n / 3.0 / (3.0 * n * n),
    });
    out
}

fn table(
    out: &mut impl Write,
    label: &str,
    system: &System<'_>,
    runs: &[Run],
    closed_form: Option<f64>,
) -> Result<Series2> {
    let d = diagnose(system);
    writeln!(
        out,
        "\n{label}: {} patches, spectral radius of ρF in [{:.4}, {:.4}], largest row sum {:.6}; auto picks {}\n",
        d.patches,
        d.radius_low,
        d.radius_high,
        d.max_row_sum,
        hemi::solve::choose(&d).solver.name()
    )?;
    writeln!(out, "| solver | iterations | work (sweeps) | seconds | final residual | max |B − B_LU| / B_LU |{}", if closed_form.is_some() { " max |B − E/(1−ρ)| / (E/(1−ρ)) |" } else { "" })?;
    writeln!(
        out,
        "|---|---|---|---|---|---|{}",
        if closed_form.is_some() { "---|" } else { "" }
    )?;
    let reference = runs
        .iter()
        .find(|r| r.name.starts_with("dense"))
        .and_then(|r| r.sol.as_ref().ok())
        .map(|s| s.radiosity.clone());
    let mut series = Vec::new();
    for r in runs {
        match &r.sol {
            Ok(s) => {
                let dev = reference.as_ref().map_or(f64::NAN, |b| {
                    s.radiosity
                        .iter()
                        .zip(b)
                        .flat_map(|(x, y)| {
                            (0..3).map(move |c| (x[c] - y[c]).abs() / y[c].abs().max(1e-300))
                        })
                        .fold(0.0, f64::max)
                });
                let work = r.work_fixed + r.work_per_step * s.iterations as f64;
                let cf = closed_form.map(|want| {
                    s.radiosity
                        .iter()
                        .flat_map(|b| b.iter())
                        .map(|x| (x - want).abs() / want)
                        .fold(0.0, f64::max)
                });
                writeln!(
                    out,
                    "| {} | {} | {:.1} | {:.5} | {:.2e} | {:.2e} |{}",
                    r.name,
                    s.iterations,
                    work,
                    r.secs,
                    s.residual,
                    dev,
                    cf.map_or(String::new(), |e| format!(" {e:.2e} |"))
                )?;
                // about 40 points per decade of work at most: log-spaced entries
                let keep = |k: usize| {
                    let f = (k + 1) as f64;
                    k + 1 == s.history.len()
                        || (f.log10() * 40.0).floor() != ((f + 1.0).log10() * 40.0).floor()
                };
                let points = s
                    .history
                    .iter()
                    .enumerate()
                    .filter(|(k, _)| keep(*k))
                    .map(|(k, (_, res))| {
                        (
                            r.work_fixed + r.work_per_step * (k + 1) as f64,
                            res.max(1e-17),
                        )
                    })
                    .collect();
                series.push(Series {
                    name: r.name.clone(),
                    points,
                });
            }
            Err(e) => writeln!(out, "| {} | failed: {e} | | {:.5} | | |", r.name, r.secs)?,
        }
    }
    Ok(Series2(series))
}

struct Series2(Vec<Series>);

/// Runs every solver on the Cornell box `cornell` and on a 6·n² furnace at ρ = 0.99, prints
/// markdown tables and writes `solvers-cornell.svg` and `solvers-furnace.svg` into `svg_dir`.
pub fn bench_solvers(
    cornell: &Scene,
    settings: &Pass1Settings,
    furnace_n: usize,
    out: &mut impl Write,
    svg_dir: Option<&Path>,
) -> Result<()> {
    let solve_settings = SolveSettings {
        tolerance: 1e-12,
        max_iterations: 20_000,
    };
    let furnace = hemi::scene::parse(&furnace_scene(furnace_n, 0.99), "furnace.toml")?;
    for (label, file, scene, closed) in [
        ("Cornell box", "solvers-cornell.svg", cornell, None),
        (
            "furnace ρ = 0.99",
            "solvers-furnace.svg",
            &furnace,
            Some(100.0),
        ),
    ] {
        let ff = form_factors(&hemi::backend::soft(scene, settings)?, &|_| {})?;
        let n = scene.patches.len();
        let areas: Vec<f64> = scene.patches.iter().map(|p| p.area as f64).collect();
        let parts = SceneParts::new(scene, ff.channels());
        let system = parts.system(ff.channels())?;
        let rs = runs(&system, &areas, &solve_settings);
        let Series2(series) = table(out, label, &system, &rs, closed)?;
        if let Some(dir) = svg_dir {
            let chart = log_log(
                &format!("Solvers on the {label}: residual against work"),
                "work in sweeps (3N² multiply-adds; LU: N³/3 per factorisation)",
                "relative residual max|B − E − ρFB| / max|B|",
                &format!(
                    "{n} patches, F from pass 1 at R = {}, K = {}; LU residual is rounding; reference B: dense LU",
                    settings.circles, settings.samples
                ),
                &series,
            );
            std::fs::write(dir.join(file), chart)?;
        }
    }
    Ok(())
}
