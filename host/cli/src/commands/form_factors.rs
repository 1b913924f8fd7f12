//! `hemi form-factors`: pass 1 alone, the patch form factors F_ij.

use crate::pipeline::{self, RunArgs};
use anyhow::Result;
use clap::Args;
use std::io::Write;

/// Pass-1 form factors between the scene's patches.
#[derive(Args)]
pub struct FormFactorsArgs {
    #[command(flatten)]
    run: RunArgs,
    /// Print JSON: `{"patches": [{"name", "area"}…], "matrix": [[F_ij…]…]}`.
    #[arg(long)]
    json: bool,
    /// Memory pass 1's form factors may take, in MiB (element rows and sparse patch rows;
    /// estimated from a pilot of hemispheres when the dense bound passes it).
    #[arg(long, default_value_t = 4096, value_name = "MIB")]
    matrix_mib: u64,
}

/// Runs `hemi form-factors`, writing to `out`.
pub fn run(args: FormFactorsArgs, out: &mut impl Write) -> Result<()> {
    let run = args.run.prepare(|_| Ok(()))?;
    let (scene, settings) = (&run.scene, &run.settings);
    let backend = run.engine.backend(scene, settings)?;
    crate::options::check_matrix(backend.get(), args.matrix_mib, "form-factors", "")?;
    let stats = args.run.engine.boards.board_stats;
    let adaptive = args
        .run
        .adaptive
        .settings(args.run.quality.quality, settings.samples)?;
    let limit = args.matrix_mib.saturating_mul(1 << 20);
    let (ff, _) = pipeline::sample(&backend, adaptive, stats, limit)?;
    if args.json {
        let patches: Vec<_> = scene
            .patches
            .iter()
            .map(|p| serde_json::json!({"name": p.name, "area": p.area}))
            .collect();
        // {"matrix": […], "patches": […]}, the matrix streamed row by row (no dense copy)
        write!(out, "{{\"matrix\":")?;
        serde_json::to_writer(&mut *out, &ff.matrix)?;
        write!(out, ",\"patches\":")?;
        serde_json::to_writer(&mut *out, &patches)?;
        writeln!(out, "}}")?;
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
        let rays = ff.stats.rays;
        let line = hemi::optics::describe("specular", &ff.stats.specular, rays, &settings.specular);
        eprintln!("{line}");
    }
    let hemispheres = ff.elements.len() as u64;
    backend.report_model(hemispheres, args.run.engine.model.clock_mhz, "pass 1");
    Ok(())
}
