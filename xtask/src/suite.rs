//! `cargo xtask test`: the whole test suite, step by step, as CI runs it.
//!
//! Each step is announced with a header and timed; the run stops at the first failing step
//! (unless `--keep-going`) and ends with a table of the steps and one closing line
//! `xtask: N passed, M failed`.

use crate::util::{self, cargo, fmt_duration, Failure};
use crate::{FIRMWARE, TARGET};
use std::process::Command;
use std::time::{Duration, Instant};

/// One step of the suite: a name (usable on the command line) and what it runs.
struct Step {
    name: &'static str,
    what: &'static str,
    kind: Kind,
}

enum Kind {
    /// `cargo xtask setup`, in-process.
    Setup,
    /// These commands, in order; the step fails at the first that fails.
    Commands(fn() -> Vec<Command>),
    /// A check run in this process.
    Check(fn() -> Result<(), String>),
}

/// The host crates: the whole workspace but the firmware (which only builds for its target).
const HOST: [&str; 3] = ["--workspace", "--exclude", FIRMWARE];

fn steps() -> Vec<Step> {
    vec![
        Step {
            name: "setup",
            what: "set-up of this machine (target, QEMU, defmt-print, Verilator, rustfmt, clippy)",
            kind: Kind::Setup,
        },
        Step {
            name: "fmt",
            what: "formatting (cargo fmt --check)",
            kind: Kind::Commands(|| vec![cargo(["fmt", "--all", "--", "--check"])]),
        },
        Step {
            name: "layout",
            what: "the host crates' architecture (cargo xtask layout: no import cycle, a library \
                   free of CLI and serial crates and of environment variables, short functions)",
            kind: Kind::Check(crate::layout::check),
        },
        Step {
            name: "clippy-host",
            what: "clippy on the host crates, warnings denied",
            kind: Kind::Commands(|| {
                let mut c = cargo(["clippy"]);
                c.args(HOST).args(["--all-targets", "--", "-D", "warnings"]);
                vec![c]
            }),
        },
        Step {
            name: "firmware-build",
            what: "release build of the firmware ELF (the HIL tests boot it), and of the board \
                   build, which must fit 128 KiB of flash and 64 KiB of RAM (memory.x)",
            kind: Kind::Commands(|| {
                let qemu = cargo(["build", "--release", "-p", FIRMWARE, "--target", TARGET]);
                // the board build, sized for a 128 KiB / 64 KiB part
                let board = crate::boards::board_build("board");
                vec![qemu, board]
            }),
        },
        Step {
            name: "clippy-firmware",
            what: "clippy on the firmware and its on-target tests, warnings denied",
            kind: Kind::Commands(|| {
                vec![cargo([
                    "clippy",
                    "-p",
                    FIRMWARE,
                    "--target",
                    TARGET,
                    // not --all-targets: that asks for a libtest harness of the lib, which
                    // cannot exist for a no_std target (the on-target tests are --tests)
                    "--lib",
                    "--bins",
                    "--examples",
                    "--tests",
                    "--",
                    "-D",
                    "warnings",
                ])]
            }),
        },
        Step {
            name: "host-tests",
            what: "host tests, including the HIL tests over QEMU (HEMI_REQUIRE_QEMU=1), and the \
                   kernel's link and board-engine tests with the large tables QEMU's model build uses",
            kind: Kind::Commands(|| {
                let mut c = cargo(["test"]);
                c.args(HOST).env("HEMI_REQUIRE_QEMU", "1");
                // the firmware turns `large-engine` on; the host never does
                let large = cargo([
                    "test",
                    "-p",
                    "hemi-kernel",
                    "--features",
                    "large-engine",
                    "--lib",
                    "--",
                    "link::",
                    "jobs::",
                ]);
                vec![c, large]
            }),
        },
        Step {
            name: "firmware-tests",
            what: "firmware unit tests on the target, under QEMU",
            kind: Kind::Commands(|| vec![cargo(["test", "-p", FIRMWARE, "--target", TARGET])]),
        },
        Step {
            name: "rtl-cosim",
            what: "the accelerator's RTL (hdl-model/rtl/) Verilated and co-simulated against the \
                   model on Cornell-box hemispheres, random rays and frames, answers and clocks \
                   bit for bit, random register traffic on the register file's AHB-Lite bus, \
                   the coarse edge units' words and verdicts on the Cornell box's set-up \
                   passes and random patches, the culling unit's sectors and bands of \
                   hemisphere and random directions and its reach of the Cornell box's \
                   patches and random ones, the set-up unit's plane tests, edge words and \
                   reaches of the Cornell box's set-up passes and random passes with their \
                   clocks, the slot boxes' writes and the horizon filter's verdicts with their \
                   clocks, a bank front's corner reads on the model's clocks (the filter \
                   stopping for a full FIFO) and the set-up unit's answers behind it, those \
                   answers into the bank's bitmaps, a bank's bitmap writer's copies and \
                   completions on the model's clocks, a lane's bitmap walk's candidates out \
                   of those bitmaps for rays of every sector and band, the exact edge unit's \
                   verdicts on the \
                   Cornell box's undecided pairs and random ones with their clocks, the \
                   plane unit's answers on the Cornell box's rays and random ones with their \
                   clocks, the multipliers against exact products, and the whole one-lane \
                   accelerator through its AHB-Lite bus and stream port (the register \
                   driver's own accesses, every read and result compared), then nineteen \
                   one-bit mutants of the RTL shown to be caught, and `hemi --backend rtl` on \
                   the Verilated accelerator against the model of the same build, form factors, \
                   hits and clocks (cargo xtask rtl is the full form, with synthesis)",
            kind: Kind::Check(crate::rtl::ci),
        },
        Step {
            name: "doc",
            what: "rustdoc of every crate, warnings denied",
            kind: Kind::Commands(|| {
                let flags = match std::env::var("RUSTDOCFLAGS") {
                    Ok(f) if !f.trim().is_empty() => format!("{f} -D warnings"),
                    _ => "-D warnings".to_string(),
                };
                let mut host = cargo(["doc", "--no-deps"]);
                host.args(HOST).env("RUSTDOCFLAGS", &flags);
                let mut firmware = cargo(["doc", "--no-deps", "-p", FIRMWARE, "--target", TARGET]);
                firmware.env("RUSTDOCFLAGS", &flags);
                vec![host, firmware]
            }),
        },
    ]
}

struct Options {
    keep_going: bool,
    list: bool,
    only: Vec<String>,
}

fn parse(args: &[String], known: &[&str]) -> Result<Options, Failure> {
    let mut opts = Options {
        keep_going: false,
        list: false,
        only: Vec::new(),
    };
    for arg in args {
        match arg.as_str() {
            "--keep-going" => opts.keep_going = true,
            "--list" => opts.list = true,
            s if s.starts_with('-') => {
                return Err(Failure::Usage(format!("`test`: unknown option `{s}`")))
            }
            s if known.contains(&s) => opts.only.push(s.to_string()),
            s => {
                return Err(Failure::Usage(format!(
                    "`test`: unknown step `{s}` (steps: {})",
                    known.join(", ")
                )))
            }
        }
    }
    Ok(opts)
}

enum Outcome {
    Passed(Duration),
    Failed(Duration, String),
    NotRun,
}

pub fn main(args: &[String]) -> Result<(), Failure> {
    let all = steps();
    let names: Vec<&str> = all.iter().map(|s| s.name).collect();
    let opts = parse(args, &names)?;
    if opts.list {
        for s in &all {
            println!("{:<16} {}", s.name, s.what);
        }
        return Ok(());
    }
    let selected: Vec<&Step> = all
        .iter()
        .filter(|s| opts.only.is_empty() || opts.only.iter().any(|o| o == s.name))
        .collect();

    let total = selected.len();
    let started = Instant::now();
    let mut outcomes: Vec<Outcome> = Vec::with_capacity(total);
    let mut stop = false;
    for (i, step) in selected.iter().enumerate() {
        if stop {
            outcomes.push(Outcome::NotRun);
            continue;
        }
        eprintln!();
        eprintln!(
            "==== xtask [{}/{total}] {}: {}",
            i + 1,
            step.name,
            step.what
        );
        let t0 = Instant::now();
        let result = match &step.kind {
            Kind::Setup => crate::setup::setup(),
            Kind::Commands(make) => make().into_iter().try_for_each(util::run),
            Kind::Check(check) => check(),
        };
        let took = t0.elapsed();
        match result {
            Ok(()) => {
                eprintln!("==== xtask: {} passed in {}", step.name, fmt_duration(took));
                outcomes.push(Outcome::Passed(took));
            }
            Err(e) => {
                eprintln!(
                    "==== xtask: {} FAILED in {}: {e}",
                    step.name,
                    fmt_duration(took)
                );
                outcomes.push(Outcome::Failed(took, e));
                stop = !opts.keep_going;
            }
        }
    }

    // The summary: one line per step, then the closing line CI's log reader looks for.
    let passed = outcomes
        .iter()
        .filter(|o| matches!(o, Outcome::Passed(_)))
        .count();
    let failed = outcomes
        .iter()
        .filter(|o| matches!(o, Outcome::Failed(..)))
        .count();
    let not_run = total - passed - failed;
    println!();
    println!(
        "xtask test summary ({} in all):",
        fmt_duration(started.elapsed())
    );
    for (step, outcome) in selected.iter().zip(&outcomes) {
        let (status, time) = match outcome {
            Outcome::Passed(t) => ("ok", fmt_duration(*t)),
            Outcome::Failed(t, _) => ("FAILED", fmt_duration(*t)),
            Outcome::NotRun => ("not run", String::new()),
        };
        println!("  {:<16} {status:<8} {time:>8}", step.name);
    }
    if let Some((step, Outcome::Failed(_, e))) = selected
        .iter()
        .zip(&outcomes)
        .find(|(_, o)| matches!(o, Outcome::Failed(..)))
    {
        let first_line = e.lines().next().unwrap_or_default();
        println!("xtask: step `{}` failed: {first_line}", step.name);
    }
    if not_run > 0 {
        println!("xtask: {not_run} step(s) not run after the failure (--keep-going runs them)");
    }
    println!("xtask: {passed} passed, {failed} failed");
    if failed == 0 {
        Ok(())
    } else {
        Err(Failure::Failed(String::new()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steps_in_the_order_ci_needs() {
        let names: Vec<&str> = steps().iter().map(|s| s.name).collect();
        assert_eq!(
            names,
            [
                "setup",
                "fmt",
                "layout",
                "clippy-host",
                "firmware-build",
                "clippy-firmware",
                "host-tests",
                "firmware-tests",
                "rtl-cosim",
                "doc"
            ]
        );
    }

    #[test]
    fn host_steps_never_build_the_firmware_for_the_host() {
        for step in steps() {
            let Kind::Commands(make) = step.kind else {
                continue;
            };
            for c in make() {
                let line = util::display(&c);
                let for_target = line.contains(&format!("--target {TARGET}"));
                let host_only = line.contains("--exclude hemi-firmware");
                // one named crate that is not the firmware (the kernel with a feature)
                let one_host_crate = line.contains(" -p ") && !line.contains(FIRMWARE);
                let fmt = line.starts_with("cargo fmt");
                assert!(
                    for_target || host_only || one_host_crate || fmt,
                    "{}: {line}",
                    step.name
                );
            }
        }
    }

    #[test]
    fn host_tests_require_qemu() {
        let step = steps()
            .into_iter()
            .find(|s| s.name == "host-tests")
            .unwrap();
        let Kind::Commands(make) = step.kind else {
            panic!()
        };
        assert!(util::display(&make()[0]).starts_with("HEMI_REQUIRE_QEMU=1 cargo test"));
    }

    #[test]
    fn parse_options() {
        let known = ["fmt", "doc"];
        let args = |a: &[&str]| a.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        let o = parse(&args(&["--keep-going", "doc"]), &known).unwrap();
        assert!(o.keep_going && !o.list);
        assert_eq!(o.only, ["doc"]);
        assert!(matches!(
            parse(&args(&["nope"]), &known),
            Err(Failure::Usage(_))
        ));
        assert!(matches!(
            parse(&args(&["--nope"]), &known),
            Err(Failure::Usage(_))
        ));
    }
}
