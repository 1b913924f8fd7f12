//! The ray rotator of paper §3.4 and fig. 6: three rotation-mode CORDIC pipes in series turn a
//! reference-hemisphere direction onto the frame, in the same order and planes as
//! `hemi_kernel::rotation::Rotation::apply`:
//!
//! 1. ψ about z: (x, y) turned by ψ, z carried;
//! 2. θ about y: (z, x) turned by θ (so x₁ = x cos θ + z sin θ, z₁ = z cos θ − x sin θ), y carried;
//! 3. φ about z: (x₁, y) turned by φ, z₁ carried.
//!
//! One direction enters per clock; latency 3(n + 4) + 2 (a register between consecutive pipes). A bypass bit (trace mode: the direction is
//! already in scene space) returns the input unchanged after the same latency, so results stay in
//! order without a second path.

use crate::cordic::{CordicConfig, CordicPipe, CordicSlot, Mode};
use crate::format::{Angle, Unit};
use crate::pipe::Pipe;

/// What rides along a direction through the pipes: the component the current pipe does not
/// turn, and the direction's slot in the side table (a 7-bit tag, as hardware would carry
/// instead of copying the frame and the info down every stage).
#[derive(Clone, Copy, Debug, Default)]
pub struct Carry {
    third: Unit,
    slot: u8,
}

/// What a direction needs besides its vector: the later pipes' angles, the unrotated direction
/// (bypass) and the device's info. Written once on entry, read at the pipe boundaries and on exit.
#[derive(Clone, Copy, Debug, Default)]
struct Side<T: Copy + Default> {
    theta: Angle,
    phi: Angle,
    original: [Unit; 3],
    bypass: bool,
    info: T,
}

/// Side-table slots: more than the longest rotator latency ([`CHAIN`], 3 (30 + 4) + 2 = 104
/// clocks), so a slot allocated round-robin, at most one per clock, is free again before it is
/// reused.
const SLOTS: usize = 128;
const _: () = assert!(SLOTS > CHAIN);

/// A direction and its frame entering the rotator.
#[derive(Clone, Copy, Debug, Default)]
pub struct RotIn<T: Copy + Default> {
    /// Direction (Q2.30).
    pub dir: [Unit; 3],
    /// ψ, θ, φ.
    pub angles: [Angle; 3],
    /// Pass the direction through unrotated.
    pub bypass: bool,
    /// Carried to the output.
    pub info: T,
}

/// The rotator's latency at `iterations`: three pipes and the register between consecutive
/// pipes, 3(n + 4) + 2.
const fn chain(iterations: u32) -> usize {
    3 * crate::cordic::pipe_latency(iterations) as usize + 2
}

/// The rotator's registers at the most iterations.
const CHAIN: usize = chain(crate::cordic::MAX_ITERATIONS);

/// The three CORDIC pipes.
///
/// Their registers are kept as one ring of 3(n + 4) + 2 ([`Pipe`]), and each pipe's stages are
/// applied as a direction leaves the ring (`Pipe::shift`): the pipes never stall and nothing
/// reads their registers, so the direction and its clock are those of three pipes ticked one
/// after the other, at the cost of one register shift a clock instead of three.
#[derive(Clone, Debug)]
pub struct Rotator<T: Copy + Default> {
    pipes: Pipes,
    regs: Pipe<CordicSlot<Carry>, CHAIN>,
    side: [Side<T>; SLOTS],
    next_slot: u8,
    /// directions in flight (entered and not yet out), kept as a counter: the device asks
    /// every clock
    in_flight: u32,
}

impl<T: Copy + Default> Rotator<T> {
    /// A rotator of three pipes built for `cfg`.
    pub fn new(cfg: CordicConfig) -> Self {
        Rotator {
            pipes: Pipes {
                psi: CordicPipe::new(Mode::Rotate, cfg),
                theta: CordicPipe::new(Mode::Rotate, cfg),
                phi: CordicPipe::new(Mode::Rotate, cfg),
            },
            regs: Pipe::new(chain(cfg.iterations)),
            side: [Side::default(); SLOTS],
            next_slot: 0,
            in_flight: 0,
        }
    }

    /// Latency in clocks.
    pub fn latency(&self) -> u32 {
        chain(self.pipes.psi.config().iterations) as u32
    }

    /// Directions in flight.
    pub fn occupancy(&self) -> u32 {
        debug_assert_eq!(self.in_flight, self.regs.occupancy());
        self.in_flight
    }

    /// Drops everything in flight.
    pub fn flush(&mut self) {
        self.regs.flush();
        self.in_flight = 0;
    }

    /// The frame's axes x̂, ŷ, ẑ turned by `angles` (ψ, θ, φ) as this rotator turns
    /// directions: what the culling unit's set-up needs of a frame (three entries through the
    /// rotator, which the frame unit issues when a frame completes, ahead of its rays).
    pub fn axes(&self, angles: [Angle; 3]) -> [[Unit; 3]; 3] {
        let one = Unit::from_bits(1 << 30);
        let e = [
            [one, Unit::ZERO, Unit::ZERO],
            [Unit::ZERO, one, Unit::ZERO],
            [Unit::ZERO, Unit::ZERO, one],
        ];
        e.map(|d| self.pipes.turn(d, angles))
    }

    /// One clock; returns the rotated direction leaving the φ pipe with its info.
    #[inline]
    pub fn tick(&mut self, input: Option<RotIn<T>>) -> Option<([Unit; 3], T)> {
        if input.is_none() && self.in_flight == 0 {
            return None;
        }
        let input = input.map(|r| {
            self.in_flight += 1;
            let slot = self.next_slot;
            self.next_slot = (slot + 1) % SLOTS as u8;
            self.side[slot as usize] = Side {
                theta: r.angles[1],
                phi: r.angles[2],
                original: r.dir,
                bypass: r.bypass,
                info: r.info,
            };
            CordicSlot {
                x: r.dir[0],
                y: r.dir[1],
                // a bypassed entry turns by whatever angles it brings: its output is the
                // side table's original direction, so the pipes' words are never seen (the
                // RTL then needs no multiplexer before its first quadrant stage)
                z: r.angles[0],
                zero: false,
                payload: Carry {
                    third: r.dir[2],
                    slot,
                },
            }
        });
        let out = self.regs.shift(input)?;
        self.in_flight -= 1;
        let side = &self.side[out.payload.slot as usize];
        if side.bypass {
            return Some((side.original, side.info));
        }
        let (dir, angles) = (
            [out.x, out.y, out.payload.third],
            [out.z, side.theta, side.phi],
        );
        Some((self.pipes.turn(dir, angles), side.info))
    }
}

/// The three CORDIC pipes, whose stages are applied together when a direction leaves the
/// rotator's ring.
#[derive(Clone, Debug)]
struct Pipes {
    psi: CordicPipe<Carry>,
    theta: CordicPipe<Carry>,
    phi: CordicPipe<Carry>,
}

impl Pipes {
    /// The three pipes' stages on one direction, as a combinational chain: (x, y) turned by ψ,
    /// z carried; (z, x) turned by θ, y carried; (x₁, y) turned by φ, z₁ carried.
    fn turn(&self, dir: [Unit; 3], angles: [Angle; 3]) -> [Unit; 3] {
        let stage = |pipe: &CordicPipe<Carry>, x, y, z, third| {
            pipe.eval(CordicSlot {
                x,
                y,
                z,
                zero: false,
                payload: Carry { third, slot: 0 },
            })
        };
        let s = stage(&self.psi, dir[0], dir[1], angles[0], dir[2]);
        let s = stage(&self.theta, s.payload.third, s.x, angles[1], s.y);
        let s = stage(&self.phi, s.y, s.payload.third, angles[2], s.x);
        [s.x, s.y, s.payload.third]
    }
}
