//! Link faults: with bytes flipped, dropped and frames truncated between
//! host and QEMU, and with a QEMU killed in the middle of a run, pass 1 still returns every row
//! exactly once and the same bits as the in-process model backend.
//!
//! The proxy is a real pty pair (`serialport::TTYPort::pair`): the host talks `serial:PATH` to
//! its slave end as it would to a board; a relay thread carries bytes between its master end and
//! QEMU's pty, damaging them at a set rate.

use hemi_bench::rng::XorShift;
use hemi_tests::{big_stack, cornell_scene, qemu_or_skip};
use std::io::{Read, Write};

use serialport::SerialPort;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use hemi::pass1;
use hemi::scene::Scene;
use hemi::settings::Pass1Settings;
use hemi_boards::{firmware_elf, BoardSpec, Boards, Farm, FarmOptions, Qemu, QemuOptions};
use hemi_hdl_model::ModelConfig;
use hemi_kernel::hemisphere::DeltaRule;
use hemi_kernel::link::AccelKind;

/// Pass 1 on the farm's boards.
fn board_form_factors(
    farm: &Farm,
    scene: &Scene,
    settings: &Pass1Settings,
) -> anyhow::Result<pass1::FormFactors> {
    let boards = Boards::new(farm, scene, settings, AccelKind::None)?;
    pass1::form_factors(&boards, &|_| {})
}

fn bits(m: &hemi::matrix::FormMatrix) -> Vec<Vec<u64>> {
    m.iter()
        .map(|r| r.iter().map(|x| x.to_bits()).collect())
        .collect()
}

/// Pass 1 through `farm` equals the in-process model backend: every row once, same bits.
fn check_against_model(scene: &Scene, settings: &Pass1Settings, got: &pass1::FormFactors) {
    let model = hemi::backend::model(scene, settings, ModelConfig::default()).unwrap();
    let want = pass1::form_factors(&model, &|_| {}).unwrap();
    assert_eq!(
        got.elements.len(),
        want.elements.len(),
        "a row lost or duplicated"
    );
    for (g, w) in got.elements.iter().zip(&want.elements) {
        assert_eq!((g.patch, g.point, &g.row), (w.patch, w.point, &w.row));
    }
    assert_eq!(bits(&got.matrix), bits(&want.matrix));
}

#[derive(Default)]
struct Faults {
    flipped: AtomicU64,
    dropped: AtomicU64,
    truncated: AtomicU64,
}

/// Relays `from` → `to`, damaging bytes: each byte is flipped, dropped, or starts a truncation
/// (everything up to the next frame delimiter dropped) with probability `rate` each.
fn relay(
    mut from: Box<dyn serialport::SerialPort>,
    mut to: Box<dyn serialport::SerialPort>,
    rate: f64,
    seed: u64,
    faults: Arc<Faults>,
    stop: Arc<AtomicBool>,
) {
    let mut rng = XorShift::new(seed);
    let mut buf = [0u8; 512];
    let mut truncating = false;
    while !stop.load(Ordering::Relaxed) {
        let n = match from.read(&mut buf) {
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::TimedOut => continue,
            Err(_) => return,
        };
        let mut out = Vec::with_capacity(n);
        for &b in &buf[..n] {
            if truncating {
                if b == 0 {
                    truncating = false;
                    out.push(b);
                }
                continue;
            }
            if rng.chance(rate) {
                faults.flipped.fetch_add(1, Ordering::Relaxed);
                out.push(b ^ (1 << (rng.bits() % 8)));
            } else if rng.chance(rate) {
                faults.dropped.fetch_add(1, Ordering::Relaxed);
            } else if rng.chance(rate) && b != 0 {
                faults.truncated.fetch_add(1, Ordering::Relaxed);
                truncating = true;
            } else {
                out.push(b);
            }
        }
        if to.write_all(&out).is_err() {
            return;
        }
    }
}

#[test]
fn pass1_through_a_proxy_that_flips_drops_and_truncates_bytes() {
    if !qemu_or_skip("fault_link proxy") {
        return;
    }
    big_stack(|| {
        let elf = firmware_elf(None).unwrap();
        let qemu = Qemu::boot(&elf, &QemuOptions::default()).unwrap();
        let to_qemu = serialport::new(qemu.pty().to_string_lossy(), 115_200)
            .timeout(Duration::from_millis(5))
            .open()
            .unwrap();
        let (mut master, slave) = serialport::TTYPort::pair().expect("a pty pair");
        master.set_timeout(Duration::from_millis(5)).unwrap();
        let slave_path = slave.name().expect("the pty's name");
        let faults = Arc::new(Faults::default());
        let stop = Arc::new(AtomicBool::new(false));
        // 0.05 % per byte per kind, both ways: about one Rows answer in five is damaged, one
        // request in fifty.
        let rate = 0.0005;
        let relays = [
            (
                Box::new(master.try_clone_native().unwrap()) as Box<dyn serialport::SerialPort>,
                to_qemu.try_clone().unwrap(),
                0x9e37_79b9_7f4a_7c15,
            ),
            (
                to_qemu,
                Box::new(master) as Box<dyn serialport::SerialPort>,
                0x2545_f491_4f6c_dd1d,
            ),
        ]
        .map(|(from, to, seed)| {
            let (faults, stop) = (faults.clone(), stop.clone());
            std::thread::spawn(move || relay(from, to, rate, seed, faults, stop))
        });

        let scene = cornell_scene();
        let settings = Pass1Settings {
            circles: 8,
            samples: 3,
            rule: DeltaRule::Band,
            ..Pass1Settings::default()
        };
        let farm = Farm::connect(&[BoardSpec::Serial(slave_path)], FarmOptions::default()).unwrap();
        let got = board_form_factors(&farm, &scene, &settings).unwrap();
        let events = farm.events();
        let injected = [&faults.flipped, &faults.dropped, &faults.truncated]
            .map(|c| c.load(Ordering::Relaxed));
        eprintln!("faults injected (flipped, dropped, truncated): {injected:?}; {events:?}");
        assert!(
            injected.iter().all(|&n| n > 0),
            "every kind of fault happened"
        );
        assert!(
            events.resent > 0,
            "some jobs had to be sent again: {events:?}"
        );
        check_against_model(&scene, &settings, &got);
        stop.store(true, Ordering::Relaxed);
        drop(farm);
        drop(slave);
        drop(qemu);
        for r in relays {
            let _ = r.join();
        }
    });
}

#[test]
fn pass1_survives_a_qemu_killed_mid_run() {
    if !qemu_or_skip("fault_link kill") {
        return;
    }
    big_stack(|| {
        let scene = cornell_scene();
        let settings = Pass1Settings {
            circles: 12,
            samples: 4,
            rule: DeltaRule::Band,
            ..Pass1Settings::default()
        };
        let farm =
            Farm::connect(&[BoardSpec::Qemu, BoardSpec::Qemu], FarmOptions::default()).unwrap();
        let victim = farm.qemu_pids()[0].expect("a QEMU pid");
        let killed = AtomicBool::new(false);
        let got = std::thread::scope(|s| {
            let run = s.spawn(|| board_form_factors(&farm, &scene, &settings));
            // Kill the first board once the run is under way.
            let t0 = Instant::now();
            while farm.events().answered < 4 && t0.elapsed() < Duration::from_secs(60) {
                std::thread::sleep(Duration::from_millis(2));
            }
            let status = std::process::Command::new("kill")
                .args(["-9", &victim.to_string()])
                .status()
                .unwrap();
            killed.store(status.success(), Ordering::Relaxed);
            run.join().unwrap().unwrap()
        });
        assert!(killed.load(Ordering::Relaxed), "QEMU {victim} was killed");
        let events = farm.events();
        eprintln!("{events:?}");
        assert!(
            events.reconnects >= 1,
            "the dead board was rebooted: {events:?}"
        );
        check_against_model(&scene, &settings, &got);
    });
}
