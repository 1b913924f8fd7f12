//! The `hemi` command line (spec §5).

use anyhow::{bail, Context, Result};
use clap::{Args, Parser, Subcommand};
use hemi::adaptive::{AdaptiveSettings, PatchReport};
use hemi::engine::{model_engine, Backend, CountedModel, Counters, SoftEngine};
use hemi::pass1::{self, FormFactors, Pass1Settings};
use hemi::scene::{self, Scene};
use hemi::solve::{self, SolveSettings};
use hemi_hdl_model::ModelConfig;
use hemi_kernel::accel::{Accelerator, Ray};
use hemi_kernel::geometry::Vec3;
use hemi_kernel::hemisphere::{DeltaRule, OwnedHemisphere};
use hemi_kernel::tracer::ShotStats;
use indicatif::{ProgressBar, ProgressStyle};
use std::io::{BufRead, Write};
use std::path::PathBuf;

#[derive(Parser)]
#[command(
    name = "hemi",
    version,
    about = "Generalized two-pass radiosity on the hemi co-processor"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Args, Clone)]
struct Common {
    /// Ray engine: soft | model | qemu | serial:PATH (comma-separated to spread jobs).
    #[arg(long, default_value = "soft")]
    backend: String,
    /// Hemisphere circles R (M = 4R rays on the horizon circle).
    #[arg(long, default_value_t = 64)]
    circles: u32,
    /// Initial K×K sample points per polygon patch [default: 16, or 2 with --adaptive].
    #[arg(long)]
    samples: Option<u32>,
    /// Adaptive patch sampling (paper §4): refine each patch where the gradient test fails.
    #[arg(long)]
    adaptive: bool,
    /// Gradient test margin (--adaptive): a 4-sample window fails when its luminances spread
    /// by more than this fraction of their mean.
    #[arg(long, default_value_t = 0.1)]
    margin: f64,
    /// Most subdivision levels beyond the initial guess (--adaptive).
    #[arg(long, default_value_t = 4)]
    max_depth: u32,
    /// What the gradient test compares (--adaptive): surplus (each sample against the previous
    /// level's interpolation of it) or spread (the paper's: the window's max − min).
    #[arg(long, default_value = "surplus", value_parser = ["surplus", "spread"])]
    test: String,
    /// Delta form factor rule: band (exact band integral, default) or paper (cos χ / K).
    #[arg(long, default_value = "band", value_parser = ["band", "paper"])]
    delta: String,
    /// Accelerator clock assumed when `--backend model` reports time.
    #[arg(long, default_value_t = 100.0)]
    clock_mhz: f64,
    /// CORDIC iterations of the modelled accelerator (`--backend model`).
    #[arg(long, default_value_t = 24)]
    cordic_iterations: u32,
    /// CORDIC word width in bits of the modelled accelerator (`--backend model`).
    #[arg(long, default_value_t = 32)]
    cordic_width: u32,
    /// Bezier subdivision depth of the modelled accelerator (`--backend model`; 1..=13 with its
    /// 40-entry stack).
    #[arg(long, default_value_t = ModelConfig::default().subdivision_depth)]
    bezier_depth: u32,
    /// Bezier control-point datapath width in bits of the modelled accelerator
    /// (`--backend model`; 12..=26).
    #[arg(long, default_value_t = ModelConfig::default().coord_width)]
    bezier_width: u32,
    /// Δ of paper §6.5: specular frustums carrying less than this fraction of their primary ray
    /// are not shot.
    #[arg(long, default_value_t = hemi_kernel::specular::DEFAULT_THRESHOLD)]
    specular_threshold: f32,
    /// Capacity of the skeleton stack (paper §6.2): the frustums waiting to be shot.
    #[arg(long, default_value_t = 64)]
    stack: usize,
    /// The most specular bounces one path may take (paper §5).
    #[arg(long, default_value_t = 24)]
    max_bounces: u16,
    /// Radiosity solver: auto | gauss-seidel | sor | direct | progressive (auto measures the
    /// system and says on stderr what it picked and why).
    #[arg(long, default_value = "auto")]
    solver: solve::Solver,
    /// Pass-1 method: hemisphere (the paper's) | hemicube | monte-carlo | monte-carlo-plain; the
    /// peers shoot as many rays per sample point as the hemisphere of --circles.
    #[arg(long, default_value = "hemisphere")]
    method: hemi::method::Method,
    /// Preset R and K from a target error and the scene's size: draft | default | high
    /// (overrides --circles and --samples, or with --adaptive --circles, --margin and
    /// --max-depth; see docs/PERFORMANCE.md for what each costs).
    #[arg(long)]
    quality: Option<hemi::quality::Quality>,
    /// Largest N×N form-factor matrix pass 1 may form, in MiB (three f64 channels); above it,
    /// `--solver auto` shoots rows on demand with progressive refinement instead.
    #[arg(long, default_value_t = 4096)]
    matrix_mib: u64,
}

impl Common {
    fn backend(&self) -> Result<Backend> {
        match self.backend.as_str() {
            "soft" => Ok(Backend::Soft),
            "model" => {
                anyhow::ensure!(self.clock_mhz > 0.0 && self.clock_mhz.is_finite(), "--clock-mhz must be positive");
                let subdiv = hemi_hdl_model::intersect::bezier::SubdivConfig { depth: self.bezier_depth, coord_width: self.bezier_width };
                anyhow::ensure!(
                    subdiv.is_valid_for(hemi_hdl_model::intersect::bezier::STACK_ENTRIES),
                    "--bezier-depth {} --bezier-width {}: the model takes depths 1..=13 and widths 12..=26",
                    self.bezier_depth,
                    self.bezier_width
                );
                Ok(Backend::Model(ModelConfig {
                    iterations: self.cordic_iterations,
                    width: self.cordic_width,
                    subdivision_depth: self.bezier_depth,
                    coord_width: self.bezier_width,
                    ..ModelConfig::default()
                }))
            }
            b => match hemi::board::jobs::parse_boards(b)? {
                Some(list) => Ok(Backend::Boards(Vec::leak(list))),
                None => bail!("--backend {b}: expected soft, model, qemu or serial:PATH (boards may be listed comma-separated)"),
            },
        }
    }

    fn pass1(&self) -> Result<Pass1Settings> {
        self.backend()?;
        if self.circles < 2 || self.circles > 1024 {
            bail!("--circles must be between 2 and 1024");
        }
        let samples = self.samples.unwrap_or(if self.adaptive { 2 } else { 16 });
        if !(1..=256).contains(&samples) {
            bail!("--samples must be between 1 and 256");
        }
        Ok(Pass1Settings {
            circles: self.circles,
            samples,
            rule: if self.delta == "paper" {
                DeltaRule::Paper
            } else {
                DeltaRule::Band
            },
            specular: hemi::optics::SpecularSettings {
                threshold: self.specular_threshold,
                stack: self.stack,
                max_bounces: self.max_bounces,
            },
            method: self.method,
        })
    }

    /// Adaptive sampling settings with `--adaptive`, else `None` (uniform K×K).
    fn adaptive(&self) -> Result<Option<AdaptiveSettings>> {
        if !self.adaptive {
            return Ok(None);
        }
        if !(self.margin >= 0.0 && self.margin.is_finite()) {
            bail!("--margin must be a finite number ≥ 0");
        }
        if self.max_depth > 8 {
            bail!("--max-depth must be at most 8 (a 2×2 guess becomes 512×512)");
        }
        // a --quality preset sets the margin and depth, as it sets R and K
        let (margin, max_depth) = self
            .quality
            .map_or((self.margin, self.max_depth), |q| q.adaptive());
        Ok(Some(AdaptiveSettings {
            margin,
            max_depth,
            test: if self.test == "spread" {
                hemi::adaptive::Test::Spread
            } else {
                hemi::adaptive::Test::Surplus
            },
            ..AdaptiveSettings::default()
        }))
    }

    /// [`Common::pass1`] with `--quality` applied for `scene`.
    fn settings_for(&self, scene: &Scene) -> Result<Pass1Settings> {
        let mut settings = self.pass1()?;
        if let Some(q) = self.quality {
            let p = if self.adaptive {
                hemi::quality::apply_adaptive(q, scene, &mut settings)
            } else {
                hemi::quality::apply(q, scene, &mut settings)
            };
            eprintln!("{}", p.why);
        }
        Ok(settings)
    }

    /// Whether this run solves without a matrix: `--solver progressive`, or `auto` on a scene
    /// whose N×N matrices would exceed `--matrix-mib`.
    fn streaming(&self, scene: &Scene) -> bool {
        let n = scene.patches.len() as u64;
        let bytes = 3 * 8 * n * n;
        match self.solver {
            solve::Solver::Progressive => true,
            solve::Solver::Auto if bytes > self.matrix_mib << 20 => {
                eprintln!("solver auto: {n} patches need {:.1} MiB of form factors (> --matrix-mib {}): progressive refinement with rows shot on demand", bytes as f64 / (1 << 20) as f64, self.matrix_mib);
                true
            }
            _ => false,
        }
    }
}

#[derive(Subcommand)]
enum Command {
    /// Both passes: writes the image (8-bit sRGB PNG, and linear EXR with --exr).
    Render {
        scene: PathBuf,
        /// Output PNG.
        #[arg(short, long)]
        output: PathBuf,
        /// Also write the linear radiances as OpenEXR.
        #[arg(long)]
        exr: Option<PathBuf>,
        /// Eye rays per pixel (anti-aliasing).
        #[arg(long, default_value_t = 1)]
        spp: u32,
        /// Exposure in stops applied before the PNG's sRGB encoding (default: automatic).
        #[arg(long, allow_hyphen_values = true)]
        exposure: Option<f64>,
        /// Draw the sample points adaptive sampling shot over the image, coloured by level
        /// (white: initial guess, then yellow, orange, red, magenta, blue); needs --adaptive.
        #[arg(long)]
        show_samples: bool,
        #[command(flatten)]
        common: Common,
    },
    /// Pass-1 form factors between the scene's patches.
    FormFactors {
        scene: PathBuf,
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        common: Common,
    },
    /// Pass 1 and the solve: radiosity per patch.
    Solve {
        scene: PathBuf,
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        common: Common,
    },
    /// Irradiance at points read from stdin (`x y z dx dy dz` per line), printed `r g b`.
    Irradiance {
        scene: PathBuf,
        #[command(flatten)]
        common: Common,
    },
    /// Nearest hit of rays read from stdin (`x y z dx dy dz`): `t patch u v` or `miss`.
    Trace {
        scene: PathBuf,
        #[command(flatten)]
        common: Common,
    },
    /// Benchmarks (speed is measured here, never asserted in tests).
    Bench {
        #[command(subcommand)]
        command: BenchCommand,
    },
    /// The ray engine (board) itself.
    Board {
        #[command(subcommand)]
        command: BoardCommand,
    },
}

#[derive(Subcommand)]
enum BenchCommand {
    /// Adaptive against uniform sampling: the error of the radiosity field B(u,v) against rows
    /// computed, measured against a finely sampled uniform reference: a markdown table
    /// (docs/ACCURACY.md).
    Adaptive {
        #[arg(default_value = "scenes/cornell.toml")]
        scene: PathBuf,
        /// K of the uniform reference (not a power of two times 2, so that no adaptive level
        /// shares its sample points and hemisphere spins).
        #[arg(long, default_value_t = 96)]
        reference: u32,
        /// Comma-separated K of the uniform runs.
        #[arg(long, default_value = "2,4,8,16,32")]
        uniform: String,
        /// Initial guess K of the adaptive runs.
        #[arg(long, default_value_t = 2)]
        initial: u32,
        /// Comma-separated margins of the adaptive runs (the points of each chart line).
        #[arg(long, default_value = "0.4,0.3,0.25,0.2,0.17,0.15,0.12,0.1,0.07,0.05")]
        margins: String,
        /// Comma-separated depth limits of the adaptive runs (one chart line each, per test).
        #[arg(long, default_value = "4,5")]
        depths: String,
        /// Comma-separated gradient tests of the adaptive runs: surplus, spread.
        #[arg(long, default_value = "surplus,spread")]
        tests: String,
        /// Also draw the chart (SVG).
        #[arg(long)]
        svg: Option<PathBuf>,
        /// Keep the reference's grids in this file between runs (recomputed when the scene, K
        /// or R differ).
        #[arg(long)]
        reference_cache: Option<PathBuf>,
        #[command(flatten)]
        common: Common,
    },
    /// Bezier intersection error (against an f64 Newton reference) over subdivision depth and
    /// flatness, with the cost per ray: a markdown table (docs/ACCURACY.md).
    Bezier {
        #[arg(default_value = "scenes/teapot.toml")]
        scene: PathBuf,
        /// Also draw the chart (SVG).
        #[arg(long)]
        svg: Option<PathBuf>,
    },
    /// The accelerator model's CORDIC error against iterations and word width, with latency and
    /// an area proxy: a markdown table with the Pareto front (docs/ACCURACY.md).
    Cordic {
        /// Also draw the chart (SVG): error against latency, one line per word width.
        #[arg(long)]
        svg: Option<PathBuf>,
    },
    /// Single rays through the soft engine with and without its BVH: rays/s and the ratio, on
    /// SCENE (optionally tessellated: Bezier patches become 2n² triangles each).
    Trace {
        #[arg(default_value = "scenes/teapot.toml")]
        scene: PathBuf,
        /// Rays to cast (random origins in the scene's box, random directions; fixed seed).
        #[arg(long, default_value_t = 100_000)]
        rays: usize,
        /// Tessellate Bezier patches into an n×n grid of triangle pairs first (0: keep them).
        #[arg(long, default_value_t = 16)]
        tessellate: usize,
    },
    /// The teapot as Bezier patches (16 samples each) against the same teapot tessellated into
    /// 2n² triangles per patch (1 sample each): time, matrix size, memory, radiosities.
    Tessellation {
        #[arg(default_value = "scenes/teapot.toml")]
        scene: PathBuf,
        /// Grid n per patch (2n² triangles; the paper's 50 is n = 5).
        #[arg(long, default_value_t = 5)]
        grid: usize,
        #[command(flatten)]
        common: Common,
    },
    /// Error against Howell's closed forms and cost, over hemisphere circles R and samples K:
    /// a markdown table (docs/ACCURACY.md).
    FormFactors {
        /// Comma-separated R values.
        #[arg(long, default_value = "16,32,64,128")]
        circles: String,
        /// Comma-separated K values.
        #[arg(long, default_value = "4,8,16,32")]
        samples: String,
        /// Also draw the chart (SVG): max error against rays, one line per K.
        #[arg(long)]
        svg: Option<PathBuf>,
    },
    /// The solvers' convergence (residual against work) on the Cornell box and a ρ = 0.99
    /// furnace: markdown tables, and with --svg-dir the charts solvers-*.svg.
    Solvers {
        #[arg(default_value = "scenes/cornell.toml")]
        scene: PathBuf,
        /// Pass-1 R for both systems.
        #[arg(long, default_value_t = 32)]
        circles: u32,
        /// Pass-1 K for both systems.
        #[arg(long, default_value_t = 8)]
        samples: u32,
        /// Furnace: n×n quads per face.
        #[arg(long, default_value_t = 4)]
        furnace: usize,
        #[arg(long)]
        svg_dir: Option<PathBuf>,
    },
    /// Hemisphere, hemicube and Monte Carlo at equal rays against Howell B-3: a markdown table,
    /// and with --svg-dir the chart methods-error.svg.
    Methods {
        /// Comma-separated R values (the ray budgets).
        #[arg(long, default_value = "8,12,16,24,32,48,64,96,128")]
        circles: String,
        /// Rectangle configurations (fixed seed).
        #[arg(long, default_value_t = 200)]
        cases: usize,
        #[arg(long)]
        svg_dir: Option<PathBuf>,
    },
    /// The paper's figure 9 on the Cornell box: b_R of two patches against R (9a) and rays
    /// against R (9b); with --svg-dir the charts fig9a.svg and fig9b.svg.
    PaperFig9 {
        #[arg(default_value = "scenes/cornell.toml")]
        scene: PathBuf,
        /// The two patches.
        #[arg(long, default_value = "floor,red_wall")]
        patches: String,
        /// K.
        #[arg(long, default_value_t = 8)]
        samples: u32,
        /// Comma-separated R values.
        #[arg(long, default_value = "4,6,8,12,16,24,32,48,64,96,128")]
        circles: String,
        /// Ray budget of the Monte Carlo reference, as R.
        #[arg(long, default_value_t = 256)]
        reference_circles: u32,
        #[arg(long)]
        svg_dir: Option<PathBuf>,
    },
    /// What each --quality preset picks on SCENE, its cost there, and its measured error.
    Quality {
        #[arg(default_value = "scenes/cornell.toml")]
        scene: PathBuf,
    },
    /// Pass-1 hemisphere rays per second of the soft backend on SCENE, on 1 thread and on all,
    /// printed as one machine-readable line per run.
    Rays {
        scene: PathBuf,
        #[command(flatten)]
        common: Common,
        /// Repeat each measurement this many times and keep the fastest.
        #[arg(long, default_value_t = 3)]
        repeat: u32,
        /// Also measure the accelerator trait's provided ray-by-ray path (rotate each ray, then a
        /// general nearest hit), on one thread over the first 64 sample points: what the
        /// shared-origin casting of the soft engine buys.
        #[arg(long)]
        per_ray: bool,
    },
}

#[derive(Subcommand)]
enum BoardCommand {
    /// The handshake of the selected backend: protocol, firmware build, accelerator, capacities.
    Info {
        /// Ray engine: soft | qemu | serial:PATH.
        #[arg(long, default_value = "soft")]
        backend: String,
        /// Firmware ELF to boot in QEMU (default: built from this checkout if missing).
        #[arg(long)]
        firmware: Option<PathBuf>,
    },
}

fn progress(len: u64, what: &str) -> ProgressBar {
    let bar = ProgressBar::new(len);
    bar.set_style(
        ProgressStyle::with_template("{msg:>12} [{bar:40}] {pos}/{len} ({eta})")
            .expect("static template")
            .progress_chars("=> "),
    );
    bar.set_message(what.to_string());
    bar
}

/// The boards of a `Boards` backend, connected (QEMU booted); `None` for in-process backends.
fn farm_for(backend: Backend, common: &Common) -> Result<Option<hemi::board::jobs::Farm>> {
    match backend {
        Backend::Boards(list) => {
            let farm = hemi::board::jobs::Farm::connect(list, None)?;
            farm.set_cordic(common.cordic_iterations, common.cordic_width)?;
            Ok(Some(farm))
        }
        _ => Ok(None),
    }
}

fn run_pass1(
    scene: &Scene,
    settings: &Pass1Settings,
    backend: Backend,
    counters: &Counters,
    farm: Option<&hemi::board::jobs::Farm>,
) -> Result<FormFactors> {
    let elements: u64 = (0..scene.patches.len())
        .map(|i| pass1::sample_count(scene, i, settings.samples) as u64)
        .sum();
    let bar = progress(elements, "pass 1");
    let patches = scene.kernel_patches();
    let ff = match backend {
        Backend::Soft => {
            pass1::form_factors_with(scene, settings, &|| SoftEngine::new(&patches), &|n| {
                bar.inc(n)
            })?
        }
        Backend::Model(cfg) => {
            model_engine(&patches, cfg)?;
            pass1::form_factors_with(
                scene,
                settings,
                &|| {
                    CountedModel::new(
                        model_engine(&patches, cfg).expect("checked above"),
                        counters,
                    )
                },
                &|n| bar.inc(n),
            )?
        }
        Backend::Boards(_) => {
            let farm = farm.context("boards not connected")?;
            let t0 = std::time::Instant::now();
            let ff = hemi::board::remote::form_factors(farm, scene, settings, &|n| bar.inc(n))?;
            if std::env::var_os("HEMI_BOARD_STATS").is_some() {
                eprintln!("pass 1 on boards: {:.3} s", t0.elapsed().as_secs_f64());
                hemi::board::remote::report(farm, "after pass 1");
            }
            ff
        }
    };
    bar.finish_and_clear();
    Ok(ff)
}

/// Pass 1, uniform or adaptive (`--adaptive`, paper §4). Adaptive sampling prints per patch the
/// depth it reached and the rows it computed to stderr and returns the same per patch.
fn run_sampling(
    scene: &Scene,
    settings: &Pass1Settings,
    adaptive: Option<AdaptiveSettings>,
    backend: Backend,
    counters: &Counters,
    farm: Option<&hemi::board::jobs::Farm>,
) -> Result<(FormFactors, Vec<PatchReport>)> {
    let Some(adaptive) = adaptive else {
        return Ok((
            run_pass1(scene, settings, backend, counters, farm)?,
            Vec::new(),
        ));
    };
    let bar = progress(0, "pass 1");
    let on = |p: hemi::adaptive::Progress| match p {
        hemi::adaptive::Progress::Planned(n) => bar.inc_length(n),
        hemi::adaptive::Progress::Done(n) => bar.inc(n),
    };
    let patches = scene.kernel_patches();
    let refined = match backend {
        Backend::Boards(_) => {
            let farm = farm.context("boards not connected")?;
            let refined = hemi::board::remote::refine(farm, scene, settings, &adaptive, &on)?;
            if std::env::var_os("HEMI_BOARD_STATS").is_some() {
                hemi::board::remote::report(farm, "after adaptive pass 1");
            }
            refined
        }
        Backend::Soft => hemi::adaptive::refine_with(
            scene,
            settings,
            &adaptive,
            &|| SoftEngine::new(&patches),
            &on,
        )?,
        Backend::Model(cfg) => {
            model_engine(&patches, cfg)?;
            hemi::adaptive::refine_with(
                scene,
                settings,
                &adaptive,
                &|| {
                    CountedModel::new(
                        model_engine(&patches, cfg).expect("checked above"),
                        counters,
                    )
                },
                &on,
            )?
        }
    };
    bar.finish_and_clear();
    let deepest = refined.patches.iter().map(|p| p.k).max().unwrap_or(0) as usize;
    let diffuse = refined.patches.iter().filter(|p| p.k > 0).count();
    eprintln!(
        "adaptive sampling (K = {}, margin {}, max depth {}): {} solves, {} rows computed (uniform {deepest}×{deepest} on the {diffuse} diffuse patches: {})",
        settings.samples,
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
            eprintln!(
                "{:<16} {:>5} {:>9} {:>14}",
                p.name,
                r.depth,
                format!("{}×{}", r.k, r.k),
                r.rows_computed()
            );
        }
    }
    Ok((refined.form_factors, refined.patches))
}

/// What the modelled accelerator did, on stderr: cycles per ray and per hemisphere, and the
/// time at the assumed clock.
fn report_model(
    backend: Backend,
    counters: &Counters,
    hemispheres: u64,
    clock_mhz: f64,
    what: &str,
) {
    if let Backend::Model(cfg) = backend {
        let (cycles, rays) = counters.get();
        eprintln!(
            "model ({} CORDIC iterations, {}-bit words): {what}: {cycles} cycles for {rays} rays = {:.1} cycles/ray, {:.0} cycles/hemisphere; {:.3} s at {clock_mhz} MHz",
            cfg.iterations,
            cfg.width,
            cycles as f64 / rays.max(1) as f64,
            cycles as f64 / hemispheres.max(1) as f64,
            cycles as f64 / (clock_mhz * 1e6)
        );
    }
}

fn irradiance_lines<A: Accelerator>(
    engine: &mut A,
    scene: &Scene,
    settings: &Pass1Settings,
    view: &hemi_kernel::hemisphere::Hemisphere<'_>,
    grids: &[hemi::radiosity::Grid],
    out: &mut impl Write,
) -> Result<()> {
    let optics = hemi::optics::SceneOptics::new(scene, view)?;
    let mut scratch =
        hemi::optics::Scratch::new(hemi::optics::pending_for(view), &settings.specular);
    for (n, line) in stdin_lines() {
        let (p, d) = parse_ray_line(&line?, n)?;
        let e = hemi::irradiance::irradiance(
            engine,
            view,
            &optics.view(),
            &mut scratch.view(),
            scene,
            grids,
            p,
            d,
        );
        writeln!(out, "{:.6e} {:.6e} {:.6e}", e[0], e[1], e[2])?;
    }
    Ok(())
}

fn trace_lines<A: Accelerator>(engine: &mut A, scene: &Scene, out: &mut impl Write) -> Result<()> {
    for (n, line) in stdin_lines() {
        let (origin, dir) = parse_ray_line(&line?, n)?;
        match engine.nearest_hit(&Ray { origin, dir }, f32::INFINITY) {
            Some(h) => writeln!(
                out,
                "{} {} {} {}",
                h.t, scene.patches[h.patch as usize].name, h.u, h.v
            )?,
            None => writeln!(out, "miss")?,
        }
    }
    Ok(())
}

fn solve_scene(scene: &Scene, ff: &FormFactors, solver: solve::Solver) -> Result<solve::Solution> {
    let parts = solve::SceneParts::new(scene, ff);
    let system = parts.system(ff)?;
    if solver != solve::Solver::Auto {
        let d = solve::diagnose::row_sums(&system);
        if d.rows_above_one > 0 {
            eprintln!("warning: {} rows of F sum above 1 (largest {:.5}): sampling error; --solver auto would scale them back", d.rows_above_one, d.max_row_sum);
        }
    }
    solve::solve(&system, solver, &SolveSettings::default(), &mut |m| {
        eprintln!("{m}")
    })
}

/// Progressive refinement with rows shot on demand (soft backend), and the grids from a second
/// shot of every patch: no N×N matrix and no stored element rows.
fn solve_streaming(
    scene: &Scene,
    settings: &Pass1Settings,
    common: &Common,
    with_grids: bool,
) -> Result<(solve::Solution, Option<Vec<hemi::radiosity::Grid>>)> {
    anyhow::ensure!(
        common.backend()? == Backend::Soft,
        "--solver progressive shoots rows on demand on the soft backend only"
    );
    anyhow::ensure!(
        !common.adaptive,
        "--adaptive refines from solved rows and needs the form-factor matrix: choose a --solver other than progressive"
    );
    let patches = scene.kernel_patches();
    let make = || SoftEngine::new(&patches);
    let n = scene.patches.len();
    // keep at most about a quarter of --matrix-mib in cached rows
    let cache = ((common.matrix_mib << 20) / 4 / (24 * n.max(1) as u64)) as usize;
    let mut shooter = solve::rows::RowShooter::new(scene, settings, &make, cache)?;
    let bar = progress(n as u64, "shots");
    let sol = solve::rows::solve_streaming(
        &mut shooter,
        &SolveSettings {
            tolerance: 1e-6,
            max_iterations: 1_000_000,
        },
        &mut |k, _| bar.set_position(k as u64),
    )?;
    bar.finish_and_clear();
    eprintln!(
        "progressive refinement: {} shots, {} rows shot ({} cached), {} rays, unshot residual {:.2e}",
        sol.iterations, shooter.shot, cache.min(n), shooter.rays, sol.residual
    );
    let grids = if with_grids {
        Some(solve::rows::grids_streaming(&mut shooter, &sol)?)
    } else {
        None
    };
    Ok((sol, grids))
}

fn bench_form_factors(
    out: &mut impl Write,
    circles: &[u32],
    samples: &[u32],
    svg: Option<&std::path::Path>,
) -> Result<()> {
    let mut series: Vec<hemi::chart::Series> = samples
        .iter()
        .map(|k| hemi::chart::Series {
            name: format!(
                "K = {k} (R = {}..{})",
                circles.first().unwrap_or(&0),
                circles.last().unwrap_or(&0)
            ),
            points: vec![],
        })
        .collect();
    let cases = hemi::analytic::howell_cases();
    let scenes: Vec<Scene> = cases
        .iter()
        .map(|(n, src, _)| scene::parse(src, n))
        .collect::<Result<_>>()?;
    writeln!(
        out,
        "| R | K | rays per hemisphere | max error | mean error | rays | seconds |"
    )?;
    writeln!(out, "|---|---|---|---|---|---|---|")?;
    for &r in circles {
        for (ki, &k) in samples.iter().enumerate() {
            let settings = Pass1Settings {
                circles: r,
                samples: k,
                ..Pass1Settings::default()
            };
            let (mut worst, mut sum, mut rays) = (0.0f64, 0.0f64, 0u64);
            let t0 = std::time::Instant::now();
            for (scene, (_, _, want)) in scenes.iter().zip(&cases) {
                let ff = pass1::form_factors(scene, &settings, &|_| {})?;
                let e = (ff.matrix[0][1] - want).abs() / want;
                worst = worst.max(e);
                sum += e;
                rays += ff.stats.rays as u64;
            }
            let secs = t0.elapsed().as_secs_f64();
            writeln!(
                out,
                "| {r} | {k} | {} | {:.3} % | {:.3} % | {rays} | {secs:.3} |",
                hemi_kernel::hemisphere::ray_count(r),
                100.0 * worst,
                100.0 * sum / cases.len() as f64
            )?;
            series[ki].points.push((rays as f64, worst));
        }
    }
    if let Some(path) = svg {
        let chart = hemi::chart::log_log(
            "Form factors: error against rays cast",
            "rays (five cases together)",
            "max relative error of F_12",
            "reference: Howell C-11 and C-14 closed forms; soft backend, band δD rule",
            &series,
        );
        std::fs::write(path, chart)?;
    }
    Ok(())
}

/// An engine that exposes only `rotate` and `nearest_hit` of the soft engine, so the tracer runs
/// the trait's provided ray-by-ray `cast_rings`.
struct PerRay<A>(A);

impl<A: Accelerator> Accelerator for PerRay<A> {
    fn rotate(&mut self, rot: &hemi_kernel::rotation::Rotation, d: Vec3) -> Vec3 {
        self.0.rotate(rot, d)
    }
    fn nearest_hit(&mut self, ray: &Ray, t_max: f32) -> Option<hemi_kernel::accel::Hit> {
        self.0.nearest_hit(ray, t_max)
    }
}

fn bench_per_ray(scene: &Scene, settings: &Pass1Settings) -> Result<(u64, f64)> {
    let hemi = OwnedHemisphere::new(settings.circles, settings.rule)
        .map_err(|e| anyhow::anyhow!("{e:?}"))?;
    let view = hemi.view();
    let patches = scene.kernel_patches();
    let optics = hemi::optics::SceneOptics::new(scene, &view)?;
    let mut scratch =
        hemi::optics::Scratch::new(hemi::optics::pending_for(&view), &settings.specular);
    let mut row = vec![[0.0f32; 3]; optics.columns.len()];
    let points: Vec<_> = (0..patches.len())
        .flat_map(|i| {
            pass1::sample_points(scene, i, settings.samples)
                .into_iter()
                .map(move |p| (i, p))
        })
        .take(64)
        .collect();
    let t0 = std::time::Instant::now();
    let mut rays = 0u64;
    for (q, (i, p)) in points.iter().enumerate() {
        let mut engine = PerRay(SoftEngine::new(&patches));
        let spin = hemi_kernel::rotation::spin_for_sample(q as u32);
        rays += hemi_kernel::tracer::shoot_hemisphere(
            &mut engine,
            &view,
            &optics.view(),
            &mut scratch.view(),
            p.position,
            p.normal,
            spin,
            Some(*i as u32),
            &mut row,
        )
        .rays as u64;
    }
    Ok((rays, t0.elapsed().as_secs_f64()))
}

fn u32_list(s: &str) -> Result<Vec<u32>> {
    s.split(',')
        .map(|x| {
            x.trim()
                .parse::<u32>()
                .with_context(|| format!("bad number `{x}`"))
        })
        .collect()
}

fn parse_ray_line(line: &str, n: usize) -> Result<(Vec3, Vec3)> {
    let v: Vec<f32> = line
        .split_whitespace()
        .map(|t| t.parse::<f32>())
        .collect::<Result<_, _>>()
        .with_context(|| format!("line {n}: expected `x y z dx dy dz`, got `{line}`"))?;
    if v.len() != 6 || v.iter().any(|x| !x.is_finite()) {
        bail!("line {n}: expected 6 finite numbers `x y z dx dy dz`, got `{line}`");
    }
    let dir = Vec3::new(v[3], v[4], v[5])
        .try_normalize()
        .with_context(|| format!("line {n}: zero direction"))?;
    Ok((Vec3::new(v[0], v[1], v[2]), dir))
}

fn stdin_lines() -> impl Iterator<Item = (usize, std::io::Result<String>)> {
    std::io::stdin()
        .lock()
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l))
        .filter(|(_, l)| {
            l.as_ref()
                .map(|s| !s.trim().is_empty() && !s.trim_start().starts_with('#'))
                .unwrap_or(true)
        })
}

fn main() -> Result<()> {
    let cli = Cli::parse();
    // `--backend model` builds a ~100 KB accelerator model per worker thread, on its stack;
    // unoptimised builds copy it several times while building it, beyond rayon's 2 MiB default.
    let _ = rayon::ThreadPoolBuilder::new()
        .stack_size(16 << 20)
        .build_global();
    let out = std::io::stdout();
    let mut out = std::io::BufWriter::new(out.lock());
    match cli.command {
        Command::Render {
            scene,
            output,
            exr,
            spp,
            exposure,
            show_samples,
            common,
        } => {
            common.pass1()?;
            let backend = common.backend()?;
            let counters = Counters::default();
            anyhow::ensure!(
                (1..=4096).contains(&spp),
                "--spp must be between 1 and 4096"
            );
            let scene = scene::load(&scene)?;
            let settings = common.settings_for(&scene)?;
            let camera = hemi::render::camera_of(&scene)?;
            let farm = farm_for(backend, &common)?;
            let t0 = std::time::Instant::now();
            anyhow::ensure!(
                !show_samples || common.adaptive,
                "--show-samples draws the points of adaptive sampling: add --adaptive"
            );
            let mut sampled = Vec::new();
            let (ff_stats, hemispheres, sol, grids, t1) = if common.streaming(&scene) {
                let (sol, grids) = solve_streaming(&scene, &settings, &common, true)?;
                let t1 = std::time::Instant::now();
                (ShotStats::default(), 0, sol, grids.unwrap_or_default(), t1)
            } else {
                let (ff, points) = run_sampling(
                    &scene,
                    &settings,
                    common.adaptive()?,
                    backend,
                    &counters,
                    farm.as_ref(),
                )?;
                sampled = points;
                let t1 = std::time::Instant::now();
                let sol = solve_scene(&scene, &ff, common.solver)?;
                let grids = hemi::radiosity::grids(&scene, &ff, &sol);
                (ff.stats, ff.elements.len(), sol, grids, t1)
            };
            let t2 = std::time::Instant::now();
            let bar = progress(camera.height as u64, "pass 2");
            let patches = scene.kernel_patches();
            let pass1_counts = counters.get();
            let rendered = match backend {
                Backend::Soft => hemi::render::render_with(
                    &scene,
                    &grids,
                    &camera,
                    spp,
                    &settings,
                    &|| SoftEngine::new(&patches),
                    &|n| bar.inc(n),
                )?,
                Backend::Model(cfg) => hemi::render::render_with(
                    &scene,
                    &grids,
                    &camera,
                    spp,
                    &settings,
                    &|| {
                        CountedModel::new(
                            model_engine(&patches, cfg).expect("checked in pass 1"),
                            &counters,
                        )
                    },
                    &|n| bar.inc(n),
                )?,
                Backend::Boards(_) => hemi::board::remote::render(
                    farm.as_ref().context("boards not connected")?,
                    &scene,
                    &settings,
                    &grids,
                    &camera,
                    spp,
                    &|n| bar.inc(n),
                )?,
            };
            let mut img = rendered.image;
            bar.finish_and_clear();
            let t3 = std::time::Instant::now();
            let ev = exposure.unwrap_or_else(|| hemi::render::auto_exposure(&img));
            if show_samples {
                let radius = (camera.height as f32 / 400.0).max(1.0);
                let dots = hemi::overlay::draw_samples(
                    &mut img,
                    &camera,
                    &sampled,
                    &mut SoftEngine::new(&patches),
                    ev,
                    radius,
                );
                eprintln!("--show-samples: {dots} visible sample points drawn");
            }
            hemi::render::write_png(&img, ev, &output)?;
            if let Some(exr) = exr {
                hemi::render::write_exr(&img, &exr)?;
            }
            eprintln!(
                "pass 1 {:.3} s ({} rays), solve {:.3} s ({}, {} sweeps), pass 2 {:.3} s ({}x{}, {} spp), exposure {:+.2} EV -> {}",
                (t1 - t0).as_secs_f64(),
                ff_stats.rays,
                (t2 - t1).as_secs_f64(),
                sol.solver.name(),
                sol.iterations,
                (t3 - t2).as_secs_f64(),
                camera.width,
                camera.height,
                spp,
                ev,
                output.display()
            );
            if ff_stats.specular.frustums + rendered.specular.frustums > 0 {
                eprintln!(
                    "{}",
                    hemi::optics::describe(
                        "specular, pass 1",
                        &ff_stats.specular,
                        ff_stats.rays as u64,
                        &settings.specular
                    )
                );
                eprintln!(
                    "{}",
                    hemi::optics::describe(
                        "specular, pass 2",
                        &rendered.specular,
                        camera.width as u64 * camera.height as u64 * spp as u64,
                        &settings.specular
                    )
                );
            }
            report_model(
                backend,
                &counters,
                hemispheres as u64,
                common.clock_mhz,
                "pass 1 and pass 2",
            );
            if let Backend::Model(_) = backend {
                let (c, r) = counters.get();
                let (c1, r1) = pass1_counts;
                eprintln!(
                    "model: pass 1 {c1} cycles ({:.0} per hemisphere), pass 2 {} cycles for {} rays",
                    c1 as f64 / hemispheres.max(1) as f64,
                    c - c1,
                    r - r1
                );
            }
        }
        Command::FormFactors {
            scene,
            json,
            common,
        } => {
            common.pass1()?;
            let backend = common.backend()?;
            let counters = Counters::default();
            let scene = scene::load(&scene)?;
            let settings = common.settings_for(&scene)?;
            let farm = farm_for(backend, &common)?;
            let (ff, _) = run_sampling(
                &scene,
                &settings,
                common.adaptive()?,
                backend,
                &counters,
                farm.as_ref(),
            )?;
            if json {
                let patches: Vec<_> = scene
                    .patches
                    .iter()
                    .map(|p| serde_json::json!({"name": p.name, "area": p.area}))
                    .collect();
                serde_json::to_writer(
                    &mut out,
                    &serde_json::json!({"patches": patches, "matrix": ff.matrix}),
                )?;
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
                eprintln!(
                    "{}",
                    hemi::optics::describe(
                        "specular",
                        &ff.stats.specular,
                        ff.stats.rays as u64,
                        &settings.specular
                    )
                );
            }
            report_model(
                backend,
                &counters,
                ff.elements.len() as u64,
                common.clock_mhz,
                "pass 1",
            );
        }
        Command::Solve {
            scene,
            json,
            common,
        } => {
            common.pass1()?;
            let backend = common.backend()?;
            let counters = Counters::default();
            let scene = scene::load(&scene)?;
            let settings = common.settings_for(&scene)?;
            let farm = farm_for(backend, &common)?;
            let (sol, hemispheres, ff_stats) = if common.streaming(&scene) {
                let sol = solve_streaming(&scene, &settings, &common, false)?.0;
                (sol, 0, ShotStats::default())
            } else {
                let (ff, _) = run_sampling(
                    &scene,
                    &settings,
                    common.adaptive()?,
                    backend,
                    &counters,
                    farm.as_ref(),
                )?;
                let sol = solve_scene(&scene, &ff, common.solver)?;
                (sol, ff.elements.len(), ff.stats)
            };
            if json {
                let patches: Vec<_> = scene
                    .patches
                    .iter()
                    .zip(&sol.radiosity)
                    .map(|(p, b)| serde_json::json!({"name": p.name, "radiosity": b}))
                    .collect();
                serde_json::to_writer(
                    &mut out,
                    &serde_json::json!({"patches": patches, "iterations": sol.iterations, "residual": sol.residual}),
                )?;
                writeln!(out)?;
            } else {
                for (p, b) in scene.patches.iter().zip(&sol.radiosity) {
                    writeln!(out, "{:<16} {:.6} {:.6} {:.6}", p.name, b[0], b[1], b[2])?;
                }
                eprintln!(
                    "{}: {} iterations, residual {:.2e}",
                    sol.solver.name(),
                    sol.iterations,
                    sol.residual
                );
            }
            if ff_stats.specular.frustums > 0 {
                eprintln!(
                    "{}",
                    hemi::optics::describe(
                        "specular",
                        &ff_stats.specular,
                        ff_stats.rays as u64,
                        &settings.specular
                    )
                );
            }
            report_model(
                backend,
                &counters,
                hemispheres as u64,
                common.clock_mhz,
                "pass 1",
            );
        }
        Command::Irradiance { scene, common } => {
            common.pass1()?;
            let backend = common.backend()?;
            let counters = Counters::default();
            let scene = scene::load(&scene)?;
            let settings = common.settings_for(&scene)?;
            let farm = farm_for(backend, &common)?;
            let (grids, hemispheres) = if common.streaming(&scene) {
                let (_, grids) = solve_streaming(&scene, &settings, &common, true)?;
                (grids.unwrap_or_default(), 0)
            } else {
                let (ff, _) = run_sampling(
                    &scene,
                    &settings,
                    common.adaptive()?,
                    backend,
                    &counters,
                    farm.as_ref(),
                )?;
                let sol = solve_scene(&scene, &ff, common.solver)?;
                (hemi::radiosity::grids(&scene, &ff, &sol), ff.elements.len())
            };
            let hemi = OwnedHemisphere::new(settings.circles, settings.rule)
                .map_err(|e| anyhow::anyhow!("--circles: {e:?}"))?;
            let view = hemi.view();
            let patches = scene.kernel_patches();
            match backend {
                Backend::Soft => irradiance_lines(
                    &mut SoftEngine::new(&patches),
                    &scene,
                    &settings,
                    &view,
                    &grids,
                    &mut out,
                )?,
                Backend::Model(cfg) => irradiance_lines(
                    &mut CountedModel::new(model_engine(&patches, cfg)?, &counters),
                    &scene,
                    &settings,
                    &view,
                    &grids,
                    &mut out,
                )?,
                Backend::Boards(_) => {
                    let farm = farm.as_ref().context("boards not connected")?;
                    for (n, line) in stdin_lines() {
                        let (p, d) = parse_ray_line(&line?, n)?;
                        let e = hemi::board::remote::irradiance(
                            farm,
                            &scene,
                            settings.circles,
                            settings.rule,
                            &grids,
                            p,
                            d,
                        )?;
                        writeln!(out, "{:.6e} {:.6e} {:.6e}", e[0], e[1], e[2])?;
                    }
                    if std::env::var_os("HEMI_BOARD_STATS").is_some() {
                        hemi::board::remote::report(farm, "after the queries");
                    }
                }
            }
            report_model(
                backend,
                &counters,
                hemispheres as u64,
                common.clock_mhz,
                "pass 1 and queries",
            );
        }
        Command::Trace { scene, common } => {
            common.pass1()?;
            let backend = common.backend()?;
            let scene = scene::load(&scene)?;
            let patches = scene.kernel_patches();
            let counters = Counters::default();
            match backend {
                Backend::Soft => trace_lines(&mut SoftEngine::new(&patches), &scene, &mut out)?,
                Backend::Model(cfg) => trace_lines(
                    &mut CountedModel::new(model_engine(&patches, cfg)?, &counters),
                    &scene,
                    &mut out,
                )?,
                Backend::Boards(_) => bail!(
                    "trace: boards answer form-factors, solve, irradiance and render; use --backend soft or model"
                ),
            }
            out.flush()?;
            report_model(backend, &counters, 0, common.clock_mhz, "trace");
        }
        Command::Bench {
            command:
                BenchCommand::Adaptive {
                    scene,
                    reference,
                    uniform,
                    initial,
                    margins,
                    depths,
                    tests,
                    svg,
                    reference_cache,
                    common,
                },
        } => {
            fn list<T: std::str::FromStr>(s: &str) -> Result<Vec<T>> {
                s.split(',')
                    .map(|x| {
                        x.trim()
                            .parse::<T>()
                            .ok()
                            .with_context(|| format!("bad number `{x}`"))
                    })
                    .collect()
            }
            let settings = common.pass1()?;
            let bench = hemi::adaptive::bench::BenchSettings {
                reference,
                uniform: list(&uniform)?,
                initial,
                margins: list(&margins)?,
                depths: list(&depths)?,
                tests: tests
                    .split(',')
                    .map(|t| match t.trim() {
                        "surplus" => Ok(hemi::adaptive::Test::Surplus),
                        "spread" => Ok(hemi::adaptive::Test::Spread),
                        t => bail!("--tests: unknown test `{t}` (surplus, spread)"),
                    })
                    .collect::<Result<_>>()?,
                reference_cache,
            };
            anyhow::ensure!(
                (1..=256).contains(&reference) && (1..=256).contains(&initial),
                "--reference and --initial must be between 1 and 256"
            );
            let command = format!(
                "hemi {}",
                std::env::args().skip(1).collect::<Vec<_>>().join(" ")
            );
            hemi::adaptive::bench::adaptive_vs_uniform(
                &scene::load(&scene)?,
                &settings,
                &bench,
                &mut out,
                svg.as_deref(),
                &command,
            )?;
        }
        Command::Bench {
            command:
                BenchCommand::Trace {
                    scene,
                    rays,
                    tessellate,
                },
        } => {
            let mut sc = scene::load(&scene)?;
            if tessellate > 0 {
                anyhow::ensure!(tessellate <= 64, "--tessellate must be at most 64");
                sc = hemi::bench::tessellate(&sc, tessellate);
            }
            hemi::bench::trace::single_rays(&sc, rays, &mut out)?;
        }
        Command::Bench {
            command: BenchCommand::Cordic { svg },
        } => {
            hemi::bench::cordic_pareto(&mut out, svg.as_deref())?;
        }
        Command::Bench {
            command: BenchCommand::Bezier { scene, svg },
        } => {
            hemi::bench::bezier_accuracy(&scene::load(&scene)?, &mut out, svg.as_deref())?;
        }
        Command::Bench {
            command:
                BenchCommand::Tessellation {
                    scene,
                    grid,
                    common,
                },
        } => {
            let settings = common.pass1()?;
            anyhow::ensure!((1..=32).contains(&grid), "--grid must be between 1 and 32");
            hemi::bench::bezier_vs_tessellated(&scene::load(&scene)?, &settings, grid, &mut out)?;
        }
        Command::Bench {
            command:
                BenchCommand::FormFactors {
                    circles,
                    samples,
                    svg,
                },
        } => {
            let list = |s: &str| -> Result<Vec<u32>> {
                s.split(',')
                    .map(|x| {
                        x.trim()
                            .parse::<u32>()
                            .with_context(|| format!("bad number `{x}`"))
                    })
                    .collect()
            };
            bench_form_factors(&mut out, &list(&circles)?, &list(&samples)?, svg.as_deref())?;
        }
        Command::Bench {
            command:
                BenchCommand::Rays {
                    scene,
                    common,
                    repeat,
                    per_ray,
                },
        } => {
            let settings = common.pass1()?;
            let path = scene.display().to_string();
            let scene = scene::load(&scene)?;
            let all = rayon::current_num_threads();
            for threads in [1, all] {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()?;
                let mut best = f64::INFINITY;
                let mut rays = 0;
                for _ in 0..repeat.max(1) {
                    let t0 = std::time::Instant::now();
                    let ff = pool.install(|| pass1::form_factors(&scene, &settings, &|_| {}))?;
                    best = best.min(t0.elapsed().as_secs_f64());
                    rays = ff.stats.rays;
                }
                writeln!(
                    out,
                    "scene={path} backend=soft circles={} samples={} threads={threads} rays={rays} seconds={best:.4} rays_per_second={:.0}",
                    settings.circles,
                    settings.samples,
                    rays as f64 / best
                )?;
            }
            if per_ray {
                let (rays, secs) = bench_per_ray(&scene, &settings)?;
                writeln!(
                    out,
                    "scene={path} backend=soft-per-ray circles={} samples={} threads=1 rays={rays} seconds={secs:.4} rays_per_second={:.0}",
                    settings.circles,
                    settings.samples,
                    rays as f64 / secs
                )?;
            }
        }
        Command::Bench {
            command:
                BenchCommand::Solvers {
                    scene,
                    circles,
                    samples,
                    furnace,
                    svg_dir,
                },
        } => {
            let settings = Pass1Settings {
                circles,
                samples,
                ..Pass1Settings::default()
            };
            hemi::bench::solvers::bench_solvers(
                &scene::load(&scene)?,
                &settings,
                furnace,
                &mut out,
                svg_dir.as_deref(),
            )?;
        }
        Command::Bench {
            command:
                BenchCommand::Methods {
                    circles,
                    cases,
                    svg_dir,
                },
        } => {
            hemi::bench::methods::bench_methods(
                &u32_list(&circles)?,
                cases,
                &mut out,
                svg_dir.as_deref(),
            )?;
        }
        Command::Bench {
            command:
                BenchCommand::PaperFig9 {
                    scene,
                    patches,
                    samples,
                    circles,
                    reference_circles,
                    svg_dir,
                },
        } => {
            let names: Vec<&str> = patches.split(',').map(str::trim).collect();
            hemi::bench::paper::bench_fig9(
                &scene::load(&scene)?,
                &names,
                samples,
                &u32_list(&circles)?,
                reference_circles,
                &mut out,
                svg_dir.as_deref(),
            )?;
        }
        Command::Bench {
            command: BenchCommand::Quality { scene },
        } => {
            let label = scene.display().to_string();
            hemi::bench::quality::bench_quality(&scene::load(&scene)?, &label, &mut out)?;
        }
        Command::Board {
            command: BoardCommand::Info { backend, firmware },
        } => {
            for b in backend.split(',') {
                let info = hemi::board::info(b, firmware.as_deref())?;
                writeln!(out, "{info}")?;
            }
        }
    }
    out.flush()?;
    Ok(())
}
