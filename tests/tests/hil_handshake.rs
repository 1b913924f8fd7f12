//! Hardware-in-the-loop over QEMU: boots the firmware, handshakes through the pty with the
//! `serialport` crate, and checks that damaged frames are answered, counted and survived.
//!
//! Skips (passes with a printed notice) only when qemu-system-arm is missing and
//! HEMI_REQUIRE_QEMU is unset; CI sets HEMI_REQUIRE_QEMU=1, making a missing QEMU a failure.

use hemi_tests::qemu_or_skip;
use std::time::Duration;

use hemi_boards::{QemuBoard, QemuOptions};
use hemi_kernel::link::{
    encode_frame, encode_request, AccelKind, ErrorCode, Request, Response, MAX_WIRE_LEN, NO_ID,
    PROTOCOL_VERSION,
};

const T: Duration = Duration::from_secs(3);

fn process_alive(pid: u32) -> bool {
    std::path::Path::new(&format!("/proc/{pid}")).exists()
}

#[test]
fn handshake_ping_and_recovery_from_damaged_frames() {
    if !qemu_or_skip("hil_handshake") {
        return;
    }
    let mut board = QemuBoard::boot(None, &QemuOptions::default())
        .expect("boot the firmware in QEMU and handshake");
    let pid = board.qemu().pid();
    assert!(process_alive(pid));

    let hello = &board.handshake.hello;
    assert_eq!(hello.protocol, PROTOCOL_VERSION);
    assert_eq!(
        hello.accel,
        AccelKind::Model,
        "QEMU builds run jobs on the HDL model"
    );
    assert!(
        hello.build.starts_with("hemi-firmware "),
        "build: {}",
        hello.build
    );
    assert!(usize::from(hello.caps.max_frame_len) >= 512);
    eprintln!(
        "handshake after {} attempt(s): {:?}",
        board.handshake.attempts, board.handshake.elapsed
    );

    let link = &mut board.link;
    link.ping(0x1234_5678, T).expect("first ping");
    // Zero the counters so the start-up (a pty may drop bytes) does not count below.
    assert!(matches!(
        link.call(&Request::Reset, T).unwrap(),
        Response::ResetDone(_)
    ));

    // A Ping with one bit flipped mid-frame: answered with an error frame without a request id
    // (the id is not trustworthy once the CRC fails).
    let mut frame = [0u8; MAX_WIRE_LEN];
    let n = encode_request(4242, &Request::Ping { nonce: 5 }, &mut frame).unwrap();
    let i = n / 2;
    frame[i] ^= if frame[i] == 0x80 { 0x40 } else { 0x80 };
    link.send_raw(&frame[..n]).unwrap();
    let reply = link
        .recv_any(T)
        .unwrap()
        .expect("an answer to the damaged frame");
    assert!(
        matches!(
            reply,
            (
                NO_ID,
                Response::Error {
                    code: ErrorCode::BadCrc | ErrorCode::BadFraming
                }
            )
        ),
        "reply to damaged frame: {reply:?}"
    );

    // The next good frame is served.
    link.ping(7, T).expect("ping after the damaged frame");

    // A message from a newer protocol (variant 200): refused as Unsupported, with its id.
    let n = encode_frame(&[77, 200, 1], &mut frame).unwrap();
    link.send_raw(&frame[..n]).unwrap();
    let reply = link
        .recv_any(T)
        .unwrap()
        .expect("an answer to the unknown message");
    assert_eq!(
        reply,
        (
            77,
            Response::Error {
                code: ErrorCode::Unsupported
            }
        )
    );

    // Garbage without any delimiter, then a ping: the ping's leading delimiter resynchronises.
    link.send_raw(b"\x13\x37 line noise \xff\xfe").unwrap();
    link.ping(8, T).expect("ping after garbage");

    let stats = link.stats(T).unwrap();
    eprintln!("stats: {stats:?}");
    assert_eq!(
        stats.bad_crc + stats.bad_framing,
        2,
        "damaged frame and garbage: {stats:?}"
    );
    assert_eq!(stats.unsupported, 1);
    assert_eq!(stats.frames_ok, 4, "ping, unknown, ping, stats: {stats:?}");
    assert_eq!(stats.too_long + stats.malformed + stats.rx_overruns, 0);

    drop(board);
    assert!(
        !process_alive(pid),
        "QEMU (pid {pid}) is still there after the board was dropped"
    );
}
