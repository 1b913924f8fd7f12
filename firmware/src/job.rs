//! The job loop: received bytes in, reply frames out, through `embedded_io` traits so it runs the
//! same against the UART and against in-memory buffers in the on-target tests. Requests beyond
//! the link's own go to the job engine ([`FwEngine`]).

use embedded_io::Write;
use hemi_kernel::jobs::{Engine, Platform};
use hemi_kernel::link::{HelloInfo, JobHandler, LinkServer, LinkStats, NoEngine, MAX_WIRE_LEN};

use crate::accel::FwAccel;

/// The machine the engine runs on: SysTick for CPU time, and the stack measurement of the
/// firmware entry (the only code allowed to look at raw memory).
/// All zero bytes when unset, so the static engine stays in `.bss`.
pub struct FwPlatform {
    /// (deepest stack use, stack size measured) in bytes, if measured.
    pub stack: Option<fn() -> (u32, u32)>,
    /// Whether SysTick was started (on-target tests run without it).
    pub clock: bool,
}

impl Platform for FwPlatform {
    fn ticks(&self) -> u64 {
        if self.clock {
            crate::clock::ticks()
        } else {
            0
        }
    }
    fn stack(&self) -> (u32, u32) {
        self.stack.map_or((0, 0), |f| f())
    }
}

/// A platform without SysTick or stack measurement.
pub const NO_PLATFORM: FwPlatform = FwPlatform {
    stack: None,
    clock: false,
};

/// The firmware's job engine: the kernel's engine over this build's accelerators.
pub type FwEngine = Engine<FwAccel, FwPlatform>;

/// A fresh engine (a `const fn`, so it can be a `static` and never be copied through the stack).
pub const fn new_engine(platform: FwPlatform) -> FwEngine {
    Engine::new(FwAccel::new(), platform)
}

/// The link server and its transmit buffer.
pub struct JobLoop {
    server: LinkServer,
    out: [u8; MAX_WIRE_LEN],
}

impl JobLoop {
    /// A job loop that introduces itself with `info`.
    pub const fn new(info: HelloInfo) -> Self {
        Self {
            server: LinkServer::new(info),
            out: [0; MAX_WIRE_LEN],
        }
    }

    /// Handles received bytes (link messages only), writing every reply to `tx` as soon as its
    /// frame is complete.
    pub fn feed<W: Write>(&mut self, bytes: &[u8], tx: &mut W) -> Result<(), W::Error> {
        self.feed_with(bytes, tx, &mut NoEngine)
    }

    /// Handles received bytes, engine requests served by `jobs`.
    pub fn feed_with<W: Write, H: JobHandler>(
        &mut self,
        bytes: &[u8],
        tx: &mut W,
        jobs: &mut H,
    ) -> Result<(), W::Error> {
        for &b in bytes {
            if let Some(n) = self.server.push_with(b, &mut self.out, jobs) {
                // `n` is within `out` by construction; `get` keeps that from being a panic path.
                if let Some(frame) = self.out.get(..n) {
                    tx.write_all(frame)?;
                    defmt::debug!("reply: {} bytes", n);
                }
            }
        }
        Ok(())
    }

    /// Records bytes the receive path lost.
    pub fn note_rx_overrun(&mut self, lost: u32) {
        if lost > 0 {
            defmt::warn!("receive ring overran: {} bytes lost", lost);
            self.server.note_rx_overrun(lost);
        }
    }

    /// The link counters.
    pub fn stats(&self) -> LinkStats {
        self.server.stats()
    }
}
