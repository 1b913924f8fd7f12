//! Link performance under QEMU, for docs/PERFORMANCE.md ("## Link"):
//!
//!     cargo test --release -p hemi-tests --test hil_link_perf -- --nocapture
//!
//! Measures boot-to-handshake time, handshake and ping round trips, and throughput in each
//! direction with four requests in flight. Asserts only correctness of every byte and a very low
//! floor, so a slow shared machine does not fail CI; the printed numbers are the result.

use std::time::{Duration, Instant};

use hemi_boards::{qemu_available, QemuBoard, QemuOptions};
use hemi_kernel::link::{crc32, Request, Response, MAX_BULK, PROTOCOL_VERSION};

const T: Duration = Duration::from_secs(5);
const WINDOW: usize = 4;

fn percentile(mut v: Vec<Duration>, p: f64) -> f64 {
    v.sort();
    let i = ((v.len() - 1) as f64 * p).round() as usize;
    v[i].as_secs_f64() * 1e3
}

#[test]
fn link_latency_and_throughput() {
    if !qemu_available() {
        let required = std::env::var("HEMI_REQUIRE_QEMU").is_ok_and(|v| !v.is_empty() && v != "0");
        assert!(
            !required,
            "HEMI_REQUIRE_QEMU is set but qemu-system-arm is not runnable"
        );
        eprintln!("SKIPPED hil_link_perf: qemu-system-arm not found");
        return;
    }
    // Build (or find) the firmware first so the boot time below is QEMU's and the handshake's.
    let elf = hemi_boards::firmware_elf(None).unwrap();
    let t0 = Instant::now();
    let mut board = QemuBoard::boot(Some(&elf), &QemuOptions::default()).unwrap();
    let boot = t0.elapsed();
    let hs = board.handshake.clone();
    let link = &mut board.link;

    let hellos: Vec<Duration> = (0..20)
        .map(|_| {
            let t = Instant::now();
            let r = link
                .call(
                    &Request::Hello {
                        protocol: PROTOCOL_VERSION,
                    },
                    T,
                )
                .unwrap();
            assert!(matches!(r, Response::Hello(_)));
            t.elapsed()
        })
        .collect();
    let pings: Vec<Duration> = (0..50).map(|i| link.ping(i, T).unwrap()).collect();

    // Host → firmware: Sink frames of MAX_BULK bytes, WINDOW in flight.
    let frames = 96;
    let data: heapless::Vec<u8, MAX_BULK> = (0..MAX_BULK).map(|i| (i * 31 % 251) as u8).collect();
    let want_crc = crc32(&data);
    let sink = Request::Sink { data };
    let t = Instant::now();
    let (mut sent, mut done) = (0, 0);
    while done < frames {
        while sent < frames && sent - done < WINDOW {
            link.send(&sink).unwrap();
            sent += 1;
        }
        match link.recv_any(T).unwrap() {
            Some((_, Response::SinkAck { len, crc })) => {
                assert_eq!((usize::from(len), crc), (MAX_BULK, want_crc));
                done += 1;
            }
            other => panic!("unexpected answer to Sink: {other:?}"),
        }
    }
    let up = (frames * MAX_BULK) as f64 / t.elapsed().as_secs_f64();

    // Firmware → host: Source frames of MAX_BULK bytes, WINDOW in flight.
    let frames = 512;
    let source = Request::Source {
        len: MAX_BULK as u16,
    };
    let t = Instant::now();
    let (mut sent, mut done) = (0, 0);
    while done < frames {
        while sent < frames && sent - done < WINDOW {
            link.send(&source).unwrap();
            sent += 1;
        }
        match link.recv_any(T).unwrap() {
            Some((_, Response::Source { data })) => {
                assert_eq!(data.len(), MAX_BULK);
                assert!(data.iter().enumerate().all(|(i, &b)| b == i as u8));
                done += 1;
            }
            other => panic!("unexpected answer to Source: {other:?}"),
        }
    }
    let down = (frames * MAX_BULK) as f64 / t.elapsed().as_secs_f64();
    let stats = link.stats(T).unwrap();
    assert_eq!(
        stats.bad_crc + stats.bad_framing + stats.too_long + stats.rx_overruns,
        0,
        "{stats:?}"
    );

    println!("| measure | value |");
    println!("|---|---|");
    println!(
        "| boot to handshake (QEMU start, pty, Hello with retries) | {:.0} ms ({} attempt(s)) |",
        boot.as_secs_f64() * 1e3,
        hs.attempts
    );
    println!(
        "| Hello round trip, median / p90 of 20 | {:.1} / {:.1} ms |",
        percentile(hellos.clone(), 0.5),
        percentile(hellos, 0.9)
    );
    println!(
        "| Ping round trip, median / p90 of 50 | {:.1} / {:.1} ms |",
        percentile(pings.clone(), 0.5),
        percentile(pings, 0.9)
    );
    println!(
        "| host → firmware payload throughput (Sink, 512 B, {WINDOW} in flight) | {:.1} KB/s |",
        up / 1e3
    );
    println!(
        "| firmware → host payload throughput (Source, 512 B, {WINDOW} in flight) | {:.1} KB/s |",
        down / 1e3
    );
    assert!(
        up > 1e3 && down > 1e3,
        "implausibly slow: up {up:.0} B/s, down {down:.0} B/s"
    );
}
