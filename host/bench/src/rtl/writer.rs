//! Vectors for a bank's bitmap writer (`hdl-model/rtl/bitmap_writer.v`), clock for clock against
//! the model's [`ColumnWriter`]: each pass's answers in slot order with the clocks they leave
//! the set-up pipe, its end, and what the model makes of them: the clock each column's copy
//! into the block RAMs begins, the words it copies, and the clock the pass's bitmaps hold every
//! answer.
//!
//! File lines (decimal): first `L sectors copy`; then, pass by pass, `P clock` (the pass
//! begins: the valid bits of its buffer are cleared), `A clock place kind lo len band_lo
//! band_hi` (an answer: kind 0 below the horizon, 1 every sector, 2 sectors lo .. lo + len − 1),
//! `E clock` (the pass's end), each on the clock it leaves the set-up pipe; then the model's
//! copies, each `C clock buffer column` (the clock its first row is at the block RAMs' write
//! port) and its words, `X row sector mask band` for each row with a bit set (the others are
//! zero), and `R clock`, the first clock the pass's bitmaps are complete.
//!
//! Workloads: bank 0 of two of a scene's slots, a pass from each of K × K lattice points of every
//! planar slot in its frame, the answers the set-up unit gives (`set_up`), a corner a clock; and
//! random passes of random reaches (below the horizon, every sector, wedges of every length,
//! band ranges) over random columns, the passes back to back or apart, the answers at their
//! corners' pace or in bursts, so that the writer falls behind, its copies wait for the port
//! and for each other, and passes end with nothing to copy.

use super::reach::{scene_frames, Axes};
use super::setup::set_up;
use crate::rng::XorShift;
use hemi_hdl_model::intersect::bitmap_write::{
    column, copy_clocks, row_writes, ColumnWriter, WRITE_LATENCY,
};
use hemi_hdl_model::intersect::cull::{CullUnit, Reach, Wedge, BANDS};
use hemi_hdl_model::intersect::patch_mem::PATCH_WORDS;
use hemi_hdl_model::intersect::{corner_clocks, CULL_SETUP_LATENCY};
use hemi_hdl_model::params::Params;
use std::collections::BTreeMap;
use std::fmt::Write as _;

/// Slots a bank holds in the RTL's default (SLOT_BITS 9 of `bitmap_writer.v`, `bank_front.v` and
/// `bitmap_walk.v`).
pub(super) const BANK_SLOTS: usize = 512;

/// What a file holds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    /// Passes.
    pub passes: usize,
    /// Answers (below the horizon included).
    pub answers: usize,
    /// Columns copied.
    pub copies: usize,
    /// Passes that ended with nothing to copy.
    pub empty: usize,
}

/// One answer: its slot's place in the bank, the clock it leaves the set-up pipe, its reach.
pub type Answer = (usize, u64, Reach);

/// The lines being written: the model's writer (it lives from pass to pass, as a bank's does).
/// Each line's tag is prefixed with `prefix` (the bank's vectors carry the writer's lines
/// behind their own as `WP`, `WA`, …).
pub struct WriterVectors {
    sectors: u32,
    prefix: &'static str,
    writer: ColumnWriter,
    text: String,
    counts: Counts,
    /// the buffer the next pass fills
    buffer: u8,
    /// the clock each buffer's last pass had its bitmaps complete: a pass fills a buffer again
    /// only after that pass's rays are done, so never before
    ready: [u64; 2],
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
    let mut out = WriterVectors::new(sectors, "");
    let bank = bank_0(slots);
    let unit = CullUnit::new(sectors);
    let mut free = 0;
    for (o, axes) in scene_frames(slots, samples) {
        let start = out.begin(free);
        let (answers, end) = scene_pass(&unit, &bank, o, &axes, start);
        free = out.pass(start, &answers, end);
    }
    let mut rng = XorShift::new(seed ^ 0x3c6e_f372_fe94_f82b);
    for _ in 0..random {
        let gap = if rng.bits().is_multiple_of(3) {
            rng.bits() % 200
        } else {
            0
        };
        let start = out.begin(free + gap);
        let (answers, end) = random_pass(&mut rng, sectors, start);
        free = out.pass(start, &answers, end);
    }
    out.into_parts()
}

/// The scene's bank 0 of two (slot i is at place i / 2 of bank i % 2), as far as a bank of the
/// RTL's default holds.
pub(super) fn bank_0(slots: &[[u32; PATCH_WORDS]]) -> Vec<&[u32; PATCH_WORDS]> {
    slots.iter().step_by(2).take(BANK_SLOTS).collect()
}

/// The answers of a pass from `o` in frame `axes` over `bank`, begun on `start`, and the clock
/// its end leaves the set-up pipe: a planar slot's set-up a corner a clock, its answer out of
/// the set-up pipe after its last corner (a slot whose plane holds the origin answers nothing).
pub(super) fn scene_pass(
    unit: &CullUnit,
    bank: &[&[u32; PATCH_WORDS]],
    o: [i32; 3],
    axes: &Axes,
    start: u64,
) -> (Vec<Answer>, u64) {
    let mut at = start;
    let mut answers = Vec::new();
    for (place, words) in bank.iter().enumerate() {
        at += corner_clocks(words[0] & 0xF);
        if let Some((_, _, reach)) = set_up(unit, words, o, axes) {
            answers.push((place, at + CULL_SETUP_LATENCY as u64, reach));
        }
    }
    (answers, at + CULL_SETUP_LATENCY as u64)
}

/// The kinds of random pass ([`random_pass`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum PassKind {
    /// Most: a run of up to 120 places from a random one (some skipped, so that columns are
    /// left out), reaches of every kind, three or four clocks apart or in bursts of one a clock.
    Run,
    /// One in eight: a column a place, narrow reaches in a burst, so that columns close faster
    /// than they are copied and a column waits for its copy of the distributed RAM.
    ColumnHops,
    /// One in eight: up to three answers, all below the horizon, so that a pass ends with
    /// nothing to copy, often on the clock the pass before it ends when the writer is behind.
    AllBelow,
    /// One in sixty-four: every slot of the bank, a wedge of every sector each, one a clock, so
    /// that hundreds of answers wait in the FIFO (32 row writes each) and the next pass's
    /// answers queue behind them.
    WholeBank,
}

/// A random pass begun on `start`, of a random [`PassKind`]: its answers and its end's clock,
/// which comes with the last answer or up to seven clocks after it (slots passed over).
pub(super) fn random_pass(rng: &mut XorShift, sectors: u32, start: u64) -> (Vec<Answer>, u64) {
    let kind = match (rng.bits() % 64, rng.bits() % 8) {
        (0, _) => PassKind::WholeBank,
        (_, 0) => PassKind::AllBelow,
        (_, 1) => PassKind::ColumnHops,
        _ => PassKind::Run,
    };
    let mut place = match kind {
        PassKind::WholeBank => 0,
        _ => (rng.bits() % BANK_SLOTS as u64) as usize,
    };
    let n = match kind {
        PassKind::AllBelow => rng.bits() % 4,
        PassKind::WholeBank => BANK_SLOTS as u64,
        _ => rng.bits() % 120,
    };
    let burst =
        matches!(kind, PassKind::ColumnHops | PassKind::WholeBank) || rng.bits().is_multiple_of(4);
    let mut at = start + 1 + CULL_SETUP_LATENCY as u64;
    let mut answers = Vec::new();
    for _ in 0..n {
        if place >= BANK_SLOTS {
            break;
        }
        let reach = match kind {
            PassKind::AllBelow => Reach {
                wedge: Wedge::Below,
                ..random_reach(rng, sectors)
            },
            PassKind::ColumnHops => narrow_reach(rng, sectors),
            PassKind::WholeBank => Reach {
                wedge: Wedge::Full,
                ..random_reach(rng, sectors)
            },
            PassKind::Run => random_reach(rng, sectors),
        };
        answers.push((place, at, reach));
        place += match kind {
            PassKind::ColumnHops => 64 - (rng.bits() % 4) as usize,
            PassKind::Run if rng.bits().is_multiple_of(5) => 1 + (rng.bits() % 100) as usize,
            _ => 1,
        };
        at += if burst { 1 } else { 3 + rng.bits() % 2 };
    }
    let last = answers.last().map_or(at, |a| a.1);
    (answers, last + rng.bits() % 8)
}

/// The rows' words a copy of column `col` writes, by row (those with a bit set): every answer
/// of the column sets its bit in its sectors' and bands' words (sector, mask, band) and its
/// bands in its sectors' mask words.
pub(super) fn column_rows(
    answers: &[Answer],
    col: u32,
    sectors: u32,
) -> BTreeMap<u32, (u64, u64, u64)> {
    let mut rows: BTreeMap<u32, (u64, u64, u64)> = BTreeMap::new();
    for (place, _, r) in answers.iter().filter(|a| column(a.0) == col) {
        let bit = 1u64 << (place % 64);
        let bands = (r.band_lo..=r.band_hi).fold(0u64, |m, b| m | 1 << b);
        for s in r.wedge.sectors(sectors) {
            let w = rows.entry(s).or_default();
            w.0 |= bit;
            w.1 |= bands;
        }
        if r.wedge != Wedge::Below {
            for b in r.band_lo..=r.band_hi {
                rows.entry(b as u32).or_default().2 |= bit;
            }
        }
    }
    rows
}

/// A reach of one to three sectors and bands.
fn narrow_reach(rng: &mut XorShift, sectors: u32) -> Reach {
    let lo = (rng.bits() % (BANDS as u64 - 2)) as u8;
    Reach {
        wedge: Wedge::Sectors {
            lo: (rng.bits() % sectors as u64) as u8,
            len: (1 + rng.bits() % 3) as u8,
        },
        band_lo: lo,
        band_hi: lo + (rng.bits() % 3) as u8,
    }
}

/// A random reach: below the horizon one time in five, every sector one in eight, else a wedge
/// of 1 to `sectors` sectors from any sector (so some wrap); bands a random range.
fn random_reach(rng: &mut XorShift, sectors: u32) -> Reach {
    let lo = (rng.bits() % BANDS as u64) as u8;
    let hi = lo + (rng.bits() % (BANDS as u64 - lo as u64)) as u8;
    let wedge = match rng.bits() % 40 {
        0..=7 => Wedge::Below,
        8..=12 => Wedge::Full,
        _ => Wedge::Sectors {
            lo: (rng.bits() % sectors as u64) as u8,
            len: (1 + rng.bits() % sectors as u64) as u8,
        },
    };
    Reach {
        wedge,
        band_lo: lo,
        band_hi: hi,
    }
}

impl WriterVectors {
    /// A writer at `sectors` sectors, its lines' tags prefixed with `prefix`, starting with
    /// its `L` line.
    pub fn new(sectors: u32, prefix: &'static str) -> Self {
        WriterVectors {
            sectors,
            prefix,
            writer: ColumnWriter::default(),
            text: format!("{prefix}L {sectors} {}\n", copy_clocks(sectors)),
            counts: Counts::default(),
            buffer: 0,
            ready: [0; 2],
        }
    }

    /// The writer reset, as the RTL's `rst` resets it: nothing open or queued, the first
    /// pass's buffer 0.
    pub fn reset(&mut self) {
        self.writer = ColumnWriter::default();
        self.buffer = 0;
        self.ready = [0; 2];
    }

    /// The lines written so far, taken (the writer's state stays).
    pub fn take_text(&mut self) -> String {
        core::mem::take(&mut self.text)
    }

    /// The lines and what they hold.
    pub fn into_parts(self) -> (String, Counts) {
        (self.text, self.counts)
    }

    /// The clock a pass may begin on from `free` (the set-up unit free): not before the last
    /// pass that filled its buffer was complete.
    pub fn begin(&self, free: u64) -> u64 {
        free.max(self.ready[self.buffer as usize])
    }

    /// One pass begun on `start` with `answers` (in place order) and its end known on `end`: its
    /// lines and the model's copies and completion. Returns the clock the set-up unit is free
    /// for the next pass (the end less the set-up pipe's latency).
    pub fn pass(&mut self, start: u64, answers: &[Answer], end: u64) -> u64 {
        let copy = copy_clocks(self.sectors);
        let pre = self.prefix;
        let _ = writeln!(self.text, "{pre}P {start}");
        let mut copies = Vec::new();
        let mut open: Option<u32> = None;
        for &(place, at, reach) in answers {
            self.answer_line(place, at, &reach);
            let rows = row_writes(&reach, self.sectors);
            let col = column(place);
            let port = self.writer.port();
            self.writer.answer(col, at, rows, copy);
            if self.writer.port() != port {
                copies.push((
                    self.writer.port() - copy + WRITE_LATENCY,
                    open.unwrap_or(col),
                ));
            }
            if rows > 0 {
                open = Some(col);
            }
        }
        let _ = writeln!(self.text, "{pre}E {end}");
        let port = self.writer.port();
        let ready = self.writer.close(end, copy);
        if self.writer.port() != port {
            copies.push((self.writer.port() - copy + WRITE_LATENCY, open.unwrap_or(0)));
        }
        self.counts.empty += copies.is_empty() as usize;
        for (clock, col) in copies {
            self.copy_lines(clock, col, answers);
        }
        let _ = writeln!(self.text, "{pre}R {ready}");
        self.ready[self.buffer as usize] = ready;
        self.buffer ^= 1;
        self.counts.passes += 1;
        end - CULL_SETUP_LATENCY as u64
    }

    fn answer_line(&mut self, place: usize, at: u64, r: &Reach) {
        let (kind, lo, len) = r.wedge.words();
        let (bl, bh) = (r.band_lo, r.band_hi);
        let _ = writeln!(
            self.text,
            "{}A {at} {place} {kind} {lo} {len} {bl} {bh}",
            self.prefix
        );
        self.counts.answers += 1;
    }

    /// A copy of column `col` on `clock` and its rows' words: every answer of the column sets
    /// its bit in its sectors' and bands' words and its bands in its sectors' mask words.
    fn copy_lines(&mut self, clock: u64, col: u32, answers: &[Answer]) {
        let _ = writeln!(self.text, "{}C {clock} {} {col}", self.prefix, self.buffer);
        for (row, (s, m, b)) in column_rows(answers, col, self.sectors) {
            let _ = writeln!(self.text, "{}X {row} {s} {m} {b}", self.prefix);
        }
        self.counts.copies += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_random_passes_hold_every_kind() {
        let (text, c) = vectors(&[], 1, 300, 5);
        assert_eq!(text.lines().next(), Some("L 32 32"));
        assert_eq!(c.passes, 300);
        assert!(c.copies > 300 && c.empty > 10, "{c:?}");
        let rs = text.lines().filter(|l| l.starts_with("R ")).count();
        assert_eq!(rs, 300);
        // each pass's answers: some a whole bank
        let mut answers = Vec::new();
        for l in text.lines() {
            match l.split(' ').next() {
                Some("P") => answers.push(0),
                Some("A") => *answers.last_mut().unwrap() += 1,
                _ => {}
            }
        }
        assert!(answers.contains(&BANK_SLOTS), "{answers:?}");
    }
}
