//! The host's end of the link: request/response over any byte stream with timeouts, request ids
//! and the handshake with retries.

use std::io::{self, Read, Write};
use std::time::{Duration, Instant};

use crate::error::describe;
use anyhow::{anyhow, bail, Context, Result};
use hemi_kernel::link::{
    decode_response, encode_request, HelloInfo, LinkStats, MaxFrameDecoder, Request, Response,
    MAX_WIRE_LEN, MIN_PROTOCOL_VERSION, NO_ID, PROTOCOL_VERSION,
};

/// A byte stream to a board: a serial port, a pty, or anything in memory. Reads must time out
/// (return `TimedOut`/`WouldBlock`, or `Ok(0)`) within a few tens of milliseconds so calls can
/// honour their deadlines.
pub trait Port: Read + Write + Send {}
impl<T: Read + Write + Send> Port for T {}

/// The first id of the link's own requests: job ids (chosen by the caller) stay below it.
pub const FIRST_LINK_ID: u32 = (1 << 21) + 1;

/// Baud rate asked of a real serial port (a pty ignores it).
pub const BAUD: u32 = 115_200;
/// How long one read may block; bounds how late a deadline is noticed.
const READ_SLICE: Duration = Duration::from_millis(20);

/// Handshake retry policy. A pty drops the board's output until QEMU notices the host opened it,
/// which it re-checks about once a second, so the first replies can vanish.
#[derive(Clone, Copy, Debug)]
pub struct Retry {
    /// Hello requests sent at most.
    pub attempts: u32,
    /// Wait for an answer to each.
    pub timeout: Duration,
}

impl Default for Retry {
    fn default() -> Self {
        Self {
            attempts: 12,
            timeout: Duration::from_millis(750),
        }
    }
}

/// A successful handshake and what it took.
#[derive(Clone, Debug)]
pub struct Handshake {
    /// What the board said.
    pub hello: HelloInfo,
    /// Hello requests sent until one was answered.
    pub attempts: u32,
    /// From the first Hello to the answer, retries included.
    pub elapsed: Duration,
    /// Round trip of the Hello that was answered.
    pub round_trip: Duration,
}

/// Request/response client of one board.
pub struct Link {
    port: Box<dyn Port>,
    decoder: Box<MaxFrameDecoder>,
    next_id: u32,
    frame: Vec<u8>,
    /// Received bytes not yet fed to the decoder: `rx[rx_start..rx_end]`.
    rx: Vec<u8>,
    rx_start: usize,
    rx_end: usize,
}

impl Link {
    /// Opens a serial device (or a pty) at [`BAUD`], 8N1.
    pub fn open_serial(path: &str) -> Result<Self> {
        let port = serialport::new(path, BAUD)
            .timeout(READ_SLICE)
            .open()
            .with_context(|| format!("opening serial port {path}"))?;
        Ok(Self::new(Box::new(port)))
    }

    /// A link over any byte stream.
    pub fn new(port: Box<dyn Port>) -> Self {
        Self {
            port,
            decoder: Box::new(MaxFrameDecoder::new()),
            next_id: FIRST_LINK_ID,
            frame: vec![0; MAX_WIRE_LEN],
            rx: vec![0; 4096],
            rx_start: 0,
            rx_end: 0,
        }
    }

    fn fresh_id(&mut self) -> u32 {
        let id = self.next_id;
        // Stay above the job ids (see `send_as`), which also skips NO_ID on wrap-around.
        self.next_id = self.next_id.wrapping_add(1).max(FIRST_LINK_ID);
        id
    }

    /// Sends a request; returns its id.
    pub fn send(&mut self, req: &Request) -> Result<u32> {
        let id = self.fresh_id();
        self.send_as(id, req)?;
        Ok(id)
    }

    /// Sends a request with the caller's id: a job's id, the same on every retry so the board
    /// counts the job once. Job ids must not collide with this link's own (see `fresh_id`): the
    /// job farm's are at most 2^21, the link's own above.
    pub fn send_as(&mut self, id: u32, req: &Request) -> Result<()> {
        let n = encode_request(id, req, &mut self.frame)
            .map_err(|e| anyhow!("request too large for one frame: {e:?}"))?;
        write_patiently(&mut self.port, &self.frame[..n])
    }

    /// Sends raw bytes (fault-injection tests; a lone 0x00 to flush the board's decoder).
    pub fn send_raw(&mut self, bytes: &[u8]) -> Result<()> {
        write_patiently(&mut self.port, bytes)
    }

    /// The next good response frame, whatever its id; `None` at the deadline. Damaged frames
    /// from the board are skipped (they were replies to nothing the caller can still use).
    pub fn recv_any(&mut self, timeout: Duration) -> Result<Option<(u32, Response)>> {
        let deadline = Instant::now() + timeout;
        loop {
            while self.rx_start < self.rx_end {
                let byte = self.rx[self.rx_start];
                self.rx_start += 1;
                if let Some(Ok(payload)) = self.decoder.push(byte) {
                    if let Ok(msg) = decode_response(payload) {
                        return Ok(Some(msg));
                    }
                }
            }
            if Instant::now() >= deadline {
                return Ok(None);
            }
            match self.port.read(&mut self.rx) {
                Ok(0) => std::thread::sleep(Duration::from_millis(1)),
                Ok(n) => (self.rx_start, self.rx_end) = (0, n),
                Err(e)
                    if matches!(
                        e.kind(),
                        io::ErrorKind::TimedOut
                            | io::ErrorKind::WouldBlock
                            | io::ErrorKind::Interrupted
                    ) => {}
                Err(e) => return Err(e).context("reading from the board"),
            }
        }
    }

    /// Sends `req` and waits for the response with its id. Stale responses (to earlier, timed
    /// out requests) are skipped. An error frame with this request's id fails the call at once.
    /// An error frame without an id (the board could not read some frame: this one, or noise
    /// before it) does not: the answer may still come, and if it does not, the timeout error
    /// names the board's complaint.
    pub fn call(&mut self, req: &Request, timeout: Duration) -> Result<Response> {
        let id = self.send(req)?;
        let deadline = Instant::now() + timeout;
        let mut complaint = None;
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.recv_any(left)? {
                None => match complaint {
                    Some(code) => bail!(
                        "no answer from the board within {timeout:?}; it reported: {}",
                        describe(code)
                    ),
                    None => bail!("no answer from the board within {timeout:?}"),
                },
                Some((rid, Response::Error { code })) if rid == id => {
                    return Err(crate::error::Refused { code }.into())
                }
                Some((NO_ID, Response::Error { code })) => complaint = Some(code),
                Some((rid, resp)) if rid == id => return Ok(resp),
                Some(_) => {}
            }
        }
    }

    /// The handshake, retried per `retry`. Sends a lone delimiter first so the board's decoder
    /// drops whatever partial frame it may hold.
    pub fn handshake(&mut self, retry: Retry) -> Result<Handshake> {
        let start = Instant::now();
        self.send_raw(&[0])?;
        let mut last_err = anyhow!("no attempt made");
        for attempt in 1..=retry.attempts.max(1) {
            let t0 = Instant::now();
            match self.call(
                &Request::Hello {
                    protocol: PROTOCOL_VERSION,
                },
                retry.timeout,
            ) {
                Ok(Response::Hello(hello)) => {
                    // The board answers the older of the two versions it speaks.
                    if !(MIN_PROTOCOL_VERSION..=PROTOCOL_VERSION).contains(&hello.protocol) {
                        bail!(
                            "the board speaks protocol {} but this host speaks \
                             {MIN_PROTOCOL_VERSION} to {PROTOCOL_VERSION}: rebuild the firmware \
                             or the host from the same revision",
                            hello.protocol
                        );
                    }
                    return Ok(Handshake {
                        hello,
                        attempts: attempt,
                        elapsed: start.elapsed(),
                        round_trip: t0.elapsed(),
                    });
                }
                Ok(other) => last_err = anyhow!("unexpected answer to Hello: {other:?}"),
                Err(e) => last_err = e,
            }
        }
        Err(last_err.context(format!(
            "no handshake after {} attempts of {:?}",
            retry.attempts, retry.timeout
        )))
    }

    /// One ping; returns its round-trip time.
    pub fn ping(&mut self, nonce: u32, timeout: Duration) -> Result<Duration> {
        let t0 = Instant::now();
        match self.call(&Request::Ping { nonce }, timeout)? {
            Response::Pong { nonce: n } if n == nonce => Ok(t0.elapsed()),
            other => bail!("unexpected answer to Ping({nonce}): {other:?}"),
        }
    }

    /// The board's link counters.
    pub fn stats(&mut self, timeout: Duration) -> Result<LinkStats> {
        match self.call(&Request::LinkStats, timeout)? {
            Response::LinkStats(s) => Ok(s),
            other => bail!("unexpected answer to LinkStats: {other:?}"),
        }
    }
}

/// How long a write may wait for the board to take its bytes. The port's timeout (20 ms) is
/// for reads; QEMU drains a pty at only ~10-15 KB/s, slower still on a loaded machine, so a full
/// pty buffer is not a dead link.
const WRITE_PATIENCE: Duration = Duration::from_secs(5);

/// Writes all of `bytes`, waiting out write timeouts up to [`WRITE_PATIENCE`] of no progress.
fn write_patiently(port: &mut Box<dyn Port>, mut bytes: &[u8]) -> Result<()> {
    let mut last_progress = Instant::now();
    while !bytes.is_empty() {
        match port.write(bytes) {
            Ok(0) => bail!("writing to the board: the port accepts no bytes"),
            Ok(n) => {
                bytes = &bytes[n..];
                last_progress = Instant::now();
            }
            Err(e)
                if matches!(
                    e.kind(),
                    io::ErrorKind::TimedOut
                        | io::ErrorKind::WouldBlock
                        | io::ErrorKind::Interrupted
                ) && last_progress.elapsed() < WRITE_PATIENCE => {}
            Err(e) => return Err(e).context("writing to the board"),
        }
    }
    port.flush().context("writing to the board")
}
