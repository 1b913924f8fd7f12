//! The smallest build on an iCE40, which issue 20 asks for "if it fits": the units of
//! `Params::SINGLE` (one lane of 256 slots on the wide datapath, no culling, a ray a clock) that
//! have RTL, at the narrowest CORDIC the model runs (12 iterations on 16 bits) and the
//! shallowest (u,v) depth (8). Each is synthesised with `synth_ice40` and set against the
//! iCE40HX8K, the largest iCE40 nextpnr-ice40 places (7,680 logic cells, 32 4-kbit block RAMs,
//! no DSP tiles, so every product is logic); those that fit on their own are placed and routed
//! with Debian's nextpnr-ice40 for their clock. The build fits only if the units' sum does.

use super::{fmax, plane_design, regs_design_slots, rotator_design, say, stat, used, work_dir};
use super::{frame_design, yosys_synth, Cordic, Design, NETLIST};
use crate::util::{run, which};
use std::path::Path;
use std::process::Command;

/// The iCE40HX8K's logic cells (a LUT4 with its carry and flip-flop) and block RAMs.
const HX8K_CELLS: u64 = 7_680;
const HX8K_RAMS: u64 = 32;

/// What a netlist asks of an iCE40.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Ice40Cells {
    pub lut4: u64,
    /// Flip-flops of every kind (SB_DFF, SB_DFFE, SB_DFFSR, …).
    pub ff: u64,
    pub rams: u64,
}

impl Ice40Cells {
    /// The logic cells it needs at least: a cell holds one LUT4 and one flip-flop.
    pub fn cells(&self) -> u64 {
        self.lut4.max(self.ff)
    }

    fn fits_hx8k(&self) -> bool {
        self.cells() <= HX8K_CELLS && self.rams <= HX8K_RAMS
    }
}

/// The smallest build's units that have RTL.
pub fn smallest() -> [Design; 4] {
    let cordic = Cordic {
        iterations: 12,
        width: 16,
    };
    [
        rotator_design(cordic),
        frame_design(cordic),
        plane_design(8),
        regs_design_slots(8),
    ]
}

/// The cells of the last `stat` in a Yosys log of `synth_ice40` (the flip-flops of every kind
/// added up; the LUT4s and RAMs as [`stat`] reads any cell).
pub fn ice40_cells(log: &str) -> Ice40Cells {
    let last = log.rfind("Number of cells:").map_or(log, |k| &log[k..]);
    let ff = last
        .lines()
        .filter_map(|l| {
            let mut w = l.split_whitespace();
            w.next()?.starts_with("SB_DFF").then_some(())?;
            w.next()?.parse::<u64>().ok()
        })
        .sum();
    Ice40Cells {
        lut4: stat(log, "SB_LUT4"),
        ff,
        rams: stat(log, "SB_RAM40_4K"),
    }
}

/// Synthesises the smallest build's units for an iCE40, places those that fit an HX8K alone and
/// says whether the build as a whole fits.
pub fn report() -> Result<(), String> {
    let mut total = Ice40Cells::default();
    for d in smallest() {
        let dir = work_dir(&format!("ice40-{}", d.name))?;
        let json = dir.join(NETLIST);
        // everything but the `check` step, whose `autoname` ran for over ten minutes on the
        // planar unit's 370,000 LUTs (Yosys 0.23) and which a netlist for nextpnr can do without
        let synth = format!(
            "synth_ice40 -top {} -run :check; write_json {NETLIST}",
            d.top
        );
        let log = yosys_synth(&d, &synth, &dir)?;
        let c = ice40_cells(&log);
        total.lut4 += c.lut4;
        total.ff += c.ff;
        total.rams += c.rams;
        let on_its_own = match c.fits_hx8k() {
            true => place(&dir, &json)?,
            false => "does not fit an iCE40HX8K on its own: not placed".to_string(),
        };
        say(format!(
            "{} for iCE40: {} SB_LUT4, {} flip-flops, {} SB_RAM40_4K; {on_its_own}",
            d.name, c.lut4, c.ff, c.rams
        ));
    }
    let verdict = match total.fits_hx8k() {
        true => "fits",
        false => "does not fit",
    };
    say(format!(
        "the smallest build's units together: {} logic cells at least ({} SB_LUT4, {} \
         flip-flops) and {} block RAMs: it {verdict} an iCE40HX8K ({HX8K_CELLS} cells, \
         {HX8K_RAMS} block RAMs)",
        total.cells(),
        total.lut4,
        total.ff,
        total.rams
    ));
    Ok(())
}

/// nextpnr-ice40 of a netlist on the HX8K (CT256 package), aiming at 50 MHz: what it says.
fn place(dir: &Path, json: &Path) -> Result<String, String> {
    let log = dir.join("nextpnr.log");
    let mut p = Command::new("nextpnr-ice40");
    p.args(["--hx8k", "--package", "ct256", "--json"])
        .arg(json)
        .args(["--freq", "50", "--seed", "1", "--timing-allow-fail", "-l"])
        .arg(&log);
    run(p)?;
    let text = std::fs::read_to_string(&log).map_err(|e| e.to_string())?;
    let f = fmax(&text).ok_or("nextpnr-ice40 reported no Fmax")?;
    Ok(format!(
        "placed on an iCE40HX8K: {} logic cells, Fmax {f:.1} MHz",
        used(&text, "ICESTORM_LC")
    ))
}

/// Installs nextpnr-ice40 from Debian when it is missing (Debian builds it; PyPI's yowasp build
/// would do as well).
pub fn tools() -> Result<(), String> {
    if which("nextpnr-ice40").is_none() {
        say("nextpnr-ice40: missing, installing from Debian (apt)");
        crate::setup::apt_install("nextpnr-ice40")?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_last_stat_counts_every_kind_of_flip_flop() {
        let log = "Number of cells: 9\n  SB_LUT4 1\n\
                   Number of cells: 20\n     SB_CARRY   4\n     SB_DFF    5\n     SB_DFFESR  2\n\
                   \x20    SB_LUT4   7\n     SB_RAM40_4K  3\n";
        let c = ice40_cells(log);
        assert_eq!((c.lut4, c.ff, c.rams, c.cells()), (7, 7, 3, 7));
        assert!(c.fits_hx8k());
        let big = Ice40Cells { rams: 88, ..c };
        assert!(!big.fits_hx8k());
    }
}
