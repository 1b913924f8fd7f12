//! Today's bytes on the wire, pinned: the frame encoder and decoder must give exactly what the
//! hand-written COBS and CRC-32 of protocol 4 gave, so a board and a host built before and after
//! a change to the framing code still understand each other.
//!
//! [`legacy`] is that hand-written code, kept here as the reference. Random payloads and random
//! messages (seeded, so every run sees the same ones) go through both; the frames must be
//! identical, and so must the decoder's verdicts on damaged frames. A digest of all the frames
//! pins them as well, in case the reference itself is ever edited.

extern crate std;

use std::vec::Vec;

use super::tests::XorShift;
use super::*;

/// The framing code of protocol 4 as first written (COBS with a code byte after a full block,
/// CRC-32/ISO-HDLC appended little-endian), only for comparison.
mod legacy {
    use super::super::FrameError;
    use std::vec::Vec;

    fn crc_table() -> [u32; 256] {
        core::array::from_fn(|i| {
            (0..8).fold(i as u32, |c, _| {
                if c & 1 != 0 {
                    0xEDB8_8320 ^ (c >> 1)
                } else {
                    c >> 1
                }
            })
        })
    }

    pub fn crc32(bytes: &[u8]) -> u32 {
        let table = crc_table();
        let state = bytes.iter().fold(0xFFFF_FFFFu32, |s, &b| {
            table[((s as u8) ^ b) as usize] ^ (s >> 8)
        });
        state ^ 0xFFFF_FFFF
    }

    /// COBS: blocks of at most 254 data bytes, a new block (code 1 if nothing follows) after
    /// every zero and every full block.
    fn stuff(src: &[u8]) -> Vec<u8> {
        let mut out = std::vec![0u8];
        let (mut code_idx, mut code) = (0usize, 1u8);
        for &b in src {
            if b != 0 {
                out.push(b);
                code += 1;
            }
            if b == 0 || code == 0xFF {
                out[code_idx] = code;
                code_idx = out.len();
                out.push(0);
                code = 1;
            }
        }
        out[code_idx] = code;
        out
    }

    /// `0x00 · COBS(payload · CRC-32 LE) · 0x00`.
    pub fn frame(payload: &[u8]) -> Vec<u8> {
        let mut content = payload.to_vec();
        content.extend_from_slice(&crc32(payload).to_le_bytes());
        let mut out = std::vec![0u8];
        out.extend(stuff(&content));
        out.push(0);
        out
    }

    /// The payload of one stuffed frame (no delimiters, no zero byte in it), or why not.
    pub fn unframe(stuffed: &[u8]) -> Result<Vec<u8>, FrameError> {
        let mut out = Vec::new();
        let mut read = 0;
        while read < stuffed.len() {
            let code = usize::from(stuffed[read]);
            read += 1;
            let end = read + code - 1;
            if end > stuffed.len() {
                return Err(FrameError::BadFraming);
            }
            out.extend_from_slice(&stuffed[read..end]);
            read = end;
            if code != 0xFF && read < stuffed.len() {
                out.push(0);
            }
        }
        let Some(payload_len) = out.len().checked_sub(4) else {
            return Err(FrameError::BadFraming);
        };
        let (payload, crc) = out.split_at(payload_len);
        if crc32(payload).to_le_bytes() != crc {
            return Err(FrameError::BadCrc);
        }
        Ok(payload.to_vec())
    }
}

/// FNV-1a, 64 bits: a fingerprint of every frame, no dependency needed.
fn fnv(hash: u64, bytes: &[u8]) -> u64 {
    bytes.iter().fold(hash, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01B3)
    })
}
const FNV_START: u64 = 0xCBF2_9CE4_8422_2325;

/// A random payload: any length up to the limit, long lengths near multiples of 254 (where COBS
/// closes full blocks) and every density of zeros from none to all.
fn random_payload(rng: &mut XorShift) -> Vec<u8> {
    let len = match rng.next() % 4 {
        0 => (rng.next() % 16) as usize,
        1 => {
            let blocks = 1 + (rng.next() % 4) as usize;
            (blocks * 254 + (rng.next() % 9) as usize).saturating_sub(8)
        }
        _ => (rng.next() % (MAX_PAYLOAD_LEN as u64 + 1)) as usize,
    };
    let len = len.min(MAX_PAYLOAD_LEN);
    // `zeros` 0: no zero at all; z > 0: besides the random ones, about one byte in 40·z² is 0
    let zeros = rng.next() % 6;
    (0..len)
        .map(|_| match zeros {
            0 => (rng.next() % 255) as u8 + 1,
            z if rng.next().is_multiple_of(z * z * 40) => 0,
            _ => rng.next() as u8,
        })
        .collect()
}

fn bulk(rng: &mut XorShift) -> heapless::Vec<u8, MAX_BULK> {
    let len = (rng.next() % (MAX_BULK as u64 + 1)) as usize;
    let mut v = heapless::Vec::new();
    for _ in 0..len {
        // mostly nonzero, with long zero-free runs
        let b = if rng.next().is_multiple_of(300) {
            0
        } else {
            rng.next() as u8
        };
        let _ = v.push(b);
    }
    v
}

fn random_request(rng: &mut XorShift) -> Request {
    let f = |rng: &mut XorShift| f32::from_bits(rng.next() as u32);
    match rng.next() % 5 {
        0 => Request::Ping {
            nonce: rng.next() as u32,
        },
        1 => Request::Sink { data: bulk(rng) },
        2 => Request::Source {
            len: rng.next() as u16,
        },
        3 => Request::Hello {
            protocol: rng.next() as u16,
        },
        _ => Request::Query {
            point: crate::geometry::Vec3::new(f(rng), f(rng), f(rng)),
            normal: crate::geometry::Vec3::new(f(rng), f(rng), f(rng)),
            skip: rng.next() as u16,
        },
    }
}

fn random_response(rng: &mut XorShift) -> Response {
    match rng.next() % 4 {
        0 => Response::Source { data: bulk(rng) },
        1 => Response::SinkAck {
            len: rng.next() as u16,
            crc: rng.next() as u32,
        },
        2 => {
            let mut hits = heapless::Vec::new();
            for _ in 0..rng.next() % (MAX_HITS as u64 + 1) {
                let hit = (!rng.next().is_multiple_of(4)).then(|| RayHit {
                    patch: rng.next() as u16 % 300,
                    front: rng.next().is_multiple_of(2),
                    u: (rng.next() % 1000) as f32 / 999.0,
                    v: (rng.next() % 1000) as f32 / 999.0,
                });
                let _ = hits.push(hit);
            }
            Response::Hits(hits)
        }
        _ => Response::Pong {
            nonce: rng.next() as u32,
        },
    }
}

/// The postcard payload of `(id, msg)`, as `codec` frames it.
fn payload<T: serde::Serialize>(id: u32, msg: &T) -> Vec<u8> {
    let mut buf = [0u8; MAX_WIRE_LEN];
    postcard::to_slice(&(id, msg), &mut buf).unwrap().to_vec()
}

#[test]
fn frames_of_random_payloads_are_todays_bytes() {
    let mut rng = XorShift(0x5EED_0FF2_A3E5_0001);
    let mut out = [0u8; MAX_WIRE_LEN];
    let mut digest = FNV_START;
    let mut full_blocks = 0;
    for i in 0..4000 {
        let payload = random_payload(&mut rng);
        let n = encode_frame(&payload, &mut out).unwrap();
        let want = legacy::frame(&payload);
        assert_eq!(
            &out[..n],
            &want[..],
            "payload {i} ({} bytes)",
            payload.len()
        );
        digest = fnv(digest, &want);
        // content ending on a full block of 254 nonzero bytes: the case where COBS coders differ
        // (a trailing code byte 1, or none)
        let mut content = payload.clone();
        content.extend_from_slice(&legacy::crc32(&payload).to_le_bytes());
        let tail = content.iter().rev().take_while(|&&b| b != 0).count();
        full_blocks += usize::from(tail > 0 && tail % 254 == 0);
    }
    assert!(
        full_blocks >= 10,
        "only {full_blocks} frames end on a full block"
    );
    assert_eq!(digest, 0x5d95_3154_b6cd_69d8, "digest {digest:#018x}");
}

#[test]
fn frames_of_random_messages_are_todays_bytes() {
    let mut rng = XorShift(0x0DDB_A11C_0FFE_E002);
    let mut out = [0u8; MAX_WIRE_LEN];
    let mut digest = FNV_START;
    for i in 0..3000u32 {
        let id = rng.next() as u32 >> (rng.next() % 32);
        let (n, want) = if i % 2 == 0 {
            let req = random_request(&mut rng);
            let n = encode_request(id, &req, &mut out).unwrap();
            (n, legacy::frame(&payload(id, &req)))
        } else {
            let resp = random_response(&mut rng);
            let n = encode_response(id, &resp, &mut out).unwrap();
            (n, legacy::frame(&payload(id, &resp)))
        };
        assert_eq!(&out[..n], &want[..], "message {i}");
        digest = fnv(digest, &want);
    }
    assert_eq!(digest, 0x2a4c_36d3_2763_acaa, "digest {digest:#018x}");
}

#[test]
fn the_decoder_judges_damaged_frames_as_before() {
    let mut rng = XorShift(0xBADF_4A3E_5EED_0003);
    let mut dec = MaxFrameDecoder::new();
    let (mut accepted, mut bad_crc, mut bad_framing) = (0, 0, 0);
    for _ in 0..6000 {
        let mut wire = legacy::frame(&random_payload(&mut rng));
        // damage 0..3 bytes of the stuffed part (never a delimiter: that would split the frame)
        for _ in 0..rng.next() % 4 {
            let i = 1 + (rng.next() as usize) % (wire.len() - 2);
            wire[i] = (rng.next() % 255) as u8 + 1;
        }
        // sometimes cut the frame short
        if rng.next().is_multiple_of(4) {
            let cut = 1 + (rng.next() as usize) % (wire.len() - 1);
            wire.truncate(cut);
            wire.push(0);
        }
        let stuffed = &wire[1..wire.len() - 1];
        if stuffed.is_empty() {
            continue;
        }
        let want = legacy::unframe(stuffed);
        let got: Vec<_> = wire
            .iter()
            .filter_map(|&b| dec.push(b).map(|r| r.map(<[u8]>::to_vec)))
            .collect();
        assert_eq!(got, core::slice::from_ref(&want), "stuffed {stuffed:02x?}");
        match want {
            Ok(_) => accepted += 1,
            Err(FrameError::BadCrc) => bad_crc += 1,
            Err(_) => bad_framing += 1,
        }
    }
    // every verdict was exercised
    assert!(accepted > 500 && bad_crc > 500 && bad_framing > 100);
}

#[test]
fn link_checksum_is_todays() {
    // the "check" value of CRC-32/ISO-HDLC in every CRC catalogue
    assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
    assert_eq!(crc32(b""), 0);
    let mut rng = XorShift(0xC4C3_2000_0000_0004);
    for _ in 0..500 {
        let bytes = random_payload(&mut rng);
        assert_eq!(crc32(&bytes), legacy::crc32(&bytes));
    }
}
