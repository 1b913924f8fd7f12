//! The corners' angles the culling set-up has already vectored, kept for the simulation's speed.
//!
//! The set-up unit vectors every corner of every patch it sets up (twice: the azimuth φ and the
//! polar angle θ, [`super::cull`]), and on a subdivided wall most corners are shared by four
//! patches, so it vectors each of them four times. The hardware pays a clock a corner either
//! way; the model's host does not have to pay the vectorings again. A corner's angles are a pure
//! function of its frame coordinates f (the vectoring's configuration is fixed), so this cache
//! keyed by f cannot change an answer or a clock: it only saves host time (a quarter of the
//! model's time on `scenes/cornell-8x8.toml` went to the vectorings before it).
//!
//! Direct-mapped: on hosts [`AngleMemo::SLOTS`] entries for the corners and
//! [`AngleMemo::RAY_ENTRIES`] for a hemisphere's reference directions; without an allocator
//! (the firmware) a memo of one entry, which costs nothing and rarely hits. `CullUnit::reach`
//! and `ray_bin` alone use a memo of none, which allocates nothing.
//!
//! ```
//! use hemi_hdl_model::intersect::angle_memo::AngleMemo;
//!
//! let mut memo = AngleMemo::new();
//! let mut vectored = 0;
//! for _ in 0..2 {
//!     let angles = memo.angles([3, 4, 5], |_| {
//!         vectored += 1;
//!         (7, 11)
//!     });
//!     assert_eq!(angles, (7, 11));
//! }
//! // the second look-up found the first one's answer
//! assert_eq!(vectored, 1);
//! ```

use crate::table::Table;

/// One remembered corner: its frame coordinates and its (φ, θ) in Q3.29 bits.
#[derive(Clone, Copy, Debug, Default)]
struct Entry {
    f: [i64; 3],
    angles: (i64, i64),
    used: bool,
}

/// The culling set-up's remembered corner angles (module doc).
#[derive(Clone, Debug)]
pub struct AngleMemo {
    entries: Table<Entry, 1>,
}

impl Default for AngleMemo {
    fn default() -> Self {
        Self::new()
    }
}

impl AngleMemo {
    /// Entries on hosts: a power of two, more than the distinct corners of a pass over a few
    /// thousand patches (each pass overwrites the one before).
    pub const SLOTS: usize = 4096;

    /// An empty memo ([`AngleMemo::SLOTS`] entries, or one without an allocator).
    pub fn new() -> Self {
        Self::with_slots(Self::SLOTS)
    }

    /// Entries for a hemisphere's reference directions on hosts: more than the 10,300 rays of
    /// the host's default hemisphere (R = 64, `--circles 64`), which thrashed a memo of
    /// [`AngleMemo::SLOTS`].
    pub const RAY_ENTRIES: usize = 1 << 15;

    /// An empty memo for rays' angles ([`AngleMemo::RAY_ENTRIES`] entries, or one without an
    /// allocator).
    pub fn for_rays() -> Self {
        Self::with_slots(Self::RAY_ENTRIES)
    }

    /// A memo of no entries, which remembers nothing (for a single patch's reach or ray's bin;
    /// an empty table allocates nothing).
    pub(crate) fn none() -> Self {
        Self::with_slots(0)
    }

    /// A memo of `slots` entries (a power of two; one without an allocator).
    fn with_slots(slots: usize) -> Self {
        AngleMemo {
            entries: Table::new(Entry::default(), slots),
        }
    }

    /// The angles of the corner at frame coordinates `f`: remembered, or `vector(f)`, which
    /// must be a function of `f` alone.
    pub fn angles(
        &mut self,
        f: [i64; 3],
        vector: impl FnOnce([i64; 3]) -> (i64, i64),
    ) -> (i64, i64) {
        let slot = self.slot(f);
        let Some(e) = self.entries.get_mut(slot) else {
            return vector(f);
        };
        if !(e.used && e.f == f) {
            *e = Entry {
                f,
                angles: vector(f),
                used: true,
            };
        }
        e.angles
    }

    /// The entry `f` maps to: the top bits of a multiplicative hash of its three words.
    fn slot(&self, f: [i64; 3]) -> usize {
        if self.entries.len() <= 1 {
            return 0;
        }
        let h = f
            .iter()
            .zip([
                0x9e37_79b9_7f4a_7c15u64,
                0xc2b2_ae3d_27d4_eb4f,
                0x1656_67b1_9e37_79f9,
            ])
            .fold(0u64, |h, (&c, k)| (h ^ c as u64).wrapping_mul(k));
        let bits = self.entries.len().trailing_zeros();
        (h >> (64 - bits)) as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_corner_that_shares_a_slot_is_vectored_again_not_mistaken() {
        // two entries for 64 corners: most share a slot, and each still gets its own angles
        let mut memo = AngleMemo::with_slots(2);
        let n = memo.entries.len();
        let corners: [[i64; 3]; 64] = core::array::from_fn(|i| [i as i64, -(i as i64), 7]);
        for _ in 0..2 {
            for f in corners {
                let got = memo.angles(f, |f| (f[0] * 3, f[1] - 1));
                assert_eq!(got, (f[0] * 3, f[1] - 1), "{n} entries");
            }
        }
    }
}
