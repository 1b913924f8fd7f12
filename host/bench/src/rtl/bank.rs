//! Vectors for the front of a bank's set-up pass (`hdl-model/rtl/bank_front.v`): the slots'
//! boxes through the horizon filter, the FIFO and the set-up unit's corner reads, clock for
//! clock against the model's [`PassTiming`]. For every pass the model gives each kept patch
//! the clock its set-up begins (the filter counted without its latency); the RTL must read
//! that patch's corners, one a clock, from [`CORNER_CLOCKS`] later, and fall idle
//! [`HORIZON_LATENCY`] clocks after the model's pass ends when no pass follows at once.
//!
//! The same file drives the front joined to its set-up unit (`bank_setup.v`): each planar
//! patch's set-up answer is due [`CULL_SETUP_LATENCY`] after its last corner reaches the unit;
//! and the set-up pass joined to the bank's bitmap writer (`bank_pass.v`): each answer the
//! writer takes on the model's clock for it, [`WRITER_LATENCY`] after its last corner's, then
//! the writer's copies and completions (the writer's lines of [`super::writer`], tagged `W`).
//!
//! File lines (decimal): first `L corner idle answer`, the three latencies; then groups, each
//! `G`, the bank's memories, then its passes. Memories: `B slot boxed clocks lo0 lo1 lo2 hi0
//! hi1 hi2` (a slot's box, whether it counts and its set-up clocks less one), `C address x y z`
//! (a corner; the address is the slot times four plus the corner) and `N slot x y z` (its
//! normal). Passes: `P start count o0 o1 o2` and the frame's nine axis words (u, v, w; the
//! clock a pass begins, from the group's first, over the first `count` slots), each followed
//! by the model's answers: `K clock slot corner last` (a corner read on the model's clock),
//! `S clock n` and the answer as the set-up unit's vectors write it (a planar patch's set-up,
//! on the model's clock for its last corner), and `I clock` (the pass's end, when the bank is
//! idle after it); then the pass as the writer has it (`WP`, `WA`, `WE`, `WC`, `WX`, `WR`: the
//! writer's `P`, `A`, … lines, its clocks the group's, the writer reset with each group; its
//! `L` line once, as `WL`, after the file's). A pass's end reaches the writer on the clock its
//! last slot's set-up would leave the set-up pipe (this bank the pass's only one), and a pass
//! begins only once the last pass into its bitmaps' buffer has them complete.
//!
//! Workloads: bank 0 of two of a scene's slots, one pass from each of K × K lattice points of
//! every planar slot in its frame; random banks of up to 512 slots in clusters of small quads
//! and triangles (and one slot in ten of another kind) with passes from random origins and
//! frames, most back to back, so that the FIFO fills and runs of patches below the horizon
//! follow.

use super::coarse::is_planar;
use super::horizon::slot_box;
use super::reach::{random_axes, scene_frames, Axes};
use super::setup::{random_slot, set_up, write_answer};
use super::writer::{bank_0, Answer, WriterVectors, BANK_SLOTS};
use crate::rng::XorShift;
use hemi_hdl_model::intersect::cull::{CullUnit, Reach};
use hemi_hdl_model::intersect::horizon::{below, PassTiming, HORIZON_LATENCY};
use hemi_hdl_model::intersect::patch_mem::PATCH_WORDS;
use hemi_hdl_model::intersect::{corner_clocks, CORNER_READ, CULL_SETUP_LATENCY};
use hemi_hdl_model::params::Params;
use std::fmt::Write as _;

/// Clocks from the model's clock for a patch's set-up to its corner out of patch memory: the
/// filter's latency, then the corner's read.
pub const CORNER_CLOCKS: u64 = HORIZON_LATENCY + CORNER_READ;

/// Clocks from the model's clock for a patch's last corner to the clock its answer is the
/// bitmap writer's input (`rtl/bank_pass.v`; the model's `at` for it, its set-up latency with
/// the filter's): the corner's read, the set-up unit's answer latency to the edge that
/// registers the answer, and the clock after it, on which the writer takes it.
pub const WRITER_LATENCY: u64 = CORNER_CLOCKS + CULL_SETUP_LATENCY as u64 + 1;

/// What a file holds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    /// Passes.
    pub passes: usize,
    /// Slots filtered (every pass's count).
    pub slots: usize,
    /// Corners read.
    pub corners: usize,
    /// Planar patches set up (`S` lines).
    pub set_up: usize,
    /// Clocks the filter stood still, a kept patch waiting for room in the FIFO.
    pub stalls: u64,
}

/// A slot as the bank holds it: its words, its box words, the box's ends when it counts for
/// the filter (a planar slot's, complete and bounded) and its set-up clocks (a planar slot's
/// corners).
#[derive(Clone, Copy, Debug)]
struct Slot {
    words: [u32; PATCH_WORDS],
    lo: [i32; 3],
    hi: [i32; 3],
    bounds: Option<([i64; 3], [i64; 3])>,
    clocks: u64,
}

impl Slot {
    fn of(words: &[u32; PATCH_WORDS]) -> Slot {
        let b = slot_box(words);
        let (lo, hi, _) = b.words();
        Slot {
            words: *words,
            lo,
            hi,
            bounds: b.bounds().filter(|_| is_planar(words)),
            clocks: corner_clocks(words[0] & 0xF),
        }
    }

    /// Corner `c`'s words (Q8.24; corners past a triangle's third are whatever memory holds).
    fn corner(&self, c: usize) -> [i32; 3] {
        core::array::from_fn(|k| self.words[1 + 3 * c + k] as i32)
    }

    /// Whether the filter passes it over for a pass from `o` with axis `w`.
    fn below(&self, o: [i32; 3], w: [i32; 3]) -> bool {
        self.bounds
            .is_some_and(|(lo, hi)| below(lo, hi, o.map(i64::from), w))
    }
}

/// A pass: its origin, its frame's axes and the slots it sets up.
type Pass = ([i32; 3], Axes, usize);

/// The vectors: the scene's bank 0 (`slots`, passes from `samples` × `samples` points of each
/// planar slot), then `random` random banks of four to eight passes each.
pub fn vectors(
    slots: &[[u32; PATCH_WORDS]],
    samples: u32,
    random: usize,
    seed: u64,
) -> (String, Counts) {
    let mut out = Vectors {
        unit: CullUnit::new(Params::DEFAULT.sectors),
        text: format!("L {CORNER_CLOCKS} {HORIZON_LATENCY} {CULL_SETUP_LATENCY}\n"),
        counts: Counts::default(),
    };
    let mut writer = WriterVectors::new(Params::DEFAULT.sectors, "W");
    out.text.push_str(&writer.take_text());
    let bank: Vec<Slot> = bank_0(slots).into_iter().map(Slot::of).collect();
    if !bank.is_empty() {
        let passes: Vec<Pass> = scene_frames(slots, samples)
            .into_iter()
            .map(|(o, axes)| (o, axes, bank.len()))
            .collect();
        out.group(&bank, &passes, &mut writer, &mut XorShift::new(seed));
    }
    let mut rng = XorShift::new(seed ^ 0x6a09_e667_f3bc_c909);
    for _ in 0..random {
        let bank = random_bank(&mut rng);
        let passes: Vec<Pass> = (0..4 + rng.bits() % 5)
            .map(|_| {
                let count = 1 + (rng.bits() as usize) % bank.len();
                (random_point(&mut rng), random_axes(&mut rng), count)
            })
            .collect();
        out.group(&bank, &passes, &mut writer, &mut rng);
    }
    (out.text, out.counts)
}

/// A point in the cube of side 4 about the scene's origin (Q8.24).
fn random_point(rng: &mut XorShift) -> [i32; 3] {
    [0; 3].map(|_| ((rng.f64() - 0.5) * 4.0 * (1u64 << 24) as f64) as i32)
}

/// A bank of random slots in clusters of 8 to 64 about random points of the cube (so that a
/// pass finds runs of patches below its horizon and runs above, as a scene's walls give it):
/// quads and triangles of the set-up unit's random patches at 2^-8 to 2^-2 of the cube's unit,
/// and one slot in ten of another kind.
fn random_bank(rng: &mut XorShift) -> Vec<Slot> {
    let n = 1 + (rng.bits() as usize) % BANK_SLOTS;
    let mut bank = Vec::with_capacity(n);
    while bank.len() < n {
        let centre = random_point(rng);
        for _ in 0..(8 + rng.bits() % 57).min((n - bank.len()) as u64) {
            let k = small_patch(rng);
            let mut words = random_slot(rng, centre, k);
            if rng.bits().is_multiple_of(10) {
                words[0] = 0;
            }
            bank.push(Slot::of(&words));
        }
    }
    bank
}

/// A random patch's number for [`random_slot`] whose corners lie 2^16 to 2^22 from its
/// centre, its edges 2^12 to 2^20 long (`coarse::random_patch`'s rules), a quad two times in
/// three.
fn small_patch(rng: &mut XorShift) -> usize {
    loop {
        let k = (rng.bits() % 100_000) as usize;
        let (far, size) = (8 + k % 25, 4 + (k / 5) % 28);
        let quad = !k.is_multiple_of(2);
        if (16..=22).contains(&far)
            && (12..=20).contains(&size)
            && quad != rng.bits().is_multiple_of(3)
        {
            return k;
        }
    }
}

/// The file being written ([`super::UnitVectors`]).
type Vectors = super::UnitVectors<Counts>;

impl Vectors {
    /// A group: `bank` written, then `passes`, each begun on the model's clock its bank is
    /// done, or after the bank has fallen idle now and then (and never before the pass two
    /// before it has its answers: the set-up unit's two sets of pass registers; nor before
    /// the last pass into its bitmaps' buffer has them complete). Each pass's answers go to
    /// the bank's bitmap writer (`writer`, reset with the group) on the model's clocks.
    fn group(
        &mut self,
        bank: &[Slot],
        passes: &[Pass],
        writer: &mut WriterVectors,
        rng: &mut XorShift,
    ) {
        self.text.push_str("G\n");
        for (i, s) in bank.iter().enumerate() {
            self.slot(i, s);
        }
        writer.reset();
        let (mut start, mut answered) = (0, [0u64; 2]);
        for (p, (o, axes, count)) in passes.iter().enumerate() {
            let (clocks, last, answers) = self.pass(&bank[..*count], start, *o, axes);
            let end = start + clocks;
            answered[p % 2] = last.map_or(0, |l| l + CORNER_CLOCKS + CULL_SETUP_LATENCY as u64);
            // the pass's end as the model's sequencer gives it to the writer: its last slot's
            // set-up out of the set-up pipe (this bank the pass's only one)
            writer.pass(start, &answers, end + WRITER_LATENCY - 1);
            self.text.push_str(&writer.take_text());
            let gap = if rng.bits().is_multiple_of(3) {
                HORIZON_LATENCY + 1 + rng.bits() % 8
            } else {
                0
            };
            // the next pass takes the tag registers of the pass before this one: it waits for
            // that pass's answers
            let next = writer.begin((end + gap).max(answered[(p + 1) % 2]));
            if next > end + HORIZON_LATENCY || p + 1 == passes.len() {
                let _ = writeln!(self.text, "I {end}");
            }
            start = next;
        }
    }

    /// A slot's memory lines: its box, its corners and its normal.
    fn slot(&mut self, i: usize, s: &Slot) {
        let (lo, hi) = (s.lo, s.hi);
        let t = &mut self.text;
        let _ = write!(t, "B {i} {} {}", s.bounds.is_some() as u8, s.clocks - 1);
        lo.iter().chain(&hi).for_each(|v| {
            let _ = write!(t, " {v}");
        });
        t.push('\n');
        for c in 0..4 {
            let v = s.corner(c);
            let _ = writeln!(t, "C {} {} {} {}", 4 * i + c, v[0], v[1], v[2]);
        }
        let n = &s.words[13..16];
        let _ = writeln!(t, "N {i} {} {} {}", n[0] as i32, n[1] as i32, n[2] as i32);
    }

    /// One pass from `start`: its line, the model's corner reads and set-ups; its clocks, the
    /// model's clock for its last planar patch's last corner, if any, and its answers with the
    /// clocks the writer takes them on.
    fn pass(
        &mut self,
        slots: &[Slot],
        start: u64,
        o: [i32; 3],
        axes: &Axes,
    ) -> (u64, Option<u64>, Vec<Answer>) {
        let _ = write!(
            self.text,
            "P {start} {} {} {} {}",
            slots.len(),
            o[0],
            o[1],
            o[2]
        );
        axes.iter().flatten().for_each(|v| {
            let _ = write!(self.text, " {v}");
        });
        self.text.push('\n');
        let (mut t, mut last, mut answers) = (PassTiming::default(), None, Vec::new());
        for (i, s) in slots.iter().enumerate() {
            let clocks = (!s.below(o, axes[2])).then_some(s.clocks);
            let Some(begin) = t.patch(0, clocks) else {
                continue;
            };
            for c in 0..s.clocks {
                let end = (c + 1 == s.clocks) as u8;
                let _ = writeln!(self.text, "K {} {i} {c} {end}", start + begin + c);
                self.counts.corners += 1;
            }
            if is_planar(&s.words) {
                let at = start + begin + s.clocks - 1;
                if let Some(reach) = self.set_up_line(s, at, o, axes) {
                    answers.push((i, at + WRITER_LATENCY, reach));
                }
                last = Some(at);
            }
        }
        self.counts.passes += 1;
        self.counts.slots += slots.len();
        self.counts.stalls += t.filter_clock(0) - slots.len() as u64;
        (t.bank_clocks(0).max(1), last, answers)
    }

    /// A planar patch's set-up as the model gives it: `S clock n` (the model's clock for its
    /// last corner, its corners) and the answer as the set-up unit's vectors have it. Its
    /// reach, unless the origin is on its plane.
    fn set_up_line(&mut self, s: &Slot, at: u64, o: [i32; 3], axes: &Axes) -> Option<Reach> {
        let sides = s.clocks as usize;
        let _ = write!(self.text, "S {at} {sides}");
        let answer = set_up(&self.unit, &s.words, o, axes);
        write_answer(&mut self.text, sides, answer.as_ref());
        self.text.push('\n');
        self.counts.set_up += 1;
        answer.map(|(_, _, reach)| reach)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_random_banks_fill_the_fifo_and_fall_idle() {
        let (text, c) = vectors(&[], 1, 20, 3);
        let latencies = format!("L {CORNER_CLOCKS} {HORIZON_LATENCY} {CULL_SETUP_LATENCY}");
        assert_eq!(text.lines().next(), Some(latencies.as_str()));
        assert_eq!(latencies, "L 11 9 84");
        assert!(c.passes >= 80 && c.corners > 1000, "{c:?}");
        // the filter stood still: runs of kept quads filled the FIFO
        assert!(c.stalls > 100, "{c:?}");
        let idles = text.lines().filter(|l| l.starts_with("I ")).count();
        assert!(idles > 20 && idles < c.passes, "{idles} {c:?}");
    }

    /// Each pass's writer lines: begun with the pass, an answer for each set-up whose origin
    /// is off the plane, on the model's clock for it, and the pass's end after its answers.
    #[test]
    fn every_answer_reaches_the_writer_on_the_model_s_clock() {
        let (text, c) = vectors(&[], 1, 20, 3);
        let field = |l: &str, k: usize| -> u64 { l.split(' ').nth(k).unwrap().parse().unwrap() };
        let (mut set_ups, mut answers, mut ends) = (Vec::new(), Vec::new(), 0);
        let (mut last_start, mut last_answer) = (None, 0);
        for l in text.lines() {
            match l.split(' ').next() {
                Some("P") => last_start = Some(field(l, 1)),
                Some("WP") => {
                    assert_eq!(Some(field(l, 1)), last_start.take());
                    last_answer = 0;
                }
                // active: the field after the clock and the corner count
                Some("S") if field(l, 3) == 1 => set_ups.push(field(l, 1)),
                Some("WA") => {
                    last_answer = field(l, 1);
                    answers.push(last_answer);
                }
                Some("WE") => {
                    assert!(last_answer <= field(l, 1), "{l}");
                    ends += 1;
                }
                _ => {}
            }
        }
        assert_eq!(ends, c.passes);
        assert!(set_ups.len() > 1000, "{}", set_ups.len());
        let due: Vec<u64> = set_ups.iter().map(|t| t + WRITER_LATENCY).collect();
        assert_eq!(answers, due);
    }
}
