//! `cargo xtask qemu` and `cargo xtask flash`: run the firmware by hand, in QEMU or on a board.

use crate::util::{cargo, display, root, run, which, Failure};
use crate::{FIRMWARE, TARGET};
use std::io::{BufRead, BufReader};
use std::path::PathBuf;
use std::process::{Command, Stdio};

/// Where cargo puts the firmware ELF built with `--release` into `target_dir`.
fn elf_in(target_dir: PathBuf) -> PathBuf {
    target_dir.join(TARGET).join("release").join(FIRMWARE)
}

/// The firmware for a board with `features` (no QEMU semihosting exits; `board` is the MMIO
/// accelerator with the soft engine as its fallback): the `board` profile, every crate
/// optimised for size so that it fits 128 KiB of flash, in `target/board/`, a directory of its
/// own, so the QEMU build the HIL tests boot is left alone.
pub(crate) fn board_build(features: &str) -> Command {
    let mut build = cargo([
        "build",
        "--profile",
        "board",
        "-p",
        FIRMWARE,
        "--target",
        TARGET,
        "--no-default-features",
        "--features",
        features,
    ]);
    build.arg("--target-dir").arg(target_dir().join("board"));
    build
}

/// Where [`board_build`] puts the ELF.
fn board_elf() -> PathBuf {
    target_dir()
        .join("board")
        .join(TARGET)
        .join("board")
        .join(FIRMWARE)
}

/// The cargo target directory (`CARGO_TARGET_DIR`, else the workspace's `target/`).
pub(crate) fn target_dir() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR")
        .filter(|d| !d.is_empty())
        .map(PathBuf::from)
        .unwrap_or_else(|| root().join("target"))
}

/// `cargo xtask qemu [ELF] [-- QEMU_ARGS...]`
///
/// Starts QEMU itself rather than through `firmware/qemu-run.sh`: that runner wraps QEMU in
/// `timeout`, which moves it to its own process group, so a Ctrl-C on the terminal would not reach
/// it. Here QEMU and defmt-print stay in our group and a Ctrl-C ends all of them.
pub fn qemu(args: &[String]) -> Result<(), Failure> {
    let (ours, extra) = match args.iter().position(|a| a == "--") {
        Some(i) => (&args[..i], &args[i + 1..]),
        None => (args, &args[args.len()..]),
    };
    let elf = match ours {
        [] => {
            run(cargo([
                "build",
                "--release",
                "-p",
                FIRMWARE,
                "--target",
                TARGET,
            ]))
            .map_err(Failure::Failed)?;
            elf_in(target_dir())
        }
        [elf] if !elf.starts_with('-') => PathBuf::from(elf),
        _ => {
            return Err(Failure::Usage(
                "usage: cargo xtask qemu [ELF] [-- QEMU_ARGS...]".into(),
            ))
        }
    };
    if !elf.is_file() {
        return Err(Failure::Failed(format!(
            "no firmware ELF at {}",
            elf.display()
        )));
    }
    if which("qemu-system-arm").is_none() {
        return Err(Failure::Failed(
            "qemu-system-arm is not installed: `cargo xtask setup` installs it".into(),
        ));
    }

    // UART0 on a pty (QEMU names it on stdout first); stdout carries the semihosting/defmt log.
    let own_serial = !extra.iter().any(|a| a == "-serial" || a == "-chardev");
    let mut q = Command::new("qemu-system-arm");
    q.args([
        "-machine",
        "mps2-an386",
        "-cpu",
        "cortex-m4",
        "-display",
        "none",
    ])
    .args([
        "-monitor",
        "none",
        "-semihosting-config",
        "enable=on,target=native",
    ]);
    if own_serial {
        q.args(["-serial", "pty"]);
    }
    q.arg("-kernel").arg(&elf).args(extra);
    eprintln!("$ {}", display(&q));
    let mut qemu = q
        .stdout(Stdio::piped())
        .spawn()
        .map_err(|e| Failure::Failed(format!("cannot start qemu-system-arm: {e}")))?;
    let mut log = BufReader::new(qemu.stdout.take().expect("piped"));
    if own_serial {
        let mut line = String::new();
        // Printed when the chardev opens, before the CPU runs: no firmware output precedes it.
        if log.read_line(&mut line).is_ok() {
            let pty = line.trim().strip_prefix("char device redirected to ");
            let pty = pty.and_then(|rest| rest.split_whitespace().next());
            match pty {
                Some(pty) => eprintln!(
                    "xtask qemu: UART0 is on {pty}; talk to it with e.g. \
                     `cargo run --release -p hemi-cli -- board info --backend serial:{pty}`. \
                     Ctrl-C stops QEMU."
                ),
                None => eprint!("{line}"),
            }
        }
    }

    let decoder = which("defmt-print").and_then(|tool| {
        let mut d = Command::new(tool);
        d.arg("-e").arg(&elf).stdin(Stdio::piped());
        d.spawn().ok()
    });
    let mut decoder = match decoder {
        Some(d) => Some(d),
        None => {
            eprintln!("xtask qemu: no defmt-print (`cargo xtask setup` installs it): raw log");
            None
        }
    };
    // Copy QEMU's stdout into the decoder (or to our stdout) until QEMU exits.
    let copy = match decoder.as_mut().and_then(|d| d.stdin.take()) {
        Some(mut stdin) => std::thread::spawn(move || std::io::copy(&mut log, &mut stdin)),
        None => std::thread::spawn(move || std::io::copy(&mut log, &mut std::io::stdout())),
    };
    let status = qemu
        .wait()
        .map_err(|e| Failure::Failed(format!("waiting for QEMU: {e}")))?;
    let _ = copy.join();
    if let Some(mut d) = decoder {
        let _ = d.wait();
    }
    if status.success() {
        Ok(())
    } else {
        Err(Failure::Failed(format!("QEMU ended with {status}")))
    }
}

/// `cargo xtask flash [--chip CHIP] [--features F] [ELF]`: `firmware/probe-run.sh ELF`, which
/// runs `probe-rs run` for the MPS2+ AN386 (firmware/mps2-an386.yaml) or for `--chip`.
///
/// Without an ELF, builds the firmware for a board (`--no-default-features --features board`, or
/// the features given; no QEMU semihosting exits, the log over RTT; the `board` profile,
/// optimised for size) into `target/board/`, so the QEMU build the HIL tests use is left alone.
/// It is the same build `cargo xtask test` checks against the flash and RAM of memory.x, and the
/// one `cargo board-run` runs.
pub fn flash(args: &[String]) -> Result<(), Failure> {
    const USAGE: &str = "usage: cargo xtask flash [--chip CHIP] [--features F] [ELF] \
                         (default chip: the MPS2+ AN386 of firmware/mps2-an386.yaml; \
                         `probe-rs chip list` names the others; env PROBE_RS_CHIP works too)";
    let mut chip: Option<String> = None;
    let mut features: Option<String> = None;
    let mut elf: Option<PathBuf> = None;
    let mut it = args.iter();
    while let Some(arg) = it.next() {
        match arg.as_str() {
            "--chip" => chip = Some(it.next().ok_or(Failure::Usage(USAGE.into()))?.clone()),
            "--features" => features = Some(it.next().ok_or(Failure::Usage(USAGE.into()))?.clone()),
            s if !s.starts_with('-') && elf.is_none() => elf = Some(PathBuf::from(s)),
            _ => return Err(Failure::Usage(USAGE.into())),
        }
    }
    if which("probe-rs").is_none() {
        return Err(Failure::Failed(
            "probe-rs is not installed. Install it with:\n  cargo install probe-rs-tools --locked\n\
             (it takes 20+ minutes to build; it is never used in CI)"
                .into(),
        ));
    }
    let elf = match elf {
        Some(elf) => elf,
        None => {
            run(board_build(features.as_deref().unwrap_or("board"))).map_err(Failure::Failed)?;
            board_elf()
        }
    };
    let mut probe = Command::new(root().join("firmware/probe-run.sh"));
    probe.arg(&elf);
    if let Some(chip) = chip {
        probe.env("PROBE_RS_CHIP", chip);
    }
    eprintln!("$ {}", display(&probe));
    let status = probe
        .status()
        .map_err(|e| Failure::Failed(format!("cannot start firmware/probe-run.sh: {e}")))?;
    if status.success() {
        Ok(())
    } else {
        Err(Failure::Failed(format!("probe-rs ended with {status}")))
    }
}
