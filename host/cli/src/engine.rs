//! The `--backend` a command runs on: checked first (before a scene is read), opened when the
//! run needs it (boards connected, QEMU booted), then made into the library's backend for the
//! scene and settings of the run.

use crate::options::{BoardAccelArg, BoardArgs, EngineArgs, ModelArgs};
use anyhow::{bail, Result};
use hemi::backend::{Backend, InProcess, Model, RtlSim, Soft};
use hemi::scene::Scene;
use hemi::settings::Pass1Settings;
use hemi_boards::farm::{parse_boards, BoardSpec, FarmOptions};
use hemi_boards::{Boards, Farm};
use hemi_hdl_model::intersect::bezier::{SubdivConfig, STACK_ENTRIES};
use hemi_hdl_model::{ModelConfig, Params};
use hemi_kernel::link::AccelKind;

/// A checked `--backend`, not yet opened.
pub enum Choice {
    /// The kernel's f32 engine in this process.
    Soft,
    /// The cycle-level model of the accelerator in this process.
    Model(ModelConfig),
    /// The accelerator's RTL in its simulator.
    Rtl(RtlSim),
    /// Boards over the link.
    Boards(Vec<BoardSpec>),
}

/// An opened engine: which kind, and for boards the connected farm.
pub enum Engine {
    /// The kernel's f32 engine in this process.
    Soft,
    /// The cycle-level model of the accelerator in this process.
    Model(ModelConfig),
    /// The accelerator's RTL in its simulator, driven from this process.
    Rtl(RtlSim),
    /// Boards over the link; the firmware runs the jobs.
    Boards {
        /// The connected boards (boxed: a farm is large beside the other engines).
        farm: Box<Farm>,
        /// The engine they are asked to use.
        accel: AccelKind,
    },
}

/// An engine made into a backend for one scene and settings.
pub enum Running<'s> {
    /// In-process soft engines.
    Soft(InProcess<'s, Soft>),
    /// In-process model engines, with their counters.
    Model(InProcess<'s, Model>),
    /// The RTL's simulators driven from this process, with their counters.
    Rtl(InProcess<'s, Model<RtlSim>>),
    /// A farm of boards.
    Boards(Boards<'s>),
}

impl EngineArgs {
    /// Parses `--backend` and checks its settings, without opening anything.
    pub fn check(&self) -> Result<Choice> {
        if self.rtl_sim.is_some() && self.backend != "rtl" {
            eprintln!("warning: --rtl-sim has no effect without --backend rtl");
        }
        match self.backend.as_str() {
            "soft" => Ok(Choice::Soft),
            "model" => Ok(Choice::Model(self.model.config()?)),
            "rtl" => {
                // the clock the report assumes is the only model option that applies
                let model = ModelArgs {
                    clock_mhz: crate::options::MEASURED_CLOCK_MHZ,
                    ..self.model.clone()
                };
                anyhow::ensure!(
                    !model.changed(),
                    "--backend rtl: the RTL is built for one configuration (the one-lane build, \
                     CONFIG's reset value); the model's options (--lanes, --cordic-*, \
                     --bezier-*, …) do not apply to it"
                );
                let default = std::path::Path::new(hemi::backend::DEFAULT_SIM);
                Ok(Choice::Rtl(RtlSim::at(
                    self.rtl_sim.as_deref().unwrap_or(default),
                )?))
            }
            list => match parse_boards(list)? {
                Some(specs) => Ok(Choice::Boards(specs)),
                None => bail!(
                    "--backend {list}: expected soft, model, rtl, qemu or serial:PATH (boards \
                     may be listed comma-separated)"
                ),
            },
        }
    }
}

impl Choice {
    /// A warning when the modelled accelerator's options were given to the soft backend.
    pub fn warn_unused(&self, model: &ModelArgs) {
        if matches!(self, Choice::Soft) && model.changed() {
            eprintln!(
                "warning: the modelled accelerator's options (--lanes, --cordic-*, --bezier-*, \
                 --clock-mhz, …) have no effect with --backend soft"
            );
        }
    }

    /// Opens the engine (boards connect here, QEMU boots).
    pub fn open(self, model: &ModelArgs, boards: &BoardArgs) -> Result<Engine> {
        Ok(match self {
            Choice::Soft => Engine::Soft,
            Choice::Model(config) => Engine::Model(config),
            Choice::Rtl(sim) => Engine::Rtl(sim),
            Choice::Boards(specs) => {
                let options = FarmOptions {
                    firmware: boards.qemu.firmware.clone(),
                    quiet: boards.quiet_boards,
                    qemu: boards.qemu.options()?,
                };
                model.check_cordic()?;
                let farm = Farm::connect(&specs, options)?;
                farm.set_cordic(model.cordic_iterations, model.cordic_width)?;
                let accel = match boards.board_accel {
                    BoardAccelArg::Soft => AccelKind::Soft,
                    BoardAccelArg::Own => AccelKind::None,
                };
                Engine::Boards {
                    farm: Box::new(farm),
                    accel,
                }
            }
        })
    }
}

impl ModelArgs {
    /// The modelled accelerator of the `--cordic-*`, `--bezier-*` options, checked.
    fn config(&self) -> Result<ModelConfig> {
        self.check_cordic()?;
        let subdiv = SubdivConfig {
            depth: self.bezier_depth,
            coord_width: self.bezier_width,
        };
        anyhow::ensure!(
            subdiv.is_valid_for(STACK_ENTRIES),
            "--bezier-depth {} --bezier-width {}: the model takes depths 1..=13 and widths 12..=26",
            self.bezier_depth,
            self.bezier_width
        );
        let params = Params {
            lanes: self.lanes,
            sectors: self.sectors,
            rays_per_clock: self.rays_per_clock,
            bank_slots: self.bank_slots,
            compact: !self.wide_datapath,
            ray_groups: self.ray_groups,
        };
        anyhow::ensure!(
            params.is_valid(),
            "--lanes {} --sectors {} --rays-per-clock {} --bank-slots {}: the model takes 1..=16 lanes, 0 or 8, 16, 32, 64 sectors, 1..=4 rays per clock and up to {} slots in all (banks × slots; a larger scene streams through them in blocks)",
            self.lanes,
            self.sectors,
            self.rays_per_clock,
            self.bank_slots,
            hemi_hdl_model::params::MAX_CAPACITY
        );
        Ok(ModelConfig {
            iterations: self.cordic_iterations,
            width: self.cordic_width,
            subdivision_depth: self.bezier_depth,
            coord_width: self.bezier_width,
            params,
            ..ModelConfig::default()
        })
    }
}

impl Engine {
    /// The backend of this engine for `scene` with `settings`.
    pub fn backend<'s>(
        &'s self,
        scene: &'s Scene,
        settings: &Pass1Settings,
    ) -> Result<Running<'s>> {
        Ok(match self {
            Engine::Soft => Running::Soft(InProcess::new(scene, settings, Soft::new())?),
            Engine::Model(config) => {
                Running::Model(InProcess::new(scene, settings, Model::new(*config))?)
            }
            Engine::Rtl(sim) => {
                let engines = Model::on(sim.clone(), RtlSim::config());
                Running::Rtl(InProcess::new(scene, settings, engines)?)
            }
            Engine::Boards { farm, accel } => {
                Running::Boards(Boards::new(farm, scene, settings, *accel)?)
            }
        })
    }

    /// The largest hemisphere (circles R) every board of the farm builds; `None` in process
    /// (or before any board answered).
    pub fn most_circles(&self) -> Option<u32> {
        match self {
            Engine::Boards { farm, .. } => farm.capacities().map(|c| u32::from(c.max_circles)),
            _ => None,
        }
    }
}

impl Running<'_> {
    /// The library's view.
    pub fn get(&self) -> &dyn Backend {
        match self {
            Running::Soft(b) => b,
            Running::Model(b) => b,
            Running::Rtl(b) => b,
            Running::Boards(b) => b,
        }
    }

    /// The modelled accelerator's (cycles, rays) so far, for `--backend model`.
    pub fn model_counts(&self) -> Option<(u64, u64)> {
        match self {
            Running::Model(b) => Some(b.engines().counters.get()),
            Running::Rtl(b) => Some(b.engines().counters.get()),
            _ => None,
        }
    }

    /// The modelled accelerator's (blocks, streaming cycles) so far, for `--backend model`.
    pub fn model_stream(&self) -> Option<(u64, u64)> {
        match self {
            Running::Model(b) => Some(b.engines().counters.stream()),
            Running::Rtl(b) => Some(b.engines().counters.stream()),
            _ => None,
        }
    }

    /// The modelled accelerator's configuration, for `--backend model`.
    pub fn model_config(&self) -> Option<ModelConfig> {
        match self {
            Running::Model(b) => Some(b.engines().config),
            Running::Rtl(b) => Some(b.engines().config),
            _ => None,
        }
    }

    /// The boards' counters on stderr after `what`, with `--board-stats`.
    pub fn board_report(&self, enabled: bool, what: &str) {
        if let (true, Running::Boards(b)) = (enabled, self) {
            hemi_boards::report::report(b.farm(), what);
        }
    }

    /// What the modelled accelerator did, on stderr: cycles per ray and per hemisphere, and the
    /// time at the assumed clock (nothing for other backends).
    pub fn report_model(&self, hemispheres: u64, clock_mhz: f64, what: &str) {
        let (Some((cycles, rays)), Some(cfg)) = (self.model_counts(), self.model_config()) else {
            return;
        };
        let p = cfg.params;
        // single rays (`trace`) cast no hemisphere: no per-hemisphere figure then
        let per_hemisphere = match hemispheres {
            0 => String::new(),
            n => format!(", {:.0} cycles/hemisphere", cycles as f64 / n as f64),
        };
        let streamed = match self.model_stream() {
            Some((blocks, clocks)) if blocks > 1 => format!(
                " (the scene streamed through patch memory in {blocks} blocks: {clocks} of the \
                 cycles, {:.1} %)",
                100.0 * clocks as f64 / cycles.max(1) as f64
            ),
            _ => String::new(),
        };
        let who = match self {
            Running::Rtl(_) => "rtl",
            _ => "model",
        };
        eprintln!(
            "{who} ({} CORDIC iterations, {}-bit words; {} lanes, {} sectors, {} rays/clock): \
             {what}: {cycles} cycles for {rays} rays = {:.2} cycles/ray{per_hemisphere}; \
             {:.3} s at {clock_mhz} MHz{streamed}",
            cfg.iterations,
            cfg.width,
            p.lanes,
            p.sectors,
            p.rays_per_clock,
            cycles as f64 / rays.max(1) as f64,
            cycles as f64 / (clock_mhz * 1e6)
        );
    }
}
