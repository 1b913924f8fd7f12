//! `hemi irradiance`: the solved field gathered at points read from stdin.

use crate::engine::Running;
use crate::input::serve;
use crate::options::{FieldArgs, SolverArgs, MOST_CIRCLES};
use crate::pipeline::{Prepared, RunArgs};
use anyhow::Result;
use clap::Args;
use hemi::backend::Query;
use hemi::direct::{applies as exact_direct_applies, Direct};
use hemi::irradiance::{Light, QuerySettings};
use hemi::settings::Pass1Settings;
use std::io::Write;

/// Irradiance at points read from stdin (`x y z dx dy dz` per line, the convention of
/// Radiance's `rtrace -I`), printed `r g b`.
#[derive(Args)]
pub struct IrradianceArgs {
    #[command(flatten)]
    run: RunArgs,
    #[command(flatten)]
    solver: SolverArgs,
    #[command(flatten)]
    field: FieldArgs,
    /// Where the lamps' direct light comes from: exact form factors to the emitting polygons
    /// (and to their images in perfect plane mirrors) with shadow rays, or the hemisphere's
    /// rays (as all other light). Exact needs single rays (boards of protocol 5 cast them) and a
    /// scene where nothing transmits specularly; elsewhere the hemisphere is used, said on
    /// stderr.
    #[arg(long, value_enum, default_value = "exact")]
    direct: DirectArg,
    /// Levels of near-field evaluation: hits within a few grid cells of a query point take the
    /// radiosity computed afresh at the hit (a query of its own, with one level less, whose
    /// near field reaches half as far) instead of the grid's, for corners and contact shadows;
    /// 0 reads every hit off the grids.
    #[arg(long, default_value_t = 4, value_name = "LEVELS")]
    near: u32,
    /// How close a hit must be to the point to be evaluated afresh, in cells of the grid it
    /// lands on (at the first level; each level below, half as close).
    #[arg(long, default_value_t = hemi::irradiance::near::NEAR, value_name = "CELLS")]
    near_cells: f32,
    /// Circles R of each query's own hemisphere (its near field's evaluations keep pass 1's):
    /// by default four times pass 1's, at most 1024, and on boards at most what they build (the
    /// boards are configured for it while they cast the queries' hemispheres).
    #[arg(long, value_name = "R")]
    query_circles: Option<u32>,
}

/// A query's own hemisphere against pass 1's R, by default. At the blocks' feet and in the
/// corners a point sees half its hemisphere at grazing angles within millimetres, and the
/// query's rays quantise that: against Radiance's 1,024-estimate references on the Cornell
/// box's 15 darkest points, with the default element budget, 4R gave RMS 0.26 %, worst
/// +0.60 %, where 2R gave 0.56 %, worst −1.48 % (docs/ACCURACY.md, "Four times the query's
/// circles").
const QUERY_CIRCLES: u32 = 4;

/// The most `--near` levels.
const MOST_NEAR: u32 = 8;

/// The widest near field, in grid cells (`--near-cells`): past a patch's few cells every hit
/// would be evaluated afresh.
const MOST_CELLS: f32 = 64.0;

/// Where a point query's direct light comes from.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
enum DirectArg {
    /// Exact form factors with shadow rays.
    Exact,
    /// The hemisphere's rays.
    Hemisphere,
}

/// Runs `hemi irradiance`, writing to `out` each answer as soon as its line is read.
pub fn run(args: IrradianceArgs, out: &mut impl Write) -> Result<()> {
    anyhow::ensure!(
        args.near <= MOST_NEAR,
        "--near {}: at most {MOST_NEAR} levels (each evaluates the near hits as queries of their \
         own, so a level multiplies a query's cost)",
        args.near
    );
    anyhow::ensure!(
        args.near_cells.is_finite() && args.near_cells > 0.0 && args.near_cells <= MOST_CELLS,
        "--near-cells {}: must be a number of grid cells in (0, {MOST_CELLS}]",
        args.near_cells
    );
    let field = args.field.settings()?;
    let run = args.run.prepare(|_| Ok(()))?;
    let backend = run.engine.backend(&run.scene, &run.settings)?;
    let own = own_backend(&args, &run)?;
    let solved = args.run.solve(&backend, &args.solver, Some(field))?;
    let direct = match args.direct {
        DirectArg::Exact if exact_direct_applies(backend.get()) => Direct::Exact,
        DirectArg::Exact => {
            eprintln!(
                "irradiance: direct light from the hemisphere (exact direct light needs single \
                 rays, which boards cast from protocol 5 on, and a scene where nothing transmits \
                 specularly)"
            );
            Direct::Hemisphere
        }
        DirectArg::Hemisphere => Direct::Hemisphere,
    };
    let settings = QuerySettings {
        direct,
        near_levels: args.near,
        near_cells: args.near_cells,
    };
    let stdin = std::io::BufReader::new(std::io::stdin());
    // a zero direction is rtrace's request for a flush, answered with a zero record
    let reach = hemi::scene::range::Reach::of(backend.get().scene());
    let mut asked = 0u64;
    let answered = serve(stdin, out, &rgb([0.0; 3]), reach, |rays, out| {
        asked += rays.len() as u64;
        let queries: Vec<Query> = rays
            .iter()
            .map(|&(point, normal)| Query { point, normal })
            .collect();
        let light = Light {
            grids: &solved.grids,
            direct: solved.direct.as_ref(),
        };
        let own = own.as_ref().map_or(backend.get(), |b| b.get());
        let answers =
            hemi::irradiance::irradiance_with(backend.get(), own, light, &queries, &settings)?;
        for e in answers {
            writeln!(out, "{}", rgb(e))?;
        }
        Ok(())
    });
    backend.board_report(args.run.engine.boards.board_stats, "after the queries");
    answered?;
    let clock = args.run.engine.model.clock_mhz;
    match &own {
        Some(own) => {
            backend.report_model(solved.hemispheres, clock, "pass 1 and the near fields");
            own.report_model(asked, clock, "the queries' own hemispheres");
        }
        None => backend.report_model(solved.hemispheres, clock, "pass 1 and queries"),
    }
    Ok(())
}

/// The backend the queries cast their own hemispheres on, where it differs from pass 1's: the
/// same engine with `--query-circles` (default [`QUERY_CIRCLES`] times pass 1's R, within
/// [`MOST_CIRCLES`] and, on boards, within the hemispheres they build); `None` where the R is
/// pass 1's. On boards it is a second backend on the same farm: each switch between the two
/// sends the boards the other's configuration (the scene stays), so a request of queries costs
/// two.
fn own_backend<'s>(args: &IrradianceArgs, run: &'s Prepared) -> Result<Option<Running<'s>>> {
    let circles = run.settings.circles;
    let own = match args.query_circles {
        Some(r) => {
            anyhow::ensure!(
                (2..=MOST_CIRCLES).contains(&r),
                "--query-circles {r}: must be between 2 and {MOST_CIRCLES}"
            );
            if let Some(most) = run.engine.most_circles().filter(|&m| r > m) {
                anyhow::bail!(
                    "--query-circles {r}: the boards build hemispheres of at most {most} circles"
                );
            }
            r
        }
        None => {
            let most = run.engine.most_circles().unwrap_or(MOST_CIRCLES);
            (QUERY_CIRCLES * circles)
                .min(MOST_CIRCLES)
                .min(most)
                .max(circles)
        }
    };
    if own == circles {
        return Ok(None);
    }
    let settings = Pass1Settings {
        circles: own,
        ..run.settings
    };
    Ok(Some(run.engine.backend(&run.scene, &settings)?))
}

/// One answer line: `r g b`.
fn rgb(e: [f64; 3]) -> String {
    format!("{:.6e} {:.6e} {:.6e}", e[0], e[1], e[2])
}
