//! The part of a run every command that solves shares: pass 1 (uniform or adaptive) with its
//! progress bar and report, the solve, and the radiosity field; or, without a matrix,
//! progressive refinement with rows shot on demand.

use crate::engine::{Engine, Running};
use crate::options::{AdaptiveArgs, EngineArgs, LimitArgs, QualityArgs, SamplingArgs, SolverArgs};
use crate::progress::{bar, bar_of_rays};
use anyhow::Result;
use clap::Args;
use hemi::adaptive::{AdaptiveSettings, PatchReport, Progress};
use hemi::field::refine::default_budget;
use hemi::field::{FieldSettings, Reflected, Sweeps};
use hemi::on_demand::{grids_streaming, solve_streaming, RowShooter};
use hemi::pass1::FormFactors;
use hemi::radiosity::Grid;
use hemi::scene::Scene;
use hemi::settings::Pass1Settings;
use hemi::solve::{self, SceneParts, Solution, SolveSettings, Solver};
use hemi_kernel::tracer::ShotStats;
use std::path::PathBuf;

/// What every command that runs pass 1 takes: the scene, the ray engine, the sampling and its
/// preset, and adaptive sampling.
#[derive(Args)]
pub struct RunArgs {
    /// The scene file (TOML; OBJ/MTL and BPT geometry may be included from it).
    pub scene: PathBuf,
    #[command(flatten)]
    pub engine: EngineArgs,
    #[command(flatten)]
    pub sampling: SamplingArgs,
    #[command(flatten)]
    pub quality: QualityArgs,
    #[command(flatten)]
    pub adaptive: AdaptiveArgs,
    #[command(flatten)]
    pub limits: LimitArgs,
}

/// A run made ready: the scene loaded, the settings with `--quality` applied, the engine open.
pub struct Prepared {
    /// The scene.
    pub scene: Scene,
    /// Pass 1's settings for it.
    pub settings: Pass1Settings,
    /// The opened engine.
    pub engine: Engine,
}

impl RunArgs {
    /// Checks the options (the backend first), loads the scene, applies `--quality`, runs
    /// `check` on the scene (a command's own checks and changes, such as a view override, before
    /// boards are booted), and opens the engine.
    pub fn prepare(&self, check: impl FnOnce(&mut Scene) -> Result<()>) -> Result<Prepared> {
        let adaptive = self.adaptive.on();
        let choice = self.engine.check()?;
        choice.warn_unused(&self.engine.model);
        let checked = self.sampling.settings(adaptive)?;
        let mut scene = self.limits.load(&self.scene)?;
        let settings = self.quality.for_scene(checked, &scene, adaptive);
        // the depth bound counts from the K that --quality chose
        self.adaptive
            .settings(self.quality.quality, settings.samples)?;
        check(&mut scene)?;
        let engine = choice.open(&self.engine.model, &self.engine.boards)?;
        Ok(Prepared {
            scene,
            settings,
            engine,
        })
    }

    /// Pass 1 and the solve of a prepared run on `backend` (see [`solve`]).
    pub fn solve(
        &self,
        backend: &Running<'_>,
        solver: &SolverArgs,
        field: Option<FieldSettings>,
    ) -> Result<Solved> {
        if !backend.get().scene().emits() {
            eprintln!(
                "warning: no patch of {} emits light: every radiosity will be 0",
                self.scene.display()
            );
        }
        let stats = self.engine.boards.board_stats;
        let q = self.quality.quality;
        solve(backend, &self.adaptive, q, solver, stats, field)
    }
}

/// A solved scene: the solution and its field, with what pass 1 did.
pub struct Solved {
    /// The solve.
    pub solution: Solution,
    /// The radiosity field (vertex grids per patch), when asked for.
    pub grids: Vec<Grid>,
    /// The field's reflected direct light, where it has it (`Field::direct`).
    pub direct: Option<Reflected>,
    /// Pass 1's counters (empty when rows were shot on demand).
    pub stats: ShotStats,
    /// Hemispheres shot by pass 1 (the elements).
    pub hemispheres: u64,
    /// What adaptive sampling did per patch (empty for uniform sampling).
    pub sampled: Vec<PatchReport>,
    /// Seconds of pass 1 (or of the whole streaming solve) and of the solve after it.
    pub seconds: (f64, f64),
}

/// Pass 1, uniform or adaptive (`--adaptive`, paper §4), on `backend`. Adaptive sampling prints
/// per patch the depth it reached and the rows it computed to stderr and returns the same.
/// Uniform pass 1 stops once its rows pass `limit` bytes (`--matrix-mib`).
pub fn sample(
    backend: &Running<'_>,
    adaptive: Option<AdaptiveSettings>,
    board_stats: bool,
    limit: u64,
) -> Result<(FormFactors, Vec<PatchReport>)> {
    let Some(adaptive) = adaptive else {
        let (scene, k) = (backend.get().scene(), backend.get().settings().samples);
        let elements: u64 = (0..scene.patches.len())
            .map(|i| hemi::shots::sample_count(scene, i, k) as u64)
            .sum();
        let rays = hemi_kernel::hemisphere::ray_count(backend.get().settings().circles);
        let bar = bar_of_rays(elements, "pass 1", rays.into());
        let t0 = std::time::Instant::now();
        let raise = "--matrix-mib raises it; --solver progressive needs no stored rows";
        let on = |n| bar.inc(n);
        let ff = hemi::pass1::form_factors_within(backend.get(), &on, limit, raise)?;
        bar.finish_and_clear();
        if board_stats && matches!(backend, Running::Boards(_)) {
            eprintln!("pass 1 on boards: {:.3} s", t0.elapsed().as_secs_f64());
        }
        backend.board_report(board_stats, "after pass 1");
        return Ok((ff, Vec::new()));
    };
    let bar = bar(0, "pass 1");
    let on = |p: Progress| match p {
        Progress::Planned(n) => bar.inc_length(n),
        Progress::Done(n) => bar.inc(n),
    };
    let refined = hemi::adaptive::refine(backend.get(), &adaptive, &on)?;
    bar.finish_and_clear();
    backend.board_report(board_stats, "after adaptive pass 1");
    report_adaptive(
        backend.get().scene(),
        backend.get().settings().samples,
        &adaptive,
        &refined,
    );
    Ok((refined.form_factors, refined.patches))
}

/// What adaptive sampling did, on stderr: totals, then per diffuse patch its depth, grid and
/// rows computed.
fn report_adaptive(
    scene: &Scene,
    k: u32,
    adaptive: &AdaptiveSettings,
    refined: &hemi::adaptive::Refined,
) {
    let deepest = refined.patches.iter().map(|p| p.k).max().unwrap_or(0) as usize;
    let diffuse = refined.patches.iter().filter(|p| p.k > 0).count();
    eprintln!(
        "adaptive sampling (K = {k}, margin {}, max depth {}): {} solves, {} rows computed \
         (uniform {deepest}×{deepest} on the {diffuse} diffuse patches: {})",
        adaptive.margin,
        adaptive.max_depth,
        refined.rounds,
        refined.rows_computed(),
        diffuse * deepest * deepest
    );
    eprintln!(
        "{:<16} {:>5} {:>9} {:>14}",
        "patch", "depth", "grid", "rows computed"
    );
    for (p, r) in scene.patches.iter().zip(&refined.patches) {
        if r.k > 0 {
            let grid = format!("{}×{}", r.k, r.k);
            eprintln!(
                "{:<16} {:>5} {grid:>9} {:>14}",
                p.name,
                r.depth,
                r.rows_computed()
            );
        }
    }
}

/// The solve of (2.6) on `ff` with `solver` (auto says what it picked on stderr).
pub fn solve_scene(scene: &Scene, ff: &FormFactors, solver: Solver) -> Result<Solution> {
    let parts = SceneParts::new(scene, ff.channels());
    let system = parts.system(ff.channels())?;
    if solver != Solver::Auto {
        let d = solve::diagnose::row_sums(&system);
        if d.rows_above_one > 0 {
            eprintln!(
                "warning: {} rows of F sum above 1 (largest {:.5}): sampling error; --solver auto \
                 would scale them back",
                d.rows_above_one, d.max_row_sum
            );
        }
    }
    solve::solve(&system, solver, &SolveSettings::default(), &mut |m| {
        eprintln!("{m}")
    })
}

/// Pass 1 and the solve, or progressive refinement with rows shot on demand when the solver
/// args say so; the field too when `field` is given.
pub fn solve(
    backend: &Running<'_>,
    adaptive: &AdaptiveArgs,
    quality: Option<crate::options::QualityArg>,
    solver: &SolverArgs,
    board_stats: bool,
    field: Option<FieldSettings>,
) -> Result<Solved> {
    let scene = backend.get().scene();
    let t0 = std::time::Instant::now();
    if solver.streaming(backend.get())? {
        if field.is_some_and(|f| f.sweeps > 0) {
            eprintln!(
                "element field: no gather sweeps with rows shot on demand (they sweep a stored \
                 pass 1): the paper's (4.2)"
            );
        }
        return streaming(backend, adaptive.on(), solver, field.is_some());
    }
    let k = backend.get().settings().samples;
    let adaptive = adaptive.settings(quality, k)?;
    let (ff, sampled) = sample(backend, adaptive, board_stats, solver.limit())?;
    let t1 = std::time::Instant::now();
    let solution = solve_scene(scene, &ff, solver.solver.into())?;
    let (ff, solution, grids, direct) = match field {
        Some(mut f) => {
            f.refine.max_elements = Some(element_budget(scene, &ff, &f, solver.limit()));
            field_grids(backend, ff, solution, &f, solver.solver.into())?
        }
        None => (ff, solution, Vec::new(), None),
    };
    Ok(Solved {
        solution,
        grids,
        direct,
        stats: ff.stats,
        hemispheres: ff.elements.len() as u64,
        sampled,
        seconds: ((t1 - t0).as_secs_f64(), t1.elapsed().as_secs_f64()),
    })
}

/// The elements refinement may reach: `--max-elements` when given, else the library's
/// [`default_budget`]; in both cases no more than the rows `limit` bytes (`--matrix-mib`)
/// leave room for at pass 1's mean row size (said on stderr when that is the bound).
fn element_budget(scene: &Scene, ff: &FormFactors, field: &FieldSettings, limit: u64) -> usize {
    let now = ff.elements.len();
    let asked = field.refine.max_elements;
    if field.refine.rounds == 0 || now == 0 {
        return asked.unwrap_or(default_budget(now));
    }
    let rows = hemi::footprint::Footprint::of(scene).rows(&ff.elements);
    let held = rows + ff.matrix_bytes() as u64;
    let each = rows.div_ceil(now as u64).max(1);
    let room = now.saturating_add((limit.saturating_sub(held) / each) as usize);
    let wanted = asked.unwrap_or(default_budget(now));
    if wanted <= now {
        eprintln!(
            "field refinement: none, --max-elements {wanted} is not above pass 1's {now} elements"
        );
    }
    if wanted > room {
        let what = match asked {
            Some(m) => format!("{m} (--max-elements)"),
            None => format!("{wanted} (11/4 of pass 1's {now})"),
        };
        eprintln!(
            "field refinement: at most {room} elements instead of {what}: pass 1 holds {:.1} MiB of \
             form factors and each element's row takes about {each} bytes (--matrix-mib {} \
             raises it)",
            held as f64 / MIB,
            limit >> 20
        );
    }
    wanted.min(room)
}

/// Bytes in a MiB, for messages.
const MIB: f64 = (1u64 << 20) as f64;

/// The field of the solved scene: the element values (4.2), then `field`'s gather sweeps and
/// its refinement rounds (with a progress bar and lines on stderr when there are any); returns
/// the pass-1 output and solve the refinement ended on, with the grids.
fn field_grids(
    backend: &Running<'_>,
    ff: FormFactors,
    solution: Solution,
    field: &FieldSettings,
    solver: Solver,
) -> Result<(FormFactors, Solution, Vec<Grid>, Option<Reflected>)> {
    let scene = backend.get().scene();
    // the bar counts hemispheres: the transport's record casts each element once, and a
    // refinement round shoots its new elements (at most the budget's) and records them all
    // again; what refinement will choose is not known here, so the total is that bound, and
    // work past it (re-cast sweeps, past the record's budget, cast every element a sweep)
    // raises the total rather than running past it
    let now = ff.elements.len() as u64;
    let total = match field.refine.rounds {
        0 => now,
        _ => {
            let most = field
                .refine
                .max_elements
                .map_or(default_budget(now as usize) as u64, |m| m as u64);
            now + 2 * most.max(now)
        }
    };
    let bar = bar(total, "field");
    let t0 = std::time::Instant::now();
    let quiet = |ff: &FormFactors| {
        let parts = SceneParts::new(scene, ff.channels());
        solve::solve(
            &parts.system(ff.channels())?,
            solver,
            &SolveSettings::default(),
            &mut |_| {},
        )
    };
    let on = |n: u64| {
        let to = bar.position() + n;
        if bar.length().is_some_and(|len| to > len) {
            bar.set_length(to);
        }
        bar.inc(n);
    };
    let refined = hemi::field::refine::refine_field(
        backend.get(),
        ff,
        solution,
        field,
        &field.refine,
        &quiet,
        &on,
    )?;
    bar.finish_and_clear();
    if field.sweeps > 0 {
        report_field(scene, &refined, field, t0.elapsed().as_secs_f64());
    }
    let field = refined.field;
    Ok((
        refined.form_factors,
        refined.solution,
        field.grids,
        field.direct,
    ))
}

/// The field's lines on stderr: each refinement round, then the sweeps of the last field.
fn report_field(
    scene: &Scene,
    refined: &hemi::field::refine::Refined,
    field: &FieldSettings,
    seconds: f64,
) {
    for (r, round) in refined.rounds.iter().enumerate() {
        let names: Vec<String> = round
            .refined
            .iter()
            .map(|&(i, k)| format!("{} {k}×{k}", scene.patches[i].name))
            .collect();
        let left = match round.left {
            0 => String::new(),
            n => format!(
                "; {n} more over the tolerance did not fit --max-elements {}",
                refined.budget
            ),
        };
        eprintln!(
            "field refinement round {}: {} elements{left} ({})",
            r + 1,
            round.elements,
            names.join(", ")
        );
    }
    let f = &refined.field;
    let how = match f.how {
        Some(Sweeps::Recorded { bytes }) => {
            format!("transport recorded in {:.1} MiB", bytes as f64 / MIB)
        }
        Some(Sweeps::OverBudget { estimate }) => format!(
            "each sweep re-cast: the transport would need about {:.0} MiB (> --field-mib {})",
            estimate as f64 / MIB,
            field.transport_bytes >> 20
        ),
        Some(Sweeps::Recast) | None => "each sweep re-cast".to_string(),
    };
    // where the lamps' light is exact, the grids' largest misses are at shadows' edges, which
    // the queries and pass 2 relight: the figure is the grids', not the answers'
    let relit = match f.direct {
        Some(_) => ", before shadows' edges are relit",
        None => "",
    };
    let worst = match refined.worst {
        Some((i, e)) => format!(
            ", worst estimated grid error {:.1} % ({}{relit})",
            100.0 * e,
            scene.patches[i].name
        ),
        None => String::new(),
    };
    eprintln!(
        "element field: {} gather sweeps of {} elements ({how}), last change {:.2e}{worst}, \
         {seconds:.3} s",
        f.sweeps,
        refined.form_factors.elements.len(),
        f.change,
    );
}

/// Says on stderr how many reflecting patches shooting left unlit ([`hemi::on_demand::unreached`]),
/// and why, when any were.
fn warn_unreached(scene: &Scene, solution: &Solution, shooter: &RowShooter<'_>) {
    let missed = hemi::on_demand::unreached(scene, solution);
    if missed == 0 {
        return;
    }
    let reflecting = (0..scene.patches.len())
        .filter(|&i| scene.material_of(i).diffuse.iter().any(|r| *r > 0.0))
        .count();
    eprintln!(
        "warning: progressive refinement left {missed} of {reflecting} reflecting patches at exactly \
         0: a shot spreads a patch's energy only over what its own rays hit ({} rays a shot \
         here), so smaller receivers are missed and those hit get too much. Raise --circles or \
         --samples, or solve with the matrix (--solver gauss-seidel), where every patch gathers.",
        shooter.rays / shooter.shot.max(1)
    );
}

/// Progressive refinement with rows shot on demand (soft backend), and the grids from a second
/// shot of every patch: no N×N matrix and no stored element rows.
fn streaming(
    backend: &Running<'_>,
    adaptive: bool,
    solver: &SolverArgs,
    with_grids: bool,
) -> Result<Solved> {
    anyhow::ensure!(
        matches!(backend, Running::Soft(_)),
        "progressive refinement (--solver progressive, or auto past --matrix-mib) shoots rows \
         on demand on the soft backend only: a larger --matrix-mib keeps pass 1's rows"
    );
    anyhow::ensure!(
        !adaptive,
        "--adaptive refines from solved rows and needs pass 1's rows stored: choose a --solver \
         other than progressive, or, where auto chose it past --matrix-mib, a larger --matrix-mib"
    );
    let t0 = std::time::Instant::now();
    let n = backend.get().scene().patches.len();
    // keep at most about a quarter of --matrix-mib in cached rows
    let cache = ((solver.matrix_mib << 20) / 4 / (24 * n.max(1) as u64)) as usize;
    let mut shooter = RowShooter::new(backend.get(), cache)?;
    let bar = bar(n as u64, "shots");
    let settings = SolveSettings {
        tolerance: 1e-6,
        max_iterations: 1_000_000,
    };
    let solution = solve_streaming(&mut shooter, &settings, &mut |k, _| {
        bar.set_position(k as u64)
    })?;
    bar.finish_and_clear();
    eprintln!(
        "progressive refinement: {} shots, {} rows shot ({} cached), {} rays, unshot residual \
         {:.2e} (of the energy the shooters' rows carry)",
        solution.iterations,
        shooter.shot,
        cache.min(n),
        shooter.rays,
        solution.residual
    );
    warn_unreached(backend.get().scene(), &solution, &shooter);
    let grids = if with_grids {
        grids_streaming(&mut shooter, &solution)?
    } else {
        Vec::new()
    };
    Ok(Solved {
        solution,
        grids,
        direct: None,
        stats: ShotStats::default(),
        hemispheres: 0,
        sampled: Vec::new(),
        seconds: (t0.elapsed().as_secs_f64(), 0.0),
    })
}
