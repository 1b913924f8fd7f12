//! The wire protocol between the host and a board: the only place that knows the byte format.
//!
//! Layers, bottom up (docs/protocol.md has the full description):
//! - [`frame`]: `0x00 · COBS(payload · CRC-32) · 0x00`, stuffed by the `cobs` crate and
//!   checksummed by the `crc` crate; a streaming [`FrameDecoder`] that resynchronises at the next
//!   delimiter after any damage;
//! - [`codec`]: payload = postcard of `(request id, message)`;
//! - [`message`]: the [`Request`] and [`Response`] enums, extended by appending variants;
//! - [`server`]: the board's end, shared by the firmware and in-process boards; it hands the
//!   requests beyond the link's own to a [`JobHandler`] (a board's job engine, `crate::jobs`,
//!   which depends on this module, never the other way).
//!
//! Nothing here allocates or panics on wire input; every buffer is bounded.

pub mod codec;
pub mod frame;
pub mod message;
pub mod server;

#[cfg(test)]
mod tests;
#[cfg(test)]
mod wire_tests;

pub use codec::{
    decode_request, decode_response, encode_request, encode_response, MessageError, NO_ID,
};
pub use frame::{
    crc32, encode_frame, EncodeError, FrameDecoder, FrameError, FrameWriter, MaxFrameDecoder,
    MAX_FRAME_LEN, MAX_PAYLOAD_LEN, MAX_STUFFED_LEN, MAX_WIRE_LEN,
};
pub use message::{
    AccelKind, Capacities, CastHit, EngineStats, ErrorCode, Feature, HelloInfo, JobConfig,
    LinkStats, PathHit, PathHits, RayHit, Request, Response, Rows, TraceSettings, TraceStats,
    WeightedHit, WeightedHits, BUILD_LEN, MAX_BULK, MAX_CAST, MAX_HITS, MAX_LOBE_CHUNK, MAX_PATHS,
    MAX_ROWS, MAX_ROW_ENTRIES, MAX_WEIGHTED, MIN_PROTOCOL_VERSION, PROTOCOL_2_CORDIC,
    PROTOCOL_VERSION, RESET_CORDIC,
};
pub use server::{JobHandler, LinkServer, NoEngine};
