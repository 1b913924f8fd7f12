//! The wire protocol between the host and a board: the only place that knows the byte format.
//!
//! Layers, bottom up (docs/protocol.md has the full description):
//! - [`frame`]: `0x00 · COBS(payload · CRC-32) · 0x00`; a streaming [`FrameDecoder`] that
//!   resynchronises at the next delimiter after any damage;
//! - [`codec`]: payload = postcard of `(request id, message)`;
//! - [`message`]: the [`Request`] and [`Response`] enums, extended by appending variants;
//! - [`server`]: the board's end, shared by the firmware and in-process boards.
//!
//! Nothing here allocates or panics on wire input; every buffer is bounded.

pub mod cobs;
pub mod codec;
pub mod crc;
pub mod frame;
pub mod message;
pub mod server;

#[cfg(test)]
mod tests;

pub use codec::{
    decode_request, decode_response, encode_request, encode_response, MessageError, NO_ID,
};
pub use frame::{
    encode_frame, EncodeError, FrameDecoder, FrameError, FrameWriter, MaxFrameDecoder,
    MAX_FRAME_LEN, MAX_PAYLOAD_LEN, MAX_STUFFED_LEN, MAX_WIRE_LEN,
};
pub use message::{
    AccelKind, Capacities, ErrorCode, HelloInfo, LinkStats, Request, Response, BUILD_LEN, MAX_BULK,
    PROTOCOL_VERSION,
};
pub use server::LinkServer;

/// The kernel's fixed budgets, reported in the handshake by every backend that runs the kernel.
///
/// They are the sizes the engine's bounded tables are to be built with (scene loading, sample
/// rows and the skeleton stack arrive with later messages); the link itself enforces
/// `max_frame_len` today.
pub const KERNEL_CAPACITIES: Capacities = Capacities {
    max_patches: 256,
    max_sample_rows: 64,
    stack_depth: 16,
    max_frame_len: MAX_FRAME_LEN as u16,
};
