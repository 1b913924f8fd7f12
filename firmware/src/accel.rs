//! The firmware's accelerators behind the kernel's [`AccelProvider`]: the kernel's soft engine
//! (always there, the fallback) and a hardware engine: with the `model` feature (QEMU builds)
//! the cycle-level HDL model driven through its register driver, exactly as the host's
//! `--backend model` drives it; on a board (feature `board`) the same driver code over the
//! accelerator's volatile registers ([`crate::accel_mmio`]), attached at boot if its ID register
//! answers (`FwAccel::attach_mmio`, board builds).
//!
//! Which one answers jobs: the hardware engine if there is one, unless the host asks for the
//! soft engine in its `Configure`. Jobs reach either engine through one [`Either`], so the
//! tracer, the walker and the pixel loop are compiled once for both: a second copy per engine
//! type is what overflowed a board's 128 KiB flash.

use hemi_kernel::accel::either::Either;
use hemi_kernel::accel::Accelerator;
use hemi_kernel::jobs::{AccelJob, AccelProvider, SoftProvider};
use hemi_kernel::link::{AccelKind, ErrorCode};
use hemi_kernel::patch::Patch;

/// The hardware engine of this build: the model under QEMU, the registers on a board.
#[cfg(feature = "model")]
type Hardware = hemi_hdl_model::ModelAccelerator;
/// The hardware engine of this build: the model under QEMU, the registers on a board.
#[cfg(all(feature = "board", not(feature = "model")))]
type Hardware = hemi_hdl_model::RegisterAccelerator<crate::accel_mmio::AccelMmio>;
/// No hardware engine in this build: a type no value of which exists.
#[cfg(not(any(feature = "model", feature = "board")))]
type Hardware = NoHardware;

/// The hardware engine of a build that has none (never constructed).
#[cfg(not(any(feature = "model", feature = "board")))]
pub enum NoHardware {}

#[cfg(not(any(feature = "model", feature = "board")))]
impl Accelerator for NoHardware {
    fn rotate(
        &mut self,
        _: &hemi_kernel::rotation::Rotation,
        _: hemi_kernel::geometry::Vec3,
    ) -> hemi_kernel::geometry::Vec3 {
        match *self {}
    }
    fn nearest_hit(
        &mut self,
        _: &hemi_kernel::accel::Ray,
        _: f32,
    ) -> Option<hemi_kernel::accel::Hit> {
        match *self {}
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
        if cfg!(feature = "model") {
            AccelKind::Model
        } else if cfg!(feature = "board") {
            AccelKind::Mmio
        } else {
            AccelKind::Soft
        }
    }

    /// Whether jobs go to the hardware engine now.
    fn on_hardware(&self) -> bool {
        !self.use_soft && self.has_hardware()
    }

    /// Whether this build's hardware engine is there: the model always, a board's registers
    /// once attached.
    fn has_hardware(&self) -> bool {
        cfg!(feature = "model") || !self.hardware.is_empty()
    }

    /// The build parameters of the hardware engine: the defaults, with the host's CORDIC if it
    /// sent one.
    #[cfg(any(feature = "model", feature = "board"))]
    fn config(&self) -> hemi_hdl_model::ModelConfig {
        let mut config = hemi_hdl_model::ModelConfig::default();
        if self.cordic != (0, 0) {
            config.iterations = u32::from(self.cordic.0);
            config.width = u32::from(self.cordic.1);
        }
        config
    }

    /// Board builds: attaches the accelerator at its base address if its ID and version
    /// answer, and returns its patch slots; `None` leaves the soft engine answering. Called
    /// once, at boot (the registers can be taken only once).
    #[cfg(all(feature = "board", not(feature = "model")))]
    pub fn attach_mmio(&mut self) -> Option<u32> {
        let bus = crate::accel_mmio::AccelMmio::take()?;
        match hemi_hdl_model::RegisterAccelerator::with_bus(bus, &[], self.config()) {
            Ok(mut hw) => {
                let slots = hw.driver_mut().patch_capacity();
                self.hardware.clear();
                let _ = self.hardware.push(hw);
                Some(slots)
            }
            Err(e) => {
                defmt::info!("no accelerator at the MMIO base: {=str}", why(&e));
                None
            }
        }
    }

    /// Loads `patches` into the hardware engine, in place.
    #[cfg(feature = "model")]
    fn load_hardware(&mut self, patches: &[Patch]) -> Result<(), hemi_hdl_model::ModelError> {
        // Dropped first: the old model's state is not needed while the new one is built.
        self.hardware.clear();
        let m = hemi_hdl_model::ModelAccelerator::new(patches, self.config())?;
        // Cannot fail: the Vec was emptied above.
        let _ = self.hardware.push(m);
        Ok(())
    }

    /// Loads `patches` into the hardware engine, in place.
    #[cfg(all(feature = "board", not(feature = "model")))]
    fn load_hardware(&mut self, patches: &[Patch]) -> Result<(), hemi_hdl_model::ModelError> {
        let config = self.config();
        match self.hardware.first_mut() {
            Some(hw) => hw.load_scene(patches, config),
            None => Ok(()),
        }
    }

    /// No hardware engine: nothing to load.
    #[cfg(not(any(feature = "model", feature = "board")))]
    fn load_hardware(&mut self, _: &[Patch]) -> Result<(), ErrorCode> {
        Ok(())
    }

    /// Clocks of the hardware engine so far.
    fn hardware_clocks(&mut self) -> u64 {
        #[cfg(feature = "model")]
        if let Some(m) = self.hardware.first() {
            return m.cycles();
        }
        #[cfg(all(feature = "board", not(feature = "model")))]
        if let Some(hw) = self.hardware.first_mut() {
            return hw.device_cycles();
        }
        self.clocks
    }
}

/// What went wrong, in a word: `Debug` formatting would pull `core::fmt` into the flash.
#[cfg(any(feature = "model", feature = "board"))]
fn why(e: &hemi_hdl_model::ModelError) -> &'static str {
    use hemi_hdl_model::ModelError;
    match e {
        ModelError::Driver(_) => "driver: ID, version or timeout",
        ModelError::TooManyPatches { .. } => "too many patches",
        ModelError::TooManyBezierPatches { .. } => "too many Bezier patches",
        ModelError::BadGeometry(_) => "bad geometry",
        #[allow(unreachable_patterns, reason = "ModelError may grow")]
        _ => "model error",
    }
}

/// Never called: a build without a hardware engine loads nothing that can fail.
#[cfg(not(any(feature = "model", feature = "board")))]
fn why(e: &ErrorCode) -> &'static str {
    let _ = e;
    "no accelerator"
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
        if let Err(e) = self.load_hardware(patches) {
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
            // f32, no CORDIC to set: only the defaults, which stand for "as exact as f32"
            return if (it, w) == (d.iterations, d.width) {
                Ok(false)
            } else {
                Err(ErrorCode::Unsupported)
            };
        }
        // the accelerator's own limits (ModelConfig): refused here, before any scene is touched
        if !(12..=32).contains(&w) || !(4..=30).contains(&it) || it + 2 > w {
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
        #[cfg(feature = "model")]
        if let Some(m) = self.hardware.first() {
            return m.cycles();
        }
        self.clocks
    }
}
