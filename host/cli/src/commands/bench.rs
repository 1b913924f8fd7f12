//! `hemi bench`: the benchmarks of crate `hemi-bench` (speed is measured there, never asserted
//! in tests), one argument struct each.

use crate::options::{list, SamplingArgs, TestArg};
use anyhow::Result;
use clap::{Args, Subcommand};
use hemi::scene::load;
use hemi::settings::Pass1Settings;
use hemi_bench::adaptive::BenchSettings;
use std::io::Write;
use std::path::PathBuf;

/// The benchmarks.
#[derive(Subcommand)]
pub enum BenchCommand {
    /// Adaptive against uniform sampling: the error of the radiosity field B(u,v) against rows
    /// computed, measured against a finely sampled uniform reference: a markdown table
    /// (docs/ACCURACY.md).
    Adaptive(AdaptiveBench),
    /// Bezier intersection error (against an f64 Newton reference) over subdivision depth and
    /// flatness, with the cost per ray: a markdown table (docs/ACCURACY.md).
    Bezier(BezierBench),
    /// The accelerator model's CORDIC error against iterations and word width, with latency and
    /// an area proxy: a markdown table with the Pareto front (docs/ACCURACY.md).
    Cordic(CordicBench),
    /// Single rays through the soft engine with and without its BVH: rays/s and the ratio, on
    /// SCENE (optionally tessellated: Bezier patches become 2n² triangles each).
    Trace(TraceBench),
    /// The teapot as Bezier patches (16 samples each) against the same teapot tessellated into
    /// 2n² triangles per patch (1 sample each): time, matrix size, memory, radiosities.
    Tessellation(TessellationBench),
    /// Error against Howell's closed forms and cost, over hemisphere circles R and samples K:
    /// a markdown table (docs/ACCURACY.md).
    FormFactors(FormFactorsBench),
    /// The solvers' convergence (residual against work) on the Cornell box and a ρ = 0.99
    /// furnace: markdown tables, and with --svg-dir the charts solvers-*.svg.
    Solvers(SolversBench),
    /// Hemisphere, hemicube and Monte Carlo at equal rays against Howell B-3: a markdown table,
    /// and with --svg-dir the chart methods-error.svg.
    Methods(MethodsBench),
    /// The paper's figure 9 on the Cornell box: b_R of two patches against R (9a) and rays
    /// against R (9b); with --svg-dir the charts fig9a.svg and fig9b.svg.
    PaperFig9(PaperFig9Bench),
    /// What each --quality preset picks on SCENE, its cost there, and its measured error.
    Quality(QualityBench),
    /// Pass-1 hemisphere rays per second of the soft backend on SCENE, on 1 thread and on all,
    /// printed as one machine-readable line per run.
    Rays(RaysBench),
    /// Pass 1 against the patch count: the Cornell box with its polygons cut n × n and a closed
    /// room holding a tessellated sphere, generated, written as scene files (--write-dir) and
    /// ray files for the Embree comparison (--rays-dir), and timed: a markdown table.
    Scale(ScaleBench),
    /// The modelled accelerator's lanes and hemisphere culling on SCENE's quads subdivided
    /// n × n: cycles per ray against lanes and patch count, the simulation's speed and the area
    /// proxy of each build (docs/PERFORMANCE.md); with --svg-dir the chart lanes-cycles.svg.
    /// With --write-scene FILE, writes SCENE subdivided by the first --subdivide instead.
    Lanes(LanesBench),
}

/// Runs `hemi bench …`, writing the tables to `out`, with a spinner on stderr that shows the
/// elapsed time and the table's last row.
pub fn run(command: BenchCommand, out: &mut impl Write) -> Result<()> {
    let mut out = crate::progress::Spinner::new(out, "bench");
    let result = dispatch(command, &mut out);
    out.finish();
    result
}

fn dispatch(command: BenchCommand, out: &mut impl Write) -> Result<()> {
    match command {
        BenchCommand::Adaptive(b) => b.run(out),
        BenchCommand::Bezier(b) => {
            let svg = chart(&b.svg_dir, "bezier-error.svg");
            hemi_bench::bezier_accuracy(&load(&b.scene)?, out, svg.as_deref())
        }
        BenchCommand::Cordic(b) => {
            hemi_bench::cordic_pareto(out, chart(&b.svg_dir, "cordic-pareto.svg").as_deref())
        }
        BenchCommand::Trace(b) => b.run(out),
        BenchCommand::Tessellation(b) => b.run(out),
        BenchCommand::FormFactors(b) => b.run(out),
        BenchCommand::Solvers(b) => b.run(out),
        BenchCommand::Methods(b) => {
            let circles = list("--circles", &b.circles)?;
            hemi_bench::methods::bench_methods(&circles, b.cases, out, b.svg_dir.as_deref())
        }
        BenchCommand::PaperFig9(b) => b.run(out),
        BenchCommand::Quality(b) => {
            let label = b.scene.display().to_string();
            hemi_bench::quality::bench_quality(&load(&b.scene)?, &label, out)
        }
        BenchCommand::Rays(b) => b.run(out),
        BenchCommand::Scale(b) => b.run(out),
        BenchCommand::Lanes(b) => b.run(out),
    }
}

/// The file `name` in the chart folder `dir`, if one was given.
fn chart(dir: &Option<PathBuf>, name: &str) -> Option<PathBuf> {
    dir.as_ref().map(|d| d.join(name))
}

/// Adaptive against uniform sampling: the error of the radiosity field B(u,v) against rows
/// computed, measured against a finely sampled uniform reference: a markdown table
/// (docs/ACCURACY.md).
#[derive(Args)]
pub struct AdaptiveBench {
    /// The scene file.
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
    /// Comma-separated gradient tests of the adaptive runs.
    #[arg(
        long,
        value_enum,
        value_delimiter = ',',
        default_value = "surplus,spread"
    )]
    tests: Vec<TestArg>,
    /// Write the chart adaptive-error.svg into this folder.
    #[arg(long, value_name = "DIR")]
    svg_dir: Option<PathBuf>,
    /// Keep the reference's grids in this file between runs (recomputed when the scene, K
    /// or R differ).
    #[arg(long)]
    reference_cache: Option<PathBuf>,
    #[command(flatten)]
    sampling: SamplingArgs,
}

/// Bezier intersection error (against an f64 Newton reference) over subdivision depth and
/// flatness, with the cost per ray: a markdown table (docs/ACCURACY.md).
#[derive(Args)]
pub struct BezierBench {
    /// The scene file.
    #[arg(default_value = "scenes/teapot.toml")]
    scene: PathBuf,
    /// Write the chart bezier-error.svg into this folder.
    #[arg(long, value_name = "DIR")]
    svg_dir: Option<PathBuf>,
}

/// The accelerator model's CORDIC error against iterations and word width, with latency and
/// an area proxy: a markdown table with the Pareto front (docs/ACCURACY.md).
#[derive(Args)]
pub struct CordicBench {
    /// Write the chart cordic-pareto.svg (error against latency, one line per word width) into
    /// this folder.
    #[arg(long, value_name = "DIR")]
    svg_dir: Option<PathBuf>,
}

/// Single rays through the soft engine with and without its BVH: rays/s and the ratio, on
/// SCENE (optionally tessellated: Bezier patches become 2n² triangles each).
#[derive(Args)]
pub struct TraceBench {
    /// The scene file.
    #[arg(default_value = "scenes/teapot.toml")]
    scene: PathBuf,
    /// Rays to cast (random origins in the scene's box, random directions; fixed seed;
    /// 1..=10⁸: they are held in memory, at least 24 bytes each).
    #[arg(long, default_value_t = 100_000,
          value_parser = clap::value_parser!(u64).range(1..=100_000_000))]
    rays: u64,
    /// Tessellate Bezier patches into an n×n grid of triangle pairs first (0: keep them).
    #[arg(long, default_value_t = 16)]
    tessellate: usize,
}

/// The teapot as Bezier patches (16 samples each) against the same teapot tessellated into
/// 2n² triangles per patch (1 sample each): time, matrix size, memory, radiosities.
#[derive(Args)]
pub struct TessellationBench {
    /// The scene file.
    #[arg(default_value = "scenes/teapot.toml")]
    scene: PathBuf,
    /// Grid n per patch (2n² triangles; the paper's 50 is n = 5).
    #[arg(long, default_value_t = 5)]
    grid: usize,
    #[command(flatten)]
    sampling: SamplingArgs,
}

/// Error against Howell's closed forms and cost, over hemisphere circles R and samples K:
/// a markdown table (docs/ACCURACY.md).
#[derive(Args)]
pub struct FormFactorsBench {
    /// Comma-separated R values.
    #[arg(long, default_value = "16,32,64,128")]
    circles: String,
    /// Comma-separated K values.
    #[arg(long, default_value = "4,8,16,32")]
    samples: String,
    /// Write the chart form-factor-error.svg (max error against rays, one line per K) into this
    /// folder.
    #[arg(long, value_name = "DIR")]
    svg_dir: Option<PathBuf>,
}

/// The solvers' convergence (residual against work) on the Cornell box and a ρ = 0.99
/// furnace: markdown tables, and with --svg-dir the charts solvers-*.svg.
#[derive(Args)]
pub struct SolversBench {
    /// The scene file.
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
    /// Write the charts (SVG) into this folder.
    #[arg(long)]
    svg_dir: Option<PathBuf>,
}

/// Hemisphere, hemicube and Monte Carlo at equal rays against Howell B-3: a markdown table,
/// and with --svg-dir the chart methods-error.svg.
#[derive(Args)]
pub struct MethodsBench {
    /// Comma-separated R values (the ray budgets).
    #[arg(long, default_value = "8,12,16,24,32,48,64,96,128")]
    circles: String,
    /// Rectangle configurations (fixed seed).
    #[arg(long, default_value_t = 200)]
    cases: usize,
    /// Write the chart (SVG) into this folder.
    #[arg(long)]
    svg_dir: Option<PathBuf>,
}

/// The paper's figure 9 on the Cornell box: b_R of two patches against R (9a) and rays
/// against R (9b); with --svg-dir the charts fig9a.svg and fig9b.svg.
#[derive(Args)]
pub struct PaperFig9Bench {
    /// The scene file.
    #[arg(default_value = "scenes/cornell.toml")]
    scene: PathBuf,
    /// The two patches.
    #[arg(long, default_value = "floor,red_wall/0")]
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
    /// Write the charts (SVG) into this folder.
    #[arg(long)]
    svg_dir: Option<PathBuf>,
}

/// What each --quality preset picks on SCENE, its cost there, and its measured error.
#[derive(Args)]
pub struct QualityBench {
    /// The scene file.
    #[arg(default_value = "scenes/cornell.toml")]
    scene: PathBuf,
}

/// Pass-1 hemisphere rays per second of the soft backend on SCENE, on 1 thread and on all,
/// printed as one machine-readable line per run.
#[derive(Args)]
pub struct RaysBench {
    /// The scene file.
    scene: PathBuf,
    #[command(flatten)]
    sampling: SamplingArgs,
    /// Repeat each measurement this many times and keep the fastest (1..=1000).
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=1000))]
    repeat: u32,
    /// Also measure the accelerator trait's provided ray-by-ray path (rotate each ray, then a
    /// general nearest hit), on one thread over the first 64 sample points: what the
    /// shared-origin casting of the soft engine buys.
    #[arg(long)]
    per_ray: bool,
}

/// The modelled accelerator's lanes and culling (see [`BenchCommand::Lanes`]).
#[derive(Args)]
pub struct LanesBench {
    /// The scene file (diffuse quads and triangles).
    #[arg(default_value = "scenes/cornell.toml")]
    scene: PathBuf,
    /// Comma-separated n: each quad cut into n × n.
    #[arg(long, default_value = "1,2,4,8")]
    subdivide: String,
    /// Comma-separated lane counts.
    #[arg(long, default_value = "1,2,4,8,16")]
    lanes: String,
    /// Hemisphere circles R.
    #[arg(long, default_value_t = 16)]
    circles: u32,
    /// Sample points K × K per patch.
    #[arg(long, default_value_t = 2)]
    samples: u32,
    /// Write the chart lanes-cycles.svg into this folder.
    #[arg(long, value_name = "DIR")]
    svg_dir: Option<PathBuf>,
    /// Write the scene subdivided by the first --subdivide to this file and stop.
    #[arg(long, value_name = "FILE")]
    write_scene: Option<PathBuf>,
}

impl LanesBench {
    fn run(self, out: &mut impl Write) -> Result<()> {
        let scene = load(&self.scene)?;
        let subdivide: Vec<u32> = list("--subdivide", &self.subdivide)?;
        let lanes: Vec<u32> = list("--lanes", &self.lanes)?;
        anyhow::ensure!(
            subdivide.iter().all(|n| (1..=64).contains(n)),
            "--subdivide takes 1..=64"
        );
        anyhow::ensure!(
            lanes.iter().all(|l| (1..=16).contains(l)),
            "--lanes takes 1..=16"
        );
        anyhow::ensure!(
            (1..=256).contains(&self.circles) && (1..=64).contains(&self.samples),
            "--circles takes 1..=256 and --samples 1..=64"
        );
        if let Some(path) = &self.write_scene {
            let n = subdivide.first().copied().unwrap_or(1);
            std::fs::write(path, hemi_bench::lanes::subdivided(&scene, n)?)?;
            return Ok(());
        }
        hemi_bench::lanes::bench(
            &scene,
            &subdivide,
            &lanes,
            self.circles,
            self.samples,
            self.svg_dir.as_deref(),
            out,
        )
    }
}

impl AdaptiveBench {
    fn run(self, out: &mut impl Write) -> Result<()> {
        let settings = self.sampling.settings(false)?;
        anyhow::ensure!(
            (1..=256).contains(&self.reference) && (1..=256).contains(&self.initial),
            "--reference and --initial must be between 1 and 256"
        );
        let bench = BenchSettings {
            reference: self.reference,
            uniform: list("--uniform", &self.uniform)?,
            initial: self.initial,
            margins: list("--margins", &self.margins)?,
            depths: list("--depths", &self.depths)?,
            tests: self.tests.into_iter().map(Into::into).collect(),
            reference_cache: self.reference_cache,
        };
        // the command line, recorded under the table so that it can be regenerated
        let command = format!(
            "hemi {}",
            std::env::args().skip(1).collect::<Vec<_>>().join(" ")
        );
        let scene = load(&self.scene)?;
        let svg = chart(&self.svg_dir, "adaptive-error.svg");
        let svg = svg.as_deref();
        hemi_bench::adaptive::adaptive_vs_uniform(&scene, &settings, &bench, out, svg, &command)?;
        Ok(())
    }
}

impl TraceBench {
    fn run(self, out: &mut impl Write) -> Result<()> {
        let mut scene = load(&self.scene)?;
        if self.tessellate > 0 {
            anyhow::ensure!(self.tessellate <= 64, "--tessellate must be at most 64");
            scene = hemi_bench::tessellate(&scene, self.tessellate);
        }
        hemi_bench::trace::single_rays(&scene, self.rays as usize, out)
    }
}

impl TessellationBench {
    fn run(self, out: &mut impl Write) -> Result<()> {
        let settings = self.sampling.settings(false)?;
        anyhow::ensure!(
            (1..=32).contains(&self.grid),
            "--grid must be between 1 and 32"
        );
        hemi_bench::bezier_vs_tessellated(&load(&self.scene)?, &settings, self.grid, out)
    }
}

impl FormFactorsBench {
    fn run(self, out: &mut impl Write) -> Result<()> {
        let r = list("--circles", &self.circles)?;
        let k = list("--samples", &self.samples)?;
        let svg = chart(&self.svg_dir, "form-factor-error.svg");
        hemi_bench::form_factors::bench_form_factors(out, &r, &k, svg.as_deref())
    }
}

impl SolversBench {
    fn run(self, out: &mut impl Write) -> Result<()> {
        let settings = Pass1Settings {
            circles: self.circles,
            samples: self.samples,
            ..Pass1Settings::default()
        };
        let scene = load(&self.scene)?;
        let dir = self.svg_dir.as_deref();
        hemi_bench::solvers::bench_solvers(&scene, &settings, self.furnace, out, dir)
    }
}

impl PaperFig9Bench {
    fn run(self, out: &mut impl Write) -> Result<()> {
        let names: Vec<&str> = self.patches.split(',').map(str::trim).collect();
        let circles = list("--circles", &self.circles)?;
        let (scene, dir) = (load(&self.scene)?, self.svg_dir.as_deref());
        let (k, r) = (self.samples, self.reference_circles);
        hemi_bench::paper::bench_fig9(&scene, &names, k, &circles, r, out, dir)
    }
}

impl RaysBench {
    fn run(self, out: &mut impl Write) -> Result<()> {
        let settings = self.sampling.settings(false)?;
        let label = self.scene.display().to_string();
        let scene = load(&self.scene)?;
        hemi_bench::rays::rays_per_second(&scene, &label, &settings, self.repeat, out)?;
        if self.per_ray {
            hemi_bench::rays::rays_per_second_per_ray(&scene, &label, &settings, out)?;
        }
        Ok(())
    }
}

/// Pass 1 against the patch count on generated scenes (docs/PERFORMANCE.md, "Pass 1 at
/// scale").
#[derive(Args)]
pub struct ScaleBench {
    /// The scene whose polygons are cut n × n.
    #[arg(long, default_value = "scenes/cornell.toml")]
    base: PathBuf,
    /// Comma-separated n of the cut boxes (20 n² patches); empty for none.
    #[arg(long, default_value = "1,2,4,8,16")]
    cuts: String,
    /// Comma-separated triangle counts of the spheres in the closed room; empty for none.
    #[arg(long, default_value = "10000")]
    rooms: String,
    /// Hemisphere circles R.
    #[arg(long, default_value_t = 64)]
    circles: u32,
    /// K for every scene [default: 8/n on the cut boxes, 1 in the room].
    #[arg(long)]
    samples: Option<u32>,
    /// Write each scene's TOML into this folder.
    #[arg(long, value_name = "DIR")]
    write_dir: Option<PathBuf>,
    /// Write each scene's ray file (`scripts/embree-bench/`) into this folder.
    #[arg(long, value_name = "DIR")]
    rays_dir: Option<PathBuf>,
    /// Only write the files; do not run pass 1.
    #[arg(long)]
    no_run: bool,
    /// Also cast each scene's rays through this Embree program (built by
    /// host/bench/embree/build.sh), right after hemi's pass 1, on as many threads.
    #[arg(long, value_name = "PROGRAM")]
    embree: Option<PathBuf>,
    /// Write the chart scale-hemisphere.svg (one hemisphere's time against the patch count)
    /// into this folder.
    #[arg(long, value_name = "DIR")]
    svg_dir: Option<PathBuf>,
    /// Time each scene's pass 1 (and each Embree mode) this many times and keep the fastest.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=100))]
    repeat: u32,
}

impl ScaleBench {
    fn run(self, out: &mut impl Write) -> Result<()> {
        use hemi_bench::scale::{self, ScaleScene};
        let opt = |name: &str, s: &str| -> Result<Vec<usize>> {
            if s.trim().is_empty() {
                return Ok(Vec::new());
            }
            list(name, s)
        };
        let mut scenes: Vec<ScaleScene> = opt("--cuts", &self.cuts)?
            .into_iter()
            .map(ScaleScene::Subdivided)
            .collect();
        scenes.extend(
            opt("--rooms", &self.rooms)?
                .into_iter()
                .map(ScaleScene::Room),
        );
        anyhow::ensure!(
            scenes
                .iter()
                .all(|s| !matches!(s, ScaleScene::Room(t) if !(20..=2_000_000).contains(t))),
            "--rooms: sphere triangle counts must be between 20 and 2000000"
        );
        anyhow::ensure!(
            (2..=1024).contains(&self.circles)
                && self.samples.is_none_or(|k| (1..=256).contains(&k)),
            "--circles must be between 2 and 1024 and --samples between 1 and 256"
        );
        let cuts = scenes
            .iter()
            .any(|s| matches!(s, ScaleScene::Subdivided(_)));
        let base = if cuts { Some(load(&self.base)?) } else { None };
        if !self.no_run {
            scale::header(out, self.embree.is_some())?;
        }
        let rays_dir = match (&self.rays_dir, &self.embree) {
            (Some(d), _) => Some(d.clone()),
            (None, Some(_)) => Some(std::env::temp_dir().join("hemi-scale-rays")),
            (None, None) => None,
        };
        let mut points = Vec::new();
        for s in scenes {
            let name = s.name();
            let text = s.toml(base.as_ref())?;
            let file = format!("{name}.toml");
            if let Some(dir) = &self.write_dir {
                std::fs::create_dir_all(dir)?;
                std::fs::write(dir.join(&file), &text)?;
            }
            let scene = hemi::scene::parse(&text, &file)?;
            let settings = Pass1Settings {
                circles: self.circles,
                samples: self.samples.unwrap_or(s.default_samples()),
                ..Pass1Settings::default()
            };
            let rays_file = rays_dir.as_ref().map(|d| d.join(format!("{name}.rays")));
            if let (Some(dir), Some(file)) = (&rays_dir, &rays_file) {
                std::fs::create_dir_all(dir)?;
                scale::write_rays(&scene, &settings, file)?;
            }
            if self.no_run {
                continue;
            }
            let hemispheres: usize = (0..scene.patches.len())
                .map(|i| hemi::shots::sample_count(&scene, i, settings.samples))
                .sum();
            let rays = hemi_kernel::hemisphere::ray_count(settings.circles);
            let repeat = self.repeat as usize;
            let all = (hemispheres * repeat) as u64;
            let bar = crate::progress::bar_of_rays(all, &name, rays.into());
            let run = scale::measure_best(&scene, &settings, repeat, &|n| bar.inc(n))?;
            bar.finish_and_clear();
            let embree = match (&self.embree, &rays_file) {
                (Some(program), Some(file)) => {
                    let threads = rayon::current_num_threads();
                    Some(scale::run_embree(program, file, threads, repeat)?)
                }
                _ => None,
            };
            scale::row(out, &name, &settings, &run, embree.as_ref())?;
            let per = |s: f64| s / run.hemispheres.max(1) as f64 * 1e6;
            let embree_us = embree.map(|e| per(e.seconds));
            points.push((s.family(), run.patches, per(run.seconds), embree_us));
        }
        if let (Some(dir), false) = (&self.svg_dir, points.is_empty()) {
            std::fs::create_dir_all(dir)?;
            std::fs::write(dir.join("scale-hemisphere.svg"), scale::chart(&points))?;
        }
        Ok(())
    }
}
