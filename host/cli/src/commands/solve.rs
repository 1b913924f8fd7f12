//! `hemi solve`: pass 1 and the solve, the radiosity per patch.

use crate::options::SolverArgs;
use crate::pipeline::RunArgs;
use anyhow::Result;
use clap::Args;
use std::io::Write;

/// Pass 1 and the solve: radiosity per patch.
#[derive(Args)]
pub struct SolveArgs {
    #[command(flatten)]
    run: RunArgs,
    /// Print JSON: `{"patches": [{"name", "radiosity"}…], "iterations", "residual"}`.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    solver: SolverArgs,
}

/// Runs `hemi solve`, writing to `out`.
pub fn run(args: SolveArgs, out: &mut impl Write) -> Result<()> {
    let run = args.run.prepare(|_| Ok(()))?;
    let (scene, settings) = (&run.scene, &run.settings);
    let backend = run.engine.backend(scene, settings)?;
    let solved = args.run.solve(&backend, &args.solver, None)?;
    let sol = &solved.solution;
    if args.json {
        let patches: Vec<_> = scene
            .patches
            .iter()
            .zip(&sol.radiosity)
            .map(|(p, b)| serde_json::json!({"name": p.name, "radiosity": b}))
            .collect();
        let json = serde_json::json!({"patches": patches, "iterations": sol.iterations, "residual": sol.residual});
        serde_json::to_writer(&mut *out, &json)?;
        writeln!(out)?;
    } else {
        for (p, b) in scene.patches.iter().zip(&sol.radiosity) {
            writeln!(out, "{:<16} {:.6} {:.6} {:.6}", p.name, b[0], b[1], b[2])?;
        }
        let name = sol.solver.name();
        eprintln!(
            "{name}: {} iterations, residual {:.2e}",
            sol.iterations, sol.residual
        );
    }
    if solved.stats.specular.frustums > 0 {
        let (s, rays) = (&solved.stats.specular, solved.stats.rays as u64);
        eprintln!(
            "{}",
            hemi::optics::describe("specular", s, rays, &settings.specular)
        );
    }
    backend.report_model(
        solved.hemispheres,
        args.run.engine.model.clock_mhz,
        "pass 1",
    );
    Ok(())
}
