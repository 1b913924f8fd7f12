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
    /// The reset configuration: 20 iterations on 24-bit words, on the accuracy-against-area
    /// front (W = n + 4), a direction within 3.9·10⁻⁶ rad (docs/ACCURACY.md): a four-hundredth
    /// of the ray spacing of a hemisphere of 1,000 rings, far inside the culling's 2^-7 rad
    /// margin, and below any pixel. Until session 44, 24 iterations on 32-bit words (1.25·10⁻⁷,
    /// about the f32 soft engine's own rounding), whose rotator and angle unit placed 62 %
    /// larger (16,558 LUT4s against 10,250) for the same form factors.
    pub const DEFAULT: CordicConfig = CordicConfig {
        iterations: 20,
        width: 24,
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

    /// The textbook bound on a pipe's error (rotation: |v − v_ref| of a unit vector; vectoring:
    /// the angle, rad): the residual angle 2^-(n-1), plus about n + 2 truncations of an LSB of
    /// the word (2^-(W-2) for vectors, 2^-(W-3) for angles). The tests hold the model to it,
    /// and derive from it what a chain of pipes may be off.
    ///
    /// ```
    /// use hemi_hdl_model::cordic::CordicConfig;
    /// // 20 iterations on 24-bit words: 2^-19 + 22 · 2^-21
    /// assert!((CordicConfig::DEFAULT.error_bound() - 1.24e-5).abs() < 1e-7);
    /// ```
    pub fn error_bound(&self) -> f64 {
        // (shifts held in range, so that an invalid configuration cannot overflow them)
        let residual = 1.0 / (1u64 << self.iterations.saturating_sub(1).min(63)) as f64;
        let lsb = 1.0 / (1u64 << self.width.saturating_sub(3).min(63)) as f64;
        residual + (self.iterations + 2) as f64 * lsb
    }

    /// What a direction the rotator turned may be off: three pipes in series, each within
    /// [`error_bound`](Self::error_bound), turning by three angles the angle unit formed, each
    /// within it too (an angle off by δ turns a unit vector by δ). 1.0e-6 at 24 iterations on
    /// 32-bit words, 7.4e-5 at the reset configuration (the textbook bound is loose there: the
    /// worst hemisphere ray measured 4.4e-6, docs/ACCURACY.md).
    pub fn turn_bound(&self) -> f64 {
        6.0 * self.error_bound()
    }
}
