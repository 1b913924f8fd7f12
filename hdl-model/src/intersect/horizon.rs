//! The horizon filter: the patches an origin's hemisphere cannot see, passed over at a patch a
//! clock ahead of the set-up units.
//!
//! A compact build's set-up unit takes a corner a clock, so every planar patch costs its bank
//! three or four clocks an origin, and on scenes of a thousand patches the set-up is what
//! bounds a hemisphere's clocks. Many of those patches the hemisphere cannot see: on
//! `scenes/cornell-8x8.toml` (R = 16, K = 2) 29 % of the (origin, patch) pairs the set-up
//! found below the horizon and 10 % in the origin's own plane (measured with the set-up's
//! own rules, session 31). The set-up unit spends its four clocks on each of them to learn
//! that.
//!
//! Each bank's filter reads a patch's bounding box a clock and tells, from the box alone,
//! whether the patch is certainly below the horizon; only the others go on, through a FIFO
//! of [`FIFO_SLOTS`] slot numbers, to the set-up unit ([`PassTiming`] counts the clocks).
//!
//! **The test.** With the frame's axis w (Q2.30) and the box [L, H] (Q8.24) relative to the
//! origin, the largest w-height of the box is Q = Σ_c q_c w_c with q_c = H_c − o_c where
//! w_c ≥ 0, else L_c − o_c, and every corner a of the patch has |a|∞ ≤ U = max_c max(|L_c −
//! o_c|, |H_c − o_c|). The filter passes the patch over if
//!
//! ```text
//! Q < −2^-7 · U      (heights in Q8.24 · Q2.30: Q < −2^23 · U)
//! ```
//!
//! so every corner is below the horizon by more than 2^-7 of its largest component. The set-up
//! unit's own test ([`super::cull`], step 2) asks f_z < −|f|∞ 2^-9 of each corner, each widened
//! by its narrow words' error, 2^-12.4 of |a|∞ at most: 2^-7 holds it with room (the test
//! `a_filtered_patch_is_one_the_set_up_finds_below` checks it on random patches and frames).
//! A patch the filter passes over is one the set-up would have found below, so no ray loses a
//! candidate in a sector and no answer changes; the only rays that see fewer patches are those
//! the culling hands every active patch (next to the pole), and those cannot meet a patch below
//! the horizon.
//!
//! **Narrow arithmetic**, as the set-up unit's: q scaled by 2^-k so that U fits 17 bits (one
//! shift for the three, by U's leading zeros), w as Q2.16 (`>> 14`), three 18 × 18 products.
//! With floor truncation Q / 2^(k+14) lies within E = Σ(|q'| + |w'| + 1) of z = Σ q' w', and
//! U / 2^k < U' + 1 for U' = U >> k, so the filter asks z + E ≤ −2^9 (U' + 1).
//!
//! **The box** is kept on patch memory's write path ([`SlotBox`]): writing a slot's header
//! starts it empty, and each corner word written after it widens it (a read-modify-write of
//! the slot's box beside the word's write). The box counts only once all twelve corner words
//! have been written since the header (the driver writes a slot's sixteen words in order), so
//! a box always holds the corners in memory. It is stored in 24-bit words (Q8.16), rounded
//! outward: the low ends down, the high ends up.

use super::patch_mem::PATCH_WORDS;

/// Bits of a box word: a Q8.24 coordinate rounded outward to Q8.16.
pub const BOX_BITS: u32 = 24;

/// Bits dropped from a coordinate for its box word.
const BOX_DROP: u32 = 32 - BOX_BITS;

/// The corner words of a slot (v0.x … v3.z, words 1 to 12), one bit each.
const CORNERS: u16 = 0x0FFF;

/// Set when a high end rounded up past the box word's range: the box bounds nothing.
const UNBOUNDED: u16 = 0x1000;

/// An empty box's ends: the largest low end, the smallest high end of a box word.
const LO_EMPTY: i32 = (1 << (BOX_BITS - 1)) - 1;
const HI_EMPTY: i32 = -(1 << (BOX_BITS - 1));

/// The axis words' shift to Q2.16 (the culling unit's).
const W_SHIFT: u32 = 14;

/// Bits of the largest |q| after the filter's shift (an 18-bit signed product operand).
const Q_BITS: u32 = 17;

/// The filter's margin below the horizon, 2^-MARGIN_SHIFT of the box's reach.
const MARGIN_SHIFT: u32 = 7;

/// Clocks of a slot's box read (`rtl/bank_front.v`): the block RAM's, then a register after it
/// (a block RAM's output comes about 6 ns after its clock on the ECP5, too late for the
/// filter's first adders at 100 MHz; one clock until session 32).
pub const BOX_READ: u64 = 2;

/// The filter's stages (`rtl/horizon_filter.v`: the subtractions; the picks and each axis's
/// larger reach; the largest; its leading zeros and the shifts; the products and the error
/// bound's parts; their sums; the sign).
pub const FILTER_STAGES: u64 = 7;

/// Clocks from a patch's box read to its verdict.
pub const HORIZON_LATENCY: u64 = BOX_READ + FILTER_STAGES;

/// Slot numbers a bank's filter can hold for its set-up unit.
pub const FIFO_SLOTS: usize = 16;

/// A slot's bounding box as the write path keeps it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SlotBox {
    lo: [i32; 3],
    hi: [i32; 3],
    /// the corner words written since the header, and [`UNBOUNDED`]
    written: u16,
}

impl Default for SlotBox {
    fn default() -> Self {
        SlotBox {
            lo: [LO_EMPTY; 3],
            hi: [HI_EMPTY; 3],
            written: 0,
        }
    }
}

impl SlotBox {
    /// The box after word `word` of its slot (0..[`PATCH_WORDS`]) is written with `value`: the
    /// header starts it again, a corner word widens it.
    pub fn write(&mut self, word: usize, value: u32) {
        debug_assert!(word < PATCH_WORDS);
        if word == 0 {
            *self = SlotBox::default();
            return;
        }
        if !(1..=12).contains(&word) {
            return;
        }
        let (c, v) = ((word - 1) % 3, value as i32 as i64);
        let lo = (v >> BOX_DROP) as i32;
        // ⌈v / 2^8⌉, which can be 2^23: one past a 24-bit word (then held at the largest)
        let mut hi = (v + (1 << BOX_DROP) - 1) >> BOX_DROP;
        if hi > LO_EMPTY as i64 {
            self.written |= UNBOUNDED;
            hi = LO_EMPTY as i64;
        }
        self.lo[c] = self.lo[c].min(lo);
        self.hi[c] = self.hi[c].max(hi as i32);
        self.written |= 1 << (word - 1);
    }

    /// The box as its memory holds it: the low and high ends (24-bit words, Q8.16) and the
    /// written bits (corner words 11:0, unbounded 12).
    pub fn words(&self) -> ([i32; 3], [i32; 3], u16) {
        (self.lo, self.hi, self.written)
    }

    /// The box's ends (Q8.24), once every corner word has been written since the header.
    pub fn bounds(&self) -> Option<([i64; 3], [i64; 3])> {
        (self.written == CORNERS).then(|| {
            (
                self.lo.map(|c| (c as i64) << BOX_DROP),
                self.hi.map(|c| (c as i64) << BOX_DROP),
            )
        })
    }
}

/// Whether every point of the box `[lo, hi]` (Q8.24) is below the horizon of the frame with
/// axis `w` (Q2.30) at origin `o` (Q8.24) by more than 2^-7 of its reach (module doc).
pub fn below(lo: [i64; 3], hi: [i64; 3], o: [i64; 3], w: [i32; 3]) -> bool {
    let l: [i64; 3] = core::array::from_fn(|c| lo[c] - o[c]);
    let h: [i64; 3] = core::array::from_fn(|c| hi[c] - o[c]);
    let u = (0..3)
        .map(|c| l[c].abs().max(h[c].abs()))
        .max()
        .unwrap_or(0);
    if u == 0 {
        return false;
    }
    let k = (64 - u.leading_zeros()).saturating_sub(Q_BITS);
    let (mut z, mut e) = (0i64, 0i64);
    for c in 0..3 {
        let q = if w[c] >= 0 { h[c] } else { l[c] } >> k;
        let wc = (w[c] >> W_SHIFT) as i64;
        z += q * wc;
        e += q.abs() + wc.abs() + 1;
    }
    let margin = ((u >> k) + 1) << (30 - MARGIN_SHIFT - W_SHIFT);
    z + e <= -margin
}

/// One bank's set-up pass in clocks, patch by patch in slot order: the filter takes a patch a
/// clock unless its FIFO is full; a patch it keeps waits in the FIFO for the set-up unit,
/// which takes its corners a clock each. Counted as if the filter had no latency: hardware
/// keeps these clocks, each [`HORIZON_LATENCY`] later, by stopping the whole filter while its
/// oldest verdict is a kept patch that finds no room (`rtl/bank_front.v`).
#[derive(Clone, Copy, Debug, Default)]
struct BankTiming {
    /// the clock the filter takes its next patch on
    filter: u64,
    /// the clock the set-up unit is free from
    setup: u64,
    /// the clocks the last [`FIFO_SLOTS`] kept patches left the FIFO (a ring)
    left: [u64; FIFO_SLOTS],
    kept: usize,
}

impl BankTiming {
    fn patch(&mut self, clocks: Option<u64>) -> Option<u64> {
        let Some(clocks) = clocks else {
            self.filter += 1;
            return None;
        };
        let slot = self.kept % FIFO_SLOTS;
        // a kept patch enters the FIFO once the one FIFO_SLOTS before it has left
        let at = if self.kept >= FIFO_SLOTS {
            self.filter.max(self.left[slot])
        } else {
            self.filter
        };
        let start = at.max(self.setup);
        self.left[slot] = start;
        self.setup = start + clocks;
        self.filter = at + 1;
        self.kept += 1;
        Some(start)
    }

    fn clocks(&self) -> u64 {
        self.setup.max(self.filter)
    }
}

/// A set-up pass's clocks over its banks (slot i in bank i mod banks), the filter's latency
/// apart.
#[derive(Clone, Copy, Debug)]
pub struct PassTiming {
    banks: [BankTiming; crate::params::MAX_LANES as usize],
}

impl Default for PassTiming {
    fn default() -> Self {
        PassTiming {
            banks: [BankTiming::default(); crate::params::MAX_LANES as usize],
        }
    }
}

impl PassTiming {
    /// The next patch of bank `bank`: `Some(clocks)` of set-up, or `None` if the filter passes
    /// it over. Returns the clock its set-up begins (its first corner's), counted from the
    /// pass's first box read without the filter's latency (`rtl/bank_front.v` shows it
    /// [`HORIZON_LATENCY`] later).
    pub fn patch(&mut self, bank: usize, clocks: Option<u64>) -> Option<u64> {
        self.banks.get_mut(bank)?.patch(clocks)
    }

    /// The clock bank `bank`'s filter takes its next patch on: its patches so far and the
    /// clocks it stood still, a kept patch waiting for room in the FIFO.
    pub fn filter_clock(&self, bank: usize) -> u64 {
        self.banks.get(bank).map_or(0, |b| b.filter)
    }

    /// Clocks until bank `bank` is done.
    pub fn bank_clocks(&self, bank: usize) -> u64 {
        self.banks.get(bank).map_or(0, BankTiming::clocks)
    }

    /// Clocks until the slowest bank is done.
    pub fn clocks(&self) -> u64 {
        self.banks.iter().map(BankTiming::clocks).max().unwrap_or(0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::format::Unit;
    use crate::intersect::coarse::Coarse;
    use crate::intersect::cull::tests::rotation;
    use crate::intersect::cull::{CullUnit, Wedge};
    use crate::intersect::tests::Rng;

    /// A random frame's axes.
    fn frame(rng: &mut Rng) -> [[f64; 3]; 3] {
        rotation([rng.sym(), rng.sym(), rng.sym(), rng.sym()])
    }

    /// On random frames, origins and patches (triangles and quads from 2^-9 to 2 units, most of
    /// them near the horizon plane, from 2^-3 of their distance above it to 2^-3 below), every
    /// patch the filter passes over is one the set-up unit's reach finds below the horizon.
    #[test]
    fn a_filtered_patch_is_one_the_set_up_finds_below() {
        let unit = CullUnit::new(32);
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let (mut filtered, mut below_only) = (0u32, 0u32);
        for _ in 0..100_000 {
            let ax = frame(&mut rng);
            let axes = ax.map(|r| r.map(Unit::from_num));
            let w = axes[2].map(|c| c.to_bits());
            let o = [rng.sym(), rng.sym(), rng.sym()];
            // the patch's centre: a distance t along the horizon, a height s·t off it
            let t = 2.0f64.powf(-8.0 + 9.0 * (rng.sym() + 1.0) / 2.0);
            let s = rng.sym() / 8.0;
            let along = [rng.sym(), rng.sym(), rng.sym()];
            let c: [f64; 3] = core::array::from_fn(|k| {
                o[k] + t * (along[k] - ax[2][k] * (0..3).map(|j| along[j] * ax[2][j]).sum::<f64>())
                    + s * t * ax[2][k]
            });
            let size = t * 2.0f64.powf(-6.0 + 5.0 * (rng.sym() + 1.0) / 2.0);
            let (p, r) = (
                [rng.sym(), rng.sym(), rng.sym()],
                [rng.sym(), rng.sym(), rng.sym()],
            );
            let corner = |i: usize| -> [f64; 3] {
                let (sp, sr) = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)][i];
                core::array::from_fn(|k| c[k] + size * (sp * p[k] + sr * r[k]))
            };
            let sides = if rng.sym() < -0.3 { 3 } else { 4 };
            let fix = |v: f64| (v * (1u64 << 24) as f64).round() as i32;
            let words: [[i32; 3]; 4] = core::array::from_fn(|i| corner(i.min(sides - 1)).map(fix));
            let (lo, hi) = written(&words).bounds().unwrap();
            let oi = o.map(fix).map(|v| v as i64);
            let a: [[i64; 3]; 4] =
                core::array::from_fn(|i| core::array::from_fn(|k| words[i][k] as i64 - oi[k]));
            let set_up = unit.reach(&a[..sides], &Coarse::default(), &axes).wedge == Wedge::Below;
            if below(lo, hi, oi, w) {
                assert!(set_up, "passed over, not below: a {a:?} w {w:?}");
                filtered += 1;
            } else if set_up {
                below_only += 1;
            }
        }
        // both many passed over and some the margin kept that the set-up finds below
        assert!(
            filtered > 10_000 && below_only > 1_000,
            "{filtered} {below_only}"
        );
    }

    fn written(corners: &[[i32; 3]; 4]) -> SlotBox {
        let mut b = SlotBox::default();
        b.write(0, 2);
        for (i, c) in corners.iter().flatten().enumerate() {
            b.write(1 + i, *c as u32);
        }
        b
    }

    #[test]
    fn the_box_holds_the_corners_written_since_the_header() {
        let corners = [[-300, 5, 1 << 24], [7, -9, 0], [256, 513, -1], [0, 0, 0]];
        let (lo, hi) = written(&corners).bounds().unwrap();
        for v in corners.iter() {
            for c in 0..3 {
                assert!(lo[c] <= v[c] as i64 && v[c] as i64 <= hi[c]);
            }
        }
        // rounded outward to 2^8
        assert_eq!((lo[0], hi[0]), (-512, 256));
        assert_eq!((lo[1], hi[1]), (-256, 768));
        // a corner word missing, or the header written again: no box
        let mut b = SlotBox::default();
        b.write(0, 2);
        (1..12).for_each(|w| b.write(w, 0));
        assert_eq!(b.bounds(), None);
        let mut b = written(&corners);
        b.write(0, 2);
        assert_eq!(b.bounds(), None);
        // a high end past the box word's range bounds nothing
        let mut far = corners;
        far[1][2] = i32::MAX;
        assert_eq!(written(&far).bounds(), None);
    }

    #[test]
    fn a_box_below_the_horizon_by_the_margin_is_passed_over() {
        let one = 1i64 << 24;
        let up = [0, 0, 1 << 30];
        // a floor tile one unit below the origin, looking up: far below
        let (lo, hi) = ([-one, -one, -one], [one, one, -one]);
        assert!(below(lo, hi, [0; 3], up));
        // looking down, or the tile at the origin's height: not
        assert!(!below(lo, hi, [0; 3], [0, 0, -(1 << 30)]));
        assert!(!below([-one, -one, 0], [one, one, 0], [0; 3], up));
        // below by less than 2^-7 of its reach: kept
        let z = -(one >> 8);
        assert!(!below([one, -one, z], [2 * one, one, z], [0; 3], up));
        let z = -(one >> 5);
        assert!(below([one, -one, z], [2 * one, one, z], [0; 3], up));
    }

    #[test]
    fn a_pass_without_filtered_patches_costs_its_corners() {
        let mut t = PassTiming::default();
        for i in 0..10 {
            t.patch(i % 2, Some(if i % 3 == 0 { 3 } else { 4 }));
        }
        // bank 0: slots 0, 2, 4, 6, 8 (3 + 4 + 4 + 3 + 4); bank 1: 1, 3, 5, 7, 9 (4 + 3 + 4 + 4 + 3)
        assert_eq!(t.clocks(), 18);
    }

    #[test]
    fn filtered_patches_cost_the_filter_a_clock_while_the_set_up_works() {
        // four kept quads then sixteen passed over: the filter takes the twenty patches in 20
        // clocks while the set-up works on the four quads for 16, so the pass is 20
        let mut t = PassTiming::default();
        let starts: [Option<u64>; 4] = core::array::from_fn(|_| t.patch(0, Some(4)));
        assert_eq!(starts, [Some(0), Some(4), Some(8), Some(12)]);
        assert!((0..16).all(|_| t.patch(0, None).is_none()));
        assert_eq!(t.clocks(), 20);
        // a full FIFO stops the filter: 40 kept quads then 40 passed over
        let mut t = PassTiming::default();
        for _ in 0..40 {
            t.patch(0, Some(4));
        }
        for _ in 0..40 {
            t.patch(0, None);
        }
        // the 40th kept patch enters the FIFO when the 24th starts (clock 92), so the filter
        // passes the rest over from clock 93 on, done at 133, after the set-up's 160; it stood
        // still 53 clocks
        assert_eq!(t.clocks(), 160);
        assert_eq!(t.filter_clock(0), 133);
    }
}
