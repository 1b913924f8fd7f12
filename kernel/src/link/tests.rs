//! Robustness of the link: every kind of damage is rejected, counted, and the next good frame
//! still decodes. The same scenarios run on the target under QEMU (firmware/tests/link.rs).

use super::*;

fn hello_info() -> HelloInfo {
    HelloInfo {
        protocol: PROTOCOL_VERSION,
        build: heapless::String::try_from("test").unwrap(),
        accel: AccelKind::Soft,
        caps: KERNEL_CAPACITIES,
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
    let last = Request::Query {
        point: crate::geometry::Vec3::ZERO,
        normal: crate::geometry::Vec3::Z,
        skip: 0,
    };
    let tag = postcard::to_slice(&last, &mut buf).unwrap()[0];
    assert_eq!(u32::from(tag), Request::VARIANTS - 1);
    let tag = postcard::to_slice(&Response::Weighted(Default::default()), &mut buf).unwrap()[0];
    assert_eq!(u32::from(tag), Response::VARIANTS - 1);
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
                crc: crc::crc32(&[0, 1, 2, 0, 0, 9])
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
struct XorShift(u64);
impl XorShift {
    fn next(&mut self) -> u64 {
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
}

/// A job engine on the soft accelerator, configured for R = `circles`, K = 2, one sample per
/// pixel, no camera.
fn configured_engine(
    circles: u16,
) -> Engine<crate::link::engine::SoftProvider, crate::link::engine::NoPlatform> {
    use crate::link::engine::{NoPlatform, SoftProvider};
    let mut engine = Engine::new(SoftProvider::new(), NoPlatform);
    let cfg = JobConfig {
        circles,
        rule: crate::hemisphere::DeltaRule::Band,
        samples: 2,
        spp: 1,
        camera: None,
        accel: AccelKind::Soft,
    };
    assert_eq!(
        engine.handle(1, &Request::Configure(cfg)),
        Some(Response::Configured)
    );
    engine
}

#[test]
fn engine_answers_jobs_and_counts_repeats_once() {
    use crate::geometry::{Polygon, Vec3};
    use crate::link::engine::{NoPlatform, SoftProvider};
    use crate::patch::Patch;
    let quad = |v: [[f32; 3]; 4]| {
        Patch::polygon(Polygon::quad(v.map(|p| Vec3::new(p[0], p[1], p[2]))).unwrap())
    };
    // Two unit squares facing each other at distance 1.
    let a = quad([[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]]);
    let b = quad([[0., 0., 1.], [0., 1., 1.], [1., 1., 1.], [1., 0., 1.]]);
    let shoot = Request::Shoot {
        patch: 0,
        first: 0,
        count: 4,
    };
    let unconfigured = Engine::new(SoftProvider::new(), NoPlatform).handle(7, &shoot);
    assert_eq!(
        unconfigured,
        Some(Response::Error {
            code: ErrorCode::NoScene
        })
    );
    let mut engine = configured_engine(8);
    engine.handle(2, &Request::SceneBegin { patches: 2 });
    for (i, p) in [a, b].into_iter().enumerate() {
        engine.handle(
            3 + i as u32,
            &Request::ScenePatch {
                index: i as u16,
                area: 1.0,
                patch: p,
            },
        );
    }
    let Some(Response::Rows(rows)) = engine.handle(10, &shoot) else {
        panic!("no rows");
    };
    assert_eq!(rows.lens.len(), 4);
    // F(square → opposite square at distance 1) = 0.1998 (Howell C-11); per sample ~ that.
    for (_, f) in &rows.entries {
        assert!(f[0] > 0.1 && f[0] < 0.4, "{f:?}");
    }
    // The same job id again: same bits, counted once.
    assert_eq!(
        engine.handle(10, &shoot),
        Some(Response::Rows(rows.clone()))
    );
    // A level job on the lattice of the configured K is the same job; a finer one has k² cells.
    let level = |k, first, count| Request::ShootLevel {
        patch: 0,
        k,
        first,
        count,
    };
    assert_eq!(
        engine.handle(11, &level(2, 0, 4)),
        Some(Response::Rows(rows))
    );
    let Some(Response::Rows(fine)) = engine.handle(12, &level(4, 12, 4)) else {
        panic!("no rows at k = 4");
    };
    assert_eq!(fine.lens.len(), 4);
    for (req, what) in [(level(4, 14, 3), "past k²"), (level(0, 0, 1), "k = 0")] {
        assert!(
            matches!(engine.handle(13, &req), Some(Response::Error { .. })),
            "{what}"
        );
    }
    // Out of range and over capacity are refused, not indexed.
    let bad = [
        Request::Shoot {
            patch: 2,
            first: 0,
            count: 1,
        },
        Request::Shoot {
            patch: 0,
            first: 3,
            count: 2,
        },
        Request::Trace { first: 0, count: 1 },
        Request::Gather {
            point: Vec3::ZERO,
            normal: Vec3::ZERO,
            ring: 0,
            first: 0,
            count: 1,
        },
    ];
    for req in &bad {
        assert!(matches!(
            engine.handle(20, req),
            Some(Response::Error { .. })
        ));
    }
    let s = engine.stats(LinkStats::default());
    // the Shoot, the two level jobs; the repeated Shoot; the two bad level jobs and `bad`
    assert_eq!((s.jobs, s.repeats, s.refused), (3, 1, 6), "{s:?}");
    assert!(s.rays > 0);
}

#[test]
fn engine_tables_fit_the_largest_hemisphere() {
    use crate::link::engine::{ENGINE_MAX_CIRCLES, ENGINE_MAX_QUARTER};
    assert_eq!(
        crate::hemisphere::quarter_len(ENGINE_MAX_CIRCLES as u32),
        ENGINE_MAX_QUARTER
    );
}

#[test]
fn engine_rows_through_mirrors_equal_the_tracer_with_a_whole_hemisphere_park() {
    extern crate std;
    use crate::accel::soft::{LocalPatch, SoftAccelerator, SoftScratch};
    use crate::geometry::{Polygon, Vec3};
    use crate::hemisphere::{DeltaRule, OwnedHemisphere};
    use crate::link::engine::{sample_point, NoPlatform, SoftProvider, ENGINE_PENDING};
    use crate::link::{TraceSettings, TraceStats, MAX_LOBE_CHUNK};
    use crate::optics::{Lobe, Optics, Specular, Surface};
    use crate::patch::Patch;
    use crate::rotation::spin_for_sample;
    use crate::skeleton::{Frame, Skeleton};
    use crate::specular::Pending;
    use crate::tracer::{shoot_hemisphere, TraceScratch};
    use std::vec;
    let quad = |v: [[f32; 3]; 4]| {
        Patch::polygon(Polygon::quad(v.map(|p| Vec3::new(p[0], p[1], p[2]))).unwrap())
    };
    // A box 2 × 2 × 2 open at z = 2: floor, ceiling, back, a mirror at x = 0 (k_r 0.9, one
    // ray) and a glossy wall at x = 2 (diffuse too, a 3-ring lobe), so frustums bounce between
    // them.
    let patches = [
        quad([[0., 0., 0.], [0., 0., 2.], [2., 0., 2.], [2., 0., 0.]]),
        quad([[0., 2., 0.], [2., 2., 0.], [2., 2., 2.], [0., 2., 2.]]),
        quad([[0., 0., 0.], [2., 0., 0.], [2., 2., 0.], [0., 2., 0.]]),
        quad([[0., 0., 0.], [0., 2., 0.], [0., 2., 2.], [0., 0., 2.]]),
        quad([[2., 0., 0.], [2., 0., 2.], [2., 2., 2.], [2., 2., 0.]]),
    ];
    let circles = 12u32;
    let hemi = OwnedHemisphere::new(circles, DeltaRule::Band).unwrap();
    let view = hemi.view();
    let mut weights = vec![1.0f32; 1];
    let mut gloss = [0.0f32; 3];
    crate::frustum::lobe_weights(&view, 40.0, 2, &mut gloss).unwrap();
    weights.extend_from_slice(&gloss);
    let mirror = Surface {
        column: None,
        back_column: None,
        reflect: Some(Specular {
            k: [0.9; 3],
            lobe: Lobe { first: 0, size: 0 },
        }),
        transmit: None,
    };
    let glossy = Surface {
        column: Some(3),
        back_column: None,
        reflect: Some(Specular {
            k: [0.5, 0.4, 0.3],
            lobe: Lobe { first: 1, size: 2 },
        }),
        transmit: None,
    };
    let surfaces = [
        Surface::diffuse(0),
        Surface::diffuse(1),
        Surface::diffuse(2),
        mirror,
        glossy,
    ];
    let settings = TraceSettings {
        threshold: 0.01,
        max_bounces: 24,
        stack: 16,
    };

    // The host's way: a park for the whole hemisphere, one cast per shot.
    let optics = Optics::new(&patches, &surfaces, &weights, circles).unwrap();
    let mut local = [LocalPatch::default(); 5];
    let (mut bt, mut bi) = ([0.0f32; 64], [0u32; 64]);
    let mut pending = vec![Pending::EMPTY; view.ray_count() as usize];
    let mut parked = vec![Pending::EMPTY; 4096];
    let mut frames = [Frame::EMPTY; 16];
    let samples = 4u32;
    let mut expected = vec![];
    let mut host_frustums = 0;
    for (i, p) in patches.iter().enumerate() {
        if surfaces[i].column.is_none() {
            continue;
        }
        let mut rows = vec![];
        for q in 0..samples {
            let point = sample_point(p, 4.0, 2, q);
            let mut accel = SoftAccelerator::new(
                &patches,
                SoftScratch {
                    local: &mut local,
                    best_t: &mut bt,
                    best_id: &mut bi,
                },
            )
            .unwrap();
            let mut scratch = TraceScratch {
                pending: &mut pending,
                parked: &mut parked,
                skeleton: Skeleton::new(&mut frames),
                threshold: settings.threshold,
                max_depth: settings.max_bounces,
            };
            let mut row = [[0.0f32; 3]; 4];
            let shot = shoot_hemisphere(
                &mut accel,
                &view,
                &optics,
                &mut scratch,
                point.position,
                point.normal,
                spin_for_sample(q),
                Some(i as u32),
                &mut row,
            );
            assert_eq!(shot.specular.recasts, 0);
            host_frustums += shot.specular.frustums;
            rows.push(row);
        }
        expected.push((i, rows));
    }
    assert!(host_frustums > 0);

    // The board's way: the optics uploaded over the link, a park of ENGINE_PENDING hits.
    let mut engine = Engine::new(SoftProvider::new(), NoPlatform);
    let cfg = JobConfig {
        circles: circles as u16,
        rule: DeltaRule::Band,
        samples: 2,
        spp: 1,
        camera: None,
        accel: AccelKind::Soft,
    };
    assert_eq!(
        engine.handle(1, &Request::Configure(cfg)),
        Some(Response::Configured)
    );
    assert_eq!(
        engine.handle(2, &Request::Tracing(settings)),
        Some(Response::Configured)
    );
    let too_deep = TraceSettings {
        stack: 17,
        ..settings
    };
    assert_eq!(
        engine.handle(2, &Request::Tracing(too_deep)),
        Some(Response::Error {
            code: ErrorCode::TooLong
        })
    );
    engine.handle(3, &Request::SceneBegin { patches: 5 });
    for (c, chunk) in weights.chunks(MAX_LOBE_CHUNK).enumerate() {
        let r = engine.handle(
            4,
            &Request::SceneLobes {
                first: (c * MAX_LOBE_CHUNK) as u16,
                weights: heapless::Vec::from_slice(chunk).unwrap(),
            },
        );
        assert!(matches!(r, Some(Response::SceneAck { .. })), "{r:?}");
    }
    for (i, s) in surfaces.iter().enumerate() {
        let r = engine.handle(
            5,
            &Request::SceneSurface {
                index: i as u16,
                surface: *s,
            },
        );
        assert!(matches!(r, Some(Response::SceneAck { .. })), "{r:?}");
    }
    for (i, p) in patches.iter().enumerate() {
        engine.handle(
            6,
            &Request::ScenePatch {
                index: i as u16,
                area: 4.0,
                patch: *p,
            },
        );
    }
    for (k, (i, rows)) in expected.iter().enumerate() {
        let shoot = Request::Shoot {
            patch: *i as u16,
            first: 0,
            count: samples as u16,
        };
        let Some(Response::Rows(got)) = engine.handle(100 + k as u32, &shoot) else {
            panic!("no rows for patch {i}");
        };
        let mut entries = got.entries.iter();
        for (r, len) in got.lens.iter().enumerate() {
            let mut want = vec![];
            for (c, f) in rows[r].iter().enumerate() {
                if *f != [0.0; 3] {
                    want.push((c as u16, f.map(f32::to_bits)));
                }
            }
            let have: std::vec::Vec<_> = entries
                .by_ref()
                .take(usize::from(*len))
                .map(|(c, f)| (*c, f.map(f32::to_bits)))
                .collect();
            assert_eq!(have, want, "patch {i} sample {r}");
        }
    }
    let Some(Response::TraceStats(t)) = engine.handle(200, &Request::TraceStats) else {
        panic!("no trace stats");
    };
    let t: TraceStats = t;
    assert_eq!(t.frustums, host_frustums);
    assert!(t.stack_high_water >= 1 && t.stack_high_water <= 16, "{t:?}");
    assert_eq!(usize::from(t.pending_capacity), ENGINE_PENDING);
    // the mirror takes more primary hits than the board parks: it cast again, same rows
    assert!(t.recasts > 0, "{t:?}");
    // pass 2 and irradiance through mirrors are refused, not answered wrong
    assert!(matches!(
        engine.handle(
            300,
            &Request::Gather {
                point: Vec3::new(1.0, 1.0, 1.0),
                normal: Vec3::new(0.0, 1.0, 0.0),
                ring: 0,
                first: 0,
                count: 1,
            }
        ),
        Some(Response::Error {
            code: ErrorCode::Unsupported
        })
    ));
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
fn random_job_requests_on_a_loaded_scene_are_answered_never_panicking() {
    // The firmware never panics on what arrives on the wire: with a scene loaded (a mirror, a
    // translucent sheet with its back column, a plain quad), jobs with random fields, NaN and
    // infinite vectors, k = 0 and k² past u16, back sides past the patches, and skips past
    // the reports, all get an answer.
    use crate::geometry::{Polygon, Vec3};
    use crate::optics::{Lobe, Specular, Surface};
    use crate::patch::Patch;
    let quad = |z: f32| {
        Patch::polygon(
            Polygon::quad(
                [[0., 0.], [1., 0.], [1., 1.], [0., 1.]].map(|[x, y]| Vec3::new(x, y, z)),
            )
            .unwrap(),
        )
    };
    let mut engine = configured_engine(4);
    engine.handle(2, &Request::SceneBegin { patches: 3 });
    let lobes = [1.0f32, 0.5, 0.25];
    engine.handle(
        3,
        &Request::SceneLobes {
            first: 0,
            weights: heapless::Vec::from_slice(&lobes).unwrap(),
        },
    );
    let mirror = Surface {
        column: None,
        back_column: None,
        reflect: Some(Specular {
            k: [0.9; 3],
            lobe: Lobe { first: 0, size: 1 },
        }),
        transmit: None,
    };
    let sheet = Surface {
        back_column: Some(3),
        ..Surface::diffuse(1)
    };
    for (i, s) in [mirror, sheet].into_iter().enumerate() {
        let r = engine.handle(
            4,
            &Request::SceneSurface {
                index: i as u16,
                surface: s,
            },
        );
        assert!(matches!(r, Some(Response::SceneAck { .. })), "{r:?}");
    }
    for (i, z) in [0.0f32, 1.0, 2.0].into_iter().enumerate() {
        engine.handle(
            5,
            &Request::ScenePatch {
                index: i as u16,
                area: 1.0,
                patch: quad(z),
            },
        );
    }
    let mut x = 0x1234_5678_9abc_def1u64;
    let mut next = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    };
    let (mut answered_rows, mut answered_queries) = (0, 0);
    for id in 10..2010u32 {
        let small = |v: u64| (v % 8) as u16;
        let any = |v: u64| v as u16;
        let pick = |v: u64, w: u64| {
            if v.is_multiple_of(2) {
                small(w)
            } else {
                any(w)
            }
        };
        let f = |v: u64| match v % 5 {
            0 => f32::NAN,
            1 => f32::INFINITY,
            2 => 0.0,
            _ => (v % 1000) as f32 / 250.0 - 2.0,
        };
        let vec = |a: u64, b: u64, c: u64| Vec3::new(f(a), f(b), f(c));
        let req = match next() % 4 {
            0 => Request::ShootLevel {
                patch: pick(next(), next()),
                k: pick(next(), next()),
                first: pick(next(), next()),
                count: pick(next(), next()),
            },
            1 => Request::Shoot {
                patch: pick(next(), next()),
                first: pick(next(), next()),
                count: pick(next(), next()),
            },
            2 => Request::Query {
                point: vec(next(), next(), next()),
                normal: vec(next(), next(), next()),
                skip: pick(next(), next()),
            },
            _ => Request::Gather {
                point: vec(next(), next(), next()),
                normal: vec(next(), next(), next()),
                ring: pick(next(), next()),
                first: pick(next(), next()),
                count: pick(next(), next()),
            },
        };
        match engine.handle(id, &req) {
            Some(Response::Rows(_)) => answered_rows += 1,
            Some(Response::Weighted(_)) => answered_queries += 1,
            Some(_) => {}
            None => panic!("{req:?} unanswered"),
        }
    }
    // the test reached the shooting paths, not only the refusals
    assert!(
        answered_rows > 20 && answered_queries > 20,
        "{answered_rows} {answered_queries}"
    );
}
