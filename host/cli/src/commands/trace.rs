//! `hemi trace`: the nearest hit of rays read from stdin.

use crate::input::serve;
use crate::options::{EngineArgs, LimitArgs};
use anyhow::Result;
use clap::Args;
use hemi::settings::Pass1Settings;
use hemi_kernel::accel::Ray;
use std::io::Write;
use std::path::PathBuf;

/// Nearest hit of rays read from stdin (`x y z dx dy dz`): `t patch u v` or `miss`.
#[derive(Args)]
pub struct TraceArgs {
    /// The scene file (TOML; OBJ/MTL and BPT geometry may be included from it).
    scene: PathBuf,
    #[command(flatten)]
    engine: EngineArgs,
    #[command(flatten)]
    limits: LimitArgs,
}

/// The hemisphere a backend for single rays is made with: it casts none, so the smallest
/// table any board holds.
const CIRCLES: u32 = 8;

/// Runs `hemi trace`, writing to `out` each answer as soon as its line is read.
pub fn run(args: TraceArgs, out: &mut impl Write) -> Result<()> {
    let choice = args.engine.check()?;
    choice.warn_unused(&args.engine.model);
    let scene = args.limits.load(&args.scene)?;
    let engine = choice.open(&args.engine.model, &args.engine.boards)?;
    let settings = Pass1Settings {
        circles: CIRCLES,
        ..Pass1Settings::default()
    };
    let backend = engine.backend(&scene, &settings)?;
    let stdin = std::io::BufReader::new(std::io::stdin());
    // a zero direction is rtrace's request for a flush: it has no hit
    let reach = hemi::scene::range::Reach::of(&scene);
    let answered = serve(stdin, out, "miss", reach, |rays, out| {
        let rays: Vec<Ray> = rays
            .iter()
            .map(|&(origin, dir)| Ray { origin, dir })
            .collect();
        for hit in backend.get().nearest(&rays)? {
            match hit {
                Some(h) => {
                    let name = &scene.patches[h.patch as usize].name;
                    writeln!(out, "{} {name} {} {}", h.t, h.u, h.v)?
                }
                None => writeln!(out, "miss")?,
            }
        }
        Ok(())
    });
    backend.board_report(args.engine.boards.board_stats, "after the rays");
    answered?;
    backend.report_model(0, args.engine.model.clock_mhz, "trace");
    Ok(())
}
