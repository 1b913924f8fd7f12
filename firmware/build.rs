//! Puts the workspace's one `memory.x` on the linker path and records the firmware's build string.
//!
//! Link arguments only apply when building for a bare-metal target, and only to binaries and
//! tests: a host build of the workspace (e.g. `cargo check --workspace`) must not get `--nmagic`.

use std::{env, fs, path::PathBuf, process::Command};

fn main() {
    let manifest = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").unwrap());
    let root = manifest.parent().unwrap();
    let out = PathBuf::from(env::var_os("OUT_DIR").unwrap());

    // Copy rather than point at the root: cortex-m-rt's link.x INCLUDEs `memory.x` from the
    // search path, and a stray memory.x in this folder would silently win (field notes).
    fs::copy(root.join("memory.x"), out.join("memory.x")).expect("workspace memory.x");
    // The accelerator model stands in for the FPGA and is larger than a small MCU: memory.x
    // gives `model` builds (QEMU only) QEMU's whole memories when this symbol is defined.
    let model = env::var_os("CARGO_FEATURE_MODEL").is_some();
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed=../memory.x");

    if env::var("CARGO_CFG_TARGET_OS").as_deref() == Ok("none") {
        for kind in ["bins", "tests", "examples"] {
            println!("cargo:rustc-link-arg-{kind}=--nmagic");
            println!("cargo:rustc-link-arg-{kind}=-Tlink.x");
            println!("cargo:rustc-link-arg-{kind}=-Tdefmt.x");
            if model {
                println!("cargo:rustc-link-arg-{kind}=--defsym=_hemi_qemu_model=1");
            }
        }
    }

    // Build string of the handshake: "hemi-firmware 0.1.0 (abc1234)"; `unknown` outside git.
    let rev = Command::new("git")
        .args(["rev-parse", "--short=10", "HEAD"])
        .current_dir(root)
        .output()
        .ok()
        .filter(|o| o.status.success())
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .map(|s| s.trim().to_owned())
        .unwrap_or_else(|| "unknown".into());
    println!("cargo:rustc-env=HEMI_GIT_REV={rev}");
    println!("cargo:rerun-if-changed=../.git/HEAD");
    println!("cargo:rerun-if-changed=../.git/refs/heads");
}
