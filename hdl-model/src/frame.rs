//! The angle unit ("another Cordic, which is not indicated in figure 6", paper §3.4): one
//! vectoring-mode CORDIC pipe that turns a frame description into the angles ψ, θ, φ the rotator
//! consumes.
//!
//! - From a normal n: φ = atan2(n_y, n_x) and, in the same pass, ρ = n_x cos φ + n_y sin φ =
//!   |(n_x, n_y)| (the gain-compensated x output); then θ = atan2(ρ, n_z) by a second pass that
//!   waits for ρ. The spin ψ is vectored from its (cos ψ, sin ψ) in between.
//! - From three (cos, sin) pairs, as `Rotation` holds them: one pass each, back to back.
//!
//! Latency: 2(n + 4) + 1 clocks from a normal, n + 6 from pairs.

use crate::cordic::{CordicConfig, CordicPipe, CordicSlot, Mode};
use crate::format::{Angle, Unit};

/// A frame to compute.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FrameRequest {
    /// From a normal (n_x, n_y, n_z) and the spin (cos ψ, sin ψ).
    Normal {
        /// The normal (need not be exactly unit).
        n: [Unit; 3],
        /// (cos ψ, sin ψ).
        spin: [Unit; 2],
    },
    /// From (cos, sin) of φ, θ and ψ.
    Pairs {
        /// (cos φ, sin φ).
        phi: [Unit; 2],
        /// (cos θ, sin θ).
        theta: [Unit; 2],
        /// (cos ψ, sin ψ).
        psi: [Unit; 2],
    },
}

/// Which angle a vectoring pass produces.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
enum Tag {
    #[default]
    Psi,
    Theta,
    /// φ; when set, its magnitude feeds the θ pass (normal mode).
    Phi {
        then_theta: bool,
    },
}

/// The angle unit.
#[derive(Clone, Debug)]
pub struct FrameUnit {
    pipe: CordicPipe<Tag>,
    /// Passes still to issue (at most two waiting: ψ and θ of the pairs mode).
    queue: [Option<CordicSlot<Tag>>; 2],
    nz: Unit,
    outstanding: u32,
    angles: [Angle; 3],
}

impl FrameUnit {
    /// An idle unit built for `cfg`.
    pub fn new(cfg: CordicConfig) -> Self {
        FrameUnit {
            pipe: CordicPipe::new(Mode::Vector, cfg),
            queue: [None; 2],
            nz: Unit::ZERO,
            outstanding: 0,
            angles: [Angle::ZERO; 3],
        }
    }

    /// Whether a frame is being computed.
    pub fn busy(&self) -> bool {
        self.outstanding > 0
    }

    /// The last frame's ψ, θ, φ.
    pub fn angles(&self) -> [Angle; 3] {
        self.angles
    }

    /// Drops the frame in flight.
    pub fn flush(&mut self) {
        self.pipe.flush();
        self.queue = [None; 2];
        self.outstanding = 0;
    }

    /// Starts a frame (the unit must be idle).
    pub fn start(&mut self, req: FrameRequest) {
        debug_assert!(!self.busy());
        let slot = |v: [Unit; 2], tag| CordicSlot {
            x: v[0],
            y: v[1],
            z: Angle::ZERO,
            zero: false,
            payload: tag,
        };
        match req {
            FrameRequest::Normal { n, spin } => {
                self.nz = n[2];
                self.queue = [
                    Some(slot([n[0], n[1]], Tag::Phi { then_theta: true })),
                    Some(slot(spin, Tag::Psi)),
                ];
            }
            FrameRequest::Pairs { phi, theta, psi } => {
                // φ goes now, θ and ψ on the next two clocks
                self.pipe.feed(slot(phi, Tag::Phi { then_theta: false }));
                self.queue = [Some(slot(theta, Tag::Theta)), Some(slot(psi, Tag::Psi))];
            }
        }
        self.outstanding = 3;
    }

    /// One clock; true on the clock the frame completes.
    #[inline]
    pub fn tick(&mut self) -> bool {
        if !self.busy() {
            // nothing queued or in the pipe (all of it counts in `outstanding`): a clock of an
            // idle unit changes no register
            return false;
        }
        self.tick_busy()
    }

    fn tick_busy(&mut self) -> bool {
        let was_busy = true;
        let mut input = None;
        if let Some(s) = self.pipe.tick(None) {
            match s.payload {
                Tag::Phi { then_theta } => {
                    self.angles[2] = s.z;
                    if then_theta {
                        // θ = atan2(ρ, n_z): the magnitude out of this pass is ρ
                        input = Some(CordicSlot {
                            x: self.nz,
                            y: s.x,
                            z: Angle::ZERO,
                            zero: false,
                            payload: Tag::Theta,
                        });
                    }
                }
                Tag::Theta => self.angles[1] = s.z,
                Tag::Psi => self.angles[0] = s.z,
            }
            self.outstanding -= 1;
        }
        if input.is_none() {
            if let Some(q) = self.queue[0].take() {
                input = Some(q);
                self.queue = [self.queue[1], None];
            }
        }
        if let Some(s) = input {
            self.pipe.feed(s);
        }
        was_busy && !self.busy()
    }
}
