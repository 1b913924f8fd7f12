//! Patch memory: what the intersection unit scans, written word by word through the register
//! window (`PATCH_ADDR` / `PATCH_DATA`).
//!
//! A patch is a slot of [`PATCH_WORDS`] 32-bit words:
//!
//! | word  | content                                                             |
//! |-------|---------------------------------------------------------------------|
//! | 0     | header: bits 3:0 kind ([`KIND_EMPTY`], [`KIND_TRIANGLE`], [`KIND_QUAD`], [`KIND_BEZIER`]) |
//! | 1–12  | v0.x v0.y v0.z v1.x … v3.z, Q8.24 normalised coordinates (triangle: v3 = v2) |
//! | 13–15 | unit front normal n.x n.y n.z, Q2.30                                  |
//!
//! A bicubic Bezier slot ([`KIND_BEZIER`], paper §7) names a row of the control-point memory
//! instead of holding vertices, so that planar slots keep their 16-word stride and patch index =
//! slot index for every kind:
//!
//! | word | content                                                                  |
//! |------|--------------------------------------------------------------------------|
//! | 0    | header: kind 3                                                           |
//! | 1    | control-point row (0..[`BEZIER_ROWS`])                                    |
//! | 2    | flatness tolerance, Q8.24 normalised units (0: subdivide to the maximum depth) |
//! | 3    | t_min, Q8.24: nearer hits are the surface the ray starts on              |
//!
//! The control-point memory sits at word address [`CP_BASE`] of the same window: row i is the
//! [`CP_WORDS`] words from `CP_BASE + 48·i`, the 16 points row-major (c along u, r along v),
//! x, y, z each, Q8.24.

use super::bezier::{BEZIER_ROWS, CP_WORDS};
use super::horizon::SlotBox;
use crate::format::{Coord, Unit};
use crate::table::Table;

/// Words per patch slot.
pub const PATCH_WORDS: usize = 16;
/// Patch slots the model holds without an allocator (the model lives on the stack of the
/// firmware, so its memories are kept small there); with the `alloc` feature a build holds
/// `banks × bank_slots` ([`crate::params::Params::capacity`]).
pub const PATCH_CAPACITY: usize = 256;
/// Unused slot (never hit).
pub const KIND_EMPTY: u32 = 0;
/// Planar triangle.
pub const KIND_TRIANGLE: u32 = 1;
/// Planar convex quad.
pub const KIND_QUAD: u32 = 2;
/// Bicubic Bezier patch (control points in control-point memory).
pub const KIND_BEZIER: u32 = 3;
/// Word address of control-point row 0 in the PATCH_ADDR / PATCH_DATA window.
pub const CP_BASE: u32 = 0x1_0000;

/// A patch slot decoded from its words.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PatchWords {
    /// Kind from the header.
    pub kind: u32,
    /// Vertices.
    pub v: [[Coord; 3]; 4],
    /// Front normal.
    pub n: [Unit; 3],
}

/// The fields of a Bezier slot.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BezierSlot {
    /// Control-point row.
    pub row: u32,
    /// Flatness tolerance (Q8.24).
    pub tol: Coord,
    /// t_min (Q8.24).
    pub t_min: Coord,
}

impl BezierSlot {
    /// The slot's words.
    pub fn encode(&self) -> [u32; PATCH_WORDS] {
        let mut w = [0u32; PATCH_WORDS];
        w[0] = KIND_BEZIER;
        w[1] = self.row;
        w[2] = self.tol.to_bits() as u32;
        w[3] = self.t_min.to_bits() as u32;
        w
    }

    /// Decodes the Bezier fields of a slot (whatever its kind).
    pub fn decode(w: &[u32]) -> Self {
        BezierSlot {
            row: w[1],
            tol: Coord::from_bits(w[2] as i32),
            t_min: Coord::from_bits(w[3] as i32),
        }
    }
}

impl PatchWords {
    /// The slot's words.
    pub fn encode(&self) -> [u32; PATCH_WORDS] {
        let mut w = [0u32; PATCH_WORDS];
        w[0] = self.kind & 0xF;
        for (i, c) in self.v.iter().flatten().enumerate() {
            w[1 + i] = c.to_bits() as u32;
        }
        for (i, c) in self.n.iter().enumerate() {
            w[13 + i] = c.to_bits() as u32;
        }
        w
    }

    /// Decodes a slot.
    pub fn decode(w: &[u32]) -> Self {
        PatchWords {
            kind: w[0] & 0xF,
            v: core::array::from_fn(|i| {
                core::array::from_fn(|k| Coord::from_bits(w[1 + 3 * i + k] as i32))
            }),
            n: core::array::from_fn(|k| Unit::from_bits(w[13 + k] as i32)),
        }
    }

    /// Number of corners (3 or 4) of a planar kind.
    pub fn sides(&self) -> usize {
        if self.kind == KIND_TRIANGLE {
            3
        } else {
            4
        }
    }
}

/// The memory: its slots and [`BEZIER_ROWS`] control-point rows.
#[derive(Clone, Debug)]
pub struct PatchMem {
    words: Table<u32, { PATCH_CAPACITY * PATCH_WORDS }>,
    /// each slot's bounding box, kept on the write path for the horizon filter
    boxes: Table<SlotBox, PATCH_CAPACITY>,
    cp: [u32; BEZIER_ROWS * CP_WORDS],
}

impl PatchMem {
    /// A zeroed memory of `slots` slots (as many as the build can hold).
    pub fn new(slots: usize) -> Self {
        PatchMem {
            words: Table::new(0, slots.saturating_mul(PATCH_WORDS)),
            boxes: Table::new(SlotBox::default(), slots),
            cp: [0; BEZIER_ROWS * CP_WORDS],
        }
    }

    /// Slots it holds.
    pub fn slots(&self) -> usize {
        self.words.len() / PATCH_WORDS
    }

    fn word_mut(&mut self, addr: u32) -> Option<&mut u32> {
        match addr.checked_sub(CP_BASE) {
            Some(a) => self.cp.get_mut(a as usize),
            None => self.words.get_mut(addr as usize),
        }
    }

    /// Word `addr`, if inside the memory (slots from 0, control points from [`CP_BASE`]).
    pub fn read(&self, addr: u32) -> Option<u32> {
        match addr.checked_sub(CP_BASE) {
            Some(a) => self.cp.get(a as usize).copied(),
            None => self.words.get(addr as usize).copied(),
        }
    }

    /// Writes word `addr`; false if outside the memory.
    pub fn write(&mut self, addr: u32, value: u32) -> bool {
        let Some(w) = self.word_mut(addr) else {
            return false;
        };
        *w = value;
        let (slot, word) = (addr as usize / PATCH_WORDS, addr as usize % PATCH_WORDS);
        if let Some(b) = self.boxes.get_mut(slot).filter(|_| addr < CP_BASE) {
            b.write(word, value);
        }
        true
    }

    /// Slot `i`'s bounding box (Q8.24 ends), if every corner word was written since its header
    /// ([`SlotBox`]).
    pub fn bounds(&self, i: usize) -> Option<([i64; 3], [i64; 3])> {
        self.boxes.get(i).and_then(SlotBox::bounds)
    }

    /// Slot `i` decoded.
    pub fn patch(&self, i: usize) -> PatchWords {
        PatchWords::decode(self.slot(i))
    }

    /// Slot `i`'s raw words.
    pub fn slot(&self, i: usize) -> &[u32] {
        &self.words[i * PATCH_WORDS..(i + 1) * PATCH_WORDS]
    }

    /// The slot's kind (header bits 3:0).
    pub fn kind(&self, i: usize) -> u32 {
        self.words[i * PATCH_WORDS] & 0xF
    }

    /// Control-point row `row` (one wide read), if inside the memory.
    pub fn cp_row(&self, row: u32) -> Option<&[u32]> {
        let r = row as usize;
        (r < BEZIER_ROWS).then(|| &self.cp[r * CP_WORDS..(r + 1) * CP_WORDS])
    }
}
