//! The board's end of the link: bytes in, reply frames out.
//!
//! It lives in the kernel, not the firmware, so the exact code the firmware runs is unit-tested on
//! the host and on the target, and so an in-process board (the soft backend, tests) speaks the
//! same protocol. It knows only link-level messages; the rest go to a [`JobHandler`] (a board's
//! job engine), so the link depends on no engine.

use super::codec::{decode_request, encode_response, MessageError, NO_ID};
use super::frame::crc32;
use super::frame::{FrameError, MaxFrameDecoder};
use super::message::{
    EngineStats, ErrorCode, HelloInfo, LinkStats, Request, Response, MAX_BULK, MIN_PROTOCOL_VERSION,
};

/// What serves the requests beyond the link's own: a board's job engine, or nothing.
pub trait JobHandler {
    /// Serves `req` (sent with id `id`); `None` if it is not a request this handler knows.
    fn handle(&mut self, id: u32, req: &Request) -> Option<Response>;
    /// Drops all job state and counters ([`Request::Reset`]).
    fn reset(&mut self) {}
    /// The engine's counters, if there is an engine.
    fn engine_stats(&self, link: LinkStats) -> Option<EngineStats> {
        let _ = link;
        None
    }
}

/// No engine: a board that answers link messages only.
pub struct NoEngine;

impl JobHandler for NoEngine {
    fn handle(&mut self, _id: u32, _req: &Request) -> Option<Response> {
        None
    }
}

/// Decoder, counters and handshake of one link.
pub struct LinkServer {
    decoder: MaxFrameDecoder,
    stats: LinkStats,
    info: HelloInfo,
}

impl LinkServer {
    /// A server that introduces itself with `info`.
    pub const fn new(info: HelloInfo) -> Self {
        Self {
            decoder: MaxFrameDecoder::new(),
            stats: zero_stats(),
            info,
        }
    }

    /// The counters so far.
    pub fn stats(&self) -> LinkStats {
        self.stats
    }

    /// Records bytes the receive path had to drop (its ring buffer was full).
    pub fn note_rx_overrun(&mut self, lost: u32) {
        self.stats.rx_overruns = self.stats.rx_overruns.wrapping_add(lost);
    }

    /// Consumes one received byte. When it completes a frame, writes the reply frame into `out`
    /// (at least [`MAX_WIRE_LEN`](super::MAX_WIRE_LEN) bytes) and returns its length, which the
    /// caller must send. Never panics, whatever the bytes.
    pub fn push(&mut self, byte: u8, out: &mut [u8]) -> Option<usize> {
        self.push_with(byte, out, &mut NoEngine)
    }

    /// [`push`](Self::push) with a job engine serving the requests beyond the link's own.
    pub fn push_with<H: JobHandler>(
        &mut self,
        byte: u8,
        out: &mut [u8],
        jobs: &mut H,
    ) -> Option<usize> {
        self.stats.bytes_rx = self.stats.bytes_rx.wrapping_add(1);
        let decoded = match self.decoder.push(byte)? {
            Ok(payload) => decode_request(payload),
            Err(e) => {
                let (counter, code) = match e {
                    FrameError::TooLong => (&mut self.stats.too_long, ErrorCode::TooLong),
                    FrameError::BadFraming => (&mut self.stats.bad_framing, ErrorCode::BadFraming),
                    FrameError::BadCrc => (&mut self.stats.bad_crc, ErrorCode::BadCrc),
                };
                *counter = counter.wrapping_add(1);
                return self.reply(NO_ID, &Response::Error { code }, out);
            }
        };
        self.stats.frames_ok = self.stats.frames_ok.wrapping_add(1);
        match decoded {
            Ok((id, req)) => {
                let resp = self.handle(id, req, jobs);
                self.reply(id, &resp, out)
            }
            Err(MessageError { id, code }) => {
                let counter = match code {
                    ErrorCode::Unsupported => &mut self.stats.unsupported,
                    _ => &mut self.stats.malformed,
                };
                *counter = counter.wrapping_add(1);
                self.reply(id.unwrap_or(NO_ID), &Response::Error { code }, out)
            }
        }
    }

    fn handle<H: JobHandler>(&mut self, id: u32, req: Request, jobs: &mut H) -> Response {
        match req {
            // The handshake settles on the older version of the two, if this build still
            // speaks it; the host then sends only that version's messages. A host older than
            // that still gets an answer (with this build's version), so the mismatch is
            // reported by the side that can explain it.
            Request::Hello { protocol } => {
                let mut info = self.info.clone();
                if protocol >= MIN_PROTOCOL_VERSION {
                    info.protocol = info.protocol.min(protocol);
                }
                Response::Hello(info)
            }
            Request::Ping { nonce } => Response::Pong { nonce },
            Request::LinkStats => Response::LinkStats(self.stats),
            Request::Reset => {
                let before = self.stats;
                self.stats = zero_stats();
                jobs.reset();
                Response::ResetDone(before)
            }
            Request::EngineStats => match jobs.engine_stats(self.stats) {
                Some(s) => Response::EngineStats(s),
                None => Response::Error {
                    code: ErrorCode::Unsupported,
                },
            },
            Request::Sink { data } => {
                // `data` holds at most MAX_BULK (512) bytes, so the length fits a u16.
                let len = u16::try_from(data.len()).unwrap_or(u16::MAX);
                Response::SinkAck {
                    len,
                    crc: crc32(&data),
                }
            }
            Request::Source { len } => {
                let mut data = heapless::Vec::new();
                if usize::from(len) > MAX_BULK {
                    return Response::Error {
                        code: ErrorCode::TooLong,
                    };
                }
                for i in 0..len {
                    // Cannot fail: len <= MAX_BULK was checked above.
                    let _ = data.push(i as u8);
                }
                Response::Source { data }
            }
            other => jobs.handle(id, &other).unwrap_or(Response::Error {
                code: ErrorCode::Unsupported,
            }),
        }
    }

    fn reply(&mut self, id: u32, resp: &Response, out: &mut [u8]) -> Option<usize> {
        // Every response fits MAX_WIRE_LEN by construction; an undersized `out` from the caller
        // drops the reply rather than panicking, and the host times out and retries.
        let n = encode_response(id, resp, out).ok()?;
        self.stats.bytes_tx = self.stats.bytes_tx.wrapping_add(n as u32);
        Some(n)
    }
}

pub(super) const fn zero_stats() -> LinkStats {
    LinkStats {
        frames_ok: 0,
        bad_crc: 0,
        bad_framing: 0,
        too_long: 0,
        malformed: 0,
        unsupported: 0,
        rx_overruns: 0,
        bytes_rx: 0,
        bytes_tx: 0,
    }
}
