//! The lanes' walk over their candidate bitmaps, word by word, and what it costs in clocks.
//!
//! A lane finds a ray's candidates in its bank as the slots set in both the ray's sector row
//! and its polar band row. Rows of a whole bank (512 bits) read in one clock need a block RAM
//! for every 36 bits of width whatever their depth: 15 a bitmap, 240 in the default build.
//! Here the rows are stored as [`BITMAP_WORD`]-bit words (a bitmap two block RAMs), and each
//! sector row has a *mask row* beside it: for each of its words, the bands its slots reach
//! ([`BANDS`] bits a word; the set-up writes it with the sector row's bits, the same writes).
//! The walk reads the ray's sector's mask row once, then, one word a clock, the sector word
//! and the band word of each word whose mask holds the ray's band, and queues their AND ahead
//! of the lane's edge test, which takes the queued slots one a clock. A word's mask holds the
//! ray's band exactly when some slot of the word is in both rows, so every word read holds a
//! candidate (or only the ray's own patch, which the lane skips): a lane is busy for a ray as
//! long as the longer of its candidates and its words read, and the words are almost never
//! the longer. [`WordWalk`] counts the words read, bank by bank, from the sector list the ray
//! walks (in slot order).
//!
//! Not charged, in clocks or in the area proxy: the set-up's writes (a patch sets its bit in a
//! word of each of its sector and band rows and ORs its bands into its sectors' mask words,
//! read-modify-writes as the rows' bits were before words), and the two reads (mask row, then
//! the first word pair) before a ray's first candidate, which overlap the previous ray's
//! candidates in a lane that has any.

use crate::intersect::cull::BANDS;
use crate::params::MAX_LANES;

/// Bits of a bitmap word: two block RAMs wide (512 × 36 each), so that a bank's 32 sector rows
/// of 512 slots, double-buffered, are one block RAM deep.
pub const BITMAP_WORD: u32 = 64;

/// Bits of a mask row for rows of `bank_slots` slots: [`BANDS`] bits for each word.
pub fn mask_row_bits(bank_slots: u32) -> u32 {
    bank_slots.div_ceil(BITMAP_WORD) * BANDS
}

/// One ray's walk: for each bank the word it is in and whether that word holds a slot in the
/// ray's band so far, and the words read.
#[derive(Clone, Copy, Debug)]
pub struct WordWalk {
    open: [Option<(usize, bool)>; MAX_LANES as usize],
    /// Words each bank's lane reads, once [`WordWalk::finish`]ed.
    pub read: [u64; MAX_LANES as usize],
    banks: usize,
}

impl WordWalk {
    /// A walk over `banks` banks.
    pub fn new(banks: u32) -> Self {
        WordWalk {
            open: [None; MAX_LANES as usize],
            read: [0; MAX_LANES as usize],
            banks: banks.max(1) as usize,
        }
    }

    /// The next slot `i` of the ray's sector row (in slot order), in the ray's band or not.
    pub fn see(&mut self, i: u16, in_band: bool) {
        let bank = i as usize % self.banks;
        let word = (i as usize / self.banks) / BITMAP_WORD as usize;
        debug_assert!(
            self.open[bank].is_none_or(|(open, _)| open <= word),
            "a sector list out of slot order"
        );
        match self.open[bank] {
            Some((open, held)) if open == word => self.open[bank] = Some((word, held | in_band)),
            previous => {
                self.close(bank, previous);
                self.open[bank] = Some((word, in_band));
            }
        }
    }

    /// Closes every bank's last word.
    pub fn finish(&mut self) {
        for bank in 0..self.open.len() {
            let last = self.open[bank].take();
            self.close(bank, last);
        }
    }

    /// The clocks bank `bank`'s lane is busy with the ray that handed it `candidates`.
    pub fn clocks(&self, bank: usize, candidates: u64) -> u64 {
        candidates.max(self.read[bank])
    }

    /// A word is read when its mask holds the ray's band: when one of its slots is in it.
    fn close(&mut self, bank: usize, word: Option<(usize, bool)>) {
        if let Some((_, true)) = word {
            self.read[bank] += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_lane_reads_the_words_that_hold_a_slot_in_the_band() {
        // two banks of 256 slots: slot i is in bank i % 2, word (i / 2) / 64
        let mut walk = WordWalk::new(2);
        // bank 0, word 0: slots 0 (in band) and 2 (not): read
        walk.see(0, true);
        walk.see(2, false);
        // bank 0, word 1 (slot 128): none in band, skipped by the mask
        walk.see(128, false);
        // bank 1, word 1 (slots 129, 131), word 2 (slot 257): all in band
        walk.see(129, true);
        walk.see(131, true);
        walk.see(257, true);
        walk.finish();
        assert_eq!(walk.read[..2], [1, 2]);
        // a lane is busy for the longer of its candidates and its words
        assert_eq!((walk.clocks(0, 1), walk.clocks(1, 3)), (1, 3));
        // a word whose only slot in band is the ray's own patch (no candidate) is a clock
        assert_eq!(walk.clocks(0, 0), 1);
        assert_eq!(mask_row_bits(512), 8 * 16);
    }
}
