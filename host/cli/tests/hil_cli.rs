//! Hardware-in-the-loop over QEMU through the CLI: the firmware's defmt log, decoded, through
//! `--firmware-log`; and `hemi trace` on a board (protocol 5's `Cast` jobs), line for line the
//! model's.
//!
//! The firmware logs its boot line at `info` level, which defmt keeps only because
//! `.cargo/config.toml` sets `DEFMT_LOG`; the host decodes it with the booted ELF's table. So a
//! decoded `INFO` line here shows both ends: the level compiled in, and the decoder.
//!
//! Skips (passes with a printed notice) only when qemu-system-arm is missing and
//! HEMI_REQUIRE_QEMU is unset; `cargo xtask test` sets it, making a missing QEMU a failure.

mod common;

use common::{cornell_rays, run, TWO_SQUARES};
use std::path::PathBuf;
use std::process::Command;
use std::sync::OnceLock;

/// Whether QEMU can run here; without it, a skip unless `HEMI_REQUIRE_QEMU` asks for a failure
/// (the rule of the HIL tests in `tests/`, whose helper this crate does not depend on).
fn qemu_or_skip(test: &str) -> bool {
    if hemi_boards::qemu_available() {
        return true;
    }
    let required = std::env::var("HEMI_REQUIRE_QEMU").is_ok_and(|v| !v.is_empty() && v != "0");
    assert!(
        !required,
        "HEMI_REQUIRE_QEMU is set but qemu-system-arm is not runnable"
    );
    eprintln!("SKIPPED {test}: qemu-system-arm not found");
    false
}

/// The firmware ELF, built once for every run below (each `hemi` would otherwise ask cargo
/// again whether it is up to date, seconds on a busy machine).
fn firmware() -> &'static str {
    static ELF: OnceLock<String> = OnceLock::new();
    ELF.get_or_init(|| {
        let elf = hemi_boards::firmware_elf(None).expect("the firmware ELF");
        elf.to_str().expect("a UTF-8 path").to_owned()
    })
}

/// Runs hemi with `args` on this checkout's firmware, with no log variable from the caller's
/// environment; returns (stdout, stderr), asserting success.
fn hemi(args: &[&str]) -> (String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_hemi"))
        .args(args)
        .args(["--firmware", firmware()])
        .env_remove("HEMI_FIRMWARE_LOG")
        .output()
        .unwrap();
    let (stdout, stderr) = (
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8(out.stderr).unwrap(),
    );
    assert!(out.status.success(), "hemi {args:?}: {stderr}");
    (stdout, stderr)
}

/// The firmware's boot line among `text`'s lines: `qemu[PID] INFO <build> up: UART0 at …`.
fn boot_line(text: &str) -> Option<&str> {
    text.lines().find(|l| {
        l.starts_with("qemu[") && l.contains("] INFO ") && l.contains(" up: UART0 at 0x40004000")
    })
}

#[test]
fn board_info_prints_the_decoded_info_line_only_when_asked() {
    if !qemu_or_skip("hil_cli") {
        return;
    }
    let (stdout, stderr) = hemi(&["board", "info", "--backend", "qemu", "--firmware-log"]);
    let line = boot_line(&stderr).unwrap_or_else(|| panic!("no boot line in:\n{stderr}"));
    // the line carries the build string the handshake reports: decoded, not raw bytes
    let build = stdout
        .lines()
        .find_map(|l| l.strip_prefix("build"))
        .map(str::trim)
        .expect("a build line");
    assert!(line.contains(&format!("INFO {build} up:")), "{line}");
    assert!(line.is_ascii(), "{line:?}");

    let (_, quiet) = hemi(&["board", "info", "--backend", "qemu"]);
    assert!(
        !quiet.contains("qemu["),
        "a log without --firmware-log:\n{quiet}"
    );
}

#[test]
fn a_farm_run_writes_the_decoded_log_to_a_file() {
    if !qemu_or_skip("hil_cli") {
        return;
    }
    let dir = std::env::temp_dir().join(format!("hemi-fwlog-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("two.toml");
    std::fs::write(&scene, TWO_SQUARES).unwrap();
    let log: PathBuf = dir.join("firmware.log");
    let (stdout, stderr) = hemi(&[
        "form-factors",
        scene.to_str().unwrap(),
        "--backend",
        "qemu",
        "--circles",
        "8",
        "--samples",
        "1",
        &format!("--firmware-log={}", log.display()),
    ]);
    assert!(stdout.contains("p1"), "{stdout}");
    let text = std::fs::read_to_string(&log).unwrap();
    assert!(boot_line(&text).is_some(), "log file:\n{text}");
    assert!(boot_line(&stderr).is_none(), "the log went to stderr too");
}

#[test]
fn trace_on_a_qemu_board_prints_the_models_hits() {
    if !qemu_or_skip("hil_cli") {
        return;
    }
    // rays from above the Cornell box's blocks in 60 directions (more than one Cast job), and
    // one that leaves through the open front: every line the model's, to the last digit
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/cornell.toml");
    let rays = cornell_rays(60);
    let trace = |backend: &[&str]| {
        let mut args = vec!["trace", scene];
        args.extend_from_slice(backend);
        let (ok, out, err) = run(&args, &rays);
        assert!(ok, "{backend:?}: {err}");
        out
    };
    let want = trace(&["--backend", "model"]);
    let got = trace(&["--backend", "qemu", "--firmware", firmware()]);
    assert_eq!(got, want);
    assert_eq!(got.lines().count(), 61);
    assert!(got.lines().filter(|l| *l != "miss").count() >= 40, "{got}");
    assert!(got.lines().last() == Some("miss"), "{got}");
}
