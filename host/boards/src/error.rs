//! What a board's answer means for the farm: a refusal is final, anything else on the link is
//! worth a retry.

use hemi_kernel::link::ErrorCode;
use std::fmt;

/// A board read a request and answered it with an error frame. Sending it again, or to the
/// board reconnected, gets the same answer: the farm fails the run instead of retrying (a
/// timeout, a damaged frame or a lost link are retried).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Refused {
    /// What the board said.
    pub code: ErrorCode,
}

impl fmt::Display for Refused {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "the board refused the request: {}", describe(self.code))
    }
}

impl std::error::Error for Refused {}

/// Whether `e` (with any context around it) is a board's refusal.
pub fn is_refusal(e: &anyhow::Error) -> bool {
    e.downcast_ref::<Refused>().is_some()
}

/// A human-readable reason for an error code.
pub fn describe(code: ErrorCode) -> &'static str {
    match code {
        ErrorCode::BadCrc => "frame damaged in transit (bad CRC)",
        ErrorCode::BadFraming => "frame damaged in transit (bad framing)",
        ErrorCode::TooLong => "too long for the board's buffers",
        ErrorCode::Malformed => "message did not decode (protocol mismatch?)",
        ErrorCode::Unsupported => {
            "message or engine unknown to this firmware (older protocol, or another build)"
        }
        ErrorCode::NoScene => "no complete scene and configuration loaded on the board",
        ErrorCode::OutOfRange => "an index or setting is outside the board's range",
        ErrorCode::BadScene => "the board's accelerator cannot load this scene",
    }
}
