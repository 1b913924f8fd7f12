//! The three kinds of CORDIC pipeline stage and the pipe that chains them.

use super::rom::{ATAN_Q62, HALF_PI_Q62, INV_GAIN_Q62};
use super::CordicConfig;
use crate::format::{rom_round, width_mask, Angle, Unit};
use crate::pipe::Pipe;

/// What the pipe computes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Mode {
    /// Turn (x, y) by z.
    #[default]
    Rotate,
    /// Turn (x, y) onto +x; z becomes atan2(y, x), x the magnitude.
    Vector,
}

/// One pipeline register of a CORDIC pipe: the vector, the angle, and whatever the surrounding
/// unit carries alongside (`payload`, delayed unchanged).
#[derive(Clone, Copy, Debug, Default)]
pub struct CordicSlot<P: Copy + Default> {
    /// x component (Q2.30, W bits).
    pub x: Unit,
    /// y component.
    pub y: Unit,
    /// Angle: the rotation left to do (rotation mode) or accumulated (vectoring mode).
    pub z: Angle,
    /// Vectoring a zero vector: the angle is forced to 0.
    pub zero: bool,
    /// Carried alongside.
    pub payload: P,
}

/// Stage 0: the coarse rotation by ±π/2 that lets the pipe cover the full circle.
#[derive(Clone, Copy, Debug)]
pub struct QuadrantStage {
    mode: Mode,
    half_pi: Angle,
    mask: i32,
}

impl QuadrantStage {
    fn new(mode: Mode, cfg: &CordicConfig) -> Self {
        QuadrantStage {
            mode,
            half_pi: Angle::from_bits(rom_round(HALF_PI_Q62, cfg.width - 3, 29)),
            mask: width_mask(cfg.width),
        }
    }

    /// The stage's logic.
    #[inline]
    pub fn eval<P: Copy + Default>(&self, s: CordicSlot<P>) -> CordicSlot<P> {
        let m = |v: Unit| Unit::from_bits(v.to_bits() & self.mask);
        let ma = |v: Angle| Angle::from_bits(v.to_bits() & self.mask);
        let (x, y, z) = (m(s.x), m(s.y), ma(s.z));
        let mut out = s;
        match self.mode {
            Mode::Rotate => {
                if z > self.half_pi {
                    (out.x, out.y, out.z) = (y.wrapping_neg(), x, z.wrapping_sub(self.half_pi));
                } else if z < self.half_pi.wrapping_neg() {
                    (out.x, out.y, out.z) = (y, x.wrapping_neg(), z.wrapping_add(self.half_pi));
                } else {
                    (out.x, out.y, out.z) = (x, y, z);
                }
                out.zero = false;
            }
            Mode::Vector => {
                out.zero = x == Unit::ZERO && y == Unit::ZERO;
                if x < Unit::ZERO {
                    if y >= Unit::ZERO {
                        // turned by −π/2: the original angle is π/2 more than what is left
                        (out.x, out.y, out.z) = (y, x.wrapping_neg(), z.wrapping_add(self.half_pi));
                    } else {
                        (out.x, out.y, out.z) = (y.wrapping_neg(), x, z.wrapping_sub(self.half_pi));
                    }
                } else {
                    (out.x, out.y, out.z) = (x, y, z);
                }
            }
        }
        out
    }
}

/// Micro-rotation stage i: shifts by the constant i and adds ±atan 2^-i from ROM.
#[derive(Clone, Copy, Debug)]
pub struct MicroRotation {
    mode: Mode,
    shift: u32,
    atan: Angle,
    mask: i32,
}

impl MicroRotation {
    fn new(mode: Mode, i: u32, cfg: &CordicConfig) -> Self {
        MicroRotation {
            mode,
            shift: i,
            atan: Angle::from_bits(rom_round(ATAN_Q62[i as usize], cfg.width - 3, 29)),
            mask: width_mask(cfg.width),
        }
    }

    /// The stage's logic.
    #[inline]
    pub fn eval<P: Copy + Default>(&self, mut s: CordicSlot<P>) -> CordicSlot<P> {
        self.apply(&mut s);
        s
    }

    /// The stage's logic on the register in place (the payload is not touched).
    #[inline]
    pub fn apply<P: Copy + Default>(&self, out: &mut CordicSlot<P>) {
        let (x, y, z) = (out.x.to_bits(), out.y.to_bits(), out.z.to_bits());
        // rotate counter-clockwise (d = +1) while angle is left (rotation mode) or while the
        // vector is below the axis (vectoring mode)
        let ccw = match self.mode {
            Mode::Rotate => z >= 0,
            Mode::Vector => y < 0,
        };
        let (x, y, z) = self.step(ccw, x, y, z);
        out.x = Unit::from_bits(x);
        out.y = Unit::from_bits(y);
        out.z = Angle::from_bits(z);
    }

    /// The adders of the stage on the raw words, given the direction bit: the operands are
    /// taken as ±v by (v ^ s) − s with s = 0 or −1, as an add/sub control line does (and
    /// without a data-dependent branch in the simulation).
    #[inline(always)]
    fn step(&self, ccw: bool, x: i32, y: i32, z: i32) -> (i32, i32, i32) {
        let dx = (x >> self.shift) & self.mask;
        let dy = (y >> self.shift) & self.mask;
        let s = -(!ccw as i32);
        let neg = |v: i32| (v ^ s).wrapping_sub(s);
        (
            x.wrapping_sub(neg(dy)),
            y.wrapping_add(neg(dx)),
            z.wrapping_sub(neg(self.atan.to_bits())),
        )
    }
}

/// The last stage: multiplies each component by the constant 1/K_n (and clears the angle of a
/// vectored zero vector).
#[derive(Clone, Copy, Debug)]
pub struct GainStage {
    mode: Mode,
    inv_gain: i32,
    mask: i32,
}

impl GainStage {
    fn new(mode: Mode, cfg: &CordicConfig) -> Self {
        GainStage {
            mode,
            inv_gain: rom_round(INV_GAIN_Q62[cfg.iterations as usize], cfg.width - 2, 30),
            mask: width_mask(cfg.width),
        }
    }

    #[inline]
    fn scale(&self, v: Unit) -> Unit {
        // 32 × 32 → 64-bit product, back to Q2.30 by the constant shift 30 (truncating)
        let p = (v.to_bits() as i64 * self.inv_gain as i64) >> 30;
        Unit::from_bits(p as i32 & self.mask)
    }

    /// The stage's logic.
    #[inline]
    pub fn eval<P: Copy + Default>(&self, mut s: CordicSlot<P>) -> CordicSlot<P> {
        self.apply(&mut s);
        s
    }

    /// The stage's logic on the register in place.
    #[inline]
    pub fn apply<P: Copy + Default>(&self, s: &mut CordicSlot<P>) {
        s.x = self.scale(s.x);
        s.y = self.scale(s.y);
        if self.mode == Mode::Vector && s.zero {
            s.z = Angle::ZERO;
        }
    }
}

/// A fully pipelined CORDIC: quadrant stage, `iterations` micro-rotations, gain stage.
#[derive(Clone, Debug)]
pub struct CordicPipe<P: Copy + Default> {
    cfg: CordicConfig,
    quadrant: QuadrantStage,
    micro: [MicroRotation; super::MAX_ITERATIONS as usize],
    gain: GainStage,
    pipe: Pipe<CordicSlot<P>>,
    pending: Option<CordicSlot<P>>,
}

impl<P: Copy + Default> CordicPipe<P> {
    /// A pipe built for `cfg` (which must be valid: the register file refuses the others).
    pub fn new(mode: Mode, cfg: CordicConfig) -> Self {
        assert!(cfg.is_valid(), "invalid CORDIC configuration {cfg:?}");
        CordicPipe {
            cfg,
            quadrant: QuadrantStage::new(mode, &cfg),
            micro: core::array::from_fn(|i| MicroRotation::new(mode, i as u32, &cfg)),
            gain: GainStage::new(mode, &cfg),
            pipe: Pipe::new(cfg.latency() as usize),
            pending: None,
        }
    }

    /// The configuration it was built for.
    pub fn config(&self) -> CordicConfig {
        self.cfg
    }

    /// Latency in clocks.
    pub fn latency(&self) -> u32 {
        self.cfg.latency()
    }

    /// Vectors in flight.
    pub fn occupancy(&self) -> u32 {
        self.pipe.occupancy() + self.pending.is_some() as u32
    }

    /// Drops everything in flight.
    pub fn flush(&mut self) {
        self.pending = None;
        self.pipe.flush();
    }

    /// Puts `s` into the quadrant stage's input register, for a unit that ticks its pipes
    /// output-first (the value enters on the next `tick`, as if presented at this clock edge).
    pub fn feed(&mut self, s: CordicSlot<P>) {
        debug_assert!(self.pending.is_none(), "two inputs in one clock");
        self.pending = Some(s);
    }

    /// One clock: `input` (or what was `feed`) enters the quadrant stage; returns the slot
    /// leaving the gain stage.
    #[inline]
    pub fn tick(&mut self, input: Option<CordicSlot<P>>) -> Option<CordicSlot<P>> {
        if input.is_none() && self.pending.is_none() && self.pipe.is_empty() {
            // an empty pipe's clock changes no register
            return None;
        }
        let input = match input {
            Some(s) => Some(s),
            None => self.pending.take(),
        }
        .map(|s| self.quadrant.eval(s));
        // register k feeds micro-rotation k (k < n), register n the gain stage: applied in that
        // order as the value leaves (see `Pipe::shift`)
        self.pipe.shift(input).map(|s| self.after_quadrant(s))
    }

    /// Every stage of the pipe in order, as one combinational chain: what a value entering the
    /// pipe leaves it as, for a unit that keeps the registers itself (the rotator chains three
    /// pipes in one ring of registers).
    #[inline]
    pub fn eval(&self, s: CordicSlot<P>) -> CordicSlot<P> {
        self.after_quadrant(self.quadrant.eval(s))
    }

    /// The micro-rotations and the gain stage.
    #[inline]
    fn after_quadrant(&self, mut s: CordicSlot<P>) -> CordicSlot<P> {
        {
            let micro = &self.micro[..self.cfg.iterations as usize];
            let (mut x, mut y, mut z) = (s.x.to_bits(), s.y.to_bits(), s.z.to_bits());
            // `MicroRotation::apply` stage after stage, with the mode decided once
            match self.gain.mode {
                Mode::Rotate => {
                    for m in micro {
                        (x, y, z) = m.step(z >= 0, x, y, z);
                    }
                }
                Mode::Vector => {
                    for m in micro {
                        (x, y, z) = m.step(y < 0, x, y, z);
                    }
                }
            }
            (s.x, s.y, s.z) = (Unit::from_bits(x), Unit::from_bits(y), Angle::from_bits(z));
            self.gain.apply(&mut s);
            s
        }
    }
}
