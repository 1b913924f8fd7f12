//! The firmware's accelerators behind the kernel's [`AccelProvider`]: the kernel's soft engine
//! (always there, the fallback) and, with the `model` feature (QEMU builds), the cycle-level HDL
//! model driven through its register driver, exactly as the host's `--backend model` drives it.
//!
//! Which one answers jobs: the build's own ([`FwAccel::native`]) unless the host asks for the
//! soft engine in its `Configure`. On a board (feature `board`) the accelerator's registers
//! ([`crate::accel_mmio`]) are probed at boot by their ID register (`probe_mmio`, feature `board`).
//! The kernel's `Accelerator` over them exists (`hemi_hdl_model::RegisterAccelerator<AccelMmio>`,
//! the model's code over volatile MMIO), but a board build that also runs jobs on it overflows
//! the 128 KiB flash by about 3.3 KB (the tracer and walker are instantiated a second time, for
//! the second accelerator type), so a board build answers jobs with the soft engine for now.

use hemi_kernel::link::engine::{AccelJob, AccelProvider, SoftProvider};
use hemi_kernel::link::{AccelKind, ErrorCode};
use hemi_kernel::patch::Patch;

/// The accelerators of this build.
pub struct FwAccel {
    soft: SoftProvider,
    /// The model with the loaded scene: a `Vec` of at most one rather than an `Option`, because
    /// an empty `Vec` is all zero bytes (so the static engine stays in `.bss`) and `None` of this
    /// type need not be.
    #[cfg(feature = "model")]
    model: heapless::Vec<hemi_hdl_model::ModelAccelerator, 1>,
    /// CORDIC (iterations, width) the host asked for; (0, 0) = the model's defaults (zero bytes,
    /// so the static engine stays in `.bss`).
    #[cfg(feature = "model")]
    cordic: (u8, u8),
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
            #[cfg(feature = "model")]
            model: heapless::Vec::new(),
            #[cfg(feature = "model")]
            cordic: (0, 0),
            use_soft: false,
        }
    }

    /// The engine this build runs jobs on unless told otherwise.
    pub const fn native() -> AccelKind {
        if cfg!(feature = "model") {
            AccelKind::Model
        } else {
            AccelKind::Soft
        }
    }
}

impl AccelProvider for FwAccel {
    fn kind(&self) -> AccelKind {
        if self.use_soft {
            AccelKind::Soft
        } else {
            Self::native()
        }
    }

    fn select(&mut self, kind: AccelKind) -> Result<(), ErrorCode> {
        if kind == AccelKind::Soft {
            self.use_soft = true;
            Ok(())
        } else if kind == Self::native() {
            self.use_soft = false;
            Ok(())
        } else {
            Err(ErrorCode::Unsupported)
        }
    }

    fn load(&mut self, patches: &[Patch]) -> Result<(), ErrorCode> {
        self.soft.load(patches)?;
        #[cfg(feature = "model")]
        {
            // Dropped first: the old model's state is not needed while the new one is built.
            self.model.clear();
            let config = self.model_config();
            match hemi_hdl_model::ModelAccelerator::new(patches, config) {
                // Cannot fail: the Vec was emptied above.
                Ok(m) => {
                    let _ = self.model.push(m);
                }
                // The soft engine still serves this scene if the host asks for it.
                Err(e) => {
                    defmt::warn!(
                        "the accelerator model cannot load the scene: {}",
                        defmt::Debug2Format(&e)
                    );
                    if !self.use_soft {
                        return Err(ErrorCode::BadScene);
                    }
                }
            }
        }
        Ok(())
    }

    fn run<J: AccelJob>(&mut self, patches: &[Patch], job: J) -> J::Out {
        #[cfg(feature = "model")]
        if !self.use_soft {
            return match self.model.first_mut() {
                Some(m) => job.run(m),
                // No model scene (it refused the scene while the soft engine was selected):
                // the soft engine answers.
                None => self.soft.run(patches, job),
            };
        }
        self.soft.run(patches, job)
    }

    #[cfg(feature = "model")]
    fn set_cordic(&mut self, iterations: u8, width: u8) -> Result<bool, ErrorCode> {
        let d = hemi_hdl_model::ModelConfig::default();
        let (it, w) = (u32::from(iterations), u32::from(width));
        // the model's own limits (ModelConfig): refused here, before any scene is touched
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
        if let Some(m) = self.model.first() {
            return m.cycles();
        }
        0
    }
}

#[cfg(feature = "model")]
impl FwAccel {
    /// The model's build parameters: the defaults, with the host's CORDIC if it sent one.
    fn model_config(&self) -> hemi_hdl_model::ModelConfig {
        let mut config = hemi_hdl_model::ModelConfig::default();
        if self.cordic != (0, 0) {
            config.iterations = u32::from(self.cordic.0);
            config.width = u32::from(self.cordic.1);
        }
        config
    }
}

/// Board builds: whether the accelerator answers at its base address, by the driver's ID and
/// version check; `Some(patch slots)` if it does. Called once, at boot.
#[cfg(feature = "board")]
pub fn probe_mmio() -> Option<u32> {
    let bus = crate::accel_mmio::AccelMmio::take()?;
    match hemi_hdl_model::driver::Driver::new(bus) {
        Ok(driver) => Some(driver.patch_capacity()),
        Err(e) => {
            defmt::info!(
                "no accelerator at the MMIO base: {}",
                defmt::Debug2Format(&e)
            );
            None
        }
    }
}
