//! On-target tests of the link under QEMU (defmt-test; exits through semihosting, 0 when all
//! pass, 1 on the first failure via the firmware's panic handler).
//!
//! The same damage scenarios as the kernel's host tests, run by the Cortex-M4 build of the kernel,
//! plus the firmware's job loop end to end against in-memory buffers.
#![no_std]
#![no_main]

use hemi_firmware as _; // panic handler, HardFault handler, defmt logger

use heapless::Vec;
use hemi_firmware::{board, job::JobLoop};
use hemi_kernel::link::{
    decode_response, encode_frame, encode_request, ErrorCode, FrameError, MaxFrameDecoder, Request,
    Response, MAX_STUFFED_LEN, MAX_WIRE_LEN, NO_ID,
};

type Verdicts = Vec<Result<Vec<u8, 64>, FrameError>, 8>;

fn feed(dec: &mut MaxFrameDecoder, bytes: &[u8]) -> Verdicts {
    let mut got = Verdicts::new();
    for &b in bytes {
        if let Some(r) = dec.push(b) {
            let r = r.map(|p| Vec::from_slice(p).unwrap());
            got.push(r).ok().unwrap();
        }
    }
    got
}

fn frame(payload: &[u8]) -> Vec<u8, 128> {
    let mut out = [0u8; 128];
    let n = encode_frame(payload, &mut out).unwrap();
    Vec::from_slice(&out[..n]).unwrap()
}

fn is_payload(r: &Result<Vec<u8, 64>, FrameError>, want: &[u8]) -> bool {
    matches!(r, Ok(p) if p.as_slice() == want)
}

/// Collects what the job loop transmits.
struct Wire(Vec<u8, 4096>);
impl embedded_io::ErrorType for Wire {
    type Error = core::convert::Infallible;
}
impl embedded_io::Write for Wire {
    fn write(&mut self, buf: &[u8]) -> Result<usize, Self::Error> {
        self.0.extend_from_slice(buf).unwrap();
        Ok(buf.len())
    }
    fn flush(&mut self) -> Result<(), Self::Error> {
        Ok(())
    }
}

fn request(id: u32, req: &Request) -> Vec<u8, MAX_WIRE_LEN> {
    let mut out = [0u8; MAX_WIRE_LEN];
    let n = encode_request(id, req, &mut out).unwrap();
    Vec::from_slice(&out[..n]).unwrap()
}

#[defmt_test::tests]
mod tests {
    use super::*;

    #[test]
    fn round_trip() {
        let mut dec = MaxFrameDecoder::new();
        let got = feed(&mut dec, &frame(b"\x00hemi\x00\x00on target"));
        defmt::assert_eq!(got.len(), 1);
        defmt::assert!(is_payload(&got[0], b"\x00hemi\x00\x00on target"));
    }

    #[test]
    fn flipped_bit_then_good_frame() {
        let good = frame(b"hello hemi");
        let mut dec = MaxFrameDecoder::new();
        for byte in 1..good.len() - 1 {
            for bit in 0..8 {
                let mut stream: Vec<u8, 256> = Vec::from_slice(&good).unwrap();
                stream[byte] ^= 1 << bit;
                stream.extend_from_slice(&good).unwrap();
                let got = feed(&mut dec, &stream);
                defmt::assert!(got.len() >= 2);
                defmt::assert!(got[..got.len() - 1].iter().all(|r| r.is_err()));
                defmt::assert!(is_payload(&got[got.len() - 1], b"hello hemi"));
            }
        }
    }

    #[test]
    fn truncated_then_good_frame() {
        let good = frame(b"0123456789abcdef");
        let mut dec = MaxFrameDecoder::new();
        for cut in 2..good.len() - 1 {
            let mut stream: Vec<u8, 256> = Vec::from_slice(&good[..cut]).unwrap();
            stream.extend_from_slice(&good).unwrap();
            let got = feed(&mut dec, &stream);
            defmt::assert_eq!(got.len(), 2);
            defmt::assert!(got[0].is_err());
            defmt::assert!(is_payload(&got[1], b"0123456789abcdef"));
        }
    }

    #[test]
    fn garbage_between_frames() {
        let good = frame(b"payload");
        let mut stream: Vec<u8, 256> = Vec::from_slice(&good).unwrap();
        stream.extend_from_slice(b"\x13\x37garbage\xff").unwrap();
        stream.extend_from_slice(&good).unwrap();
        let mut dec = MaxFrameDecoder::new();
        let got = feed(&mut dec, &stream);
        defmt::assert_eq!(got.len(), 3);
        defmt::assert!(is_payload(&got[0], b"payload"));
        defmt::assert!(got[1].is_err());
        defmt::assert!(is_payload(&got[2], b"payload"));
    }

    #[test]
    fn over_long_then_good_frame() {
        let mut dec = MaxFrameDecoder::new();
        let _ = dec.push(0);
        for _ in 0..2 * MAX_STUFFED_LEN {
            defmt::assert!(dec.push(0x55).is_none());
        }
        defmt::assert!(matches!(dec.push(0), Some(Err(FrameError::TooLong))));
        let got = feed(&mut dec, &frame(b"after"));
        defmt::assert_eq!(got.len(), 1);
        defmt::assert!(is_payload(&got[0], b"after"));
    }

    #[test]
    fn job_loop_answers_errors_and_recovers() {
        let mut job = JobLoop::new(board::hello_info());
        let mut wire = Wire(Vec::new());
        let mut bad = request(2, &Request::Ping { nonce: 7 });
        bad[2] ^= 0x04;
        job.feed(&request(1, &Request::Hello { protocol: 1 }), &mut wire)
            .unwrap();
        job.feed(&bad, &mut wire).unwrap();
        job.feed(&request(3, &Request::Ping { nonce: 8 }), &mut wire)
            .unwrap();

        let mut dec = MaxFrameDecoder::new();
        let mut replies: Vec<(u32, Response), 4> = Vec::new();
        for &b in wire.0.iter() {
            if let Some(Ok(p)) = dec.push(b) {
                replies.push(decode_response(p).unwrap()).ok().unwrap();
            }
        }
        defmt::assert_eq!(replies.len(), 3);
        defmt::assert!(
            matches!(&replies[0], (1, Response::Hello(h)) if h.build.as_str() == board::BUILD)
        );
        defmt::assert!(matches!(
            replies[1],
            (
                NO_ID,
                Response::Error {
                    code: ErrorCode::BadCrc | ErrorCode::BadFraming
                }
            )
        ));
        defmt::assert!(matches!(replies[2], (3, Response::Pong { nonce: 8 })));
        let stats = job.stats();
        defmt::assert_eq!(stats.frames_ok, 2);
        defmt::assert_eq!(stats.bad_crc + stats.bad_framing, 1);
    }
}
