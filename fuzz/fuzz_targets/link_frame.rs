//! The link's frame decoder and message codec (kernel/src/link) on arbitrary bytes, as a board
//! and a host receive them: every byte through `FrameDecoder`, every frame's payload decoded as
//! a request and as a response.
#![no_main]

use hemi_kernel::link::codec::{decode_request, decode_response};
use hemi_kernel::link::frame::MaxFrameDecoder;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let mut decoder = MaxFrameDecoder::default();
    for &b in data {
        if let Some(Ok(payload)) = decoder.push(b) {
            let _ = decode_request(payload);
            let _ = decode_response(payload);
        }
    }
});
