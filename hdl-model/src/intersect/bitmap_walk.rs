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
//! the longer. [`WordWalk`] counts the words read, bank by bank, from the ray's candidates (the
//! slots in both its rows, in slot order).
//!
//! The set-up's writes into the rows are [`super::bitmap_write`]'s, charged since session 33
//! (a column of a pass not written reads as zero there, by its valid bit). Not charged: the two
//! reads (mask row, then the first word pair) before a ray's first candidate, which overlap the
//! previous ray's candidates in a lane that has any.

use crate::intersect::cull::BANDS;
use crate::params::MAX_LANES;

/// Bits of a bitmap word: two block RAMs wide (512 × 36 each), so that a bank's 32 sector rows
/// of 512 slots, double-buffered, are one block RAM deep.
pub const BITMAP_WORD: u32 = 64;

/// Words of a row of `bank_slots` slots.
pub fn row_words(bank_slots: u32) -> u32 {
    bank_slots.div_ceil(BITMAP_WORD)
}

/// Bits of a mask row for rows of `bank_slots` slots: [`BANDS`] bits for each word.
pub fn mask_row_bits(bank_slots: u32) -> u32 {
    row_words(bank_slots) * BANDS
}

/// No word open in a bank yet.
const NONE: u32 = u32::MAX;

/// One ray's walk: the words each bank's lane reads, counted from the ray's candidates, the
/// slots in both its sector row and its band row (a word is read when one of its slots is in
/// both, which is what its mask says), in slot order. Small and cleared per ray: the model walks
/// every culled ray through it.
#[derive(Clone, Copy, Debug)]
pub struct WordWalk {
    /// the last word read in each bank
    open: [u32; MAX_LANES as usize],
    read: [u32; MAX_LANES as usize],
}

impl Default for WordWalk {
    fn default() -> Self {
        WordWalk {
            open: [NONE; MAX_LANES as usize],
            read: [0; MAX_LANES as usize],
        }
    }
}

impl WordWalk {
    /// The next slot in the ray's band (in slot order), at `place` of bank `bank` (slot i is
    /// at place i / banks of bank i % banks).
    pub fn see(&mut self, bank: usize, place: usize) {
        let word = place as u32 / BITMAP_WORD;
        let (Some(open), Some(read)) = (self.open.get_mut(bank), self.read.get_mut(bank)) else {
            return;
        };
        debug_assert!(
            *open == NONE || *open <= word,
            "candidates out of slot order"
        );
        if *open != word {
            *open = word;
            *read += 1;
        }
    }

    /// The clocks bank `bank`'s lane is busy with the ray that handed it `candidates`.
    pub fn clocks(&self, bank: usize, candidates: u64) -> u64 {
        let read = self.read.get(bank).copied().unwrap_or(0);
        candidates.max(read as u64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_lane_reads_the_words_that_hold_a_slot_in_the_band() {
        // two banks of 256 slots: slot i is at place i / 2 of bank i % 2, word (i / 2) / 64;
        // the slots seen are those in the ray's band
        let mut walk = WordWalk::default();
        for i in [0usize, 2, 129, 131, 257] {
            walk.see(i % 2, i / 2);
        }
        // bank 0: word 0 (slots 0, 2); bank 1: word 1 (129, 131) and word 2 (257)
        assert_eq!(walk.read[..2], [1, 2]);
        // a lane is busy for the longer of its candidates and its words
        assert_eq!((walk.clocks(0, 1), walk.clocks(1, 3)), (1, 3));
        // a word whose only slot in band is the ray's own patch (no candidate) is a clock
        assert_eq!(walk.clocks(0, 0), 1);
        assert_eq!(mask_row_bits(512), 8 * 16);
    }
}
