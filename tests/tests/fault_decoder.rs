//! Property tests of the wire decoders (fuzzing): whatever bytes arrive, the
//! frame decoder and the message codec never panic, a good frame after any garbage still
//! decodes, and the board's server answers every delimited frame with one reply.

use hemi_kernel::jobs::ENGINE_CAPACITIES;
use hemi_kernel::link::{
    decode_request, decode_response, encode_request, AccelKind, HelloInfo, LinkServer,
    MaxFrameDecoder, Request, MAX_WIRE_LEN, PROTOCOL_VERSION,
};
use proptest::prelude::*;

fn server() -> LinkServer {
    LinkServer::new(HelloInfo {
        protocol: PROTOCOL_VERSION,
        build: heapless::String::try_from("fuzz").unwrap(),
        accel: AccelKind::Soft,
        caps: ENGINE_CAPACITIES,
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn garbage_then_a_good_frame_decodes(garbage in proptest::collection::vec(any::<u8>(), 0..3000)) {
        let mut dec = MaxFrameDecoder::new();
        for &b in &garbage {
            if let Some(Ok(p)) = dec.push(b) {
                // Whatever a garbage frame decodes to, decoding its message must not panic.
                let _ = decode_request(p);
                let _ = decode_response(p);
            }
        }
        let mut frame = [0u8; MAX_WIRE_LEN];
        let n = encode_request(9, &Request::Ping { nonce: 42 }, &mut frame).unwrap();
        let mut got = None;
        for &b in &frame[..n] {
            if let Some(Ok(p)) = dec.push(b) {
                got = Some(decode_request(p).unwrap());
            }
        }
        prop_assert_eq!(got, Some((9, Request::Ping { nonce: 42 })));
    }

    #[test]
    fn mutated_frames_never_panic_the_server(
        seed_req in 0u32..6,
        flips in proptest::collection::vec((any::<u16>(), any::<u8>()), 0..8),
    ) {
        let req = match seed_req {
            0 => Request::Ping { nonce: 1 },
            1 => Request::Shoot { patch: 3, first: 0, count: 4 },
            2 => Request::Trace { first: 100, count: 80 },
            3 => Request::SceneBegin { patches: 19 },
            4 => Request::Source { len: 512 },
            _ => Request::EngineStats,
        };
        let mut frame = [0u8; MAX_WIRE_LEN];
        let n = encode_request(5, &req, &mut frame).unwrap();
        for (pos, x) in flips {
            let i = 1 + usize::from(pos) % (n - 2).max(1);
            frame[i] ^= x;
        }
        let mut srv = server();
        let mut out = [0u8; MAX_WIRE_LEN];
        let mut replies = 0;
        for &b in &frame[..n] {
            if srv.push(b, &mut out).is_some() {
                replies += 1;
            }
        }
        // Flips may create delimiters (more frames), each answered once; never a panic.
        prop_assert!(replies >= 1);
        prop_assert!(replies <= n);
    }
}
