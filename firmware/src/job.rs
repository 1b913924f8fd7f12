//! The job loop: received bytes in, reply frames out, through `embedded_io` traits so it runs the
//! same against the UART and against in-memory buffers in the on-target tests.

use embedded_io::Write;
use hemi_kernel::link::{HelloInfo, LinkServer, LinkStats, MAX_WIRE_LEN};

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

    /// Handles received bytes, writing every reply to `tx` as soon as its frame is complete.
    pub fn feed<W: Write>(&mut self, bytes: &[u8], tx: &mut W) -> Result<(), W::Error> {
        for &b in bytes {
            if let Some(n) = self.server.push(b, &mut self.out) {
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
