//! Scenes larger than the accelerator's patch memory, streamed through it in blocks.
//!
//! The host cuts the scene into blocks of consecutive patches that each fit the build: at most
//! the patch memory's slots, at most [`BEZIER_ROWS`] Bezier patches (a board's MCU could do the
//! same from its SRAM over its own bus; none does today). A cast runs once per block, the block written into patch
//! memory before it through the same PATCH_DATA window as any scene, and each ray keeps the
//! nearest of its blocks' answers. So the stream's cost is in the clock count: a bus write a
//! word, [`PATCH_WORDS`] words a slot, for every block a cast (a batch of hemispheres) needs
//! beyond the one already loaded.
//!
//! **Same hits as one memory.** Every block is normalised by the whole scene's box (the same
//! fixed-point words as a memory that held them all), a block's answer for a ray is the nearest
//! of its own patches, and the blocks' answers are compared as the min tree compares lanes': on
//! t as the accelerator's Q8.24 word (not as the f32 it becomes, which can tie two words), ties
//! to the lower patch index. The patch a hemisphere stands on is skipped in the block that
//! holds it. The blocks run starting from the one already in memory, which saves one load a
//! cast and does not change the answers, since the comparison does not depend on the order.
//! (Hosts only: the `alloc` feature, for the blocks' bounds and the rays' nearest answers.)

extern crate alloc;

use super::{decode, ModelConfig, ModelError, Normalise, RegisterAccelerator, RingCursor, MISS};
use crate::driver::{ClockedBus, ModelBus};
use crate::intersect::bezier::BEZIER_ROWS;
#[cfg(doc)]
use crate::intersect::patch_mem::PATCH_WORDS;
use crate::params::Params;
use crate::regs::result;
use alloc::vec::Vec;
use core::ops::Range;
use hemi_kernel::accel::{Accelerator, HemiShot, Hit, Ray};
use hemi_kernel::geometry::Vec3;
use hemi_kernel::hemisphere::Hemisphere;
use hemi_kernel::patch::{Patch, Shape};
use hemi_kernel::rotation::Rotation;

/// The accelerator over a scene of any size: a [`RegisterAccelerator`] (the model's, by
/// default) with the scene's patches at hand, loading them block by block when they do not fit
/// at once. A scene that fits is one block and costs nothing more than the accelerator alone.
pub struct StreamingModel<'p, B: ClockedBus = ModelBus> {
    hw: RegisterAccelerator<B>,
    patches: &'p [Patch],
    /// consecutive ranges of `patches`, each within the build's memories
    blocks: Vec<Range<usize>>,
    /// the block in patch memory now
    loaded: usize,
    origin_patch: Option<u32>,
    /// each ray's nearest answer so far, by its place in the cast
    nearest: Vec<Nearest>,
    /// clocks spent writing blocks after the first
    stream_clocks: u64,
    /// clocks spent configuring the accelerator and writing the first block
    load_clocks: u64,
    /// clocks spent loading blocks to align with a batch's place ([`Self::align_to_batch`])
    align_clocks: u64,
}

impl<'p> StreamingModel<'p> {
    /// Configures a model of `config` and loads the first block of `patches`.
    pub fn new(patches: &'p [Patch], config: ModelConfig) -> Result<Self, ModelError> {
        if !config.params.is_valid() {
            return Err(ModelError::BadParams);
        }
        Self::with_bus(patches, config, ModelBus::with_params(config.params))
    }

    /// Blocks a model of `params` cuts `patches` into (1 when they fit its patch memory).
    pub fn blocks_needed(patches: &[Patch], params: Params) -> usize {
        blocks(patches, params.capacity() as usize).len()
    }

    /// The lanes' work counters over every block: candidates tested, rays culled, set-up
    /// passes.
    pub fn lane_stats(&self) -> crate::intersect::LaneStats {
        self.hw.lane_stats()
    }
}

impl<'p, B: ClockedBus> StreamingModel<'p, B> {
    /// The accelerator behind `bus` (its own patch capacity, from CAPS) configured with
    /// `config`'s CORDIC, (u,v) and Bezier settings, and the first block of `patches` loaded:
    /// the model's, or another implementation's behind the same registers (the RTL in a
    /// simulator).
    pub fn with_bus(patches: &'p [Patch], config: ModelConfig, bus: B) -> Result<Self, ModelError> {
        let mut hw = RegisterAccelerator::unattached(bus);
        hw.configure(config)?;
        hw.norm = Normalise::around(patches, config.flatness)?;
        let blocks = blocks(patches, hw.driver.patch_capacity() as usize);
        hw.load_block(&patches[blocks[0].clone()])?;
        let load_clocks = hw.cycles();
        Ok(StreamingModel {
            hw,
            patches,
            blocks,
            loaded: 0,
            origin_patch: None,
            nearest: Vec::new(),
            stream_clocks: 0,
            load_clocks,
            align_clocks: 0,
        })
    }

    /// Clocks the model has run, the stream's writes included.
    pub fn cycles(&self) -> u64 {
        self.hw.cycles()
    }

    /// Clocks spent configuring the accelerator and writing the first block into patch memory
    /// (part of [`Self::cycles`]): what a board pays once a scene, however many model engines a
    /// host runs in parallel.
    pub fn load_cycles(&self) -> u64 {
        self.load_clocks
    }

    /// Clocks [`Self::align_to_batch`] spent (part of [`Self::cycles`], not of
    /// [`Self::stream_cycles`]): what one engine casting every batch would not have spent.
    pub fn aligning_cycles(&self) -> u64 {
        self.align_clocks
    }

    /// Loads the block that one model casting a pass's batches in order would hold at the start
    /// of batch `number` (batch 0 finding the first block in memory, as `new` leaves it), if
    /// another is in memory, and keeps its clocks apart ([`Self::aligning_cycles`]). A batch
    /// casts every block starting from the one in memory, so it ends on the block before it:
    /// batch k starts on block −k modulo the blocks. A host that shares a pass's batches among
    /// several models then counts, over all of them, the stream one model would have cast.
    pub fn align_to_batch(&mut self, number: u64) {
        let n = self.blocks.len();
        let want = (n - (number % n as u64) as usize) % n;
        if want == self.loaded {
            return;
        }
        let (before, streamed) = (self.hw.cycles(), self.stream_clocks);
        self.load(want);
        self.align_clocks += self.hw.cycles() - before;
        self.stream_clocks = streamed;
    }

    /// Clocks spent writing blocks into patch memory after the first block.
    pub fn stream_cycles(&self) -> u64 {
        self.stream_clocks
    }

    /// Blocks the scene is cut into (1 when it fits the patch memory).
    pub fn blocks(&self) -> usize {
        self.blocks.len()
    }

    /// Rays cast (each once, however many blocks it met).
    pub fn rays(&self) -> u64 {
        self.hw.rays()
    }

    /// Rays reported as misses because their origin was outside the coordinate range.
    pub fn out_of_range(&self) -> u64 {
        self.hw.out_of_range()
    }

    /// Runs `cast` once per block (the loaded one first), `n` rays a run, and hands each
    /// ray's nearest answer to `emit` by its place in the cast; `cast` hands its answers to the
    /// block's sink by place. The rays are counted once.
    fn each_block(
        &mut self,
        n: usize,
        mut cast: impl FnMut(&mut RegisterAccelerator<B>, Range<usize>, &mut dyn FnMut(usize, [u32; 4])),
        mut emit: impl FnMut(usize, Option<Hit>),
    ) {
        self.nearest.clear();
        self.nearest.resize(n, Nearest::NONE);
        // the first block's counts stand for the cast (the others count the same rays again)
        let mut counted = None;
        let (first, count) = (self.loaded, self.blocks.len());
        for b in (0..count).map(|i| (first + i) % count) {
            self.load(b);
            let block = self.blocks[b].clone();
            let base = block.start as u32;
            let nearest = &mut self.nearest;
            cast(&mut self.hw, block, &mut |i, r| nearest[i].keep(r, base));
            counted.get_or_insert((self.hw.rays, self.hw.out_of_range));
        }
        if let Some(counts) = counted {
            (self.hw.rays, self.hw.out_of_range) = counts;
        }
        let scale = self.hw.norm.scale;
        for (i, near) in self.nearest.iter().enumerate() {
            emit(i, near.hit(scale));
        }
    }

    /// Block `b` into patch memory, if it is not there.
    fn load(&mut self, b: usize) {
        if self.loaded == b {
            return;
        }
        let before = self.hw.cycles();
        let block = &self.patches[self.blocks[b].clone()];
        // Every patch was checked against the normalisation when the scene was cut.
        if let Err(e) = self.hw.load_block(block) {
            panic!("streaming accelerator: a checked block did not load: {e:?}");
        }
        self.stream_clocks += self.hw.cycles() - before;
        self.loaded = b;
    }
}

/// `patch` (a scene index) as a slot of `block`, if the block holds it.
fn local(block: Range<usize>, patch: u32) -> Option<u32> {
    let p = patch as usize;
    block.contains(&p).then(|| (p - block.start) as u32)
}

/// The scene cut into consecutive blocks of at most `slots` patches and [`BEZIER_ROWS`] Bezier
/// patches (one empty block for an empty scene).
fn blocks(patches: &[Patch], slots: usize) -> Vec<Range<usize>> {
    let mut out = Vec::new();
    let (mut start, mut beziers) = (0, 0);
    for (i, p) in patches.iter().enumerate() {
        let bezier = matches!(p.shape, Shape::Bezier(_)) as usize;
        if i - start == slots || beziers + bezier > BEZIER_ROWS {
            out.push(start..i);
            (start, beziers) = (i, 0);
        }
        beziers += bezier;
    }
    out.push(start..patches.len());
    out
}

/// A ray's nearest answer over the blocks so far: its RESULT words and the scene index of the
/// patch hit.
#[derive(Clone, Copy, Debug)]
struct Nearest {
    words: [u32; 4],
    patch: u32,
}

impl Nearest {
    const NONE: Nearest = Nearest {
        words: MISS,
        patch: 0,
    };

    fn is_hit(words: &[u32; 4]) -> bool {
        words[0] & result::HIT != 0
    }

    /// Keeps block answer `r` (its slot counted from `base`) if it is nearer: t compared as
    /// the accelerator's Q8.24 word, ties to the lower patch index, as the min tree does.
    fn keep(&mut self, r: [u32; 4], base: u32) {
        if !Self::is_hit(&r) {
            return;
        }
        let patch = base + (r[0] & result::PATCH_MASK);
        let t = r[1] as i32;
        if !Self::is_hit(&self.words) || (t, patch) < (self.words[1] as i32, self.patch) {
            *self = Nearest { words: r, patch };
        }
    }

    fn hit(&self, scale: f64) -> Option<Hit> {
        decode(scale, self.words).map(|h| Hit {
            patch: self.patch,
            ..h
        })
    }
}

impl<B: ClockedBus> Accelerator for StreamingModel<'_, B> {
    fn rotate(&mut self, rot: &Rotation, d: Vec3) -> Vec3 {
        self.hw.rotate(rot, d)
    }

    fn set_origin_patch(&mut self, patch: Option<u32>) {
        self.origin_patch = patch;
        if self.blocks.len() == 1 {
            self.hw.set_origin_patch(patch);
        }
    }

    fn nearest_hit(&mut self, ray: &Ray, t_max: f32) -> Option<Hit> {
        let mut hit = None;
        self.cast_from(ray.origin, &[ray.dir], true, |_, h| hit = h);
        hit.filter(|h| h.t < t_max)
    }

    fn cast_from<F: FnMut(usize, Option<Hit>)>(
        &mut self,
        origin: Vec3,
        dirs: &[Vec3],
        want_uv: bool,
        sink: F,
    ) {
        if self.blocks.len() == 1 {
            return self.hw.cast_from(origin, dirs, want_uv, sink);
        }
        let own = self.origin_patch;
        let cast = |hw: &mut RegisterAccelerator<B>,
                    block: Range<usize>,
                    put: &mut dyn FnMut(usize, [u32; 4])| {
            hw.origin_patch = own.and_then(|p| local(block, p));
            hw.cast_from_words(origin, dirs, want_uv, put);
        };
        self.each_block(dirs.len(), cast, sink);
    }

    fn cast_rings<F: FnMut(usize, u32, Option<Hit>)>(
        &mut self,
        origin: Vec3,
        rot: &Rotation,
        hemi: &Hemisphere<'_>,
        rings: Range<usize>,
        want_uv: bool,
        mut sink: F,
    ) {
        if self.blocks.len() == 1 {
            return self.hw.cast_rings(origin, rot, hemi, rings, want_uv, sink);
        }
        let places = RingPlaces::new(hemi, rings.clone());
        let own = self.origin_patch;
        let cast = |hw: &mut RegisterAccelerator<B>,
                    block: Range<usize>,
                    put: &mut dyn FnMut(usize, [u32; 4])| {
            hw.origin_patch = own.and_then(|p| local(block, p));
            hw.cast_rings_words(origin, rot, hemi, rings.clone(), want_uv, |j, k, r| {
                put(places.place(j, k), r)
            });
        };
        let mut at = RingCursor::new(hemi, rings.clone());
        self.each_block(places.len, cast, |_, hit| {
            let (j, k) = at.next_index();
            sink(j, k, hit)
        });
    }

    fn cast_hemispheres<F: FnMut(usize, usize, u32, Option<Hit>)>(
        &mut self,
        shots: &[HemiShot],
        hemi: &Hemisphere<'_>,
        rings: Range<usize>,
        want_uv: bool,
        mut sink: F,
    ) {
        if self.blocks.len() == 1 {
            return self.hw.cast_hemispheres(shots, hemi, rings, want_uv, sink);
        }
        let places = RingPlaces::new(hemi, rings.clone());
        let per_shot = places.len;
        let mut local_shots = shots.to_vec();
        let cast = |hw: &mut RegisterAccelerator<B>,
                    block: Range<usize>,
                    put: &mut dyn FnMut(usize, [u32; 4])| {
            // each shot's own patch, as a slot of this block
            for (mine, shot) in local_shots.iter_mut().zip(shots) {
                mine.origin_patch = shot.origin_patch.and_then(|p| local(block.clone(), p));
            }
            hw.cast_hemispheres_words(&local_shots, hemi, rings.clone(), want_uv, |s, j, k, r| {
                put(s * per_shot + places.place(j, k), r)
            });
        };
        let mut at = RingCursor::new(hemi, rings.clone());
        let mut s = 0;
        self.each_block(shots.len() * per_shot, cast, |i, hit| {
            if i > 0 && i % per_shot == 0 {
                s += 1;
                at = RingCursor::new(hemi, rings.clone());
            }
            let (j, k) = at.next_index();
            sink(s, j, k, hit)
        });
        // as the accelerator underneath: a batch's shots name their own patches, and the one
        // set before the batch is forgotten
        self.origin_patch = None;
    }
}

/// Places of a range of rings' rays in a flat array, ring after ring (the order
/// [`RingCursor`] walks them in).
struct RingPlaces {
    first: usize,
    /// each ring's first place
    starts: Vec<usize>,
    /// the rays in all
    len: usize,
}

impl RingPlaces {
    fn new(hemi: &Hemisphere<'_>, rings: Range<usize>) -> Self {
        let mut starts = Vec::with_capacity(rings.len());
        let mut len = 0;
        for j in rings.clone() {
            starts.push(len);
            len += hemi.rings()[j].count as usize;
        }
        RingPlaces {
            first: rings.start,
            starts,
            len,
        }
    }

    fn place(&self, j: usize, k: u32) -> usize {
        self.starts[j - self.first] + k as usize
    }
}
#[cfg(test)]
mod tests {
    use super::*;
    use hemi_kernel::geometry::{Bezier, Polygon};

    fn quad(x: f32) -> Patch {
        let v = |a: f32, b: f32| Vec3::new(x + a, b, 0.0);
        Patch::polygon(Polygon::quad([v(0.0, 0.0), v(1.0, 0.0), v(1.0, 1.0), v(0.0, 1.0)]).unwrap())
    }

    fn bezier(x: f32) -> Patch {
        let cp = core::array::from_fn(|i| Vec3::new(x + (i % 4) as f32, (i / 4) as f32, 0.5));
        Patch::bezier(Bezier::new(cp).unwrap())
    }

    #[test]
    fn blocks_hold_at_most_the_slots_and_the_control_point_rows() {
        let quads: Vec<Patch> = (0..10).map(|i| quad(i as f32)).collect();
        assert_eq!(blocks(&quads, 4), [0..4, 4..8, 8..10]);
        // a scene that fits, and the empty scene, are one block
        let one = |b: Vec<Range<usize>>| (b.len(), b[0].clone());
        assert_eq!(one(blocks(&quads, 10)), (1, 0..10));
        assert_eq!(one(blocks(&[], 4)), (1, 0..0));
        // Bezier rows run out before the slots: a block ends at the row limit
        let mut mixed: Vec<Patch> = (0..BEZIER_ROWS + 3).map(|i| bezier(i as f32)).collect();
        mixed.insert(1, quad(-1.0));
        let cut = blocks(&mixed, 1000);
        assert_eq!(cut, [0..BEZIER_ROWS + 1, BEZIER_ROWS + 1..BEZIER_ROWS + 4]);
    }

    #[test]
    fn the_nearer_answer_is_kept_ties_to_the_lower_index() {
        let hit = |slot: u32, t: i32| [result::HIT | slot, t as u32, 0, 0];
        let mut n = Nearest::NONE;
        n.keep(MISS, 0);
        assert!(!Nearest::is_hit(&n.words));
        n.keep(hit(3, 500), 10);
        assert_eq!((n.patch, n.words[1]), (13, 500));
        // a later block's equal t loses; a nearer one wins; an earlier block's equal t wins
        n.keep(hit(0, 500), 20);
        assert_eq!(n.patch, 13);
        n.keep(hit(1, 499), 20);
        assert_eq!(n.patch, 21);
        n.keep(hit(2, 499), 0);
        assert_eq!(n.patch, 2);
        n.keep(MISS, 0);
        assert_eq!(n.patch, 2);
    }
}
