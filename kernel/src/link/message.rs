//! The messages of the link. Host → board: [`Request`]; board → host: [`Response`].
//!
//! Compatibility rule (see docs/protocol.md): postcard encodes an enum as a varint variant index
//! followed by the variant's fields. New messages are therefore **appended** as new variants and
//! never inserted or reordered; an existing variant's fields never change without bumping
//! [`PROTOCOL_VERSION`]. A receiver that sees an index it does not know answers
//! [`ErrorCode::Unsupported`] (see `codec`), so a newer host talking to an older board gets a clear
//! refusal instead of garbage.

use heapless::{String, Vec};
use serde::{Deserialize, Serialize};

/// Version of the wire protocol. Bumped on any incompatible change to an existing message.
pub const PROTOCOL_VERSION: u16 = 1;
/// Longest firmware build string in the handshake.
pub const BUILD_LEN: usize = 48;
/// Largest data block of the link-test messages ([`Request::Sink`], [`Response::Source`]).
pub const MAX_BULK: usize = 512;

/// Host → board.
#[allow(
    clippy::large_enum_variant,
    reason = "no heap on the board: a message is decoded once into one bounded stack slot"
)]
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Request {
    /// Handshake: the host's protocol version. Answered by [`Response::Hello`]. Idempotent, so the
    /// host may repeat it until it gets an answer (a pty drops bytes at start-up).
    Hello {
        /// The host's [`PROTOCOL_VERSION`].
        protocol: u16,
    },
    /// Liveness check, answered by [`Response::Pong`] with the same nonce.
    Ping {
        /// Echoed back unchanged.
        nonce: u32,
    },
    /// Asks for the link counters, answered by [`Response::LinkStats`].
    LinkStats,
    /// Drops all job state and zeroes the counters; answered by [`Response::ResetDone`] (the reply
    /// still reports the counters from before the reset).
    Reset,
    /// Link test, host → board direction: the board checksums `data` and answers
    /// [`Response::SinkAck`]. Measures upstream throughput.
    Sink {
        /// Arbitrary bytes.
        data: Vec<u8, MAX_BULK>,
    },
    /// Link test, board → host direction: asks for `len` bytes of a known pattern
    /// (`byte[i] = i as u8`), answered by [`Response::Source`]. Measures downstream throughput.
    Source {
        /// Number of bytes wanted; more than [`MAX_BULK`] is refused with
        /// [`ErrorCode::TooLong`].
        len: u16,
    },
}

impl Request {
    /// Number of variants: variant indices at or above it are unknown to this build.
    pub const VARIANTS: u32 = 6;
}

/// Board → host. Every response carries the id of the request it answers (see `codec`).
#[allow(
    clippy::large_enum_variant,
    reason = "no heap on the board: a message is encoded from one bounded stack slot"
)]
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Response {
    /// The handshake.
    Hello(HelloInfo),
    /// Answer to [`Request::Ping`].
    Pong {
        /// The request's nonce.
        nonce: u32,
    },
    /// Answer to [`Request::LinkStats`].
    LinkStats(LinkStats),
    /// Answer to [`Request::Reset`], with the counters as they were before it.
    ResetDone(LinkStats),
    /// Answer to [`Request::Sink`]: how many bytes arrived and their CRC-32.
    SinkAck {
        /// Number of data bytes received.
        len: u16,
        /// CRC-32 (IEEE) of those bytes, so the host can check them end to end.
        crc: u32,
    },
    /// Answer to [`Request::Source`].
    Source {
        /// `len` bytes, `byte[i] = i as u8`.
        data: Vec<u8, MAX_BULK>,
    },
    /// The request could not be served. The response's id is the request's when it could be read,
    /// else [`NO_ID`](super::codec::NO_ID).
    Error {
        /// Why.
        code: ErrorCode,
    },
}

impl Response {
    /// Number of variants: variant indices at or above it are unknown to this build.
    pub const VARIANTS: u32 = 7;
}

/// What kind of engine answers: decides what "shoot" and "trace" cost and how exact they are.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum AccelKind {
    /// No engine: the board answers link messages only.
    None,
    /// The kernel in software (f32) on the CPU.
    Soft,
    /// The bit-accurate cycle-level model of the accelerator.
    Model,
    /// The accelerator's registers (an FPGA on the memory bus).
    Mmio,
}

/// Fixed limits of a board, so the host can size jobs without trial and error.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Capacities {
    /// Patches of a loaded scene.
    pub max_patches: u16,
    /// Sample rows (hemisphere jobs) in flight.
    pub max_sample_rows: u16,
    /// Depth of the skeleton stack of specular frustums.
    pub stack_depth: u16,
    /// Largest frame the board accepts and sends, payload plus CRC, before stuffing.
    pub max_frame_len: u16,
}

/// The handshake.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct HelloInfo {
    /// The board's [`PROTOCOL_VERSION`].
    pub protocol: u16,
    /// Firmware name, version and git revision.
    pub build: String<BUILD_LEN>,
    /// The engine that will run jobs.
    pub accel: AccelKind,
    /// The board's limits.
    pub caps: Capacities,
}

/// Counters of the link since boot or the last [`Request::Reset`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct LinkStats {
    /// Frames that passed framing and CRC checks.
    pub frames_ok: u32,
    /// Frames dropped for a wrong CRC.
    pub bad_crc: u32,
    /// Frames dropped for invalid COBS or being shorter than a CRC.
    pub bad_framing: u32,
    /// Frames dropped for exceeding the receive buffer.
    pub too_long: u32,
    /// Good frames whose message did not decode.
    pub malformed: u32,
    /// Good frames with a message this build does not know.
    pub unsupported: u32,
    /// Bytes lost because the receive ring was full.
    pub rx_overruns: u32,
    /// Bytes received.
    pub bytes_rx: u32,
    /// Bytes sent.
    pub bytes_tx: u32,
}

/// Why a request was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum ErrorCode {
    /// The frame's CRC did not match.
    BadCrc,
    /// The frame was not valid COBS or too short.
    BadFraming,
    /// The frame, or what the request asked for, exceeds the board's limits.
    TooLong,
    /// The frame was intact but its message did not decode.
    Malformed,
    /// The message is unknown to this build (newer protocol).
    Unsupported,
}
