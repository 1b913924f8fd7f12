//! Proofs by Yosys's SAT solver, for units a proof covers better than any workload:
//! - the culling's leading one (`rtl/leading_one.v`), whose patch side takes 66-bit words,
//!   proved equal to its specification (`rtl/tb/leading_one_check.v`, the first bit set found
//!   by a plain loop) for every word at each range the RTL instantiates it with;
//! - the adder-subtractor (`rtl/add_sub.v`: the CORDIC's, and `rtl/magnitude.v`'s), whose
//!   synthesis form (Yosys's `$alu` cell, the inversion in the carry cells' LUT4s) is not the
//!   form Verilator co-simulates: mapped to the ECP5's cells and proved equal to a + b and
//!   a − b (`rtl/tb/add_sub_check.v`) at each width the RTL instantiates it with;
//! - the registered product on a multiplier tile (`rtl/mul18.v`), whose synthesis form
//!   instantiates the ECP5's MULT18X18D with its output register. Yosys has no simulation
//!   model of the tile, so this is a check of its wiring, not a proof: the tile's inputs, sign
//!   and source pins must be connected exactly as Yosys connects them when it maps the written
//!   form (`ecp5/dsp_map.v`), its output register must be on the unit's clock and enable
//!   with its 36 products on the unit's output, and it must have no other register.
//!
//! Each proof is then run on a mutant, which must fail, so that a proof that cannot fail is
//! caught. Yosys runs in the work dir on relative paths, as synthesis does
//! ([`RTL_FROM_WORK_DIR`] says why).

use super::{rtl_dir, say, work_dir, yosys, CONFIGS, RTL_FROM_WORK_DIR};
use std::path::Path;
use std::process::{Command, Stdio};

/// (word width, LO, HI) of each `leading_one` instance: the patch side's two normalisations
/// (`cull_reach.v`'s `cull_angles`: bits 0..65 and 0..37 of 66) and the ray side's
/// (`cull_ray.v`'s: bits 27..34 and 25..31 of 35).
const RANGES: [(u32, u32, u32); 4] = [(66, 0, 65), (66, 0, 37), (35, 27, 34), (35, 25, 31)];

/// The leading one's mutant: `w2[i]` without its last `w1`, so a 16-bit window misses bits
/// i+12..i+15.
const MUTANT_FROM: &str = "w1[i] | w1[i + 4] | w1[i + 8] | w1[i + 12]";
const MUTANT_TO: &str = "w1[i] | w1[i + 4] | w1[i + 8]";

/// The adder-subtractor's mutant: the carry in of a − b = a + ~b + 1 dropped from the cell.
const ADD_SUB_FROM: &str = ".CI(sub)";
const ADD_SUB_TO: &str = ".CI(1'b0)";

/// Widths the RTL instantiates `add_sub` at besides CONFIGS' CORDIC widths: the culling's
/// CORDIC (`cull_reach.v`'s and `cull_ray.v`'s W, the model's `cull::CULL_CORDIC`: 20 bits),
/// and the magnitudes (`magnitude.v`) of the reach (`cull_reach.v`: 18, 23, 33, 38 bits; its
/// per-patch angles 35 bits wide until session 45) and of the culling's normalisations
/// (`cull_angles.v`: 33, 35, 39, 66).
const OTHER_WIDTHS: [u32; 8] = [18, 20, 23, 33, 35, 38, 39, 66];

/// The tile check's mutant: the second operand taken unsigned.
const TILE_FROM: &str = ".SIGNEDB(1'b1)";
const TILE_TO: &str = ".SIGNEDB(1'b0)";

/// Whether Yosys's `script`, run in `dir` with its log `log` there, succeeds (a proof's
/// `sat -verify` fails the script when the proof fails).
fn yosys_ok(dir: &Path, script: &str, log: &str) -> Result<bool, String> {
    let status = Command::new(yosys())
        .current_dir(dir)
        .args(["-q", "-l", log, "-p", script])
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .map_err(|e| format!("cannot start {}: {e}", yosys()))?;
    Ok(status.success())
}

/// Whether Yosys proves `leading_one.v` (as `unit`, a path relative to the work dir `dir`)
/// equal to its specification at one range, its log `log` in `dir`.
fn proved(dir: &Path, unit: &str, (w, lo, hi): (u32, u32, u32), log: &str) -> Result<bool, String> {
    let script = format!(
        "read_verilog {unit} {RTL_FROM_WORK_DIR}/tb/leading_one_check.v; \
         chparam -set W {w} -set LO {lo} -set HI {hi} leading_one_check; \
         hierarchy -top leading_one_check; proc; flatten; opt; \
         sat -verify -prove bad 0 leading_one_check"
    );
    yosys_ok(dir, &script, log)
}

/// Whether `add_sub.v` (as `unit`, relative to `dir`) at width `w`, synthesised for the ECP5
/// and read back with the cells' simulation models, is proved equal to a ± b.
fn add_sub_proved(dir: &Path, unit: &str, w: u32, log: &str) -> Result<bool, String> {
    let mapped = format!("add_sub_mapped_{w}.v");
    let synth = format!(
        "read_verilog -icells {unit}; chparam -set W {w} add_sub; synth_ecp5 -top add_sub; \
         rename add_sub add_sub_mapped; write_verilog -noattr {mapped}"
    );
    if !yosys_ok(dir, &synth, &format!("synth-{log}"))? {
        return Err(format!(
            "{unit} at W {w} did not synthesise ({})",
            dir.join(format!("synth-{log}")).display()
        ));
    }
    let script = format!(
        "read_verilog {mapped} {RTL_FROM_WORK_DIR}/tb/add_sub_check.v; \
         read_verilog +/ecp5/cells_sim.v; chparam -set W {w} add_sub_check; \
         hierarchy -top add_sub_check; proc; flatten; opt; \
         sat -verify -prove bad 0 add_sub_check"
    );
    yosys_ok(dir, &script, log)
}

/// `unit`'s text with `from` replaced by `to`, written as `name` in `dir` (a mutant).
fn mutant(dir: &Path, unit: &str, from: &str, to: &str, name: &str) -> Result<(), String> {
    let path = rtl_dir().join(unit);
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    if !text.contains(from) {
        return Err(format!("{unit} no longer holds `{from}`"));
    }
    let out = dir.join(name);
    std::fs::write(&out, text.replace(from, to)).map_err(|e| format!("{}: {e}", out.display()))
}

/// Proves the leading one at every range, and shows the mutant's proof failing.
fn leading_one(dir: &Path) -> Result<(), String> {
    let unit_in_dir = format!("{RTL_FROM_WORK_DIR}/leading_one.v");
    for r in RANGES {
        let log = format!("leading_one-{}-{}-{}.log", r.0, r.1, r.2);
        if !proved(dir, &unit_in_dir, r, &log)? {
            return Err(format!(
                "leading_one.v differs from its specification at W {}, LO {}, HI {} ({})",
                r.0,
                r.1,
                r.2,
                dir.join(log).display()
            ));
        }
        say(format!(
            "leading_one.v proved equal to its specification at W {}, LO {}, HI {}",
            r.0, r.1, r.2
        ));
    }
    mutant(
        dir,
        "leading_one.v",
        MUTANT_FROM,
        MUTANT_TO,
        "leading_one_mutant.v",
    )?;
    if proved(dir, "leading_one_mutant.v", RANGES[0], "mutant.log")? {
        return Err("the leading one's mutant (a 16-bit window 4 bits short) was proved equal to its specification: the proof cannot fail".to_string());
    }
    say("leading_one.v's mutant (a 16-bit window 4 bits short) caught by the same proof");
    Ok(())
}

/// Proves the adder-subtractor as mapped at every CORDIC width, and shows the mutant's proof
/// failing.
fn add_sub(dir: &Path) -> Result<(), String> {
    let unit_in_dir = format!("{RTL_FROM_WORK_DIR}/add_sub.v");
    let mut widths: Vec<u32> = CONFIGS.iter().map(|c| c.width).collect();
    widths.extend(OTHER_WIDTHS);
    widths.sort_unstable();
    widths.dedup();
    for w in widths {
        let log = format!("add_sub-{w}.log");
        if !add_sub_proved(dir, &unit_in_dir, w, &log)? {
            return Err(format!(
                "add_sub.v as mapped to the ECP5 differs from a ± b at W {w} ({})",
                dir.join(log).display()
            ));
        }
        say(format!(
            "add_sub.v as mapped to the ECP5 proved equal to a ± b at W {w}"
        ));
    }
    mutant(
        dir,
        "add_sub.v",
        ADD_SUB_FROM,
        ADD_SUB_TO,
        "add_sub_mutant.v",
    )?;
    if add_sub_proved(
        dir,
        "add_sub_mutant.v",
        CONFIGS[0].width,
        "add_sub-mutant.log",
    )? {
        return Err("the adder-subtractor's mutant (its carry in dropped) was proved equal to a ± b: the proof cannot fail".to_string());
    }
    say("add_sub.v's mutant (its carry in dropped) caught by the same proof");
    Ok(())
}

/// The connections and parameters of the one MULT18X18D `synth_ecp5` makes of `mul18` (as
/// `unit`, relative to `dir`), read with `defines`: Yosys's `dump` lines, trimmed.
fn tile_lines(dir: &Path, unit: &str, defines: &str, log: &str) -> Result<Vec<String>, String> {
    let script = format!(
        "read_verilog {defines}-icells {unit}; synth_ecp5 -top mul18; \
         select -module mul18 t:MULT18X18D; tee -o {log}.dump dump"
    );
    if !yosys_ok(dir, &script, log)? {
        return Err(format!(
            "{unit} did not synthesise ({})",
            dir.join(log).display()
        ));
    }
    let path = dir.join(format!("{log}.dump"));
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(text
        .lines()
        .map(str::trim)
        .filter(|l| l.starts_with("connect ") || l.starts_with("parameter "))
        .map(str::to_string)
        .collect())
}

/// Whether the tile form of `mul18.v` (as `unit`) is wired as Yosys maps its written form,
/// with the output register on the unit's clock, enable and output.
fn tile_wired(dir: &Path, unit: &str, log: &str) -> Result<bool, String> {
    let written = tile_lines(dir, unit, "", &format!("written-{log}"))?;
    let tile = tile_lines(dir, unit, "-DHEMI_ECP5 ", &format!("tile-{log}"))?;
    // the operands, the unused third input, signs and sources: every pin but the products
    // and the register's (18 + 18 + 18 + 4)
    let operand = |l: &&String| {
        let pin = l
            .strip_prefix("connect \\")
            .and_then(|rest| rest.split(' ').next())
            .unwrap_or("");
        let product = pin.starts_with('P') && pin[1..].parse::<u32>().is_ok();
        !pin.is_empty() && !product && !["CLK0", "CE0", "RST0"].contains(&pin)
    };
    let mut w: Vec<&String> = written.iter().filter(operand).collect();
    let mut t: Vec<&String> = tile.iter().filter(operand).collect();
    w.sort();
    t.sort();
    // the output register on the unit's clock and enable, and no other register of the tile's
    // (an input or pipeline register would add a clock the written form does not have)
    let mut params: Vec<&str> = tile
        .iter()
        .filter(|l| l.starts_with("parameter "))
        .map(String::as_str)
        .collect();
    params.sort_unstable();
    let register_params = [
        "parameter \\REG_OUTPUT_CE \"CE0\"",
        "parameter \\REG_OUTPUT_CLK \"CLK0\"",
        "parameter \\REG_OUTPUT_RST \"RST0\"",
    ];
    let register_pins = [
        "connect \\CLK0 \\clk",
        "connect \\CE0 \\ce",
        "connect \\RST0 1'0",
    ];
    // its 36 products on `p36`, which is the unit's output `p` at AW + BW = 36
    let products = (0..36).all(|i| tile.contains(&format!("connect \\P{i} \\p36 [{i}]")));
    Ok(w.len() == 58
        && w == t
        && params == register_params
        && register_pins.iter().all(|r| tile.iter().any(|l| l == r))
        && products)
}

/// Checks the tile's wiring, and shows the mutant's check failing.
fn tile(dir: &Path) -> Result<(), String> {
    let unit_in_dir = format!("{RTL_FROM_WORK_DIR}/mul18.v");
    if !tile_wired(dir, &unit_in_dir, "mul18.log")? {
        return Err(format!(
            "mul18.v's tile is not wired as Yosys maps its written form ({})",
            dir.display()
        ));
    }
    say("mul18.v's tile wired as Yosys maps its written form, its output register on the clock");
    mutant(dir, "mul18.v", TILE_FROM, TILE_TO, "mul18_mutant.v")?;
    if tile_wired(dir, "mul18_mutant.v", "mul18-mutant.log")? {
        return Err("the tile's mutant (its second operand unsigned) passed the wiring check: the check cannot fail".to_string());
    }
    say("mul18.v's mutant (its second operand unsigned) caught by the same check");
    Ok(())
}

/// Every proof, each with its mutant.
pub fn all() -> Result<(), String> {
    let dir = work_dir("prove")?;
    leading_one(&dir)?;
    add_sub(&dir)?;
    tile(&dir)
}
