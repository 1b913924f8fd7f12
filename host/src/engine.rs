//! Ray engines as the host runs them: one per worker thread, each owning its working memory.
//!
//! Pass 1, pass 2 and the queries are generic over [`Accelerator`]; this module provides the
//! software engine in that form. Other backends (the HDL model, a board over the link) are
//! plugged in the same way: anything that implements `Accelerator` and can be made per thread.

use hemi_kernel::accel::bvh::{self, Bvh, Node};
use hemi_kernel::accel::soft::{LocalPatch, SoftAccelerator, SoftScratch};
use hemi_kernel::accel::{Accelerator, Hit, Ray};
use hemi_kernel::geometry::Vec3;
use hemi_kernel::hemisphere::{Hemisphere, MAX_CIRCLES};
use hemi_kernel::patch::Patch;
use hemi_kernel::rotation::Rotation;
use std::ops::Range;

/// The kernel's f32 engine with its scratch memory, sized for any hemisphere table.
pub struct SoftEngine<'p> {
    patches: &'p [Patch],
    /// The patch casts start on (the kernel accelerator is rebuilt per call, so the engine
    /// keeps this between calls and hands it on each time).
    origin_patch: Option<u32>,
    local: Vec<LocalPatch>,
    best_t: Vec<f32>,
    best_id: Vec<u32>,
    /// The BVH for single rays and `cast_from` bundles, built on the first query that uses it
    /// (see [`TREE_MIN_SINGLE`], [`TREE_MIN_BUNDLE`]; hemisphere shots never need it).
    tree: Option<(Vec<Node>, Vec<u32>)>,
}

/// Patches from which single rays (`nearest_hit`: `trace`, frustum rays) go through the BVH:
/// `hemi bench trace` finds it 1.1–2.2× the linear scan on the Cornell box's 19 patches, 3–8×
/// on the teapot's 34 and 30–49× on 242 triangles (docs/PERFORMANCE.md).
pub const TREE_MIN_SINGLE: usize = 16;
/// Patches from which bundles from a shared origin (`cast_from`: eye rays) go through the BVH.
/// The linear path sets every patch up once per bundle and culls by cone, which beats per-ray
/// traversal on small scenes: 0.5–0.6× on the Cornell box, 1.2–1.6× on the teapot, 8–14× on
/// 994 triangles (`hemi bench trace`).
pub const TREE_MIN_BUNDLE: usize = 32;

impl<'p> SoftEngine<'p> {
    /// An engine over `patches` (its patch memory).
    pub fn new(patches: &'p [Patch]) -> Self {
        let max_ring = 4 * MAX_CIRCLES;
        SoftEngine {
            patches,
            origin_patch: None,
            local: vec![LocalPatch::default(); patches.len()],
            best_t: vec![0.0; max_ring],
            best_id: vec![0; max_ring],
            tree: None,
        }
    }

    fn accel(&mut self) -> SoftAccelerator<'p, '_> {
        self.accel_with_tree(false)
    }

    /// The accelerator, through the BVH when `tree` (built on first use).
    fn accel_with_tree(&mut self, tree: bool) -> SoftAccelerator<'p, '_> {
        let n = self.patches.len();
        if tree && self.tree.is_none() {
            let mut nodes = vec![Node::default(); bvh::nodes_for(n)];
            let mut order = vec![0u32; n];
            let mut boxes: Vec<_> = self.patches.iter().map(|p| p.bounds()).collect();
            if bvh::build(self.patches, &mut nodes, &mut order, &mut boxes).is_ok() {
                self.tree = Some((nodes, order));
            }
        }
        let origin_patch = self.origin_patch;
        let mut accel = SoftAccelerator::new(
            self.patches,
            SoftScratch {
                local: &mut self.local,
                best_t: &mut self.best_t,
                best_id: &mut self.best_id,
            },
        )
        .expect("scratch is sized for the patches and the largest ring");
        accel.set_origin_patch(origin_patch);
        match &self.tree {
            Some((nodes, order)) if tree => accel.with_bvh(Bvh::from_parts(nodes, order)),
            _ => accel,
        }
    }
}

impl Accelerator for SoftEngine<'_> {
    fn rotate(&mut self, rot: &Rotation, d: Vec3) -> Vec3 {
        rot.apply(d)
    }
    fn set_origin_patch(&mut self, patch: Option<u32>) {
        self.origin_patch = patch;
    }
    fn nearest_hit(&mut self, ray: &Ray, t_max: f32) -> Option<Hit> {
        let tree = self.patches.len() >= TREE_MIN_SINGLE;
        self.accel_with_tree(tree).nearest_hit(ray, t_max)
    }
    fn cast_from<F: FnMut(usize, Option<Hit>)>(
        &mut self,
        origin: Vec3,
        dirs: &[Vec3],
        want_uv: bool,
        sink: F,
    ) {
        let tree = self.patches.len() >= TREE_MIN_BUNDLE;
        self.accel_with_tree(tree)
            .cast_from(origin, dirs, want_uv, sink)
    }
    fn cast_rings<F: FnMut(usize, u32, Option<Hit>)>(
        &mut self,
        origin: Vec3,
        rot: &Rotation,
        hemi: &Hemisphere<'_>,
        rings: Range<usize>,
        want_uv: bool,
        sink: F,
    ) {
        self.accel()
            .cast_rings(origin, rot, hemi, rings, want_uv, sink)
    }
}

/// Which ray engine a command runs on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Backend {
    /// The kernel's f32 engine in this process.
    Soft,
    /// The cycle-level model of the accelerator, driven through its register driver.
    Model(hemi_hdl_model::ModelConfig),
    /// Boards over the link (`qemu`, `serial:PATH`, comma-separated): the firmware runs the jobs.
    Boards(&'static [crate::board::jobs::BoardSpec]),
}

/// Cycles and rays summed over the model engines of a run (one engine per worker thread).
#[derive(Debug, Default)]
pub struct Counters {
    /// Accelerator clock cycles.
    pub cycles: std::sync::atomic::AtomicU64,
    /// Rays the accelerator cast.
    pub rays: std::sync::atomic::AtomicU64,
}

impl Counters {
    /// (cycles, rays) so far.
    pub fn get(&self) -> (u64, u64) {
        use std::sync::atomic::Ordering::Relaxed;
        (self.cycles.load(Relaxed), self.rays.load(Relaxed))
    }
}

/// A model engine that adds its cycles and rays to shared [`Counters`] when dropped.
pub struct CountedModel<'c> {
    inner: hemi_hdl_model::ModelAccelerator,
    counters: &'c Counters,
}

impl<'c> CountedModel<'c> {
    /// Wraps `inner`.
    pub fn new(inner: hemi_hdl_model::ModelAccelerator, counters: &'c Counters) -> Self {
        CountedModel { inner, counters }
    }
}

impl Drop for CountedModel<'_> {
    fn drop(&mut self) {
        use std::sync::atomic::Ordering::Relaxed;
        self.counters.cycles.fetch_add(self.inner.cycles(), Relaxed);
        self.counters.rays.fetch_add(self.inner.rays(), Relaxed);
    }
}

impl Accelerator for CountedModel<'_> {
    fn rotate(&mut self, rot: &Rotation, d: Vec3) -> Vec3 {
        self.inner.rotate(rot, d)
    }
    fn set_origin_patch(&mut self, patch: Option<u32>) {
        self.inner.set_origin_patch(patch)
    }
    fn nearest_hit(&mut self, ray: &Ray, t_max: f32) -> Option<Hit> {
        self.inner.nearest_hit(ray, t_max)
    }
    fn cast_from<F: FnMut(usize, Option<Hit>)>(
        &mut self,
        origin: Vec3,
        dirs: &[Vec3],
        want_uv: bool,
        sink: F,
    ) {
        self.inner.cast_from(origin, dirs, want_uv, sink)
    }
    fn cast_rings<F: FnMut(usize, u32, Option<Hit>)>(
        &mut self,
        origin: Vec3,
        rot: &Rotation,
        hemi: &Hemisphere<'_>,
        rings: Range<usize>,
        want_uv: bool,
        sink: F,
    ) {
        self.inner
            .cast_rings(origin, rot, hemi, rings, want_uv, sink)
    }
}

/// Builds a model engine over `patches`, with an error that says what the model cannot load.
pub fn model_engine(
    patches: &[Patch],
    config: hemi_hdl_model::ModelConfig,
) -> anyhow::Result<hemi_hdl_model::ModelAccelerator> {
    use hemi_hdl_model::ModelError;
    hemi_hdl_model::ModelAccelerator::new(patches, config).map_err(|e| match e {
        ModelError::TooManyPatches { count, capacity } => anyhow::anyhow!(
            "--backend model: the scene has {count} patches, the accelerator's patch memory holds {capacity}"
        ),
        ModelError::TooManyBezierPatches { count, capacity } => anyhow::anyhow!(
            "--backend model: the scene has {count} Bezier patches, the accelerator's control-point memory holds {capacity}"
        ),
        ModelError::BadGeometry(i) => anyhow::anyhow!(
            "--backend model: patch {i} does not fit the accelerator's fixed-point formats (non-finite or out of range)"
        ),
        other => anyhow::anyhow!("--backend model: {other:?}"),
    })
}
