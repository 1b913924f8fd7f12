//! What the engine asks of the machine it runs on, beyond an accelerator: a clock and a stack
//! measurement, both optional, for the counters of `EngineStats`.

/// Hooks of the machine the engine runs on: a clock for CPU time and the stack's high-water mark.
pub trait Platform {
    /// A monotonic tick count (SysTick on a Cortex-M); 0 if there is none.
    fn ticks(&self) -> u64 {
        0
    }
    /// (deepest stack use, stack size) in bytes; zeros if not measured.
    fn stack(&self) -> (u32, u32) {
        (0, 0)
    }
}

/// A platform without a clock or stack measurement (host tests).
pub struct NoPlatform;
impl Platform for NoPlatform {}
