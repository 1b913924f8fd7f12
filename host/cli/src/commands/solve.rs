//! `hemi solve`: pass 1 and the solve, the radiosity per patch.

use crate::options::{FieldArgs, SolverArgs};
use crate::output::{export_path, not_the_input};
use crate::pipeline::{RunArgs, Solved};
use anyhow::Result;
use clap::Args;
use hemi::scene::Scene;
use std::io::Write;
use std::path::PathBuf;

/// Pass 1 and the solve: radiosity per patch, and the solution as meshes for viewers.
#[derive(Args)]
pub struct SolveArgs {
    #[command(flatten)]
    run: RunArgs,
    /// Print JSON: `{"patches": [{"name", "radiosity"}…], "iterations", "residual"}`.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    solver: SolverArgs,
    /// Also write every patch's radiosity grid as a mesh to this PLY file: per vertex the
    /// radiosity (float properties radiosity_r/g/b, W/m²) and an sRGB colour (MeshLab, Blender).
    #[arg(long, value_name = "OUT.ply")]
    ply: Option<PathBuf>,
    /// Also write the meshes of --ply as binary glTF: per vertex COLOR_0 and the attribute
    /// _RADIOSITY, an unlit material, one node per patch (Blender, any glTF viewer).
    #[arg(long, value_name = "OUT.glb")]
    gltf: Option<PathBuf>,
    /// Exposure in stops of the exported vertex colours (default: automatic, as `render`).
    #[arg(long, allow_hyphen_values = true)]
    exposure: Option<f64>,
    // the field exported with --ply/--gltf (the printed patch radiosities do not depend on it)
    #[command(flatten)]
    field: FieldArgs,
}

/// Runs `hemi solve`, writing to `out`.
pub fn run(args: SolveArgs, out: &mut impl Write) -> Result<()> {
    let export = args.ply.is_some() || args.gltf.is_some();
    if let Some(p) = &args.ply {
        export_path(p, "--ply", &["ply"])?;
        not_the_input(p, "--ply", &args.run.scene)?;
    }
    if let Some(p) = &args.gltf {
        export_path(p, "--gltf", &["glb"])?;
        not_the_input(p, "--gltf", &args.run.scene)?;
    }
    anyhow::ensure!(
        args.exposure.is_none_or(f64::is_finite),
        "--exposure must be a finite number of stops"
    );
    let field = match export {
        true => Some(args.field.settings()?),
        false => None,
    };
    let run = args.run.prepare(|_| Ok(()))?;
    let (scene, settings) = (&run.scene, &run.settings);
    let backend = run.engine.backend(scene, settings)?;
    let solved = args.run.solve(&backend, &args.solver, field)?;
    if export {
        write_meshes(&args, scene, &solved)?;
    }
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
        let (s, rays) = (&solved.stats.specular, solved.stats.rays);
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

/// The meshes of the solved field to the files of `--ply` and `--gltf`.
fn write_meshes(args: &SolveArgs, scene: &Scene, solved: &Solved) -> Result<()> {
    let meshes = hemi::export::meshes(scene, &solved.grids)?;
    let ev = args
        .exposure
        .unwrap_or_else(|| hemi::export::auto_exposure(&meshes));
    let vertices: usize = meshes.iter().map(|m| m.positions.len()).sum();
    let triangles: usize = meshes.iter().map(|m| m.triangles.len()).sum();
    let files = [
        (&args.ply, hemi::export::write_ply as hemi::export::Writer),
        (&args.gltf, hemi::export::write_glb),
    ];
    for (path, write) in files {
        if let Some(path) = path {
            hemi::export::write_file(path, &meshes, ev, write)?;
            eprintln!(
                "{} patches, {vertices} vertices, {triangles} triangles, colours at {ev:+.2} EV \
                 -> {}",
                meshes.len(),
                path.display()
            );
        }
    }
    Ok(())
}
