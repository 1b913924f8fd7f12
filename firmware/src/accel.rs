//! The firmware's accelerators behind the kernel's [`AccelProvider`]: the kernel's soft engine
//! (always there, the fallback) and a hardware engine: with the `model` feature (QEMU builds)
//! the cycle-level HDL model driven through its register driver, exactly as the host's
//! `--backend model` drives it; on a board (feature `board`) the same driver code over the
//! accelerator's volatile registers ([`crate::accel_mmio`]), attached at boot if its ID register
//! answers (`FwAccel::attach_mmio`).
//!
//! Which one answers jobs: the hardware engine if there is one, unless the host asks for the
//! soft engine in its `Configure`. Jobs reach either engine through one [`Either`], so the
//! tracer, the walker and the pixel loop are compiled once for both: a second copy per engine
//! type is what overflowed a board's 128 KiB flash.
//!
//! Which hardware engine a build has is decided in one place, `selected`, from the features:
//! `model` (the default), `board`, or neither (the soft engine only). `model` and `board`
//! exclude each other.

#[cfg(all(feature = "model", feature = "board"))]
compile_error!(
    "features `model` and `board` exclude each other: `model` runs jobs on the simulated \
     accelerator (QEMU builds), `board` on a real one's registers (build a board with \
     `--no-default-features --features board`)"
);

use hemi_hdl_model::cordic::CordicConfig;
use hemi_hdl_model::{ModelConfig, ModelError};
use hemi_kernel::accel::either::Either;
use hemi_kernel::accel::Accelerator;
use hemi_kernel::jobs::{AccelJob, AccelProvider, SoftProvider};
use hemi_kernel::link::{AccelKind, ErrorCode};
use hemi_kernel::patch::Patch;

/// The hardware engine of this build: the model under QEMU, the registers on a board, or none
/// (chosen in `selected`).
type Hardware = selected::Hardware;

/// What [`FwAccel`] needs of a hardware engine, so that everything but `selected` is the same
/// code in every build.
trait HardwareEngine: Accelerator + Sized {
    /// Its kind in the handshake and in `Configure`.
    const KIND: AccelKind;
    /// Whether it is there from boot (the model) rather than once attached (a board's
    /// registers, if their ID answers).
    const FROM_BOOT: bool;
    /// Attaches the engine at boot if it answers, with its patch slots; `None` for engines
    /// that need no attaching or are not there.
    fn attach(config: ModelConfig) -> Option<(Self, u32)> {
        let _ = config;
        None
    }
    /// Loads `patches` under `config` into `slot`, the engine if there is one.
    fn load(
        slot: &mut heapless::Vec<Self, 1>,
        patches: &[Patch],
        config: ModelConfig,
    ) -> Result<(), ModelError>;
    /// Accelerator clocks so far (on a board these are bus reads, so they are read once per
    /// job).
    fn clocks(&mut self) -> u64;
    /// The clocks without a bus read, if the engine can give them for free (the model).
    fn clocks_now(&self) -> Option<u64> {
        None
    }
}

/// The one place that reads the `model` and `board` features: the hardware engine of a QEMU
/// build, the HDL model driven through its register driver exactly as the host's
/// `--backend model` drives it.
#[cfg(feature = "model")]
mod selected {
    use super::{AccelKind, HardwareEngine, ModelConfig, ModelError, Patch};
    use hemi_hdl_model::ModelAccelerator;

    pub(super) type Hardware = ModelAccelerator;

    impl HardwareEngine for ModelAccelerator {
        const KIND: AccelKind = AccelKind::Model;
        const FROM_BOOT: bool = true;
        fn load(
            slot: &mut heapless::Vec<Self, 1>,
            patches: &[Patch],
            config: ModelConfig,
        ) -> Result<(), ModelError> {
            // Dropped first: the old model's state is not needed while the new one is built.
            slot.clear();
            let m = ModelAccelerator::new(patches, config)?;
            // Cannot fail: the Vec was emptied above.
            let _ = slot.push(m);
            Ok(())
        }
        fn clocks(&mut self) -> u64 {
            self.cycles()
        }
        fn clocks_now(&self) -> Option<u64> {
            Some(self.cycles())
        }
    }
}

/// The hardware engine of a board build: the same driver code over the accelerator's volatile
/// registers ([`crate::accel_mmio`]), attached at boot if its ID register answers.
#[cfg(feature = "board")]
mod selected {
    use super::{why, AccelKind, HardwareEngine, ModelConfig, ModelError, Patch};
    use crate::accel_mmio::AccelMmio;
    use hemi_hdl_model::RegisterAccelerator;

    pub(super) type Hardware = RegisterAccelerator<AccelMmio>;

    impl HardwareEngine for RegisterAccelerator<AccelMmio> {
        const KIND: AccelKind = AccelKind::Mmio;
        const FROM_BOOT: bool = false;
        fn attach(config: ModelConfig) -> Option<(Self, u32)> {
            let bus = AccelMmio::take()?;
            match RegisterAccelerator::with_bus(bus, &[], config) {
                Ok(mut hw) => {
                    let slots = hw.driver_mut().patch_capacity();
                    Some((hw, slots))
                }
                Err(e) => {
                    defmt::info!("no accelerator at the MMIO base: {=str}", why(&e));
                    None
                }
            }
        }
        fn load(
            slot: &mut heapless::Vec<Self, 1>,
            patches: &[Patch],
            config: ModelConfig,
        ) -> Result<(), ModelError> {
            match slot.first_mut() {
                Some(hw) => hw.load_scene(patches, config),
                None => Ok(()),
            }
        }
        fn clocks(&mut self) -> u64 {
            self.device_cycles()
        }
    }
}

/// A build without a hardware engine: the soft engine answers every job.
#[cfg(not(any(feature = "model", feature = "board")))]
mod selected {
    use super::{AccelKind, HardwareEngine, ModelConfig, ModelError, Patch};
    use hemi_kernel::accel::{Accelerator, Hit, Ray};
    use hemi_kernel::geometry::Vec3;
    use hemi_kernel::rotation::Rotation;

    pub(super) type Hardware = NoHardware;

    /// The hardware engine of a build that has none: a type no value of which exists.
    pub enum NoHardware {}

    impl Accelerator for NoHardware {
        fn rotate(&mut self, _: &Rotation, _: Vec3) -> Vec3 {
            match *self {}
        }
        fn nearest_hit(&mut self, _: &Ray, _: f32) -> Option<Hit> {
            match *self {}
        }
    }

    impl HardwareEngine for NoHardware {
        const KIND: AccelKind = AccelKind::Soft;
        const FROM_BOOT: bool = false;
        fn load(
            _: &mut heapless::Vec<Self, 1>,
            _: &[Patch],
            _: ModelConfig,
        ) -> Result<(), ModelError> {
            Ok(())
        }
        fn clocks(&mut self) -> u64 {
            match *self {}
        }
    }
}

/// The accelerators of this build.
pub struct FwAccel {
    soft: SoftProvider,
    /// The hardware engine with the loaded scene: a `Vec` of at most one rather than an
    /// `Option`, because an empty `Vec` is all zero bytes (so the static engine stays in `.bss`)
    /// and `None` of this type need not be.
    hardware: heapless::Vec<Hardware, 1>,
    /// CORDIC (iterations, width) the host asked for; (0, 0) = the defaults (zero bytes, so the
    /// static engine stays in `.bss`).
    cordic: (u8, u8),
    /// Accelerator clocks counted so far, read after each job (a board's CYCLE registers cost
    /// bus reads, so they are not read on every `cycles()`).
    clocks: u64,
    use_soft: bool,
}

impl Default for FwAccel {
    fn default() -> Self {
        Self::new()
    }
}

impl FwAccel {
    /// Soft engine scratch, no scene loaded.
    pub const fn new() -> Self {
        FwAccel {
            soft: SoftProvider::new(),
            hardware: heapless::Vec::new(),
            cordic: (0, 0),
            clocks: 0,
            use_soft: false,
        }
    }

    /// The hardware engine this build has, if any (whether a board's answers is known only
    /// after `FwAccel::attach_mmio`).
    pub const fn native() -> AccelKind {
        Hardware::KIND
    }

    /// Whether jobs go to the hardware engine now.
    fn on_hardware(&self) -> bool {
        !self.use_soft && self.has_hardware()
    }

    /// Whether this build's hardware engine is there: the model always, a board's registers
    /// once attached.
    fn has_hardware(&self) -> bool {
        Hardware::FROM_BOOT || !self.hardware.is_empty()
    }

    /// The build parameters of the hardware engine: the defaults, with the host's CORDIC if it
    /// sent one.
    fn config(&self) -> ModelConfig {
        let mut config = ModelConfig::default();
        if self.cordic != (0, 0) {
            config.iterations = u32::from(self.cordic.0);
            config.width = u32::from(self.cordic.1);
        }
        config
    }

    /// Attaches a board's accelerator at its base address if its ID and version answer, and
    /// returns its patch slots; `None` leaves the soft engine answering (and is all other
    /// builds have). Called once, at boot (the registers can be taken only once).
    pub fn attach_mmio(&mut self) -> Option<u32> {
        let (hw, slots) = Hardware::attach(self.config())?;
        self.hardware.clear();
        let _ = self.hardware.push(hw);
        Some(slots)
    }

    /// Clocks of the hardware engine so far.
    fn hardware_clocks(&mut self) -> u64 {
        self.hardware
            .first_mut()
            .map_or(self.clocks, HardwareEngine::clocks)
    }
}

/// What went wrong, in a word: `Debug` formatting would pull `core::fmt` into the flash.
fn why(e: &ModelError) -> &'static str {
    match e {
        ModelError::Driver(_) => "driver: ID, version or timeout",
        ModelError::TooManyPatches { .. } => "too many patches",
        ModelError::TooManyBezierPatches { .. } => "too many Bezier patches",
        ModelError::BadGeometry(_) => "bad geometry",
        ModelError::BadParams => "bad build parameters",
        #[expect(unreachable_patterns, reason = "ModelError may grow")]
        _ => "model error",
    }
}

/// A job on either engine, as one job for the soft provider: `job.run` is compiled once, for
/// `Either<soft, hardware>`.
struct OnEither<'h, J> {
    job: J,
    hardware: Option<&'h mut Hardware>,
}

impl<J: AccelJob> AccelJob for OnEither<'_, J> {
    type Out = J::Out;
    fn run<A: Accelerator>(self, soft: &mut A) -> J::Out {
        let mut engine: Either<'_, A, Hardware> = match self.hardware {
            Some(hw) => Either::Right(hw),
            None => Either::Left(soft),
        };
        self.job.run(&mut engine)
    }
}

impl AccelProvider for FwAccel {
    fn kind(&self) -> AccelKind {
        if self.on_hardware() {
            Self::native()
        } else {
            AccelKind::Soft
        }
    }

    fn select(&mut self, kind: AccelKind) -> Result<(), ErrorCode> {
        if kind == AccelKind::Soft {
            self.use_soft = true;
            Ok(())
        } else if kind == Self::native() && self.has_hardware() {
            self.use_soft = false;
            Ok(())
        } else {
            Err(ErrorCode::Unsupported)
        }
    }

    fn load(&mut self, patches: &[Patch]) -> Result<(), ErrorCode> {
        self.soft.load(patches)?;
        let config = self.config();
        if let Err(e) = Hardware::load(&mut self.hardware, patches, config) {
            defmt::warn!("the accelerator cannot load the scene: {=str}", why(&e));
            // The soft engine still serves this scene if the host asks for it.
            self.hardware.clear();
            if !self.use_soft {
                return Err(ErrorCode::BadScene);
            }
        }
        Ok(())
    }

    fn run<J: AccelJob>(&mut self, patches: &[Patch], job: J) -> J::Out {
        // No hardware scene (it refused the scene while the soft engine was selected, or there
        // is no hardware): the soft engine answers.
        let hardware = if self.use_soft {
            None
        } else {
            self.hardware.first_mut()
        };
        let out = self.soft.run(patches, OnEither { job, hardware });
        self.clocks = self.hardware_clocks();
        out
    }

    fn set_cordic(&mut self, iterations: u8, width: u8) -> Result<bool, ErrorCode> {
        let d = hemi_hdl_model::ModelConfig::default();
        let (it, w) = (u32::from(iterations), u32::from(width));
        if !self.has_hardware() {
            // f32, no CORDIC to set: only the reset configuration, which a host asks when its
            // user chose none
            return if (it, w) == (d.iterations, d.width) {
                Ok(false)
            } else {
                Err(ErrorCode::Unsupported)
            };
        }
        // the accelerator's own limits: refused here, before any scene is touched
        if !(CordicConfig {
            iterations: it,
            width: w,
        })
        .is_valid()
        {
            return Err(ErrorCode::OutOfRange);
        }
        let new = if (it, w) == (d.iterations, d.width) {
            (0, 0)
        } else {
            (iterations, width)
        };
        if self.use_soft && new != (0, 0) {
            // the soft engine answers jobs: f32, no CORDIC to set
            return Err(ErrorCode::Unsupported);
        }
        let changed = new != self.cordic;
        self.cordic = new;
        Ok(changed)
    }

    fn cycles(&self) -> u64 {
        self.hardware
            .first()
            .and_then(HardwareEngine::clocks_now)
            .unwrap_or(self.clocks)
    }
}
