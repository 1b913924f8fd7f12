//! The ray rotator of paper §3.4 and fig. 6: three rotation-mode CORDIC pipes in series turn a
//! reference-hemisphere direction onto the frame, in the same order and planes as
//! `hemi_kernel::rotation::Rotation::apply`:
//!
//! 1. ψ about z: (x, y) turned by ψ, z carried;
//! 2. θ about y: (z, x) turned by θ (so x₁ = x cos θ + z sin θ, z₁ = z cos θ − x sin θ), y carried;
//! 3. φ about z: (x₁, y) turned by φ, z₁ carried.
//!
//! One direction enters per clock; latency 3(n + 2) + 2 (a register between consecutive pipes). A bypass bit (trace mode: the direction is
//! already in scene space) returns the input unchanged after the same latency, so results stay in
//! order without a second path.

use crate::cordic::{CordicConfig, CordicPipe, CordicSlot, Mode};
use crate::format::{Angle, Unit};

/// What rides along a direction through the rotator.
#[derive(Clone, Copy, Debug, Default)]
pub struct Carry<T: Copy + Default> {
    third: Unit,
    theta: Angle,
    phi: Angle,
    original: [Unit; 3],
    bypass: bool,
    info: T,
}

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

/// The three CORDIC pipes.
#[derive(Clone, Debug)]
pub struct Rotator<T: Copy + Default> {
    psi: CordicPipe<Carry<T>>,
    theta: CordicPipe<Carry<T>>,
    phi: CordicPipe<Carry<T>>,
}

impl<T: Copy + Default> Rotator<T> {
    /// A rotator of three pipes built for `cfg`.
    pub fn new(cfg: CordicConfig) -> Self {
        Rotator {
            psi: CordicPipe::new(Mode::Rotate, cfg),
            theta: CordicPipe::new(Mode::Rotate, cfg),
            phi: CordicPipe::new(Mode::Rotate, cfg),
        }
    }

    /// Latency in clocks.
    pub fn latency(&self) -> u32 {
        3 * self.psi.latency() + 2
    }

    /// Directions in flight.
    pub fn occupancy(&self) -> u32 {
        self.psi.occupancy() + self.theta.occupancy() + self.phi.occupancy()
    }

    /// Drops everything in flight.
    pub fn flush(&mut self) {
        self.psi.flush();
        self.theta.flush();
        self.phi.flush();
    }

    /// One clock; returns the rotated direction leaving the φ pipe with its info.
    #[inline]
    pub fn tick(&mut self, input: Option<RotIn<T>>) -> Option<([Unit; 3], T)> {
        // the pipes are ticked last-first, as registers all update on the same edge
        let out = self.phi.tick(None);
        let from_theta = self.theta.tick(None);
        let from_psi = self.psi.tick(input.map(|r| CordicSlot {
            x: r.dir[0],
            y: r.dir[1],
            z: if r.bypass { Angle::ZERO } else { r.angles[0] },
            zero: false,
            payload: Carry {
                third: r.dir[2],
                theta: r.angles[1],
                phi: r.angles[2],
                original: r.dir,
                bypass: r.bypass,
                info: r.info,
            },
        }));
        if let Some(s) = from_psi {
            // (z, x) turned by θ; y carried
            self.theta.feed(CordicSlot {
                x: s.payload.third,
                y: s.x,
                z: s.payload.theta,
                zero: false,
                payload: Carry {
                    third: s.y,
                    ..s.payload
                },
            });
        }
        if let Some(s) = from_theta {
            // (x₁, y) turned by φ; z₁ carried
            self.phi.feed(CordicSlot {
                x: s.y,
                y: s.payload.third,
                z: s.payload.phi,
                zero: false,
                payload: Carry {
                    third: s.x,
                    ..s.payload
                },
            });
        }
        out.map(|s| {
            let p = s.payload;
            let v = if p.bypass {
                p.original
            } else {
                [s.x, s.y, p.third]
            };
            (v, p.info)
        })
    }
}
