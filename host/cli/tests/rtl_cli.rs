//! `--backend rtl`: the passes on the one-lane build's Verilog (`hdl-model/rtl/accel_single.v`)
//! in its Verilator simulator, through the register driver, against the model of the same
//! build (`--lanes 1 --sectors 0 --rays-per-clock 1 --bank-slots 256 --wide-datapath
//! --ray-groups 1`): the
//! same form factors and hits to the last digit, and the same clocks.
//!
//! The tests that run the simulator are ignored by default: it is built by `cargo xtask
//! rtl-sim` (with Verilator). The suite's `rtl-cosim` step builds it and runs them with
//! `--ignored`, `HEMI_RTL_SIM` naming it; run that way without it, they fail.

mod common;

use common::{cornell_rays, run, TWO_SQUARES};

const CORNELL: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/cornell.toml");
const TEAPOT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/teapot.toml");

/// The model of the build the RTL is.
const SINGLE: [&str; 13] = [
    "--backend",
    "model",
    "--lanes",
    "1",
    "--sectors",
    "0",
    "--rays-per-clock",
    "1",
    "--bank-slots",
    "256",
    "--wide-datapath",
    "--ray-groups",
    "1",
];

/// The simulator `cargo xtask rtl-sim` built, as `HEMI_RTL_SIM` names it.
fn sim() -> String {
    std::env::var("HEMI_RTL_SIM").expect("HEMI_RTL_SIM names the simulator (cargo xtask rtl-sim)")
}

/// The cycles of a `hemi` report line on stderr (`…: N cycles for …`).
fn cycles(stderr: &str) -> u64 {
    let line = stderr
        .lines()
        .find(|l| l.contains(" cycles for "))
        .unwrap_or_else(|| panic!("no cycle report in: {stderr}"));
    let before = line.split(" cycles for ").next().unwrap();
    before.rsplit(' ').next().unwrap().parse().unwrap()
}

#[test]
#[ignore = "needs the RTL simulator: cargo xtask rtl-sim (the suite's rtl-cosim step runs it)"]
fn pass_1_on_the_rtl_is_the_models_to_the_bit_and_the_clock() {
    let args = ["form-factors", CORNELL, "--circles", "4", "--samples", "1"];
    let rtl_sim = sim();
    let rtl = [&args[..], &["--backend", "rtl", "--rtl-sim", &rtl_sim]].concat();
    let (ok, got, got_err) = run(&rtl, "");
    assert!(ok, "{got_err}");
    let (ok, want, want_err) = run(&[&args[..], &SINGLE].concat(), "");
    assert!(ok, "{want_err}");
    assert_eq!(got, want);
    assert_eq!(got.lines().count(), 20, "{got}");
    assert_eq!(cycles(&got_err), cycles(&want_err), "{got_err}\n{want_err}");
    assert!(
        got_err.starts_with("740 rays") && got_err.contains("rtl ("),
        "{got_err}"
    );
}

#[test]
#[ignore = "needs the RTL simulator: cargo xtask rtl-sim (the suite's rtl-cosim step runs it)"]
fn single_rays_on_the_rtl_hit_what_the_model_hits() {
    // rays from above the Cornell box's blocks, with (u,v), and one out through the open front
    let rays = cornell_rays(40);
    let rtl_sim = sim();
    let rtl = ["trace", CORNELL, "--backend", "rtl", "--rtl-sim", &rtl_sim];
    let (ok, got, err) = run(&rtl, &rays);
    assert!(ok, "{err}");
    let (ok, want, want_err) = run(&[&["trace", CORNELL][..], &SINGLE].concat(), &rays);
    assert!(ok, "{want_err}");
    assert_eq!(got, want);
    assert!(got.lines().filter(|l| *l != "miss").count() >= 25, "{got}");
    // the RTL answered. (Not its clocks: `trace` casts the rays in batches as they arrive on
    // its input, each batch's engine setting up its origin, so a run's clocks depend on how
    // the pipe delivered them, on the model as on the RTL; pass 1's do not, above.)
    assert!(err.contains("rtl (") && err.contains("41 rays"), "{err}");
}

#[test]
#[ignore = "needs the RTL simulator: cargo xtask rtl-sim (the suite's rtl-cosim step runs it)"]
fn the_rtl_refuses_a_bezier_scene_it_has_no_unit_for() {
    let rtl_sim = sim();
    let args = [
        "form-factors",
        TEAPOT,
        "--backend",
        "rtl",
        "--rtl-sim",
        &rtl_sim,
    ];
    let (ok, _, err) = run(&args, "");
    assert!(!ok);
    assert!(
        err.contains("Bezier") && err.contains("--backend model"),
        "{err}"
    );
}

#[test]
fn without_its_simulator_the_rtl_backend_says_how_to_build_it() {
    let args = [
        "form-factors",
        "-",
        "--backend",
        "rtl",
        "--rtl-sim",
        "/nonexistent/accel-sim",
    ];
    let (ok, _, err) = run(&args, TWO_SQUARES);
    assert!(!ok);
    assert!(err.contains("cargo xtask rtl-sim"), "{err}");
}

#[test]
fn the_rtl_backend_takes_none_of_the_models_options() {
    let args = ["form-factors", "-", "--backend", "rtl", "--lanes", "2"];
    let (ok, _, err) = run(&args, TWO_SQUARES);
    assert!(!ok);
    assert!(err.contains("do not apply"), "{err}");
}
