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
//! [`KIND_BEZIER`] is reserved for bicubic patches (paper §7): their 16 control points will take
//! a slot of their own stride; the unit reports such a slot as unsupported and skips it.

use crate::format::{Coord, Unit};

/// Words per patch slot.
pub const PATCH_WORDS: usize = 16;
/// Patches the memory holds (the model lives on the stack of every worker thread and of the
/// firmware, without an allocator, so the memory is kept small).
pub const PATCH_CAPACITY: usize = 256;
/// Unused slot (never hit).
pub const KIND_EMPTY: u32 = 0;
/// Planar triangle.
pub const KIND_TRIANGLE: u32 = 1;
/// Planar convex quad.
pub const KIND_QUAD: u32 = 2;
/// Bicubic Bezier patch (reserved: the subdivision unit is not built yet).
pub const KIND_BEZIER: u32 = 3;

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

/// The memory: [`PATCH_CAPACITY`] slots.
#[derive(Clone, Debug)]
pub struct PatchMem {
    words: [u32; PATCH_CAPACITY * PATCH_WORDS],
}

impl Default for PatchMem {
    fn default() -> Self {
        PatchMem {
            words: [0; PATCH_CAPACITY * PATCH_WORDS],
        }
    }
}

impl PatchMem {
    /// Word `addr`, if inside the memory.
    pub fn read(&self, addr: u32) -> Option<u32> {
        self.words.get(addr as usize).copied()
    }

    /// Writes word `addr`; false if outside the memory.
    pub fn write(&mut self, addr: u32, value: u32) -> bool {
        match self.words.get_mut(addr as usize) {
            Some(w) => {
                *w = value;
                true
            }
            None => false,
        }
    }

    /// Slot `i` decoded.
    pub fn patch(&self, i: usize) -> PatchWords {
        PatchWords::decode(&self.words[i * PATCH_WORDS..(i + 1) * PATCH_WORDS])
    }
}
