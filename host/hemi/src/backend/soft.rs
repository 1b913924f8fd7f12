//! The kernel's f32 engine in this process, one per worker thread, each owning its working
//! memory; what depends on the patches alone (the BVH, the (u,v) frames, the curved patches'
//! trees) is built once before any pass and shared.

use super::Engines;
use hemi_kernel::accel::bvh::{self, Bvh, Node};
use hemi_kernel::accel::soft::{LocalPatch, SoftAccelerator, SoftScratch};
use hemi_kernel::accel::wide_bvh::{self, WideNode};
use hemi_kernel::accel::{Accelerator, Hit, Ray};
use hemi_kernel::geometry::{Bezier, BezierTree, Subdivision, TreeNode, UvFrame, Vec3};
use hemi_kernel::hemisphere::{Hemisphere, MAX_CIRCLES};
use hemi_kernel::patch::{Patch, Shape};
use hemi_kernel::rotation::Rotation;
use rayon::prelude::*;
use std::borrow::Cow;
use std::ops::Range;
use std::sync::OnceLock;

/// The in-process engines of the soft backend ([`super::InProcess`]`<Soft>`). Holds what
/// every engine reads and none changes, built once by [`Engines::check`] and shared by all: a
/// pass makes an engine per worker job (rayon's `map_init`), dozens a pass, and on 10⁵ patches
/// a BVH of its own in each took half of pass 1.
#[derive(Debug, Default)]
pub struct Soft {
    shared: OnceLock<Shared>,
}

/// The BVH's nodes and patch order, and its wide form (`wide_bvh`), which single rays walk.
type Tree = (Vec<Node>, Vec<u32>, Vec<WideNode>);

/// What [`Soft`]'s engines share, and the patch memory it was built for.
#[derive(Debug)]
struct Shared {
    /// The patch memory's address and length: the only patches these parts describe.
    built_for: (usize, usize),
    trees: BezierTrees,
    tree: Option<Tree>,
    uv_frames: Vec<Option<UvFrame>>,
}

impl Shared {
    fn new(patches: &[Patch]) -> Shared {
        let big = patches.len() >= TREE_MIN_SINGLE.min(TREE_MIN_HEMISPHERE);
        Shared {
            built_for: (patches.as_ptr() as usize, patches.len()),
            trees: BezierTrees::new(patches),
            tree: if big { build_tree(patches) } else { None },
            uv_frames: uv_frames(patches),
        }
    }

    /// Whether these parts describe `patches`.
    fn fits(&self, patches: &[Patch]) -> bool {
        self.built_for == (patches.as_ptr() as usize, patches.len())
    }
}

impl Soft {
    /// The soft backend's engines (no tree built yet).
    pub const fn new() -> Soft {
        Soft {
            shared: OnceLock::new(),
        }
    }
}

impl Engines for Soft {
    type Engine<'p> = SoftEngine<'p>;

    /// Builds the trees here, once, before any pass: `engine` runs on the worker threads,
    /// where a build (itself parallel) could be re-entered by a worker waiting on it.
    fn check(&self, patches: &[Patch]) -> anyhow::Result<()> {
        self.shared.get_or_init(|| Shared::new(patches));
        Ok(())
    }

    fn engine<'p>(&'p self, patches: &'p [Patch]) -> SoftEngine<'p> {
        // without a check first, or for another patch memory than the checked one (a backend
        // is made per scene, so never in practice): the engine builds its own parts, and
        // curved patches are subdivided per ray, the same hits
        match self.shared.get().filter(|s| s.fits(patches)) {
            Some(shared) => SoftEngine::with_shared(patches, shared),
            None => SoftEngine::new(patches),
        }
    }
}

/// Sub-patches stored at most per curved patch ([`Bezier::build_tree`]): the first eight
/// levels (1 + 4 + … + 4⁷), which hold all of most teapot patches' trees (6,605–23,677 nodes).
pub const TREE_NODES_PER_PATCH: usize = 21845;

/// Bytes all curved patches' trees may take together (224 bytes a node): a scene of many
/// curved patches stores fewer levels of each, and subdivides the rest per ray.
pub const TREE_BYTES: usize = 64 << 20;

/// Nodes each of `curved` patches may store: [`TREE_NODES_PER_PATCH`], or an equal share of
/// [`TREE_BYTES`], but always the root and its children.
fn tree_nodes_per_patch(curved: usize) -> usize {
    let node = std::mem::size_of::<TreeNode>() + std::mem::size_of::<[Vec3; 16]>();
    (TREE_BYTES / node / curved.max(1)).clamp(5, TREE_NODES_PER_PATCH)
}

/// The curved patches of `patches`, with their ids.
fn curved(patches: &[Patch]) -> impl Iterator<Item = (usize, Bezier)> + '_ {
    patches
        .iter()
        .enumerate()
        .filter_map(|(id, p)| match p.shape {
            Shape::Bezier(b) => Some((id, b)),
            Shape::Polygon(_) => None,
        })
}

/// The subdivision trees of a patch memory's curved patches, all in two arrays.
#[derive(Debug)]
struct BezierTrees {
    /// The curved patches they were built from, with their ids.
    curved: Vec<(usize, Bezier)>,
    nodes: Vec<TreeNode>,
    cps: Vec<[Vec3; 16]>,
    /// Each curved patch's nodes in `nodes` and `cps`, in the order of `curved`.
    spans: Vec<Range<usize>>,
}

impl BezierTrees {
    fn new(patches: &[Patch]) -> BezierTrees {
        let curved: Vec<(usize, Bezier)> = curved(patches).collect();
        // each patch built in its own scratch, on all threads (this runs before pass 1 can
        // start), then only the nodes used are kept, in one allocation
        let cap = tree_nodes_per_patch(curved.len());
        let built: Vec<(Vec<TreeNode>, Vec<[Vec3; 16]>)> = curved
            .par_iter()
            .map(|(_, b)| {
                let mut nodes = vec![TreeNode::default(); cap];
                let mut cps = vec![[Vec3::ZERO; 16]; cap];
                let used = b
                    .build_tree(&Subdivision::default(), &mut nodes, &mut cps)
                    .len();
                nodes.truncate(used);
                cps.truncate(used);
                (nodes, cps)
            })
            .collect();
        let (mut nodes, mut cps, mut spans) = (Vec::new(), Vec::new(), Vec::new());
        for (n, c) in built {
            spans.push(nodes.len()..nodes.len() + n.len());
            nodes.extend_from_slice(&n);
            cps.extend_from_slice(&c);
        }
        BezierTrees {
            curved,
            nodes,
            cps,
            spans,
        }
    }

    /// One tree per patch id (`None` for polygons).
    fn views(&self, patch_count: usize) -> Vec<Option<BezierTree<'_>>> {
        let mut views = vec![None; patch_count];
        for ((id, _), span) in self.curved.iter().zip(&self.spans) {
            views[*id] = Some(BezierTree::from_parts(
                &self.nodes[span.clone()],
                &self.cps[span.clone()],
                Subdivision::default(),
            ));
        }
        views
    }
}

/// The kernel's f32 engine with its scratch memory, sized for any hemisphere table.
pub struct SoftEngine<'p> {
    patches: &'p [Patch],
    /// The patch casts start on (the kernel accelerator is rebuilt per call, so the engine
    /// keeps this between calls and hands it on each time).
    origin_patch: Option<u32>,
    local: Vec<LocalPatch>,
    best_t: Vec<f32>,
    best_id: Vec<u32>,
    /// The BVH (see [`TREE_MIN_SINGLE`], [`TREE_MIN_BUNDLE`], [`TREE_MIN_HEMISPHERE`]):
    /// [`Soft`]'s, or built on the first query that uses it by an engine made without one.
    tree: Option<Cow<'p, Tree>>,
    /// Each patch's (u,v) frame (`Polygon::uv_frame`), so a hit's (u,v) does not rebuild it.
    uv_frames: Cow<'p, [Option<UvFrame>]>,
    /// Whether every patch is a polygon: hemispheres are then cast patch by patch
    /// (`SoftAccelerator::with_patch_major`), which a curved patch's subdivision does not allow.
    polygons_only: bool,
    /// Each curved patch's stored subdivision, by patch id (empty without curved patches).
    trees: Vec<Option<BezierTree<'p>>>,
}

/// Patches from which hemispheres skip what is below their horizon through the BVH
/// (`Bvh::visit_above`) instead of setting every patch up.
pub const TREE_MIN_HEMISPHERE: usize = 32;

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
        SoftEngine {
            uv_frames: Cow::Owned(uv_frames(patches)),
            ..SoftEngine::new_bare(patches)
        }
    }

    /// An engine over `patches` with its scratch and no (u,v) frames yet.
    fn new_bare(patches: &'p [Patch]) -> Self {
        let max_ring = 4 * MAX_CIRCLES;
        SoftEngine {
            patches,
            origin_patch: None,
            local: vec![LocalPatch::default(); patches.len()],
            best_t: vec![0.0; max_ring],
            best_id: vec![0; max_ring],
            tree: None,
            uv_frames: Cow::Borrowed(&[]),
            polygons_only: patches.iter().all(|p| p.as_polygon().is_some()),
            trees: Vec::new(),
        }
    }

    /// An engine over `patches` reading `shared`, built for them.
    fn with_shared(patches: &'p [Patch], shared: &'p Shared) -> Self {
        let mut engine = SoftEngine::new_bare(patches);
        engine.tree = shared.tree.as_ref().map(Cow::Borrowed);
        engine.uv_frames = Cow::Borrowed(&shared.uv_frames);
        engine.with_bezier_trees(Some(&shared.trees))
    }

    /// Intersects the curved patches from `trees`, their stored subdivision.
    fn with_bezier_trees(mut self, trees: Option<&'p BezierTrees>) -> Self {
        if let Some(trees) = trees.filter(|t| !t.curved.is_empty()) {
            self.trees = trees.views(self.patches.len());
        }
        self
    }

    fn accel(&mut self) -> SoftAccelerator<'p, '_> {
        self.accel_with_tree(false)
    }

    /// The accelerator, through the BVH when `tree` (built on first use).
    fn accel_with_tree(&mut self, tree: bool) -> SoftAccelerator<'p, '_> {
        if tree && self.tree.is_none() {
            self.tree = build_tree(self.patches).map(Cow::Owned);
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
        let mut accel = accel.with_uv_frames(&self.uv_frames);
        if !self.trees.is_empty() {
            accel = accel.with_bezier_trees(&self.trees);
        }
        match &self.tree {
            Some(t) if tree => accel.with_bvh(Bvh::from_parts(&t.0, &t.1).with_wide(&t.2)),
            _ => accel,
        }
    }
}

/// Each patch's (u,v) frame (`None` for curved patches and polygons without one).
fn uv_frames(patches: &[Patch]) -> Vec<Option<UvFrame>> {
    patches
        .iter()
        .map(|p| p.as_polygon().and_then(|poly| poly.uv_frame()))
        .collect()
}

/// The BVH over `patches`, or `None` if the kernel cannot build one (the linear scan then
/// answers alone).
fn build_tree(patches: &[Patch]) -> Option<Tree> {
    let n = patches.len();
    let mut nodes = vec![Node::default(); bvh::nodes_for(n)];
    let mut order = vec![0u32; n];
    let mut boxes: Vec<_> = patches.iter().map(|p| p.bounds()).collect();
    bvh::build(patches, &mut nodes, &mut order, &mut boxes).ok()?;
    // (the binary tree alone, should it ever not widen: the same answers, slower)
    let mut wide = vec![WideNode::default(); wide_bvh::nodes_for(n)];
    let used = wide_bvh::widen(&Bvh::from_parts(&nodes, &order), &mut wide).unwrap_or(0);
    // (a third or less of the bound is used, 365 of 1,280 on the Cornell box cut 8 × 8: the
    // rest, 128 bytes a node, is given back)
    wide.truncate(used);
    wide.shrink_to_fit();
    Some((nodes, order, wide))
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
        if !self.polygons_only {
            return self
                .accel()
                .cast_rings(origin, rot, hemi, rings, want_uv, sink);
        }
        // the whole hemisphere's nearest hits, so that it can be cast patch by patch
        let rays = hemi.ray_count() as usize;
        if self.best_t.len() < rays {
            self.best_t.resize(rays, 0.0);
            self.best_id.resize(rays, 0);
        }
        let tree = self.patches.len() >= TREE_MIN_HEMISPHERE;
        let accel = self.accel_with_tree(tree);
        let bvh = accel.bvh();
        accel
            .with_patch_major(bvh)
            .cast_rings(origin, rot, hemi, rings, want_uv, sink)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hemi_kernel::hemisphere::{DeltaRule, OwnedHemisphere};

    /// Every hit of hemispheres on the teapot, through the engines' stored subdivision trees,
    /// against the same engine subdividing from the root for every ray: the same bits, on
    /// seams and corners too (u, v ∈ {0, 1}).
    #[test]
    fn bezier_trees_change_no_hit() {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/teapot.toml");
        let scene = crate::scene::load(&path).unwrap();
        let patches: Vec<Patch> = scene
            .bezier_patches()
            .into_iter()
            .map(Patch::bezier)
            .collect();
        let soft = Soft::new();
        soft.check(&patches).unwrap();
        let mut with = soft.engine(&patches);
        assert!(with.trees.iter().all(|t| t.is_some_and(|t| t.len() > 5)));
        let mut without = SoftEngine::new(&patches);
        let hemi = OwnedHemisphere::new(12, DeltaRule::Band).unwrap();
        let hemi = hemi.view();
        let (mut hits, mut rays) = (0, 0);
        for (id, p) in patches.iter().enumerate().step_by(3) {
            let Shape::Bezier(b) = &p.shape else { continue };
            for (u, v) in [(0.0, 0.0), (0.5, 0.5), (1.0, 0.3), (0.2, 1.0)] {
                let (origin, normal) = (b.point(u, v), b.normal_near(u, v).unwrap_or(Vec3::Z));
                let rot = Rotation::onto(normal);
                let cast = |engine: &mut SoftEngine<'_>| {
                    engine.set_origin_patch(Some(id as u32));
                    let mut seen = Vec::new();
                    engine.cast_rings(
                        origin,
                        &rot,
                        &hemi,
                        0..hemi.rings().len(),
                        true,
                        |j, k, h| {
                            seen.push((
                                j,
                                k,
                                h.map(|h| {
                                    (
                                        h.patch,
                                        h.t.to_bits(),
                                        h.u.to_bits(),
                                        h.v.to_bits(),
                                        h.front,
                                    )
                                }),
                            ))
                        },
                    );
                    seen
                };
                let (got, want) = (cast(&mut with), cast(&mut without));
                assert_eq!(got, want, "patch {id} at ({u}, {v})");
                rays += got.len();
                hits += got.iter().filter(|s| s.2.is_some()).count();
            }
        }
        assert!(hits > rays / 10, "{hits} of {rays} rays hit the teapot");
    }
}
