//! Vectors for a lane's bitmap walk (`hdl-model/rtl/bitmap_walk.v`): the bitmaps of a bank's
//! passes as the model's writer copies them, and rays of every sector and band of each pass with
//! their candidates in slot order, the slots set in both the ray's sector row and band row (the
//! lane's candidates in `intersect::IntersectUnit::lanes`, less the slot the ray skips). They
//! are worked out from the pass's answers by the rule the model builds its candidate bitmaps by
//! (a slot is in the rows of its reach's sectors and bands), not read from those bitmaps.
//!
//! File lines (decimal): first `L rows` (the rows a column's copy writes, the more of the
//! sectors and bands); then, pass by pass, `P buffer` (the pass fills that buffer: its valid
//! bits are cleared), for each column the pass copies `C column` and its rows with a bit set,
//! `X row sector mask band` (the others zero), then its rays, `Y sector band skip n p_1 … p_n`
//! (skip: the place the ray skips, or −1; p: its candidates' places).
//!
//! Workloads: the passes of the bitmap writer's vectors ([`super::writer`]): bank 0 of two of a
//! scene's slots from K × K lattice points of every planar slot in its frame, then random
//! passes (every kind of reach, columns left out, whole banks, passes with nothing to copy).
//! Each pass's rays: every sector and band, each skipping nothing, one of its candidates or a
//! random place; the buffers alternate, so that a column a pass does not copy holds the rows of
//! the pass before the last, which the walk must read as zero.

use super::reach::scene_frames;
use super::writer::{bank_0, column_rows, random_pass, scene_pass, Answer, BANK_SLOTS};
use crate::rng::XorShift;
use hemi_hdl_model::intersect::bitmap_write::{column, copy_clocks};
use hemi_hdl_model::intersect::cull::{CullUnit, Wedge, BANDS};
use hemi_hdl_model::intersect::patch_mem::PATCH_WORDS;
use hemi_hdl_model::params::Params;
use std::fmt::Write as _;

/// What a file holds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    /// Passes.
    pub passes: usize,
    /// Rays.
    pub rays: usize,
    /// Candidates of all the rays.
    pub candidates: usize,
}

/// The vectors: the scene's bank 0 (`slots`, passes from `samples` × `samples` points of each
/// planar slot), then `random` random passes.
pub fn vectors(
    slots: &[[u32; PATCH_WORDS]],
    samples: u32,
    random: usize,
    seed: u64,
) -> (String, Counts) {
    let sectors = Params::DEFAULT.sectors;
    let mut out = WalkVectors {
        sectors,
        text: format!("L {}\n", copy_clocks(sectors)),
        counts: Counts::default(),
        buffer: 0,
        rng: XorShift::new(seed ^ 0x5be0_cd19_137e_2179),
    };
    let bank = bank_0(slots);
    let unit = CullUnit::new(sectors);
    for (o, axes) in scene_frames(slots, samples) {
        let (answers, _) = scene_pass(&unit, &bank, o, &axes, 0);
        out.pass(&answers);
    }
    let mut rng = XorShift::new(seed ^ 0x3c6e_f372_fe94_f82b);
    for _ in 0..random {
        let (answers, _) = random_pass(&mut rng, sectors, 0);
        out.pass(&answers);
    }
    (out.text, out.counts)
}

/// The lines being written.
struct WalkVectors {
    sectors: u32,
    text: String,
    counts: Counts,
    /// the buffer the next pass fills
    buffer: u8,
    rng: XorShift,
}

impl WalkVectors {
    /// One pass's lines: its buffer, its copies (the columns of its answers above the horizon,
    /// as the writer opens them) and its rays.
    fn pass(&mut self, answers: &[Answer]) {
        let _ = writeln!(self.text, "P {}", self.buffer);
        let mut copied: Vec<u32> = Vec::new();
        for a in answers.iter().filter(|a| a.2.wedge != Wedge::Below) {
            if copied.last() != Some(&column(a.0)) {
                copied.push(column(a.0));
            }
        }
        for col in copied {
            let _ = writeln!(self.text, "C {col}");
            for (row, (s, m, b)) in column_rows(answers, col, self.sectors) {
                let _ = writeln!(self.text, "X {row} {s} {m} {b}");
            }
        }
        for sector in 0..self.sectors {
            for band in 0..BANDS {
                self.ray(answers, sector, band);
            }
        }
        self.buffer ^= 1;
        self.counts.passes += 1;
    }

    /// A ray of `sector` and `band`: its candidates, each answer whose sectors hold `sector`
    /// and whose bands hold `band`, in place order, less the place it skips (none, one of them
    /// or any, a third of the rays each).
    fn ray(&mut self, answers: &[Answer], sector: u32, band: u32) {
        let mut found: Vec<usize> = answers
            .iter()
            .filter(|(_, _, r)| {
                r.wedge.sectors(self.sectors).any(|s| s == sector)
                    && (r.band_lo as u32..=r.band_hi as u32).contains(&band)
            })
            .map(|a| a.0)
            .collect();
        let skip = match self.rng.bits() % 3 {
            0 => None,
            1 if !found.is_empty() => Some(found[(self.rng.bits() % found.len() as u64) as usize]),
            _ => Some((self.rng.bits() % BANK_SLOTS as u64) as usize),
        };
        found.retain(|&p| Some(p) != skip);
        let skip = skip.map_or(-1, |p| p as i64);
        let _ = write!(self.text, "Y {sector} {band} {skip} {}", found.len());
        for p in &found {
            let _ = write!(self.text, " {p}");
        }
        self.text.push('\n');
        self.counts.rays += 1;
        self.counts.candidates += found.len();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn random_passes_give_rays_with_and_without_candidates() {
        let (text, counts) = vectors(&[], 2, 20, 7);
        assert_eq!(counts.passes, 20);
        assert_eq!(counts.rays, 20 * 32 * BANDS as usize);
        let empty = text
            .lines()
            .filter(|l| l.starts_with("Y ") && l.ends_with(" 0"))
            .count();
        assert!(
            empty > 0 && empty < counts.rays,
            "{empty} rays without a candidate"
        );
        assert!(counts.candidates > counts.rays, "{counts:?}");
    }
}
