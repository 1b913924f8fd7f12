//! Robustness of the link: every kind of damage is rejected, counted, and the next good frame
//! still decodes. The same scenarios run on the target under QEMU (firmware/tests/link.rs).

use super::*;

fn hello_info() -> HelloInfo {
    HelloInfo {
        protocol: PROTOCOL_VERSION,
        build: heapless::String::try_from("test").unwrap(),
        accel: AccelKind::Soft,
        // the values of the in-process engines' budgets; the link only carries them
        caps: Capacities {
            max_patches: 256,
            max_sample_rows: 64,
            stack_depth: 16,
            max_frame_len: MAX_FRAME_LEN as u16,
            max_circles: 1024,
            max_in_flight: 1,
        },
    }
}

fn frame(payload: &[u8]) -> ([u8; MAX_WIRE_LEN], usize) {
    let mut out = [0u8; MAX_WIRE_LEN];
    let n = encode_frame(payload, &mut out).unwrap();
    (out, n)
}

/// Feeds bytes, collecting every decoder verdict (payloads copied out).
fn feed(
    dec: &mut MaxFrameDecoder,
    bytes: &[u8],
) -> std::vec::Vec<Result<std::vec::Vec<u8>, FrameError>> {
    let mut got = std::vec::Vec::new();
    for &b in bytes {
        if let Some(r) = dec.push(b) {
            got.push(r.map(|p| p.to_vec()));
        }
    }
    got
}

extern crate std;

#[test]
fn frame_round_trip_all_lengths() {
    let mut dec = MaxFrameDecoder::new();
    for len in [0usize, 1, 2, 253, 254, 255, 600, MAX_PAYLOAD_LEN] {
        let payload: std::vec::Vec<u8> = (0..len).map(|i| (i * 7 % 256) as u8).collect();
        let (buf, n) = frame(&payload);
        assert_eq!(buf[0], 0);
        assert_eq!(buf[n - 1], 0);
        assert!(!buf[1..n - 1].contains(&0));
        assert_eq!(feed(&mut dec, &buf[..n]), [Ok(payload)]);
    }
}

#[test]
fn payload_over_limit_is_refused_by_encoder() {
    let payload = [1u8; MAX_PAYLOAD_LEN + 1];
    let mut out = [0u8; 2 * MAX_WIRE_LEN];
    assert_eq!(encode_frame(&payload, &mut out), Err(EncodeError::TooLong));
    let mut small = [0u8; 8];
    assert_eq!(
        encode_frame(&[1, 2, 3, 4, 5, 6, 7], &mut small),
        Err(EncodeError::TooLong)
    );
}

#[test]
fn flipped_bit_is_bad_crc_and_next_frame_decodes() {
    let (good, n) = frame(b"hello hemi");
    let mut dec = MaxFrameDecoder::new();
    for byte in 1..n - 1 {
        for bit in 0..8 {
            let mut bad = good;
            bad[byte] ^= 1 << bit;
            let mut stream = bad[..n].to_vec();
            stream.extend_from_slice(&good[..n]);
            let got = feed(&mut dec, &stream);
            // A flip that creates a 0x00 splits the frame in two damaged ones; otherwise COBS or
            // the CRC catches it. Either way: only errors, then the good frame.
            assert_eq!(
                got.last(),
                Some(&Ok(b"hello hemi".to_vec())),
                "byte {byte} bit {bit}"
            );
            assert!(
                got[..got.len() - 1].iter().all(|r| r.is_err()),
                "byte {byte} bit {bit}"
            );
            assert!(!got[..got.len() - 1].is_empty());
        }
    }
}

#[test]
fn truncated_frame_is_rejected_and_next_frame_decodes() {
    let (good, n) = frame(b"0123456789abcdef");
    let mut dec = MaxFrameDecoder::new();
    for cut in 2..n - 1 {
        // Lost tail including the trailing delimiter: the next frame's leading 0x00 ends it.
        let mut stream = good[..cut].to_vec();
        stream.extend_from_slice(&good[..n]);
        let got = feed(&mut dec, &stream);
        assert_eq!(got.len(), 2, "cut {cut}");
        assert!(got[0].is_err(), "cut {cut}");
        assert_eq!(got[1], Ok(b"0123456789abcdef".to_vec()));
        // Lost middle byte, delimiter intact.
        let mut stream = good[..n].to_vec();
        stream.remove(cut);
        stream.extend_from_slice(&good[..n]);
        let got = feed(&mut dec, &stream);
        assert_eq!(got.len(), 2, "drop {cut}");
        assert!(got[0].is_err());
        assert_eq!(got[1], Ok(b"0123456789abcdef".to_vec()));
    }
}

#[test]
fn garbage_between_frames_is_rejected() {
    let (good, n) = frame(b"payload");
    let mut stream = good[..n].to_vec();
    stream.extend_from_slice(b"\x13\x37garbage\xff\xfe");
    stream.extend_from_slice(&good[..n]);
    let mut dec = MaxFrameDecoder::new();
    let got = feed(&mut dec, &stream);
    assert_eq!(got.len(), 3);
    assert_eq!(got[0], Ok(b"payload".to_vec()));
    assert!(got[1].is_err());
    assert_eq!(got[2], Ok(b"payload".to_vec()));
}

#[test]
fn over_long_frame_is_too_long_and_next_frame_decodes() {
    let mut stream = std::vec![0u8];
    stream.extend(std::iter::repeat_n(0x55u8, 3 * MAX_STUFFED_LEN));
    stream.push(0);
    let (good, n) = frame(b"after");
    stream.extend_from_slice(&good[..n]);
    let mut dec = MaxFrameDecoder::new();
    assert_eq!(
        feed(&mut dec, &stream),
        [Err(FrameError::TooLong), Ok(b"after".to_vec())]
    );
}

#[test]
fn idle_delimiters_are_silent() {
    let mut dec = MaxFrameDecoder::new();
    assert!(feed(&mut dec, &[0, 0, 0, 0]).is_empty());
}

#[test]
fn messages_round_trip() {
    let reqs = [
        Request::Hello {
            protocol: PROTOCOL_VERSION,
        },
        Request::Ping { nonce: 0xDEAD_BEEF },
        Request::LinkStats,
        Request::Reset,
        Request::Sink {
            data: heapless::Vec::from_slice(&[7u8; MAX_BULK]).unwrap(),
        },
        Request::Source { len: 512 },
    ];
    let mut dec = MaxFrameDecoder::new();
    let mut out = [0u8; MAX_WIRE_LEN];
    for (i, req) in reqs.iter().enumerate() {
        let n = encode_request(i as u32 + 1, req, &mut out).unwrap();
        let got = feed(&mut dec, &out[..n]);
        let payload = got[0].as_ref().unwrap();
        assert_eq!(decode_request(payload), Ok((i as u32 + 1, req.clone())));
    }
    let resps = [
        Response::Hello(hello_info()),
        Response::Pong { nonce: 1 },
        Response::LinkStats(LinkStats {
            frames_ok: 3,
            ..Default::default()
        }),
        Response::ResetDone(LinkStats::default()),
        Response::SinkAck { len: 3, crc: 9 },
        Response::Source {
            data: heapless::Vec::from_slice(&[0xAB; MAX_BULK]).unwrap(),
        },
        Response::Error {
            code: ErrorCode::Unsupported,
        },
    ];
    for resp in &resps {
        let n = encode_response(77, resp, &mut out).unwrap();
        let got = feed(&mut dec, &out[..n]);
        assert_eq!(
            decode_response(got[0].as_ref().unwrap()),
            Ok((77, resp.clone()))
        );
    }
}

#[test]
fn variant_counts_match_the_enums() {
    // The last variant's index must be VARIANTS - 1, else "unsupported" detection is wrong.
    let mut buf = [0u8; 128];
    let last = Request::Cast {
        rays: heapless::Vec::new(),
    };
    let tag = postcard::to_slice(&last, &mut buf).unwrap()[0];
    assert_eq!(u32::from(tag), Request::VARIANTS - 1);
    let last = Response::Nearest(heapless::Vec::new());
    let tag = postcard::to_slice(&last, &mut buf).unwrap()[0];
    assert_eq!(u32::from(tag), Response::VARIANTS - 1);
    // protocol 4's last messages keep theirs
    let query = Request::Query {
        point: crate::geometry::Vec3::ZERO,
        normal: crate::geometry::Vec3::Z,
        skip: 0,
    };
    assert_eq!(postcard::to_slice(&query, &mut buf).unwrap()[0], 20);
    let tag = postcard::to_slice(&Response::Weighted(Default::default()), &mut buf).unwrap()[0];
    assert_eq!(tag, 13);
    // protocol 2's messages keep their indices (appended, never inserted)
    let tag = postcard::to_slice(&Request::EngineStats, &mut buf).unwrap()[0];
    assert_eq!(tag, 12);
    let tag =
        postcard::to_slice(&Response::EngineStats(EngineStats::default()), &mut buf).unwrap()[0];
    assert_eq!(tag, 11);
}

#[test]
fn unknown_message_is_unsupported_with_its_id() {
    // id 5, variant 99 (a message from a newer host).
    assert_eq!(
        decode_request(&[5, 99, 1, 2]),
        Err(MessageError {
            id: Some(5),
            code: ErrorCode::Unsupported
        })
    );
    // id 6, Ping without its nonce.
    assert_eq!(
        decode_request(&[6, 1]),
        Err(MessageError {
            id: Some(6),
            code: ErrorCode::Malformed
        })
    );
    // Trailing bytes.
    assert_eq!(
        decode_request(&[6, 2, 0]),
        Err(MessageError {
            id: Some(6),
            code: ErrorCode::Malformed
        })
    );
    assert_eq!(
        decode_request(&[]),
        Err(MessageError {
            id: None,
            code: ErrorCode::Malformed
        })
    );
}

/// Runs a byte stream through a server; returns the decoded replies.
fn serve(server: &mut LinkServer, bytes: &[u8]) -> std::vec::Vec<(u32, Response)> {
    let mut out = [0u8; MAX_WIRE_LEN];
    let mut host = MaxFrameDecoder::new();
    let mut replies = std::vec::Vec::new();
    for &b in bytes {
        if let Some(n) = server.push(b, &mut out) {
            for r in feed(&mut host, &out[..n]) {
                replies.push(decode_response(&r.unwrap()).unwrap());
            }
        }
    }
    replies
}

fn request(id: u32, req: &Request) -> std::vec::Vec<u8> {
    let mut out = [0u8; MAX_WIRE_LEN];
    let n = encode_request(id, req, &mut out).unwrap();
    out[..n].to_vec()
}

#[test]
fn server_answers_and_counts() {
    let mut s = LinkServer::new(hello_info());
    let mut stream = request(
        1,
        &Request::Hello {
            protocol: PROTOCOL_VERSION,
        },
    );
    let mut bad = request(2, &Request::Ping { nonce: 42 });
    bad[3] ^= 0x10;
    stream.extend(&bad);
    stream.extend(request(3, &Request::Ping { nonce: 43 }));
    stream.extend([0x00, 0x02, 0x01, 0x01, 0x00]); // valid COBS, 2 bytes: too short for a CRC
    stream.extend(request(4, &Request::Source { len: 600 }));
    stream.extend(request(5, &Request::LinkStats));
    let r = serve(&mut s, &stream);
    assert_eq!(r[0], (1, Response::Hello(hello_info())));
    assert_eq!(r[1].0, NO_ID);
    assert!(matches!(
        r[1].1,
        Response::Error {
            code: ErrorCode::BadCrc | ErrorCode::BadFraming
        }
    ));
    assert_eq!(r[2], (3, Response::Pong { nonce: 43 }));
    assert_eq!(
        r[3],
        (
            NO_ID,
            Response::Error {
                code: ErrorCode::BadFraming
            }
        )
    );
    assert_eq!(
        r[4],
        (
            4,
            Response::Error {
                code: ErrorCode::TooLong
            }
        )
    );
    let Response::LinkStats(st) = r[5].1 else {
        panic!("{:?}", r[5])
    };
    assert_eq!(st.frames_ok, 4);
    assert_eq!(st.bad_crc + st.bad_framing, 2);
    let r = serve(&mut s, &request(6, &Request::Reset));
    assert!(matches!(
        r[0],
        (6, Response::ResetDone(LinkStats { frames_ok: 5, .. }))
    ));
    assert_eq!(s.stats().frames_ok, 0);
}

#[test]
fn server_sink_and_source() {
    let mut s = LinkServer::new(hello_info());
    let data = heapless::Vec::from_slice(&[0u8, 1, 2, 0, 0, 9]).unwrap();
    let r = serve(&mut s, &request(9, &Request::Sink { data }));
    assert_eq!(
        r[0],
        (
            9,
            Response::SinkAck {
                len: 6,
                crc: crc32(&[0, 1, 2, 0, 0, 9])
            }
        )
    );
    let r = serve(&mut s, &request(10, &Request::Source { len: 300 }));
    let Response::Source { data } = &r[0].1 else {
        panic!()
    };
    assert!(data.iter().enumerate().all(|(i, &b)| b == i as u8) && data.len() == 300);
}

/// xorshift64*: deterministic pseudo-random input without a test-only dependency.
pub(super) struct XorShift(pub(super) u64);
impl XorShift {
    pub(super) fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
}

#[test]
fn random_damage_never_panics_and_good_frames_survive() {
    let mut rng = XorShift(0x9E37_79B9_7F4A_7C15);
    let mut s = LinkServer::new(hello_info());
    let mut out = [0u8; MAX_WIRE_LEN];
    for round in 0..3000u32 {
        // Random junk of random length, sometimes long enough to overflow...
        let junk_len = (rng.next() % if round % 50 == 0 { 3000 } else { 40 }) as usize;
        for _ in 0..junk_len {
            let b = rng.next() as u8;
            let _ = s.push(b, &mut out);
        }
        // ...then a random mutation of a valid request, then a good ping that must be answered.
        let mut bytes = request(round + 1, &Request::Ping { nonce: round });
        let i = (rng.next() as usize) % bytes.len();
        bytes[i] = rng.next() as u8;
        for b in bytes {
            let _ = s.push(b, &mut out);
        }
        let r = serve(
            &mut s,
            &request(100_000 + round, &Request::Ping { nonce: round }),
        );
        assert_eq!(
            r.last(),
            Some(&(100_000 + round, Response::Pong { nonce: round })),
            "round {round}"
        );
    }
    // Pure random frames through the message decoders.
    for _ in 0..20000 {
        let len = (rng.next() % 64) as usize;
        let bytes: std::vec::Vec<u8> = (0..len).map(|_| rng.next() as u8).collect();
        let _ = decode_request(&bytes);
        let _ = decode_response(&bytes);
    }
}

#[test]
fn job_requests_fit_16_bytes_on_the_wire() {
    // Worst cases the host sends: job id up to 2^21 (3-byte varint), patch < 128, sample index
    // up to 255 (K = 16), pixel index of a 512×512 image.
    let mut out = [0u8; MAX_WIRE_LEN];
    let reqs = [
        Request::Shoot {
            patch: 47,
            first: 255,
            count: 64,
        },
        Request::Trace {
            first: 512 * 512 - 1,
            count: 80,
        },
        Request::TraceRow {
            row: 16383,
            skip: 16383,
        },
    ];
    for req in reqs {
        let n = encode_request(1 << 21, &req, &mut out).unwrap();
        assert!(n <= 16, "{req:?}: {n} bytes");
    }
    // Adaptive sampling's level jobs carry the lattice's k as well (k ≤ 127, so cell < 16 384):
    // 16 bytes with every 3-byte job id (below 2^21), 17 with the one 4-byte id, 2^21 itself.
    let level = |k: u16| Request::ShootLevel {
        patch: 47,
        k,
        first: k * k - 1,
        count: 64,
    };
    assert!(encode_request((1 << 21) - 1, &level(127), &mut out).unwrap() <= 16);
    assert!(encode_request(1 << 21, &level(11), &mut out).unwrap() <= 16);
    assert!(encode_request(1 << 21, &level(127), &mut out).unwrap() <= 17);
    // The two query requests carry a point and a normal: few, and larger.
    let point = crate::geometry::Vec3::new(1.0, 2.0, 3.0);
    let query = Request::Query {
        point,
        normal: point,
        skip: 16383,
    };
    let gather = Request::Gather {
        point,
        normal: point,
        ring: 63,
        first: 255,
        count: 80,
    };
    let (q, g) = (
        encode_request(1 << 21, &query, &mut out).unwrap(),
        encode_request(1 << 21, &gather, &mut out).unwrap(),
    );
    assert!(q <= 40 && g <= 40, "Query {q} bytes, Gather {g}");
    // The field's hemisphere job adds a spin and an origin patch.
    let hemisphere = Request::Hemisphere {
        origin: point,
        normal: point,
        spin: 6.2,
        origin_patch: Some(u16::MAX),
        skip: u16::MAX,
    };
    let h = encode_request(u32::MAX, &hemisphere, &mut out).unwrap();
    assert!(h <= 48, "Hemisphere {h} bytes");
}

#[test]
fn the_largest_messages_of_protocol_5_fit_a_frame() {
    // Every field at its widest varint, every float with all bits set in the stuffing's worst
    // pattern: a full Cast, its full answer, and a full window of path reports.
    use crate::geometry::Vec3;
    use crate::specular::Via;
    let mut out = [0u8; MAX_WIRE_LEN];
    let v = Vec3::new(-1.0e30, 3.3e-30, f32::MAX);
    let cast = Request::Cast {
        rays: core::iter::repeat_n((v, v), MAX_CAST).collect(),
    };
    assert!(encode_request(u32::MAX, &cast, &mut out).is_ok());
    let hit = CastHit {
        patch: u16::MAX,
        front: true,
        t: f32::MAX,
        u: -1.0e30,
        v: 3.3e-30,
    };
    let nearest = Response::Nearest(core::iter::repeat_n(Some(hit), MAX_CAST).collect());
    assert!(encode_response(u32::MAX, &nearest, &mut out).is_ok());
    let path = PathHit {
        patch: u16::MAX,
        u: f32::MAX,
        v: -1.0e30,
        weight: [3.3e-30; 3],
        via: Via {
            bounces: u16::MAX,
            last: u32::MAX,
            mirror: true,
        },
    };
    let paths = Response::Paths(PathHits {
        total: u32::MAX,
        rays: u32::MAX,
        back_hits: u32::MAX,
        hits: core::iter::repeat_n(path, MAX_PATHS).collect(),
    });
    assert!(encode_response(u32::MAX, &paths, &mut out).is_ok());
}

#[test]
fn the_handshake_settles_on_the_older_version() {
    use crate::link::MIN_PROTOCOL_VERSION;
    let mut s = LinkServer::new(hello_info());
    let mut stream = request(
        1,
        &Request::Hello {
            protocol: PROTOCOL_VERSION + 1,
        },
    );
    stream.extend(request(
        2,
        &Request::Hello {
            protocol: MIN_PROTOCOL_VERSION,
        },
    ));
    stream.extend(request(
        3,
        &Request::Hello {
            protocol: MIN_PROTOCOL_VERSION - 1,
        },
    ));
    let r = serve(&mut s, &stream);
    let version = |resp: &Response| match resp {
        Response::Hello(h) => Some(h.protocol),
        _ => None,
    };
    // a newer host: the board's own version; an older one it still speaks: that one
    assert_eq!(version(&r[0].1), Some(PROTOCOL_VERSION));
    assert_eq!(version(&r[1].1), Some(MIN_PROTOCOL_VERSION));
    // a host too old: still answered, with the board's version, for the host to explain
    assert_eq!(version(&r[2].1), Some(PROTOCOL_VERSION));
}

#[test]
fn features_are_supported_from_the_version_that_added_them() {
    use crate::link::MIN_PROTOCOL_VERSION;
    let mut hello = hello_info();
    // oldest first, each within the versions this build speaks, and every one in this build
    let since = Feature::ALL.map(Feature::since);
    assert!(since.windows(2).all(|w| w[0] <= w[1]), "{since:?}");
    assert!(since
        .iter()
        .all(|v| (MIN_PROTOCOL_VERSION..=PROTOCOL_VERSION).contains(v)));
    for f in Feature::ALL {
        hello.protocol = PROTOCOL_VERSION;
        assert!(hello.supports(f), "{f}");
        hello.protocol = f.since() - 1;
        assert!(!hello.supports(f), "{f} at protocol {}", hello.protocol);
    }
    // what the host checks today: specular settings at 3, adaptive sampling at 4
    hello.protocol = 3;
    assert!(hello.supports(Feature::Tracing) && !hello.supports(Feature::ShootLevel));
    assert!(hello.supports(Feature::Jobs));
}

#[test]
fn protocol_5_does_not_grow_the_boards_message_slots() {
    // A board decodes each request into one stack slot and builds its answer in another; with
    // the teapot a 64 KiB board has about 1.6 KiB of stack to spare, so protocol 5's messages
    // must not make either larger than protocol 4's largest (the link test's `Sink` and the
    // `Hits` of 80 rays)
    assert!(
        core::mem::size_of::<Request>() <= 528,
        "{}",
        core::mem::size_of::<Request>()
    );
    assert!(
        core::mem::size_of::<Response>() <= 1176,
        "{}",
        core::mem::size_of::<Response>()
    );
}
