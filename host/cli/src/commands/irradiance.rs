//! `hemi irradiance`: the solved field gathered at points read from stdin.

use crate::input::rays_from_stdin;
use crate::options::{AdaptiveArgs, EngineArgs, FieldArgs, QualityArgs, SamplingArgs, SolverArgs};
use crate::pipeline;
use anyhow::Result;
use clap::Args;
use hemi::backend::Query;
use std::io::Write;
use std::path::PathBuf;

/// Irradiance at points read from stdin (`x y z dx dy dz` per line, the convention of
/// Radiance's `rtrace -I`), printed `r g b`.
#[derive(Args)]
pub struct IrradianceArgs {
    /// The scene file (TOML; OBJ/MTL and BPT geometry may be included from it).
    scene: PathBuf,
    #[command(flatten)]
    engine: EngineArgs,
    #[command(flatten)]
    sampling: SamplingArgs,
    #[command(flatten)]
    quality: QualityArgs,
    #[command(flatten)]
    adaptive: AdaptiveArgs,
    #[command(flatten)]
    solver: SolverArgs,
    #[command(flatten)]
    field: FieldArgs,
}

/// Runs `hemi irradiance`, writing to `out`.
pub fn run(args: IrradianceArgs, out: &mut impl Write) -> Result<()> {
    let adaptive = args.adaptive.adaptive;
    let choice = args.engine.check()?;
    let checked = args.sampling.settings(adaptive)?;
    let scene = hemi::scene::load(&args.scene)?;
    let settings = args.quality.for_scene(checked, &scene, adaptive);
    let engine = choice.open(&args.engine.model, &args.engine.boards)?;
    let backend = engine.backend(&scene, &settings)?;
    let stats = args.engine.boards.board_stats;
    let q = args.quality.quality;
    let solved = pipeline::solve(
        &backend,
        &args.adaptive,
        q,
        &args.solver,
        stats,
        Some(args.field.settings()?),
    )?;
    let (rays, bad_line) = rays_from_stdin();
    let queries: Vec<Query> = rays
        .into_iter()
        .map(|(point, normal)| Query { point, normal })
        .collect();
    for e in hemi::irradiance::irradiance(backend.get(), &solved.grids, &queries)? {
        writeln!(out, "{:.6e} {:.6e} {:.6e}", e[0], e[1], e[2])?;
    }
    backend.board_report(stats, "after the queries");
    if let Some(e) = bad_line {
        return Err(e);
    }
    backend.report_model(
        solved.hemispheres,
        args.engine.model.clock_mhz,
        "pass 1 and queries",
    );
    Ok(())
}
