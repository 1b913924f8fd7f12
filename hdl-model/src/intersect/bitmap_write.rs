//! The set-up's bitmap writer: how a bank's set-up answers get into the candidate bitmaps the
//! lanes walk ([`super::bitmap_walk`]), and what that costs in clocks.
//!
//! A set-up answer sets its patch's bit in a word of each sector row of its wedge (every sector
//! row for a wedge of every sector) and of each band row of its bands, and ORs its bands into
//! its sectors' mask words. The rows are block RAM, double-buffered in one block RAM deep: one
//! port is the lanes', reading the current buffer, so the writer has one port, and a
//! read-modify-write a word needs two. The writer therefore works a column at a time:
//!
//! - Slots come in order, and the bits of a column of [`BITMAP_WORD`] slots all fall in one word
//!   of each row. The open column's words are gathered in distributed RAM, three small memories
//!   (sector rows, band rows, mask words) read-modify-written a row a clock, side by side, so
//!   an answer takes [`row_writes`] clocks: the more of its sectors and its bands.
//! - When an answer opens the next column, the closed one is copied into the block RAMs a row a
//!   clock, the three at once ([`copy_clocks`]: the more of the sector and band rows), while the
//!   next column gathers in a second copy of the distributed RAM. The writer learns that a
//!   column is complete only from that answer, or from the pass's end, which follows the pass's
//!   last answer down the set-up pipe: no copy begins before either. A column no answer wrote to
//!   is not copied: a valid bit a column, cleared when the pass starts, tells the walk which
//!   columns' words are this pass's (the others read as zero).
//! - Answers wait for the writer in a FIFO of two a slot (at most two passes' answers are in
//!   flight: a pass's buffer is set up again only once its rays are done, after it was ready),
//!   so the set-up unit never waits for the writer.
//!
//! The bitmaps are complete when the pass's last column is copied, and a ray of the pass waits
//! for that as it waits for the set-up pipe's last answer. Charged since session 33 on the
//! compact datapath; before, the model took the writes to be free (docs/PERFORMANCE.md,
//! "Session 33"). `rtl/bitmap_writer.v` is this writer in RTL, co-simulated clock for clock
//! against [`ColumnWriter`] since session 34; it showed the two latencies the model now charges
//! ([`FIFO_LATENCY`], [`WRITE_LATENCY`]). The wide datapath, whose set-up takes a patch a clock
//! a bank while its lanes wait, is still charged nothing for them: no writer of this design
//! keeps up with it.

use super::bitmap_walk::BITMAP_WORD;
use super::cull::{Reach, Wedge, BANDS};

/// Clocks an answer of `reach` holds the writer (its three memories side by side): the more of
/// its sector rows (all `sectors` for a wedge of every sector) and its band rows; 0 for a patch
/// below the horizon, which no culled ray meets and which sets no bit.
pub fn row_writes(reach: &Reach, sectors: u32) -> u64 {
    let sector_rows = match reach.wedge {
        Wedge::Below => return 0,
        Wedge::Full => sectors,
        Wedge::Sectors { len, .. } => len as u32,
    };
    let band_rows = (reach.band_hi as u32 + 1).saturating_sub(reach.band_lo as u32);
    sector_rows.max(band_rows) as u64
}

/// Clocks a column's copy into the block RAMs takes at `sectors` sectors: its sector rows and
/// mask words (one a sector) and its band rows, the three memories side by side.
pub fn copy_clocks(sectors: u32) -> u64 {
    sectors.max(BANDS) as u64
}

/// Clocks from an answer leaving the set-up pipe to the writer taking it at the earliest: its
/// FIFO's block RAM written, read, the read registered, and its rows worked out into the queue
/// ahead of the writer (`rtl/bitmap_writer.v`, whose co-simulation showed them in session 34;
/// the model took them to be none before). A pass's end reaches the writer as late.
pub const FIFO_LATENCY: u64 = 4;

/// Clocks from the writer's decision to copy a row to the row in the block RAMs: the decision
/// is registered, and the distributed RAM's read and the block RAM's write have a clock of
/// their own (`rtl/bitmap_writer.v`).
pub const WRITE_LATENCY: u64 = 1;

/// The column of slot place `place` in its bank.
pub fn column(place: usize) -> u32 {
    place as u32 / BITMAP_WORD
}

/// One bank's writer in clocks, answer by answer in slot order (module doc).
///
/// ```
/// use hemi_hdl_model::intersect::bitmap_write::ColumnWriter;
/// let mut w = ColumnWriter::default();
/// // two answers in column 0 out of the set-up pipe on clocks 10 and 11, of 3 and 2 row
/// // writes: the writer takes the first on 14 (FIFO_LATENCY later) and is done on 19
/// w.answer(0, 10, 3, 32);
/// w.answer(0, 11, 2, 32);
/// // the pass ends on 12 (its last answer's clock), which the writer sees on 16: the column's
/// // copy takes 32 clocks from 19, and its last row is in the block RAMs on 51 + 1
/// assert_eq!(w.close(12, 32), 52);
/// // had the pass ended on 20 (slots passed over after the last answer), from 24
/// # let mut w = ColumnWriter::default();
/// # w.answer(0, 10, 3, 32);
/// # w.answer(0, 11, 2, 32);
/// assert_eq!(w.close(20, 32), 57);
/// ```
#[derive(Clone, Copy, Debug, Default)]
pub struct ColumnWriter {
    /// the clock the writer takes its next answer on
    free: u64,
    /// the clock the block RAMs' write port is free (the last copy's end)
    port: u64,
    /// the clock each distributed-RAM copy of a column is free again (its copy done)
    copy_free: [u64; 2],
    /// the open column and the copy it gathers in
    open: Option<(u32, usize)>,
    /// the copy the next column gathers in
    next: usize,
}

impl ColumnWriter {
    /// An answer for a slot of column `column`, out of the set-up pipe on clock `at`, of `rows`
    /// row writes ([`row_writes`]); `copy` is [`copy_clocks`]. An answer of no row writes
    /// opens no column. The writer sees it [`FIFO_LATENCY`] later.
    pub fn answer(&mut self, column: u32, at: u64, rows: u64, copy: u64) {
        if rows == 0 {
            return;
        }
        let at = at + FIFO_LATENCY;
        if self.open.map(|(c, _)| c) != Some(column) {
            // the open column is known to be complete when this answer comes
            self.copy_open(at, copy);
            let buf = self.next;
            self.next = 1 - buf;
            self.open = Some((column, buf));
            // the copy gathers again once its last column is in the block RAMs
            self.free = self.free.max(self.copy_free[buf]);
        }
        self.free = self.free.max(at) + rows;
    }

    /// The clock the copy engine is free: the last copy's last row decided, a clock before
    /// [`WRITE_LATENCY`] puts it in the block RAMs (the co-simulation's vectors read each copy's
    /// clocks from it).
    pub fn port(&self) -> u64 {
        self.port
    }

    /// Copies the open column, if any, into the block RAMs once its last answer is written, the
    /// port is free and the writer knows the column is complete, on `known` (an answer of a
    /// later column comes, or the pass's end: the set-up pipe's last answer, or the clock it
    /// would have left on). Returns the clock the bitmaps hold every answer so far: the
    /// clock after the writer learns of the end with nothing left to copy, or after the last
    /// copy's last row.
    pub fn close(&mut self, known: u64, copy: u64) -> u64 {
        let known = known + FIFO_LATENCY;
        self.copy_open(known, copy);
        known.max(self.free).max(self.port) + WRITE_LATENCY
    }

    /// The open column's copy, once the writer knows on `known` (its own clock) that the
    /// column is complete.
    fn copy_open(&mut self, known: u64, copy: u64) {
        if let Some((_, buf)) = self.open.take() {
            let start = self.free.max(self.port).max(known);
            self.port = start + copy;
            self.copy_free[buf] = self.port;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_answer_takes_the_more_of_its_sectors_and_bands() {
        let r = |wedge, band_lo, band_hi| Reach {
            wedge,
            band_lo,
            band_hi,
        };
        assert_eq!(row_writes(&r(Wedge::Below, 0, 15), 32), 0);
        assert_eq!(row_writes(&r(Wedge::Full, 3, 4), 32), 32);
        assert_eq!(
            row_writes(&r(Wedge::Sectors { lo: 30, len: 3 }, 2, 7), 32),
            6
        );
        assert_eq!(
            row_writes(&r(Wedge::Sectors { lo: 0, len: 5 }, 9, 9), 32),
            5
        );
        assert_eq!(copy_clocks(8), 16);
        assert_eq!(copy_clocks(64), 64);
    }

    #[test]
    fn answers_queue_behind_the_writer() {
        let mut w = ColumnWriter::default();
        // arriving faster than written: each waits for the one before (the first taken on 4)
        w.answer(0, 0, 5, 32);
        w.answer(0, 1, 5, 32);
        w.answer(0, 2, 5, 32);
        assert_eq!(w.close(2, 32), 4 + 15 + 32 + 1);
    }

    #[test]
    fn a_column_is_copied_when_the_next_opens_and_the_copies_alternate() {
        let mut w = ColumnWriter::default();
        w.answer(0, 0, 2, 32);
        // column 1 opens on clock 100, which the writer sees on 104 and learns that column 0
        // (written by 6) is complete: it is copied 104..136
        w.answer(1, 100, 2, 32);
        assert_eq!(w.port(), 136);
        // column 2 opens on 107 in column 0's copy, free since 136; column 1's copy waits for
        // the port, 136..168
        w.answer(2, 103, 2, 32);
        assert_eq!((w.free, w.port), (138, 168));
        // column 3 goes to column 1's copy, which is free again only on 168
        w.answer(3, 140, 1, 32);
        assert_eq!(w.free, 169);
        // column 2 was copied after column 1 (168..200), column 3 after it, its last row in
        // the block RAMs on 232 + 1
        assert_eq!(w.close(141, 32), 233);
    }

    #[test]
    fn a_pass_of_answers_below_the_horizon_writes_nothing() {
        let mut w = ColumnWriter::default();
        w.answer(0, 7, 0, 32);
        w.answer(1, 9, 0, 32);
        // complete the clock after the writer sees the pass's end
        assert_eq!(w.close(9, 32), 9 + 4 + 1);
        assert_eq!(w.port(), 0);
    }
}
