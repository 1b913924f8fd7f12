//! Proofs by Yosys's SAT solver, for a unit a proof covers better than any workload: the
//! culling's leading one (`rtl/leading_one.v`), whose patch side takes 66-bit words, proved
//! equal to its specification (`rtl/tb/leading_one_check.v`, the first bit set found by a plain
//! loop) for every word at each range the RTL instantiates it with; then the same proof on a
//! mutant, one of its 16-bit windows a bit short, which must fail, so that a proof that cannot
//! fail is caught.

use super::{rtl_dir, say, work_dir, yosys, RTL_FROM_WORK_DIR};
use std::path::Path;
use std::process::{Command, Stdio};

/// (word width, LO, HI) of each `leading_one` instance: the patch side's two normalisations
/// (`cull_reach.v`'s `cull_angles`: bits 0..65 and 0..37 of 66) and the ray side's
/// (`cull_ray.v`'s: bits 27..34 and 25..31 of 35).
const RANGES: [(u32, u32, u32); 4] = [(66, 0, 65), (66, 0, 37), (35, 27, 34), (35, 25, 31)];

/// The mutant: `w2[i]` without its last `w1`, so a 16-bit window misses bits i+12..i+15.
const MUTANT_FROM: &str = "w1[i] | w1[i + 4] | w1[i + 8] | w1[i + 12]";
const MUTANT_TO: &str = "w1[i] | w1[i + 4] | w1[i + 8]";

/// Whether Yosys proves `leading_one.v` (as `unit`, a path relative to the work dir `dir`)
/// equal to its specification at one range, its log `log` in `dir`. Yosys runs in `dir` on
/// relative paths, as synthesis does ([`RTL_FROM_WORK_DIR`] says why).
fn proved(dir: &Path, unit: &str, (w, lo, hi): (u32, u32, u32), log: &str) -> Result<bool, String> {
    let script = format!(
        "read_verilog {unit} {RTL_FROM_WORK_DIR}/tb/leading_one_check.v; \
         chparam -set W {w} -set LO {lo} -set HI {hi} leading_one_check; \
         hierarchy -top leading_one_check; proc; flatten; opt; \
         sat -verify -prove bad 0 leading_one_check"
    );
    let status = Command::new(yosys())
        .current_dir(dir)
        .args(["-q", "-l", log, "-p", &script])
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .map_err(|e| format!("cannot start {}: {e}", yosys()))?;
    Ok(status.success())
}

/// Proves the leading one at every range, and shows the mutant's proof failing.
pub fn leading_one() -> Result<(), String> {
    let dir = work_dir("prove")?;
    let unit = rtl_dir().join("leading_one.v");
    let unit_in_dir = format!("{RTL_FROM_WORK_DIR}/leading_one.v");
    for r in RANGES {
        let log = format!("leading_one-{}-{}-{}.log", r.0, r.1, r.2);
        if !proved(&dir, &unit_in_dir, r, &log)? {
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
    let text = std::fs::read_to_string(&unit).map_err(|e| format!("{}: {e}", unit.display()))?;
    if !text.contains(MUTANT_FROM) {
        return Err(format!("leading_one.v no longer holds `{MUTANT_FROM}`"));
    }
    let mutant = dir.join("leading_one_mutant.v");
    std::fs::write(&mutant, text.replace(MUTANT_FROM, MUTANT_TO))
        .map_err(|e| format!("{}: {e}", mutant.display()))?;
    if proved(&dir, "leading_one_mutant.v", RANGES[0], "mutant.log")? {
        return Err("the leading one's mutant (a 16-bit window 4 bits short) was proved equal to its specification: the proof cannot fail".to_string());
    }
    say("leading_one.v's mutant (a 16-bit window 4 bits short) caught by the same proof");
    Ok(())
}
