//! Vectors for the horizon filter (`hdl-model/rtl/horizon_filter.v`) and the slot boxes it
//! reads (`slot_box.v`): the model's [`SlotBox::write`] on a sequence of patch-memory writes,
//! the box after each, and its [`below`] on the boxes, origins and frames of the set-up passes,
//! for the testbench to feed the RTL a write and a box a clock and compare in order; the
//! filter's verdict must leave seven clocks after its box goes in (the model's
//! [`FILTER_STAGES`]; its box read comes before them, `bank.rs`). The RTL writes a box a
//! clock after its write (the model's write path has no clock).
//!
//! File lines (decimal): first `L n`, the clocks from a box into the filter to its verdict
//! ([`FILTER_STAGES`]); then `W word value lo0 lo1 lo2 hi0 hi1 hi2 written` (a write of `value` to
//! word `word` of the slot, then the box as the model holds it: the 24-bit ends and the
//! written bits), `H boxed lo0 lo1 lo2 hi0 hi1 hi2 o0 o1 o2 w0 w1 w2 below` (a box as its
//! memory holds it, whether it counts, the origin (Q8.24), the frame's axis w (Q2.30) and the
//! model's verdict).
//!
//! Workloads: every slot of a scene written word by word, then random writes (any word, any
//! value, high ends past the box word's range); the set-up passes of pass 1 on the scene (every
//! slot's box from K × K lattice points of every planar slot, in that point's frame), random
//! boxes near the horizon in random frames, and random words (ends in any order, any origin
//! and axis, a box on the origin).

use super::coarse::is_planar;
use super::reach::{random_axes, scene_frames};
use crate::rng::XorShift;
use hemi_hdl_model::intersect::horizon::{below, SlotBox, FILTER_STAGES};
use hemi_hdl_model::intersect::patch_mem::PATCH_WORDS;
use std::fmt::Write as _;

/// What a file holds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    /// `W` lines.
    pub writes: usize,
    /// `H` lines.
    pub boxes: usize,
    /// Of them, below the horizon.
    pub below: usize,
}

/// The vectors: `slots` written, then `random` random writes (now and then a whole slot); the set-up passes
/// over `slots` from K × K (`samples`) points of each planar slot, then `random` random boxes.
pub fn vectors(
    slots: &[[u32; PATCH_WORDS]],
    samples: u32,
    random: usize,
    seed: u64,
) -> (String, Counts) {
    let mut out = Vectors::default();
    let _ = writeln!(out.text, "L {FILTER_STAGES}");
    let mut rng = XorShift::new(seed ^ 0xd1b5_4a32_d192_ed03);
    let mut b = SlotBox::default();
    for slot in slots {
        for (word, &value) in slot.iter().enumerate() {
            out.write(&mut b, word, value);
        }
    }
    let mut n = 0;
    while n < random {
        // a whole slot in order now and then (a box that counts), else one word anywhere
        let words = if rng.bits().is_multiple_of(8) {
            0..PATCH_WORDS
        } else {
            let w = (rng.bits() % PATCH_WORDS as u64) as usize;
            w..w + 1
        };
        for word in words {
            let value = match rng.bits() % 16 {
                0 => (0x7fff_ff00 + rng.bits() % 256) as u32,
                1..=7 => ((rng.bits() as i32) >> (rng.bits() % 32)) as u32,
                _ => rng.bits() as u32,
            };
            out.write(&mut b, word, value);
            n += 1;
        }
    }
    for (o, axes) in scene_frames(slots, samples) {
        for s in slots {
            out.filter(&slot_box(s), is_planar(s), o, axes[2]);
        }
    }
    for n in 0..random {
        match n % 3 {
            0 | 1 => out.near_horizon(&mut rng),
            _ => out.random_words(&mut rng, n),
        }
    }
    (out.text, out.counts)
}

/// The box the write path keeps for a slot written whole, word by word in order.
pub(super) fn slot_box(words: &[u32; PATCH_WORDS]) -> SlotBox {
    let mut b = SlotBox::default();
    words.iter().enumerate().for_each(|(k, &v)| b.write(k, v));
    b
}

#[derive(Default)]
struct Vectors {
    text: String,
    counts: Counts,
}

impl Vectors {
    fn write(&mut self, b: &mut SlotBox, word: usize, value: u32) {
        b.write(word, value);
        let (lo, hi, written) = b.words();
        let _ = writeln!(
            self.text,
            "W {word} {value} {} {} {} {} {} {} {written}",
            lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]
        );
        self.counts.writes += 1;
    }

    /// The filter's verdict on box `b` of a slot (planar or not) from origin `o` in a frame
    /// with axis `w`, as the set-up pass asks it.
    fn filter(&mut self, b: &SlotBox, planar: bool, o: [i32; 3], w: [i32; 3]) {
        let (lo, hi, _) = b.words();
        let boxed = planar && b.bounds().is_some();
        self.line(boxed, lo, hi, o, w);
    }

    fn line(&mut self, boxed: bool, lo: [i32; 3], hi: [i32; 3], o: [i32; 3], w: [i32; 3]) {
        let q824 = |v: [i32; 3]| v.map(|c| (c as i64) << 8);
        let is_below = boxed && below(q824(lo), q824(hi), o.map(i64::from), w);
        let _ = writeln!(
            self.text,
            "H {} {} {} {} {} {} {} {} {} {} {} {} {} {}",
            boxed as u8,
            lo[0],
            lo[1],
            lo[2],
            hi[0],
            hi[1],
            hi[2],
            o[0],
            o[1],
            o[2],
            w[0],
            w[1],
            w[2],
            is_below as u8
        );
        self.counts.boxes += 1;
        self.counts.below += is_below as usize;
    }

    /// A patch-sized box a distance t from the origin along the horizon and s·t off it (s
    /// within ±1/8), in a random frame: the filter's margin is where these fall.
    fn near_horizon(&mut self, rng: &mut XorShift) {
        let w = random_axes(rng)[2];
        let wf = w.map(|c| c as f64 / (1u64 << 30) as f64);
        let o = [0; 3].map(|_| ((rng.f64() - 0.5) * 2.0 * (1u64 << 24) as f64) as i32);
        let t = 2f64.powf(-8.0 + 9.0 * rng.f64()) * (1u64 << 24) as f64;
        let s = (rng.f64() - 0.5) / 4.0;
        let along = [0; 3].map(|_| rng.f64() - 0.5);
        let dot = (0..3).map(|c| along[c] * wf[c]).sum::<f64>();
        let size = t * 2f64.powf(-6.0 + 5.0 * rng.f64());
        let centre: [f64; 3] =
            core::array::from_fn(|c| o[c] as f64 + t * (along[c] - dot * wf[c]) + s * t * wf[c]);
        let half = [0; 3].map(|_| rng.f64() * size);
        let word = |v: f64| (v / 256.0).clamp(-(1 << 23) as f64, ((1 << 23) - 1) as f64) as i32;
        let lo = core::array::from_fn(|c| word((centre[c] - half[c]).floor()));
        let hi = core::array::from_fn(|c| word((centre[c] + half[c]).ceil()));
        self.line(true, lo, hi, o, w);
    }

    /// Words of any size: ends in any order (a box need not be one), any origin and axis, and
    /// every so often a box on the origin or an axis of zero.
    fn random_words(&mut self, rng: &mut XorShift, n: usize) {
        let signed = |rng: &mut XorShift, bits: u64| {
            let b = 1 + rng.bits() % bits;
            ((rng.bits() as i64) >> (64 - b)) as i32
        };
        let lo = [0; 3].map(|_| signed(rng, 24));
        let hi = [0; 3].map(|_| signed(rng, 24));
        let mut o = [0; 3].map(|_| signed(rng, 32));
        let mut w = [0; 3].map(|_| signed(rng, 32));
        if n % 9 == 2 {
            o = lo.map(|c| c << 8);
        }
        if n % 11 == 2 {
            w = [0; 3];
        }
        self.line(!rng.bits().is_multiple_of(8), lo, hi, o, w);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_workload_holds_both_verdicts_and_every_kind_of_write() {
        let (text, c) = vectors(&[], 1, 3_000, 1);
        assert_eq!(text.lines().count(), 1 + c.writes + c.boxes);
        assert_eq!(text.lines().next(), Some("L 7"));
        assert!(c.below > 200 && c.below < c.boxes - 200, "{c:?}");
        // boxes complete, and a high end past the word's range, among the writes
        assert!(text
            .lines()
            .any(|l| l.starts_with('W') && l.ends_with(" 4095")));
        assert!(text
            .lines()
            .any(|l| l.starts_with('W') && l.ends_with(" 8191")));
    }
}
