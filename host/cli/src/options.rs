//! The option groups commands share, each flattened only into the commands that use it, with
//! clap `ValueEnum`s for the library's choices and the conversions to its typed settings.

use anyhow::{bail, Result};
use clap::builder::FalseyValueParser;
use clap::{Args, ValueEnum};
use hemi::adaptive::{AdaptiveSettings, Test};
use hemi::backend::Backend;
use hemi::footprint::Need;
use hemi::method::Method;
use hemi::optics::SpecularSettings;
use hemi::quality::Quality;
use hemi::scene::Scene;
use hemi::settings::Pass1Settings;
use hemi::solve::Solver;
use hemi_boards::FirmwareLog;
use hemi_hdl_model::cordic::CordicConfig;
use hemi_hdl_model::{ModelConfig, Params};
use hemi_kernel::geometry::Vec3;
use hemi_kernel::hemisphere::DeltaRule;
use std::path::PathBuf;

/// How δD is assigned to rings.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum DeltaArg {
    /// The exact band integral (default).
    Band,
    /// The paper's cos χ / K.
    Paper,
}

/// The pass-1 method.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum MethodArg {
    /// The paper's hemisphere of R circles.
    Hemisphere,
    /// Cohen & Greenberg's hemicube at the same ray budget.
    Hemicube,
    /// Stratified cosine-weighted Monte Carlo at the same ray budget.
    MonteCarlo,
    /// Plain (unstratified) cosine-weighted Monte Carlo at the same ray budget.
    MonteCarloPlain,
}

/// A `--quality` preset.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum QualityArg {
    /// 3 % target error, a ray budget for a quick look.
    Draft,
    /// 0.5 % target error.
    Default,
    /// 0.1 % target error, no ray budget.
    High,
}

/// The radiosity solver.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum SolverArg {
    /// Measure the system and pick, saying why on stderr.
    Auto,
    /// Gauss-Seidel sweeps, the paper's solver.
    #[value(alias = "gs")]
    GaussSeidel,
    /// Successive over-relaxation with ω from the measured spectral radius.
    Sor,
    /// Jacobi sweeps (the textbook baseline).
    Jacobi,
    /// Dense LU with partial pivoting.
    Direct,
    /// Progressive refinement shooting rows on demand (never forms the N×N matrix).
    Progressive,
}

/// What adaptive sampling's gradient test compares.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum TestArg {
    /// Each sample against the previous level's interpolation of it.
    Surplus,
    /// The paper's: the window's max − min.
    Spread,
}

impl From<MethodArg> for Method {
    fn from(m: MethodArg) -> Method {
        match m {
            MethodArg::Hemisphere => Method::Hemisphere,
            MethodArg::Hemicube => Method::Hemicube,
            MethodArg::MonteCarlo => Method::MonteCarlo { stratified: true },
            MethodArg::MonteCarloPlain => Method::MonteCarlo { stratified: false },
        }
    }
}

impl From<QualityArg> for Quality {
    fn from(q: QualityArg) -> Quality {
        match q {
            QualityArg::Draft => Quality::Draft,
            QualityArg::Default => Quality::Default,
            QualityArg::High => Quality::High,
        }
    }
}

impl From<SolverArg> for Solver {
    fn from(s: SolverArg) -> Solver {
        match s {
            SolverArg::Auto => Solver::Auto,
            SolverArg::GaussSeidel => Solver::GaussSeidel,
            SolverArg::Sor => Solver::Sor,
            SolverArg::Jacobi => Solver::Jacobi,
            SolverArg::Direct => Solver::Direct,
            SolverArg::Progressive => Solver::Progressive,
        }
    }
}

impl From<TestArg> for Test {
    fn from(t: TestArg) -> Test {
        match t {
            TestArg::Surplus => Test::Surplus,
            TestArg::Spread => Test::Spread,
        }
    }
}

/// Which ray engine runs the passes, and how the modelled accelerator and the boards are set.
#[derive(Args, Clone, Debug)]
pub struct EngineArgs {
    /// Ray engine: soft | model | rtl | qemu | serial:PATH (boards comma-separated to spread
    /// jobs). `rtl` runs the one-lane build's Verilog in its Verilator simulator (`cargo xtask
    /// rtl-sim` builds it; planar scenes).
    #[arg(long, default_value = "soft")]
    pub backend: String,
    /// The RTL's simulator program, for `--backend rtl` (default: where `cargo xtask rtl-sim`
    /// builds it, target/rtl/sim/accel-sim under the working folder).
    #[arg(long, value_name = "PATH")]
    pub rtl_sim: Option<std::path::PathBuf>,
    #[command(flatten)]
    pub model: ModelArgs,
    #[command(flatten)]
    pub boards: BoardArgs,
}

impl ModelArgs {
    /// Whether any option of the modelled accelerator differs from its default: on the soft
    /// backend they would do nothing, which is said rather than passed over.
    pub fn changed(&self) -> bool {
        use clap::{CommandFactory as _, FromArgMatches as _, Parser};
        #[derive(Parser)]
        struct Defaults {
            #[command(flatten)]
            model: ModelArgs,
        }
        let matches = Defaults::command().get_matches_from(["hemi"]);
        Defaults::from_arg_matches(&matches).is_ok_and(|d| d.model != *self)
    }
}

/// The slowest placed unit's clock (`cargo xtask rtl`'s Fmax, session 46: the set-up pass joined to
/// its bitmap writer at its first placement seed, where every unit met 100 MHz, once the set-up
/// family's products took their registers in their DSP tiles, `rtl/mul18.v`; 101.0 in session 45,
/// the same pass at its sixth seed, after its reach's bins were shared and narrowed; 101.8 at that
/// session's start, the same pass at its third seed; 102.5 in session 43, the horizon filter with
/// the slot boxes' write path, once the set-up unit's waiting words had moved into LUT RAM; 100.1
/// in session 38, a bank's set-up pass, its front and set-up unit, at the first placement seed;
/// 99.9 in session 37, the same pass, the best of three seeds; 101.1 in session 36, the same pass
/// joined to its bitmap writer; 97.4 in session 35; 101.2, the culling unit's patch side, in
/// session 33; 92.8, a bank's whole set-up pass, in session 32; 103.0, the register file's, in
/// session 31), where the model's reports had assumed 100 MHz.
pub const MEASURED_CLOCK_MHZ: f64 = 100.9;

/// The modelled accelerator (`--backend model`, and the CORDIC of boards' models).
#[derive(Args, Clone, Debug, PartialEq)]
pub struct ModelArgs {
    /// Accelerator clock at which `--backend model` reports time: by default the slowest unit's
    /// clock as `cargo xtask rtl` places each unit on an ECP5-85k (docs/PERFORMANCE.md, session
    /// 46: the joined set-up pass, 100.9 MHz). The whole datapath has not been placed.
    #[arg(long, default_value_t = MEASURED_CLOCK_MHZ)]
    pub clock_mhz: f64,
    /// CORDIC iterations of the modelled accelerator (`--backend model`, and boards' models).
    #[arg(long, default_value_t = CordicConfig::DEFAULT.iterations)]
    pub cordic_iterations: u32,
    /// CORDIC word width in bits of the modelled accelerator (`--backend model`, and boards').
    #[arg(long, default_value_t = CordicConfig::DEFAULT.width)]
    pub cordic_width: u32,
    /// Bezier subdivision depth of the modelled accelerator (`--backend model`; 1..=13 with its
    /// 40-entry stack).
    #[arg(long, default_value_t = ModelConfig::default().subdivision_depth)]
    pub bezier_depth: u32,
    /// Bezier control-point datapath width in bits of the modelled accelerator
    /// (`--backend model`; 12..=26).
    #[arg(long, default_value_t = ModelConfig::default().coord_width)]
    pub bezier_width: u32,
    /// Intersection lanes of the modelled accelerator (`--backend model`; 1..=16).
    #[arg(long, default_value_t = Params::DEFAULT.lanes)]
    pub lanes: u32,
    /// Azimuth sectors of its hemisphere culling (`--backend model`; 0 for none, or 8, 16, 32, 64).
    #[arg(long, default_value_t = Params::DEFAULT.sectors)]
    pub sectors: u32,
    /// Rays its front end takes and returns per clock (`--backend model`; 1..=4).
    #[arg(long, default_value_t = Params::DEFAULT.rays_per_clock)]
    pub rays_per_clock: u32,
    /// Patch slots per bank of its on-chip patch memory (`--backend model`; banks = lanes / ray
    /// groups, banks × slots ≤ 4096; a larger scene streams through them in blocks).
    #[arg(long, default_value_t = Params::DEFAULT.bank_slots)]
    pub bank_slots: u32,
    /// The wide datapath instead of the compact one sized for an ECP5-85k (`--backend model`;
    /// docs/PERFORMANCE.md): set-up passes wait for idle lanes.
    #[arg(long)]
    pub wide_datapath: bool,
    /// Ray groups the lanes form (`--backend model`; dividing --lanes): each group holds all
    /// the patches and takes every n-th ray.
    #[arg(long, default_value_t = Params::DEFAULT.ray_groups)]
    pub ray_groups: u32,
}

impl ModelArgs {
    /// Refuses CORDIC settings the accelerator cannot be built with (its CONFIG fields would
    /// otherwise wrap), naming both options and their ranges.
    pub fn check_cordic(&self) -> Result<()> {
        use hemi_hdl_model::cordic::{
            CordicConfig, MAX_ITERATIONS, MAX_WIDTH, MIN_ITERATIONS, MIN_WIDTH,
        };
        let c = CordicConfig {
            iterations: self.cordic_iterations,
            width: self.cordic_width,
        };
        if !c.is_valid() {
            bail!(
                "--cordic-iterations {} --cordic-width {}: the accelerator takes \
                 {MIN_ITERATIONS}..={MAX_ITERATIONS} iterations, widths {MIN_WIDTH}..={MAX_WIDTH} \
                 bits, and at most width − 2 iterations",
                c.iterations,
                c.width
            );
        }
        // an FPGA clock: from a kilohertz (a slow test clock) to 10 GHz, well past any part
        if !(self.clock_mhz >= 1e-3 && self.clock_mhz <= 1e4) {
            bail!(
                "--clock-mhz {}: must be a clock in MHz between 0.001 and 10000",
                hemi::scene::range::show(self.clock_mhz)
            );
        }
        Ok(())
    }
}

/// How boards are booted and driven (the environment variables are read here only; a flag's
/// variable counts as set unless it is empty, 0, false, no or off).
#[derive(Args, Clone, Debug, Default)]
pub struct BoardArgs {
    #[command(flatten)]
    pub qemu: QemuArgs,
    /// The engine boards run jobs on.
    #[arg(long, value_enum, env = "HEMI_BOARD_ACCEL", default_value = "own")]
    pub board_accel: BoardAccelArg,
    /// Print the boards' counters (jobs, rays, ticks per ray, stack, link) after each pass.
    #[arg(long, env = "HEMI_BOARD_STATS", value_parser = FalseyValueParser::new())]
    pub board_stats: bool,
    /// Do not log board reconnections and re-issued jobs.
    #[arg(long, env = "HEMI_QUIET_BOARDS", value_parser = FalseyValueParser::new())]
    pub quiet_boards: bool,
}

/// How QEMU boards are booted.
#[derive(Args, Clone, Debug, Default)]
pub struct QemuArgs {
    /// Firmware ELF QEMU boards boot (default: built from this checkout if missing).
    #[arg(long, env = "HEMI_FIRMWARE_ELF")]
    pub firmware: Option<PathBuf>,
    /// The QEMU binary `--backend qemu` starts.
    #[arg(long, env = "HEMI_QEMU", default_value = "qemu-system-arm")]
    pub qemu: String,
    /// Boot QEMU with `-icount shift=0`, so the boards' SysTick counts instructions.
    #[arg(long, env = "HEMI_QEMU_ICOUNT", value_parser = FalseyValueParser::new())]
    pub qemu_icount: bool,
    /// Print the QEMU firmware's defmt log, decoded with the booted ELF's table, one line per
    /// message prefixed with its QEMU's pid: to stderr, or to FILE with --firmware-log=FILE
    /// (HEMI_FIRMWARE_LOG: `-` for stderr, or a path). Off by default, and then not decoded.
    #[arg(
        long,
        env = "HEMI_FIRMWARE_LOG",
        value_name = "FILE",
        num_args = 0..=1,
        require_equals = true,
        default_missing_value = "-"
    )]
    pub firmware_log: Option<PathBuf>,
}

/// The engine boards are asked to run jobs on.
#[derive(Clone, Copy, Debug, Default, ValueEnum)]
pub enum BoardAccelArg {
    /// Each board's own: its accelerator, or its model under QEMU.
    #[default]
    #[value(alias = "none", alias = "model", alias = "mmio")]
    Own,
    /// The firmware's soft fallback: the kernel in f32 on the board's CPU (for measurements).
    Soft,
}

impl QemuArgs {
    /// How QEMU boards are started. A log file is created here, before any board boots.
    pub fn options(&self) -> Result<hemi_boards::QemuOptions> {
        let log = match self.firmware_log.as_deref() {
            None => None,
            Some(path) if path.as_os_str() == "-" => Some(FirmwareLog::stderr()),
            Some(path) => Some(FirmwareLog::create(path)?),
        };
        Ok(hemi_boards::QemuOptions {
            program: self.qemu.clone(),
            icount: self.qemu_icount,
            log,
        })
    }
}

/// A `--quality` preset for R and K (and with `--adaptive` the margin and depth).
#[derive(Args, Clone, Debug)]
pub struct QualityArgs {
    /// Preset R and K from a target error and the scene's size (overrides --circles and
    /// --samples, or with --adaptive --circles, --margin and --max-depth; see
    /// docs/PERFORMANCE.md for what each costs).
    #[arg(long, value_enum)]
    pub quality: Option<QualityArg>,
}

/// Hemisphere, lattice, method and specular bounds: everything [`Pass1Settings`] holds.
#[derive(Args, Clone, Debug)]
pub struct SamplingArgs {
    /// Hemisphere circles R (M = 4R rays on the horizon circle).
    #[arg(long, default_value_t = 64)]
    pub circles: u32,
    /// Initial K×K sample points per polygon patch [default: 16, or 2 with --adaptive].
    #[arg(long)]
    pub samples: Option<u32>,
    /// Delta form factor rule.
    #[arg(long, value_enum, default_value = "band")]
    pub delta: DeltaArg,
    /// Pass-1 method; the peers shoot as many rays per sample point as the hemisphere of
    /// --circles.
    #[arg(long, value_enum, default_value = "hemisphere")]
    pub method: MethodArg,
    /// Δ of paper §6.5: specular frustums carrying less than this fraction of their primary ray
    /// are not shot.
    #[arg(long, default_value_t = hemi_kernel::specular::DEFAULT_THRESHOLD)]
    pub specular_threshold: f32,
    /// Capacity of the skeleton stack (paper §6.2): the frustums waiting to be shot.
    #[arg(long, default_value_t = 64)]
    pub stack: usize,
    /// The most specular bounces one path may take (paper §5).
    #[arg(long, default_value_t = 24)]
    pub max_bounces: u16,
}

impl SamplingArgs {
    /// The settings, checked, K defaulting to 16 (2 when `adaptive`); `--quality` is applied by
    /// [`QualityArgs::for_scene`] once the scene is loaded.
    pub fn settings(&self, adaptive: bool) -> Result<Pass1Settings> {
        if self.circles < 2 || self.circles > MOST_CIRCLES {
            bail!(
                "--circles {}: must be between 2 and {MOST_CIRCLES}",
                self.circles
            );
        }
        if matches!(self.delta, DeltaArg::Paper) && !matches!(self.method, MethodArg::Hemisphere) {
            eprintln!(
                "warning: --delta paper has no effect with --method {}: the peers weight their \
                 own rays",
                self.method
                    .to_possible_value()
                    .map_or(String::new(), |v| v.get_name().into())
            );
        }
        let samples = self.samples.unwrap_or(if adaptive { 2 } else { 16 });
        if !(1..=256).contains(&samples) {
            bail!("--samples {samples}: must be between 1 and 256");
        }
        Ok(Pass1Settings {
            circles: self.circles,
            samples,
            rule: match self.delta {
                DeltaArg::Band => DeltaRule::Band,
                DeltaArg::Paper => DeltaRule::Paper,
            },
            specular: SpecularSettings {
                threshold: self.specular_threshold,
                stack: self.stack,
                max_bounces: self.max_bounces,
            },
            method: self.method.into(),
        })
    }
}

impl QualityArgs {
    /// `settings` (from [`SamplingArgs::settings`]) with `--quality` applied for `scene`
    /// (saying on stderr what it picked).
    pub fn for_scene(
        &self,
        mut settings: Pass1Settings,
        scene: &Scene,
        adaptive: bool,
    ) -> Pass1Settings {
        if let Some(q) = self.quality {
            let p = if adaptive {
                hemi::quality::apply_adaptive(q.into(), scene, &mut settings)
            } else {
                hemi::quality::apply(q.into(), scene, &mut settings)
            };
            eprintln!("{}", p.why);
        }
        settings
    }
}

/// The finest lattice side adaptive sampling may reach, K·2^depth (a 2×2 guess at depth 8).
const MAX_LATTICE: u64 = 512;

/// The budget of reading a scene's files.
#[derive(Args, Clone, Debug)]
pub struct LimitArgs {
    /// The largest file a scene may read (the TOML, and each OBJ, MTL and .bpt file), in MiB:
    /// parsing the TOML takes about a hundred times its size.
    #[arg(long, default_value_t = hemi::scene::DEFAULT_FILE_MIB, value_name = "MIB")]
    pub max_file_mib: u64,
}

impl LimitArgs {
    /// The scene at `path`, read within the limits.
    pub fn load(&self, path: &std::path::Path) -> Result<Scene> {
        let limits = hemi::scene::Limits {
            file_bytes: self.max_file_mib.saturating_mul(1 << 20),
        };
        hemi::scene::load_with(path, &limits)
    }
}

/// Adaptive patch sampling (paper §4).
#[derive(Args, Clone, Debug)]
pub struct AdaptiveArgs {
    /// Adaptive patch sampling: refine each patch where the gradient test fails.
    #[arg(long)]
    pub adaptive: bool,
    /// Gradient test margin (--adaptive): a 4-sample window fails when its luminances spread
    /// by more than this fraction of their mean.
    #[arg(long, default_value_t = 0.1, requires = "adaptive")]
    pub margin: f64,
    /// Most subdivision levels beyond the initial guess (--adaptive).
    #[arg(long, default_value_t = 4, requires = "adaptive")]
    pub max_depth: u32,
    /// What the gradient test compares (--adaptive).
    #[arg(long, value_enum, default_value = "surplus", requires = "adaptive")]
    pub test: TestArg,
}

impl AdaptiveArgs {
    /// Whether pass 1 samples adaptively (`--adaptive`).
    pub fn on(&self) -> bool {
        self.adaptive
    }

    /// The settings when sampling adaptively ([`AdaptiveArgs::on`]), else `None` (uniform K×K); a `--quality` preset sets the
    /// margin and depth, as it sets R and K.
    /// `k` is the initial K of the lattice, which the depth bound counts from.
    pub fn settings(
        &self,
        quality: Option<QualityArg>,
        k: u32,
    ) -> Result<Option<AdaptiveSettings>> {
        if !self.on() {
            return Ok(None);
        }
        if !(self.margin >= 0.0 && self.margin.is_finite()) {
            bail!("--margin {}: must be a finite number ≥ 0", self.margin);
        }
        let (margin, max_depth) = quality.map_or((self.margin, self.max_depth), |q| {
            Quality::from(q).adaptive()
        });
        let finest = u64::from(k.max(1)) << max_depth.min(32);
        if finest > MAX_LATTICE {
            let deepest = (MAX_LATTICE / u64::from(k.max(1))).max(1).ilog2();
            bail!(
                "--max-depth {max_depth} from --samples {k}: a patch could be refined to \
                 {finest}×{finest} points, past the {MAX_LATTICE}×{MAX_LATTICE} adaptive \
                 sampling keeps (its rows grow with the square); at K = {k} the depth is at most \
                 {deepest}"
            );
        }
        Ok(Some(AdaptiveSettings {
            margin,
            max_depth,
            test: self.test.into(),
            ..AdaptiveSettings::default()
        }))
    }
}

/// The solve of (2.6).
#[derive(Args, Clone, Debug)]
pub struct SolverArgs {
    /// Radiosity solver.
    #[arg(long, value_enum, default_value = "auto")]
    pub solver: SolverArg,
    /// Memory pass 1's form factors may take, in MiB (element rows and sparse patch rows;
    /// estimated before pass 1 from a pilot of hemispheres when the dense bound passes it, and
    /// counted while it runs); above it, `--solver auto` shoots rows on demand with progressive
    /// refinement instead.
    #[arg(long, default_value_t = 4096)]
    pub matrix_mib: u64,
}

impl SolverArgs {
    /// The bytes `--matrix-mib` allows.
    pub fn limit(&self) -> u64 {
        self.matrix_mib.saturating_mul(1 << 20)
    }

    /// Whether this run solves without stored rows: `--solver progressive`, or `auto` on a
    /// scene whose pass 1 would take more than `--matrix-mib` (said on stderr). An explicit
    /// solver that needs the rows is refused past `--matrix-mib`, before pass 1 takes them.
    pub fn streaming(&self, backend: &dyn Backend) -> Result<bool> {
        if self.solver == SolverArg::Progressive {
            return Ok(true);
        }
        let need = Need::of(backend, self.limit())?;
        let n = backend.scene().patches.len();
        let over = need.bytes > self.limit();
        Ok(match self.solver {
            SolverArg::Auto if over => {
                eprintln!(
                    "solver auto: pass 1 of {n} patches needs {} of form factors (> --matrix-mib \
                     {}): progressive refinement with rows shot on demand",
                    need.describe(),
                    self.matrix_mib
                );
                true
            }
            SolverArg::Auto => {
                if need.pilot > 0 {
                    eprintln!(
                        "pass 1 of {n} patches: {} of form factors, within --matrix-mib {}",
                        need.describe(),
                        self.matrix_mib
                    );
                }
                false
            }
            explicit => {
                let name = explicit
                    .to_possible_value()
                    .map(|v| v.get_name().to_string());
                let what = format!("--solver {}", name.unwrap_or_default());
                refuse_over(
                    &need,
                    n,
                    self.matrix_mib,
                    &what,
                    "--solver progressive, or ",
                )?;
                if explicit == SolverArg::Direct {
                    self.check_lu(n)?;
                }
                false
            }
        })
    }

    /// Refuses `--solver direct` on `n` patches when its dense N×N matrix and LU factors pass
    /// `--matrix-mib`, and says what the factorisation will cost when auto would not choose it.
    fn check_lu(&self, n: usize) -> Result<()> {
        let bytes = 16u64.saturating_mul(n as u64).saturating_mul(n as u64);
        if bytes > self.limit() {
            bail!(
                "--solver direct: the dense LU of {n} patches needs {:.1} MiB (an N×N matrix and \
                 its factors), more than --matrix-mib {} (--solver auto or gauss-seidel sweep the \
                 sparse rows, or a larger --matrix-mib)",
                hemi::footprint::mib(bytes),
                self.matrix_mib
            );
        }
        if n > hemi::solve::DIRECT_LIMIT {
            let flop = |n: f64| 2.0 * n.powi(3) / 3.0;
            let most = hemi::solve::DIRECT_LIMIT;
            eprintln!(
                "--solver direct: the dense LU of {n} patches is {:.0} GFLOP a channel, {:.0}× \
                 the largest auto factors ({most} patches)",
                flop(n as f64) / 1e9,
                flop(n as f64) / flop(most as f64)
            );
        }
        Ok(())
    }
}

/// Refuses a run (`what`) whose pass 1 needs more than `matrix_mib`, naming the figure and the
/// options (`alternative`, then `--matrix-mib`) that avoid it.
pub fn check_matrix(
    backend: &dyn Backend,
    matrix_mib: u64,
    what: &str,
    alternative: &str,
) -> Result<()> {
    let need = Need::of(backend, matrix_mib.saturating_mul(1 << 20))?;
    refuse_over(
        &need,
        backend.scene().patches.len(),
        matrix_mib,
        what,
        alternative,
    )
}

/// The refusal of [`check_matrix`] for a known `need` of `n` patches.
fn refuse_over(
    need: &Need,
    n: usize,
    matrix_mib: u64,
    what: &str,
    alternative: &str,
) -> Result<()> {
    if need.bytes > matrix_mib.saturating_mul(1 << 20) {
        bail!(
            "{what}: pass 1 of {n} patches needs {} of form factors, more than --matrix-mib \
             {matrix_mib} ({alternative}a larger --matrix-mib)",
            need.describe()
        );
    }
    Ok(())
}

/// The field at the elements ([`hemi::field`]): gather sweeps after the patch solve.
#[derive(Args, Clone, Debug)]
pub struct FieldArgs {
    /// Element-level gather sweeps after the patch solve: each element gathers the radiosity
    /// field at its hemisphere's hits instead of patch averages (0: the paper's element values
    /// (4.2) from the patch solution); they stop at --gather-tolerance.
    #[arg(long, default_value_t = DEFAULT_SWEEPS, value_name = "SWEEPS")]
    pub gather: u32,
    /// Stop the sweeps when no element value changes by more than this fraction of the largest.
    #[arg(long, default_value_t = 1e-4)]
    pub gather_tolerance: f64,
    /// Memory for the recorded element transport (MiB): what each element's hemisphere gathers
    /// from each grid vertex, cast once so the sweeps need no rays; past it every sweep
    /// re-casts its hemispheres (said on stderr).
    #[arg(long, default_value_t = 1024, value_name = "MIB")]
    pub field_mib: u64,
    /// Rounds of refinement by the field's own error: patches whose grid is estimated to miss
    /// their light by more than --refine-tolerance are sampled twice as finely and the field
    /// solved again (0: the field at pass 1's sampling).
    #[arg(long, default_value_t = DEFAULT_REFINE_ROUNDS, value_name = "ROUNDS")]
    pub refine: u32,
    /// The grid error (a fraction of the light) refinement aims at.
    #[arg(long, default_value_t = 0.01, value_name = "FRACTION")]
    pub refine_tolerance: f64,
    /// The most elements (sample points, all patches together) refinement may reach [default:
    /// 11/4 of pass 1's].
    #[arg(long, value_name = "N")]
    pub max_elements: Option<usize>,
}

/// Gather sweeps at most, by default: with the recorded transport a sweep costs no rays, so
/// the sweeps run to the tolerance (9 on the Cornell box; docs/ACCURACY.md, "The field against
/// Radiance 6.0a").
const DEFAULT_SWEEPS: u32 = 20;

/// Refinement rounds by default: from K = 16, two rounds let a patch reach 64 × 64 where its
/// light needs it (docs/ACCURACY.md, "Refinement by the field's own error").
const DEFAULT_REFINE_ROUNDS: u32 = 2;

impl FieldArgs {
    /// The settings, checked.
    pub fn settings(&self) -> Result<hemi::field::FieldSettings> {
        let sweeps = self.gather;
        if sweeps > 1000 {
            bail!("--gather {sweeps}: must be at most 1000 sweeps");
        }
        if !(self.gather_tolerance >= 0.0 && self.gather_tolerance.is_finite()) {
            bail!(
                "--gather-tolerance {}: must be a finite number ≥ 0",
                self.gather_tolerance
            );
        }
        Ok(hemi::field::FieldSettings {
            sweeps,
            tolerance: self.gather_tolerance,
            direct: hemi::direct::Direct::Exact,
            transport_bytes: self.field_mib.saturating_mul(1 << 20),
            refine: self.refine()?,
        })
    }

    /// The refinement settings, checked.
    fn refine(&self) -> Result<hemi::field::refine::RefineSettings> {
        let rounds = self.refine;
        if rounds > 8 {
            bail!(
                "--refine {rounds}: must be at most 8 rounds (each quadruples a patch's elements)"
            );
        }
        if !(self.refine_tolerance > 0.0 && self.refine_tolerance < 1.0) {
            bail!(
                "--refine-tolerance {}: must be a fraction above 0 and below 1",
                self.refine_tolerance
            );
        }
        Ok(hemi::field::refine::RefineSettings {
            rounds,
            tolerance: self.refine_tolerance,
            max_elements: self.max_elements,
            ..Default::default()
        })
    }
}

/// The most circles R of a hemisphere (`--circles`, and a query's own, `--query-circles`).
pub const MOST_CIRCLES: u32 = 1024;

/// A comma-separated list of numbers (`--circles 16,32,64`), with the option named in errors.
pub fn list<T: std::str::FromStr>(option: &str, s: &str) -> Result<Vec<T>> {
    s.split(',')
        .map(|x| {
            x.trim()
                .parse::<T>()
                .map_err(|_| anyhow::anyhow!("{option}: bad number `{x}`"))
        })
        .collect()
}

/// The view of pass 2, overriding the scene's `[camera]` (rpict's `-vp`, `-vh`/`-vv`, `-x -y`;
/// the direction is given by a point looked at, as in the scene file).
#[derive(Args, Clone, Debug, Default)]
pub struct ViewArgs {
    /// Image size in pixels, `WIDTHxHEIGHT` (default: the scene's camera, else 512x512).
    #[arg(long, value_name = "WxH")]
    pub size: Option<String>,
    /// Eye position `X,Y,Z`, in scene units (default: the scene's camera).
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub eye: Option<String>,
    /// The point looked at, `X,Y,Z` (default: the scene's camera).
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub look_at: Option<String>,
    /// Vertical field of view in degrees, as the scene's `fov_y_deg` (default: the scene's
    /// camera, else 40).
    #[arg(long, value_name = "DEG")]
    pub fov: Option<f64>,
}

impl ViewArgs {
    /// The scene's camera with the overrides applied; a scene without a `[camera]` needs
    /// `--eye` and `--look-at` (up is then +y, or +z when looking along y).
    pub fn camera(&self, scene: Option<&hemi::scene::Camera>) -> Result<hemi::scene::Camera> {
        let point = |option: &str, s: &Option<String>| -> Result<Option<Vec3>> {
            let Some(s) = s else { return Ok(None) };
            let v: Vec<f64> = list(option, s)?;
            if v.len() != 3 {
                bail!("{option} {s}: expected three numbers X,Y,Z");
            }
            let mut p = [0.0f32; 3];
            for (k, x) in v.iter().enumerate() {
                p[k] = hemi::scene::range::coordinate(*x)
                    .map_err(|e| anyhow::anyhow!("{option} {s}: component {k}: {e}"))?;
            }
            Ok(Some(Vec3::new(p[0], p[1], p[2])))
        };
        let (eye, look_at) = (
            point("--eye", &self.eye)?,
            point("--look-at", &self.look_at)?,
        );
        let size = self.size.as_deref().map(parse_size).transpose()?;
        if let Some(fov) = self.fov {
            if !(fov > 0.0 && fov < 180.0) {
                bail!("--fov {fov}: the field of view must be between 0 and 180 degrees");
            }
        }
        let mut camera = match (scene, eye, look_at) {
            (Some(c), _, _) => c.clone(),
            (None, Some(eye), Some(look_at)) => default_camera(eye, look_at),
            (None, _, _) => bail!(
                "the scene has no [camera] table: give --eye X,Y,Z and --look-at X,Y,Z (or add \
                 one, docs/scene-format.md)"
            ),
        };
        camera.eye = eye.unwrap_or(camera.eye);
        camera.look_at = look_at.unwrap_or(camera.look_at);
        // the kernel's own test of a camera frame, blamed on the options that made it
        let framed = || {
            let c = &camera;
            let fov = c.fov_y_deg as f32;
            hemi_kernel::camera::Camera::look_at(c.eye, c.look_at, c.up, fov, 1, 1).is_some()
        };
        if (eye.is_some() || look_at.is_some()) && !framed() {
            let d = camera.look_at - camera.eye;
            bail!(
                "--eye and --look-at: the view direction {} is zero or parallel to up {}",
                show3(d),
                show3(camera.up)
            );
        }
        camera.fov_y_deg = self.fov.unwrap_or(camera.fov_y_deg);
        if let Some((w, h)) = size {
            (camera.width, camera.height) = (w, h);
        }
        Ok(camera)
    }
}

/// `(x, y, z)` for messages.
fn show3(v: Vec3) -> String {
    format!("({}, {}, {})", v.x, v.y, v.z)
}

/// A camera for a scene without one: up +y (+z when looking along y), 40°, 512×512.
fn default_camera(eye: Vec3, look_at: Vec3) -> hemi::scene::Camera {
    let d = look_at - eye;
    let along_y = d.y.abs() > 0.99 * d.length();
    hemi::scene::Camera {
        eye,
        look_at,
        up: if along_y {
            Vec3::Z
        } else {
            Vec3::new(0.0, 1.0, 0.0)
        },
        fov_y_deg: 40.0,
        width: 512,
        height: 512,
    }
}

/// `WIDTHxHEIGHT`, each 1..=16384.
fn parse_size(s: &str) -> Result<(u32, u32)> {
    let bad = || anyhow::anyhow!("--size {s}: expected WIDTHxHEIGHT, e.g. 640x480, each 1..=16384");
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    let (w, h): (u32, u32) = (
        w.trim().parse().map_err(|_| bad())?,
        h.trim().parse().map_err(|_| bad())?,
    );
    if !(1..=16384).contains(&w) || !(1..=16384).contains(&h) {
        return Err(bad());
    }
    Ok((w, h))
}
