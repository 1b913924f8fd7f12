//! Vectors for the front of a bank's set-up pass (`hdl-model/rtl/bank_front.v`): the slots'
//! boxes through the horizon filter, the FIFO and the set-up unit's corner reads, clock for
//! clock against the model's [`PassTiming`]. For every pass the model gives each kept patch
//! the clock its set-up begins (the filter counted without its latency); the RTL must read
//! that patch's corners, one a clock, from [`CORNER_CLOCKS`] later, and fall idle
//! [`HORIZON_LATENCY`] clocks after the model's pass ends when no pass follows at once.
//!
//! File lines (decimal): first `L corner idle`, the two latencies; then groups, each `G`,
//! the bank's memories, then its passes. Memories: `B slot boxed clocks lo0 lo1 lo2 hi0 hi1
//! hi2` (a slot's box, whether it counts and its set-up clocks less one) and `C address x y z`
//! (a corner; the address is the slot times four plus the corner). Passes: `P start count o0
//! o1 o2 w0 w1 w2` (the clock a pass begins, from the group's first, over the first `count`
//! slots), each followed by the model's answers: `K clock slot corner last` (a corner read on
//! the model's clock) and `I clock` (the pass's end, when the bank is idle after it).
//!
//! Workloads: bank 0 of two of a scene's slots, one pass from each of K × K lattice points of
//! every planar slot in its frame; random banks of up to 512 slots (quads, triangles and other
//! slots, boxes strewn about the origins) with passes from random origins and frames, most
//! back to back, so that the filter keeps long runs of quads and the FIFO fills.

use super::coarse::is_planar;
use super::reach::{random_axes, scene_frames};
use crate::rng::XorShift;
use hemi_hdl_model::intersect::horizon::{below, PassTiming, SlotBox, HORIZON_LATENCY};
use hemi_hdl_model::intersect::patch_mem::{KIND_QUAD, KIND_TRIANGLE, PATCH_WORDS};
use hemi_hdl_model::intersect::{corner_clocks, CORNER_READ};
use std::fmt::Write as _;

/// Clocks from the model's clock for a patch's set-up to its corner out of patch memory: the
/// filter's latency, then the corner's read.
pub const CORNER_CLOCKS: u64 = HORIZON_LATENCY + CORNER_READ;

/// Slots a bank holds in the RTL's default (`bank_front.v`'s SLOT_BITS 9).
const BANK_SLOTS: usize = 512;

/// What a file holds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    /// Passes.
    pub passes: usize,
    /// Slots filtered (every pass's count).
    pub slots: usize,
    /// Corners read.
    pub corners: usize,
    /// Clocks the filter stood still, a kept patch waiting for room in the FIFO.
    pub stalls: u64,
}

/// A slot as the bank front holds it: its box words, whether the box counts, its set-up
/// clocks and its four corners (Q8.24).
#[derive(Clone, Copy, Debug)]
struct Slot {
    lo: [i32; 3],
    hi: [i32; 3],
    boxed: bool,
    clocks: u64,
    corners: [[i32; 3]; 4],
}

impl Slot {
    fn of(words: &[u32; PATCH_WORDS]) -> Slot {
        let mut b = SlotBox::default();
        words.iter().enumerate().for_each(|(k, &v)| b.write(k, v));
        let (lo, hi, _) = b.words();
        Slot {
            lo,
            hi,
            boxed: is_planar(words) && b.bounds().is_some(),
            clocks: corner_clocks(words[0] & 0xF),
            corners: core::array::from_fn(|c| {
                core::array::from_fn(|k| words[1 + 3 * c + k] as i32)
            }),
        }
    }

    /// Whether the filter passes it over for a pass from `o` with axis `w`.
    fn below(&self, o: [i32; 3], w: [i32; 3]) -> bool {
        let q824 = |v: [i32; 3]| v.map(|c| (c as i64) << 8);
        self.boxed && below(q824(self.lo), q824(self.hi), o.map(i64::from), w)
    }
}

/// The vectors: the scene's bank 0 (`slots`, passes from `samples` × `samples` points of each
/// planar slot), then `random` random banks of four to eight passes each.
pub fn vectors(
    slots: &[[u32; PATCH_WORDS]],
    samples: u32,
    random: usize,
    seed: u64,
) -> (String, Counts) {
    let mut out = Vectors::default();
    let _ = writeln!(out.text, "L {CORNER_CLOCKS} {HORIZON_LATENCY}");
    let bank: Vec<Slot> = slots
        .iter()
        .step_by(2)
        .take(BANK_SLOTS)
        .map(Slot::of)
        .collect();
    if !bank.is_empty() {
        let passes: Vec<_> = scene_frames(slots, samples)
            .into_iter()
            .map(|(o, axes)| (o, axes[2], bank.len()))
            .collect();
        out.group(&bank, &passes, &mut XorShift::new(seed));
    }
    let mut rng = XorShift::new(seed ^ 0x6a09_e667_f3bc_c909);
    for _ in 0..random {
        let bank = random_bank(&mut rng);
        let passes: Vec<_> = (0..4 + rng.bits() % 5)
            .map(|_| {
                let count = 1 + (rng.bits() as usize) % bank.len();
                (random_point(&mut rng), random_axes(&mut rng)[2], count)
            })
            .collect();
        out.group(&bank, &passes, &mut rng);
    }
    (out.text, out.counts)
}

/// A point in the cube of side 4 about the scene's origin (Q8.24).
fn random_point(rng: &mut XorShift) -> [i32; 3] {
    [0; 3].map(|_| ((rng.f64() - 0.5) * 4.0 * (1u64 << 24) as f64) as i32)
}

/// A bank of random slots: mostly quads, boxes of up to a quarter about random points of the
/// cube, now and then a box that does not count.
fn random_bank(rng: &mut XorShift) -> Vec<Slot> {
    let n = 1 + (rng.bits() as usize) % BANK_SLOTS;
    (0..n)
        .map(|_| {
            let kind = match rng.bits() % 10 {
                0..=5 => KIND_QUAD,
                6..=8 => KIND_TRIANGLE,
                _ => 0,
            };
            let c = random_point(rng);
            let half = [0; 3].map(|_| (rng.f64() * 0.25 * (1u64 << 16) as f64) as i32);
            Slot {
                lo: core::array::from_fn(|k| (c[k] >> 8) - half[k]),
                hi: core::array::from_fn(|k| (c[k] >> 8) + half[k]),
                boxed: kind != 0 && !rng.bits().is_multiple_of(10),
                clocks: corner_clocks(kind),
                corners: [0; 4].map(|_| [0; 3].map(|_| rng.bits() as i32)),
            }
        })
        .collect()
}

#[derive(Default)]
struct Vectors {
    text: String,
    counts: Counts,
}

impl Vectors {
    /// A group: `bank` written, then `passes` (origin, axis w, count), each begun on the
    /// model's clock its bank is done, or some clocks later now and then.
    fn group(&mut self, bank: &[Slot], passes: &[([i32; 3], [i32; 3], usize)], rng: &mut XorShift) {
        self.text.push_str("G\n");
        for (i, s) in bank.iter().enumerate() {
            let (lo, hi) = (s.lo, s.hi);
            let _ = writeln!(
                self.text,
                "B {i} {} {} {} {} {} {} {} {}",
                s.boxed as u8,
                s.clocks - 1,
                lo[0],
                lo[1],
                lo[2],
                hi[0],
                hi[1],
                hi[2]
            );
            for (c, v) in s.corners.iter().enumerate() {
                let _ = writeln!(self.text, "C {} {} {} {}", 4 * i + c, v[0], v[1], v[2]);
            }
        }
        let mut start = 0;
        for (p, &(o, w, count)) in passes.iter().enumerate() {
            let end = start + self.pass(&bank[..count], start, o, w);
            // the next pass on the clock this one ends, or after the bank has fallen idle
            let gap = if rng.bits().is_multiple_of(3) {
                HORIZON_LATENCY + 1 + rng.bits() % 8
            } else {
                0
            };
            if gap > 0 || p + 1 == passes.len() {
                let _ = writeln!(self.text, "I {end}");
            }
            start = end + gap;
        }
    }

    /// One pass from `start`: its line and the model's corner reads; its clocks.
    fn pass(&mut self, slots: &[Slot], start: u64, o: [i32; 3], w: [i32; 3]) -> u64 {
        let _ = writeln!(
            self.text,
            "P {start} {} {} {} {} {} {} {}",
            slots.len(),
            o[0],
            o[1],
            o[2],
            w[0],
            w[1],
            w[2]
        );
        let mut t = PassTiming::default();
        for (i, s) in slots.iter().enumerate() {
            let clocks = (!s.below(o, w)).then_some(s.clocks);
            let Some(begin) = t.patch(0, clocks) else {
                continue;
            };
            for c in 0..s.clocks {
                let last = (c + 1 == s.clocks) as u8;
                let _ = writeln!(self.text, "K {} {i} {c} {last}", start + begin + c);
                self.counts.corners += 1;
            }
        }
        self.counts.passes += 1;
        self.counts.slots += slots.len();
        self.counts.stalls += t.filter_clock(0) - slots.len() as u64;
        t.bank_clocks(0).max(1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_random_banks_fill_the_fifo_and_fall_idle() {
        let (text, c) = vectors(&[], 1, 20, 3);
        assert_eq!(text.lines().next(), Some("L 9 8"));
        assert!(c.passes >= 80 && c.corners > 1000, "{c:?}");
        // the filter stood still: runs of kept quads filled the FIFO
        assert!(c.stalls > 100, "{c:?}");
        let idles = text.lines().filter(|l| l.starts_with("I ")).count();
        assert!(idles > 20 && idles < c.passes, "{idles} {c:?}");
    }
}
