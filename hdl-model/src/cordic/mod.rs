//! The CORDIC processor of paper §3.4 (Volder's algorithm), fully pipelined.
//!
//! One pipe is a coarse-rotation stage, `n` micro-rotation stages (stage i adds or subtracts the
//! other component shifted right by the constant i, and ±atan 2^-i from ROM) and a gain
//! compensation stage (a constant multiply by 1/K_n, for each component separately). It accepts
//! one vector per clock and returns it n + 4 clocks later.
//!
//! - **Rotation mode** turns (x, y) by the angle z. The coarse stage first turns by ±π/2 so that
//!   the residual angle is within the ±1.743 rad the micro-rotations converge over, which covers
//!   the full circle.
//! - **Vectoring mode** turns (x, y) onto the +x axis and accumulates the angle it took:
//!   z = atan2(y, x), x = |(x, y)|. The coarse stage moves the left half-plane into the right
//!   one; a zero vector is flagged and gives angle 0 (libm's `atan2(0, 0)`), since the micro-
//!   rotations of (0, 0) would otherwise add up every ROM angle.
//!
//! Error: after n iterations the residual angle is at most atan 2^-(n-1) ≈ 2^-(n-1); each stage
//! truncates to the word, which adds up to about n LSBs (so log2 n guard bits keep the rounding
//! under the angle error). `docs/ACCURACY.md` has the measured table.

pub mod rom;
pub mod stage;

pub use stage::{CordicPipe, CordicSlot, GainStage, MicroRotation, Mode, QuadrantStage};

/// CORDIC parameters (the `ITER` and `WIDTH` fields of the CONFIG register).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CordicConfig {
    /// Micro-rotation stages n.
    pub iterations: u32,
    /// Word width W of every datapath register, in bits (binary points fixed: see `format`).
    pub width: u32,
}

/// Clocks of a pipe of `iterations` micro-rotations: the coarse stage in two (the decision,
/// then the turn: in one clock the compare and its fanout held the rotator to 85 MHz; until
/// session 25, one), the micro-rotations and the gain stage in two (its adder tree registered
/// halfway, `rtl/const_mul.v`: in one clock the 32-bit tree held the rotator to 76 MHz; until
/// session 24, one).
pub const fn pipe_latency(iterations: u32) -> u32 {
    iterations + 4
}

/// Fewest iterations accepted (below this the coarse stage alone would be most of the answer).
pub const MIN_ITERATIONS: u32 = 4;
/// Most iterations accepted (the ROM has 32 entries; 30 fraction bits at W = 32).
pub const MAX_ITERATIONS: u32 = 30;
/// Narrowest word accepted.
pub const MIN_WIDTH: u32 = 12;
/// Widest word (the 32-bit containers).
pub const MAX_WIDTH: u32 = 32;

impl CordicConfig {
    /// The reset configuration: 24 iterations on 32-bit words, about as accurate as the f32 soft
    /// engine (2^-23 ≈ 1.2·10⁻⁷ rad).
    pub const DEFAULT: CordicConfig = CordicConfig {
        iterations: 24,
        width: 32,
    };

    /// Whether the hardware can be built this way: iterations past the fraction bits of the
    /// word shift everything out and only add truncation error, so they are refused.
    pub fn is_valid(&self) -> bool {
        (MIN_ITERATIONS..=MAX_ITERATIONS).contains(&self.iterations)
            && (MIN_WIDTH..=MAX_WIDTH).contains(&self.width)
            && self.iterations <= self.width - 2
    }

    /// Pipeline latency in clocks ([`pipe_latency`]).
    pub fn latency(&self) -> u32 {
        pipe_latency(self.iterations)
    }
}
