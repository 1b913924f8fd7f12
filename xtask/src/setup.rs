//! `cargo xtask setup`: make a fresh machine able to run the whole test suite (the firmware's
//! target, qemu-system-arm, defmt-print, Verilator, rustfmt and clippy).
//!
//! Idempotent: every check comes first, and only what is missing is installed. Everything it does
//! is said on stderr. What it cannot do (not root, no apt-get, no rustup) is collected and reported
//! at the end with the exact command to run, and setup fails.

use crate::util::{cargo, output, run, which};
use crate::TARGET;
use std::process::Command;

/// The QEMU machine the firmware runs on (an MPS2+ AN386, a Cortex-M4 board QEMU emulates).
const QEMU_MACHINE: &str = "mps2-an386";
/// The rustup components the test suite uses.
const COMPONENTS: [&str; 2] = ["rustfmt", "clippy"];

/// What to do about one missing (or present) tool.
#[derive(Debug)]
enum Plan {
    /// Present: nothing to do.
    Present,
    /// Missing: run these commands, in order.
    Install(Vec<Command>),
    /// Missing and cannot be installed from here: the instructions for the user.
    Manual(String),
}

fn say(msg: impl AsRef<str>) {
    eprintln!("xtask setup: {}", msg.as_ref());
}

pub fn setup() -> Result<(), String> {
    let mut manual: Vec<String> = Vec::new();
    let has_rustup = which("rustup").is_some();

    // (1) The firmware's target.
    let plan = target_plan(has_rustup, has_rustup.then(installed_targets).flatten());
    apply(&format!("target {TARGET}"), plan, &mut manual)?;

    // (2) qemu-system-arm, with the mps2-an386 machine.
    let plan = qemu_plan(
        which("qemu-system-arm").is_some(),
        is_root(),
        which("apt-get").is_some(),
    );
    apply("qemu-system-arm", plan, &mut manual)?;
    if which("qemu-system-arm").is_none() {
        still_missing("qemu-system-arm", &manual)?;
    } else {
        let version = output(cmd("qemu-system-arm", ["--version"])).unwrap_or_default();
        let version = version
            .lines()
            .next()
            .unwrap_or("version unknown")
            .to_string();
        let machines = output(cmd("qemu-system-arm", ["-machine", "help"])).unwrap_or_default();
        if machines
            .lines()
            .any(|l| l.split_whitespace().next() == Some(QEMU_MACHINE))
        {
            say(format!(
                "qemu-system-arm: {version} (machine {QEMU_MACHINE}: yes)"
            ));
        } else {
            manual.push(format!(
                "qemu-system-arm ({version}) has no `{QEMU_MACHINE}` machine: install QEMU 6.0 \
                 or newer"
            ));
        }
    }

    // (3) defmt-print: the firmware's QEMU runner decodes the defmt log with it.
    let plan = defmt_print_plan(which("defmt-print").is_some());
    apply("defmt-print", plan, &mut manual)?;
    if let Some(path) = which("defmt-print") {
        let version = output(cmd("defmt-print", ["--version"])).unwrap_or_default();
        let version = version
            .lines()
            .next()
            .unwrap_or("version unknown")
            .to_string();
        say(format!("defmt-print: {version} at {}", path.display()));
    }

    // (4) Verilator, for the co-simulation of the RTL against the model.
    if let Err(e) = verilator() {
        manual.push(e);
    }

    // (5) rustfmt and clippy.
    let missing = if has_rustup {
        missing_components()
    } else {
        COMPONENTS
            .iter()
            .filter(|c| output(cargo([component_subcommand(c), "--version"])).is_none())
            .map(|c| c.to_string())
            .collect()
    };
    apply(
        "rustfmt and clippy",
        components_plan(has_rustup, &missing),
        &mut manual,
    )?;

    if manual.is_empty() {
        say("this machine is ready");
        Ok(())
    } else {
        let mut msg = String::from("setup cannot finish on its own; please do this, then rerun:");
        for m in &manual {
            msg.push_str("\n  - ");
            msg.push_str(m);
        }
        Err(msg)
    }
}

fn apply(what: &str, plan: Plan, manual: &mut Vec<String>) -> Result<(), String> {
    match plan {
        Plan::Present => say(format!("{what}: present")),
        Plan::Install(cmds) => {
            say(format!("{what}: missing, installing"));
            for c in cmds {
                run(c).map_err(|e| format!("setup: installing {what}: {e}"))?;
            }
            say(format!("{what}: installed"));
        }
        Plan::Manual(instructions) => {
            say(format!(
                "{what}: missing, and cannot be installed from here"
            ));
            manual.push(instructions);
        }
    }
    Ok(())
}

/// After `apply`: a tool that was to be installed here but is still not on PATH is an error (one
/// left to the user is already in `manual`).
fn still_missing(tool: &str, manual: &[String]) -> Result<(), String> {
    if manual.iter().any(|m| m.contains(tool)) {
        Ok(())
    } else {
        Err(format!(
            "setup: {tool} is still not on PATH after installing it"
        ))
    }
}

fn cmd<const N: usize>(program: &str, args: [&str; N]) -> Command {
    let mut c = Command::new(program);
    c.args(args);
    c
}

/// Whether we run as root (`id -u` is 0): only then does setup use apt-get.
fn is_root() -> bool {
    output(cmd("id", ["-u"])).is_some_and(|uid| uid.trim() == "0")
}

/// The installed targets of the toolchain in use here (rust-toolchain.toml's), None if rustup fails.
fn installed_targets() -> Option<Vec<String>> {
    let out = output(cmd("rustup", ["target", "list", "--installed"]))?;
    Some(out.lines().map(|l| l.trim().to_string()).collect())
}

fn missing_components() -> Vec<String> {
    let installed = output(cmd("rustup", ["component", "list", "--installed"])).unwrap_or_default();
    COMPONENTS
        .iter()
        // Installed components are listed as `rustfmt-x86_64-unknown-linux-gnu` (or bare names).
        .filter(|c| {
            !installed
                .lines()
                .any(|l| l.trim() == **c || l.trim().starts_with(&format!("{c}-")))
        })
        .map(|c| c.to_string())
        .collect()
}

fn component_subcommand(component: &str) -> &str {
    if component == "rustfmt" {
        "fmt"
    } else {
        component
    }
}

fn target_plan(has_rustup: bool, installed: Option<Vec<String>>) -> Plan {
    match installed {
        Some(targets) if targets.iter().any(|t| t == TARGET) => Plan::Present,
        Some(_) => Plan::Install(vec![cmd("rustup", ["target", "add", TARGET])]),
        None if has_rustup => Plan::Manual(format!(
            "`rustup target list --installed` failed; run: rustup target add {TARGET}"
        )),
        None => Plan::Manual(format!(
            "no rustup on PATH: install it (https://rustup.rs), then run: rustup target add \
             {TARGET}"
        )),
    }
}

fn qemu_plan(present: bool, root: bool, has_apt: bool) -> Plan {
    apt_plan(
        "qemu-system-arm",
        "QEMU's Arm system emulator (qemu-system-arm, 6.0 or newer)",
        present,
        root,
        has_apt,
    )
}

/// A tool Debian packages under its own name: installed with apt-get as root, else the user is
/// told the command (or, without apt-get, what to install).
fn apt_plan(package: &str, what: &str, present: bool, root: bool, has_apt: bool) -> Plan {
    if present {
        return Plan::Present;
    }
    if !has_apt {
        return Plan::Manual(format!("install {what} with your system's package manager"));
    }
    if !root {
        return Plan::Manual(format!(
            "run: sudo apt-get update && sudo apt-get install -y {package}"
        ));
    }
    let apt = |args: &[&str]| {
        let mut c = Command::new("apt-get");
        c.args(args).env("DEBIAN_FRONTEND", "noninteractive");
        c
    };
    Plan::Install(vec![apt(&["update"]), apt(&["install", "-y", package])])
}

/// Installs a Debian package as root with apt-get, or says why it cannot.
pub fn apt_install(package: &str) -> Result<(), String> {
    let mut manual = Vec::new();
    let plan = apt_plan(
        package,
        package,
        false,
        is_root(),
        which("apt-get").is_some(),
    );
    apply(package, plan, &mut manual)?;
    match manual.first() {
        Some(m) => Err(format!("{package} is missing: {m}")),
        None => Ok(()),
    }
}

/// Verilator, which builds the accelerator's RTL for the co-simulation against the model
/// (`cargo xtask rtl`, the suite's `rtl-cosim` step): Debian's `verilator` package.
pub fn verilator() -> Result<(), String> {
    let mut manual = Vec::new();
    let plan = apt_plan(
        "verilator",
        "Verilator (5.x)",
        which("verilator").is_some(),
        is_root(),
        which("apt-get").is_some(),
    );
    apply("verilator", plan, &mut manual)?;
    if let Some(m) = manual.first() {
        return Err(format!("verilator is missing: {m}"));
    }
    // `verilator --build` runs make and a C++ compiler, which Debian's package does not pull in
    for (tool, package) in [("g++", "g++"), ("make", "make")] {
        if which(tool).is_none() {
            apt_install(package)?;
        }
    }
    // ccache only makes the builds quicker (`rtl::build` says why): without it they are slower
    if which("ccache").is_none() {
        if let Err(e) = apt_install("ccache") {
            say(format!(
                "ccache not installed, so RTL builds take longer: {e}"
            ));
        }
    }
    match output(cmd("verilator", ["--version"])) {
        Some(v) => say(format!("verilator: {}", v.trim())),
        None => return Err("setup: verilator is still not on PATH after installing it".into()),
    }
    Ok(())
}

fn defmt_print_plan(present: bool) -> Plan {
    if present {
        Plan::Present
    } else {
        Plan::Install(vec![cargo(["install", "defmt-print", "--locked"])])
    }
}

fn components_plan(has_rustup: bool, missing: &[String]) -> Plan {
    if missing.is_empty() {
        Plan::Present
    } else if has_rustup {
        let mut c = Command::new("rustup");
        c.args(["component", "add"]).args(missing);
        Plan::Install(vec![c])
    } else {
        Plan::Manual(format!(
            "install the Rust components: {}",
            missing.join(", ")
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::util::display;

    fn commands(plan: Plan) -> Vec<String> {
        match plan {
            Plan::Install(cmds) => cmds.iter().map(display).collect(),
            other => panic!("expected Install, got {other:?}"),
        }
    }

    fn manual(plan: Plan) -> String {
        match plan {
            Plan::Manual(m) => m,
            other => panic!("expected Manual, got {other:?}"),
        }
    }

    #[test]
    fn target() {
        let listed = |ts: &[&str]| Some(ts.iter().map(|t| t.to_string()).collect());
        assert!(matches!(
            target_plan(true, listed(&["x86_64-unknown-linux-gnu", TARGET])),
            Plan::Present
        ));
        assert_eq!(
            commands(target_plan(true, listed(&["x86_64-unknown-linux-gnu"]))),
            ["rustup target add thumbv7em-none-eabihf"]
        );
        assert!(manual(target_plan(false, None)).contains("rustup target add"));
    }

    #[test]
    fn qemu_installs_only_as_root_with_apt() {
        assert!(matches!(qemu_plan(true, false, false), Plan::Present));
        assert_eq!(
            commands(qemu_plan(false, true, true)),
            [
                "DEBIAN_FRONTEND=noninteractive apt-get update",
                "DEBIAN_FRONTEND=noninteractive apt-get install -y qemu-system-arm"
            ]
        );
        assert_eq!(
            manual(qemu_plan(false, false, true)),
            "run: sudo apt-get update && sudo apt-get install -y qemu-system-arm"
        );
        assert!(manual(qemu_plan(false, true, false)).contains("package manager"));
        assert_eq!(
            commands(apt_plan("verilator", "Verilator", false, true, true))[1],
            "DEBIAN_FRONTEND=noninteractive apt-get install -y verilator"
        );
    }

    #[test]
    fn defmt_print() {
        assert!(matches!(defmt_print_plan(true), Plan::Present));
        assert_eq!(
            commands(defmt_print_plan(false)),
            ["cargo install defmt-print --locked"]
        );
    }

    #[test]
    fn components() {
        assert!(matches!(components_plan(true, &[]), Plan::Present));
        assert_eq!(
            commands(components_plan(true, &["clippy".to_string()])),
            ["rustup component add clippy"]
        );
        assert!(manual(components_plan(false, &["rustfmt".to_string()])).contains("rustfmt"));
    }
}
