//! The accelerators a board's engine runs its jobs on, behind [`AccelProvider`]: the kernel's
//! soft engine ([`SoftProvider`]) here, the HDL model or the MMIO accelerator in the firmware.
//! A job is an [`AccelJob`], generic over the accelerator, so the provider picks the engine and
//! the job's code is the same on each.

use heapless::Vec;

use super::capacity::{ENGINE_MAX_PATCHES, ENGINE_MAX_RING};
use crate::accel::soft::{LocalPatch, SoftAccelerator, SoftScratch};
use crate::accel::Accelerator;
use crate::link::message::{AccelKind, ErrorCode};
use crate::patch::Patch;

/// A piece of work that needs an accelerator, whichever one the board has.
pub trait AccelJob {
    /// What the job produces.
    type Out: Default;
    /// Runs the job.
    fn run<A: Accelerator>(self, accel: &mut A) -> Self::Out;
}

/// The accelerators of a board.
pub trait AccelProvider {
    /// The engine jobs run on now.
    fn kind(&self) -> AccelKind;
    /// Chooses the engine for the following jobs; `Unsupported` if the board has no such engine.
    fn select(&mut self, kind: AccelKind) -> Result<(), ErrorCode>;
    /// Loads a complete scene (patch memory of a hardware engine); `BadScene` if it cannot.
    fn load(&mut self, patches: &[Patch]) -> Result<(), ErrorCode>;
    /// Runs `job` on the selected engine over `patches` (the scene last loaded).
    fn run<J: AccelJob>(&mut self, patches: &[Patch], job: J) -> J::Out;
    /// Accelerator clock cycles so far (0 for engines without a clock of their own).
    fn cycles(&self) -> u64 {
        0
    }
    /// Sets the CORDIC of the accelerator (iterations, word width) for scenes loaded from now
    /// on; `Ok(true)` if that changed it (the engine then loads its scene again). Engines
    /// without a CORDIC compute in f32 and accept only the reset configuration
    /// ([`crate::link::RESET_CORDIC`]), which a host asks when its user chose none.
    fn set_cordic(&mut self, iterations: u8, width: u8) -> Result<bool, ErrorCode> {
        if (iterations, width) == crate::link::RESET_CORDIC {
            Ok(false)
        } else {
            Err(ErrorCode::Unsupported)
        }
    }
}

/// The kernel's f32 engine in fixed buffers: always there, the fallback of every board.
pub struct SoftProvider {
    local: Vec<LocalPatch, ENGINE_MAX_PATCHES>,
    best_t: [f32; ENGINE_MAX_RING],
    best_id: [u32; ENGINE_MAX_RING],
}

impl Default for SoftProvider {
    fn default() -> Self {
        Self::new()
    }
}

impl SoftProvider {
    /// Scratch for [`ENGINE_MAX_PATCHES`] patches and rings of up to [`ENGINE_MAX_RING`] rays.
    pub const fn new() -> Self {
        SoftProvider {
            local: Vec::new(),
            best_t: [0.0; ENGINE_MAX_RING],
            best_id: [0; ENGINE_MAX_RING],
        }
    }

    /// Runs `job` on the soft engine; `None` if the scratch cannot hold `patches`.
    pub fn run_soft<J: AccelJob>(&mut self, patches: &[Patch], job: J) -> Option<J::Out> {
        while self.local.len() < patches.len() {
            self.local.push(LocalPatch::default()).ok()?;
        }
        let scratch = SoftScratch {
            local: &mut self.local,
            best_t: &mut self.best_t,
            best_id: &mut self.best_id,
        };
        let mut accel = SoftAccelerator::new(patches, scratch).ok()?;
        Some(job.run(&mut accel))
    }
}

impl AccelProvider for SoftProvider {
    fn kind(&self) -> AccelKind {
        AccelKind::Soft
    }
    fn select(&mut self, kind: AccelKind) -> Result<(), ErrorCode> {
        match kind {
            AccelKind::Soft => Ok(()),
            _ => Err(ErrorCode::Unsupported),
        }
    }
    fn load(&mut self, patches: &[Patch]) -> Result<(), ErrorCode> {
        if patches.len() > ENGINE_MAX_PATCHES {
            return Err(ErrorCode::TooLong);
        }
        Ok(())
    }
    fn run<J: AccelJob>(&mut self, patches: &[Patch], job: J) -> J::Out {
        // `load` refused more patches than the scratch holds, and jobs only run on a loaded
        // scene, so `None` cannot happen; an empty result keeps it from being a panic path.
        self.run_soft(patches, job).unwrap_or_default()
    }
}
