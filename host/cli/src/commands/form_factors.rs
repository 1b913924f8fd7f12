//! `hemi form-factors`: pass 1 alone, the patch form factors F_ij.

use crate::options::{AdaptiveArgs, EngineArgs, QualityArgs, SamplingArgs};
use crate::pipeline;
use anyhow::Result;
use clap::Args;
use std::io::Write;
use std::path::PathBuf;

/// Pass-1 form factors between the scene's patches.
#[derive(Args)]
pub struct FormFactorsArgs {
    /// The scene file (TOML; OBJ/MTL and BPT geometry may be included from it).
    scene: PathBuf,
    /// Print JSON: `{"patches": [{"name", "area"}…], "matrix": [[F_ij…]…]}`.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    engine: EngineArgs,
    #[command(flatten)]
    sampling: SamplingArgs,
    #[command(flatten)]
    quality: QualityArgs,
    #[command(flatten)]
    adaptive: AdaptiveArgs,
}

/// Runs `hemi form-factors`, writing to `out`.
pub fn run(args: FormFactorsArgs, out: &mut impl Write) -> Result<()> {
    let adaptive = args.adaptive.adaptive;
    let choice = args.engine.check()?;
    let checked = args.sampling.settings(adaptive)?;
    let scene = hemi::scene::load(&args.scene)?;
    let settings = args.quality.for_scene(checked, &scene, adaptive);
    let engine = choice.open(&args.engine.model, &args.engine.boards)?;
    let backend = engine.backend(&scene, &settings)?;
    let stats = args.engine.boards.board_stats;
    let adaptive = args.adaptive.settings(args.quality.quality)?;
    let (ff, _) = pipeline::sample(&backend, adaptive, stats)?;
    if args.json {
        let patches: Vec<_> = scene
            .patches
            .iter()
            .map(|p| serde_json::json!({"name": p.name, "area": p.area}))
            .collect();
        let json = serde_json::json!({"patches": patches, "matrix": ff.matrix});
        serde_json::to_writer(&mut *out, &json)?;
        writeln!(out)?;
    } else {
        for (i, p) in scene.patches.iter().enumerate() {
            let sum: f64 = ff.matrix[i].iter().sum();
            write!(out, "{:<16} sum {:.6} |", p.name, sum)?;
            for f in &ff.matrix[i] {
                write!(out, " {f:.6}")?;
            }
            writeln!(out)?;
        }
        eprintln!("{} rays, {} elements", ff.stats.rays, ff.elements.len());
    }
    if ff.stats.specular.frustums > 0 {
        let rays = ff.stats.rays as u64;
        let line = hemi::optics::describe("specular", &ff.stats.specular, rays, &settings.specular);
        eprintln!("{line}");
    }
    let hemispheres = ff.elements.len() as u64;
    backend.report_model(hemispheres, args.engine.model.clock_mhz, "pass 1");
    Ok(())
}
