//! Messages ↔ frame payloads: `postcard(request id: u32 varint, message)`.
//!
//! Decoding reads the id first and then peeks at the variant index, so that a frame with an
//! unknown message is answered [`ErrorCode::Unsupported`] *with* its request id, and only a
//! message that is known but does not parse is [`ErrorCode::Malformed`].

use serde::{de::DeserializeOwned, Serialize};

use super::frame::{EncodeError, FrameWriter};
use super::message::{ErrorCode, Request, Response};

/// The id of a response that answers no readable request (e.g. a frame with a bad CRC). Hosts
/// never use it for requests.
pub const NO_ID: u32 = 0;

/// A payload that is not a message this build understands.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MessageError {
    /// The request id, when it could be read.
    pub id: Option<u32>,
    /// What is wrong.
    pub code: ErrorCode,
}

/// Encodes a request as one frame into `out`; returns the frame's length.
pub fn encode_request(id: u32, req: &Request, out: &mut [u8]) -> Result<usize, EncodeError> {
    encode(id, req, out)
}

/// Encodes a response as one frame into `out`; returns the frame's length.
pub fn encode_response(id: u32, resp: &Response, out: &mut [u8]) -> Result<usize, EncodeError> {
    encode(id, resp, out)
}

/// Decodes a request from a frame payload.
pub fn decode_request(payload: &[u8]) -> Result<(u32, Request), MessageError> {
    decode(payload, Request::VARIANTS)
}

/// Decodes a response from a frame payload.
pub fn decode_response(payload: &[u8]) -> Result<(u32, Response), MessageError> {
    decode(payload, Response::VARIANTS)
}

fn encode<T: Serialize>(id: u32, msg: &T, out: &mut [u8]) -> Result<usize, EncodeError> {
    let writer = FrameWriter::new(out)?;
    postcard::serialize_with_flavor(&(id, msg), writer).map_err(|e| match e {
        postcard::Error::SerializeBufferFull => EncodeError::TooLong,
        _ => EncodeError::Serialize,
    })
}

fn decode<T: DeserializeOwned>(payload: &[u8], variants: u32) -> Result<(u32, T), MessageError> {
    let malformed = |id| MessageError {
        id,
        code: ErrorCode::Malformed,
    };
    let (id, body) = postcard::take_from_bytes::<u32>(payload).map_err(|_| malformed(None))?;
    let (tag, _) = postcard::take_from_bytes::<u32>(body).map_err(|_| malformed(Some(id)))?;
    if tag >= variants {
        return Err(MessageError {
            id: Some(id),
            code: ErrorCode::Unsupported,
        });
    }
    match postcard::take_from_bytes::<T>(body) {
        // Trailing bytes mean sender and receiver disagree on the message's shape.
        Ok((msg, [])) => Ok((id, msg)),
        _ => Err(malformed(Some(id))),
    }
}
