//! Bicubic Bezier patches (paper §7) and their intersection by bounding-box subdivision (§6.1).
//!
//! A patch has 16 control points, row-major: `cp[4·r + c]`, c along u and r along v, so
//! `P(u,v) = Σ_r Σ_c B_r(v) B_c(u) cp[4r + c]` with the cubic Bernstein polynomials B. The
//! front side is the one `∂P/∂u × ∂P/∂v` points to. Only the four corners lie on the surface; the
//! surface lies inside the convex hull of the control points, so the axis-aligned box of the
//! control points bounds it, and so does the box of every sub-patch.
//!
//! Intersection (§6.1): pop a sub-patch, split it at the midpoints into four by de Casteljau,
//! test each child's control-point box against the ray (slab test), push the children that are
//! hit, nearest entry on top. The stack is an explicit bounded array, not recursion. At the
//! maximum depth, or when a box is smaller than the minimum size, the leaf's four corners (points
//! on the surface) are taken as a bilinear patch and intersected exactly: that gives t and
//! (u,v) to second order in the leaf size. A collapsed edge (a pole, as at the teapot's lid knob
//! and bottom) makes the leaf a triangle, which that test handles like any other.

use super::Vec3;

/// Largest subdivision depth the bounded stack supports.
pub const MAX_DEPTH: u32 = 16;
const STACK: usize = 3 * MAX_DEPTH as usize + 4;

/// A bicubic Bezier patch.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Bezier {
    /// Control points, row-major (c along u, r along v).
    pub cp: [Vec3; 16],
}

/// Termination of the subdivision.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Subdivision {
    /// Maximum depth (≤ [`MAX_DEPTH`]).
    pub max_depth: u32,
    /// A box whose largest side is below this (in scene units) is a leaf.
    pub min_box: f32,
    /// A sub-patch whose control points all lie within this fraction of the whole patch's size
    /// of the bilinear map of its four corners is a leaf: the surface then lies that close to
    /// the corner quad the leaf is intersected with (the paper's "accuracy criteria are met").
    pub flatness: f32,
}

impl Default for Subdivision {
    fn default() -> Self {
        Subdivision {
            max_depth: 10,
            min_box: 0.0,
            flatness: 1e-4,
        }
    }
}

fn bern(t: f32) -> [f32; 4] {
    let s = 1.0 - t;
    [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t]
}

fn bern_d(t: f32) -> [f32; 4] {
    let s = 1.0 - t;
    [
        -3.0 * s * s,
        3.0 * s * s - 6.0 * t * s,
        6.0 * t * s - 3.0 * t * t,
        3.0 * t * t,
    ]
}

/// Splits a cubic at t = ½ (de Casteljau), returning the left and right halves.
#[inline]
fn split(p: [Vec3; 4]) -> ([Vec3; 4], [Vec3; 4]) {
    let m = |a: Vec3, b: Vec3| (a + b) * 0.5;
    let p01 = m(p[0], p[1]);
    let p12 = m(p[1], p[2]);
    let p23 = m(p[2], p[3]);
    let a = m(p01, p12);
    let b = m(p12, p23);
    let c = m(a, b);
    ([p[0], p01, a, c], [c, b, p23, p[3]])
}

/// An axis-aligned box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Minimum corner.
    pub min: Vec3,
    /// Maximum corner.
    pub max: Vec3,
}

impl Aabb {
    /// The box of a set of points.
    pub fn of(points: &[Vec3]) -> Aabb {
        let mut b = Aabb {
            min: points[0],
            max: points[0],
        };
        for p in &points[1..] {
            b.min = b.min.min(*p);
            b.max = b.max.max(*p);
        }
        b
    }
    /// Largest side.
    pub fn size(&self) -> f32 {
        let d = self.max - self.min;
        d.x.max(d.y).max(d.z)
    }
    /// The slab test (§6.1): the ray's entry and exit distances, if `t_enter ≤ t_exit`,
    /// `t_exit ≥ t_min` and `t_enter < t_max`. A zero direction component is handled without
    /// dividing: the ray is then inside the slab or misses it.
    #[inline]
    pub fn slab(&self, o: Vec3, d: Vec3, t_min: f32, t_max: f32) -> Option<f32> {
        SlabRay::new(o, d).enter(self, t_min, t_max)
    }
}

/// A ray made ready for many slab tests: its inverse direction, computed once per ray instead
/// of once per box (the same quotients, so the same entry distances bit for bit).
#[derive(Clone, Copy, Debug)]
struct SlabRay {
    o: Vec3,
    d: Vec3,
    inv: [f32; 3],
}

impl SlabRay {
    #[inline]
    fn new(o: Vec3, d: Vec3) -> SlabRay {
        SlabRay {
            o,
            d,
            inv: [1.0 / d.x, 1.0 / d.y, 1.0 / d.z],
        }
    }

    /// [`SlabRay::enter`] of four boxes (a node's children) at once: the same arithmetic lane
    /// by lane, so the same bits, on the boxes' sides gathered axis by axis so that the lanes
    /// run side by side.
    #[inline]
    fn enter4(&self, boxes: &[Aabb; 4], t_min: f32, t_max: f32) -> [Option<f32>; 4] {
        let axis = |f: fn(&Aabb) -> Vec3| -> [[f32; 4]; 3] {
            let p: [Vec3; 4] = core::array::from_fn(|l| f(&boxes[l]));
            [
                [p[0].x, p[1].x, p[2].x, p[3].x],
                [p[0].y, p[1].y, p[2].y, p[3].y],
                [p[0].z, p[1].z, p[2].z, p[3].z],
            ]
        };
        let (lo, hi) = (axis(|b| b.min), axis(|b| b.max));
        let (o, d) = (
            [self.o.x, self.o.y, self.o.z],
            [self.d.x, self.d.y, self.d.z],
        );
        let mut enter = [f32::NEG_INFINITY; 4];
        let mut exit = [f32::INFINITY; 4];
        let mut inside = [true; 4];
        for k in 0..3 {
            let (ok, lo, hi) = (o[k], lo[k], hi[k]);
            if d[k] == 0.0 {
                for l in 0..4 {
                    inside[l] &= !(ok < lo[l] || ok > hi[l]);
                }
                continue;
            }
            let inv = self.inv[k];
            for l in 0..4 {
                let (a, c) = ((lo[l] - ok) * inv, (hi[l] - ok) * inv);
                let (a, c) = if a < c { (a, c) } else { (c, a) };
                // f32::max and min as plain selects (no NaN reaches them from finite boxes
                // and a finite inverse; at worst a zero's sign differs, which compares equal)
                enter[l] = if a > enter[l] { a } else { enter[l] };
                exit[l] = if c < exit[l] { c } else { exit[l] };
            }
        }
        core::array::from_fn(|l| {
            let (enter, exit) = (enter[l], exit[l]);
            (inside[l] && enter <= exit && exit >= t_min && enter < t_max).then(|| enter.max(t_min))
        })
    }

    /// [`Aabb::slab`] of this ray.
    #[inline]
    fn enter(&self, b: &Aabb, t_min: f32, t_max: f32) -> Option<f32> {
        let mut enter = f32::NEG_INFINITY;
        let mut exit = f32::INFINITY;
        let axes = [
            (self.o.x, self.d.x, b.min.x, b.max.x),
            (self.o.y, self.d.y, b.min.y, b.max.y),
            (self.o.z, self.d.z, b.min.z, b.max.z),
        ];
        for (k, (ok, dk, lo, hi)) in axes.into_iter().enumerate() {
            if dk == 0.0 {
                if ok < lo || ok > hi {
                    return None;
                }
            } else {
                let inv = self.inv[k];
                let (a, b) = ((lo - ok) * inv, (hi - ok) * inv);
                let (a, b) = if a < b { (a, b) } else { (b, a) };
                enter = enter.max(a);
                exit = exit.min(b);
            }
        }
        if enter <= exit && exit >= t_min && enter < t_max {
            Some(enter.max(t_min))
        } else {
            None
        }
    }
}

/// A nearest hit on a Bezier patch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BezierHit {
    /// Distance along the (unit) ray.
    pub t: f32,
    /// Parametric u.
    pub u: f32,
    /// Parametric v.
    pub v: f32,
}

/// A sub-patch waiting on the intersection's stack. Its control points are either a node of
/// the patch's [`BezierTree`] (`at`) or, below what the tree stores, on the stack of owned
/// control points beside it (both stacks are popped in the same order).
#[derive(Clone, Copy)]
struct Node {
    /// Index in the tree, or [`OWNED`].
    at: u32,
    u0: f32,
    v0: f32,
    size: f32,
    depth: u32,
    enter: f32,
    /// Largest side of this node's control-point box (computed once, in the parent's slab test).
    extent: f32,
}

impl Node {
    /// Child `k` (bit 0: the upper u half, bit 1: the upper v half), entered at `enter`.
    #[inline]
    fn child(&self, k: usize, at: u32, enter: f32, extent: f32) -> Node {
        let half = self.size * 0.5;
        let (cu, cv) = ((k & 1) as f32, (k >> 1) as f32);
        Node {
            at,
            u0: self.u0 + cu * half,
            v0: self.v0 + cv * half,
            size: half,
            depth: self.depth + 1,
            enter,
            extent,
        }
    }
}

/// The children a ray enters, as (entry, index), far to near: pushed in this order, the
/// nearest is examined first.
#[inline]
fn far_to_near(entered: [Option<f32>; 4]) -> ([(f32, usize); 4], usize) {
    let mut order = [(0.0, 0); 4];
    let mut n = 0;
    for (k, e) in entered.into_iter().enumerate() {
        if let Some(e) = e {
            order[n] = (e, k);
            n += 1;
        }
    }
    order[..n].sort_unstable_by(|a, b| b.0.total_cmp(&a.0));
    (order, n)
}

/// A [`Node`] whose control points are on the owned stack.
const OWNED: u32 = u32::MAX;

/// One stored sub-patch of a [`BezierTree`]: what a ray's descent reads at every node, kept
/// apart from the control points (read at leaves and where the stored levels end) so that
/// the four children's boxes share two cache lines.
#[derive(Clone, Copy, Debug)]
pub struct TreeNode {
    bounds: Aabb,
    /// Index of the first of the four children (stored consecutively), or 0 when the storage
    /// ended before them: they are then subdivided per ray, as without a tree.
    children: u32,
    /// The intersection stops here ([`Subdivision`]'s depth, size or flatness).
    leaf: bool,
}

impl Default for TreeNode {
    fn default() -> Self {
        TreeNode {
            bounds: Aabb {
                min: Vec3::ZERO,
                max: Vec3::ZERO,
            },
            children: 0,
            leaf: true,
        }
    }
}

/// A patch's first subdivision levels, computed once instead of once per ray: every ray that
/// reaches a patch descends from the same root through the same sub-patches, and splitting
/// them (de Casteljau, boxes, flatness) was most of a ray's cost. The sub-patches do not
/// depend on the ray, so the tree holds exactly the control points, boxes and leaf decisions
/// the per-ray subdivision computes: the hits are the same bits. Its storage is the caller's
/// (no allocation in the kernel); levels that do not fit are subdivided per ray.
#[derive(Clone, Copy, Debug)]
pub struct BezierTree<'s> {
    nodes: &'s [TreeNode],
    /// Each node's control points.
    cps: &'s [[Vec3; 16]],
    sub: Subdivision,
}

impl<'s> BezierTree<'s> {
    /// The tree in `nodes` and `cps`, as [`Bezier::build_tree`] stored them for `sub` (for
    /// storage that outlives the build, as a host's shared by threads).
    pub fn from_parts(
        nodes: &'s [TreeNode],
        cps: &'s [[Vec3; 16]],
        sub: Subdivision,
    ) -> BezierTree<'s> {
        let n = nodes.len().min(cps.len());
        BezierTree {
            nodes: &nodes[..n],
            cps: &cps[..n],
            sub,
        }
    }

    /// The number of stored sub-patches (the root first, then level by level).
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Whether nothing is stored (the storage given was empty).
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// The subdivision the tree was built for; intersections with another ignore the tree.
    pub fn subdivision(&self) -> Subdivision {
        self.sub
    }

    /// The patch's size (largest side of its control points' box), which hits are measured
    /// against, without recomputing the box.
    pub fn size(&self) -> Option<f32> {
        self.nodes.first().map(|n| n.bounds.size())
    }
}

/// Whether the subdivision stops at a sub-patch: at the depth or size limit, or where it is
/// flat to `flat_tol` (no sub-patch above depth 2 is flat enough to matter: not tested there).
#[inline]
fn is_leaf(cp: &[Vec3; 16], depth: u32, extent: f32, sub: &Subdivision, flat_tol: f32) -> bool {
    depth >= sub.max_depth.min(MAX_DEPTH)
        || extent <= sub.min_box
        || (depth >= 2 && flatness(cp) <= flat_tol)
}

impl Bezier {
    /// A patch from its 16 control points; `None` if any is not finite.
    pub fn new(cp: [Vec3; 16]) -> Option<Bezier> {
        cp.iter().all(|p| p.is_finite()).then_some(Bezier { cp })
    }

    /// P(u, v).
    pub fn point(&self, u: f32, v: f32) -> Vec3 {
        let (bu, bv) = (bern(u), bern(v));
        let mut p = Vec3::ZERO;
        for (row, wv) in self.cp.chunks_exact(4).zip(bv) {
            for (q, wu) in row.iter().zip(bu) {
                p += *q * (wv * wu);
            }
        }
        p
    }

    /// The normal at (u, v), or where that is singular (a pole) the limit from inside the
    /// patch: the normal a little way towards the patch centre.
    pub fn normal_near(&self, u: f32, v: f32) -> Option<Vec3> {
        self.normal(u, v).or_else(|| {
            [1e-3f32, 1e-2, 1e-1]
                .iter()
                .find_map(|s| self.normal(u + (0.5 - u) * s, v + (0.5 - v) * s))
        })
    }

    /// (∂P/∂u, ∂P/∂v) at (u, v).
    pub fn derivatives(&self, u: f32, v: f32) -> (Vec3, Vec3) {
        let (bu, bv, du, dv) = (bern(u), bern(v), bern_d(u), bern_d(v));
        let (mut pu, mut pv) = (Vec3::ZERO, Vec3::ZERO);
        for r in 0..4 {
            for c in 0..4 {
                let p = self.cp[4 * r + c];
                pu += p * (bv[r] * du[c]);
                pv += p * (dv[r] * bu[c]);
            }
        }
        (pu, pv)
    }

    /// The unit normal of the front side at (u, v), or `None` where the surface is singular
    /// (at a pole both derivatives are parallel or one vanishes).
    pub fn normal(&self, u: f32, v: f32) -> Option<Vec3> {
        let (pu, pv) = self.derivatives(u, v);
        let n = pu.cross(pv);
        let scale = pu.length() * pv.length();
        if n.length() > 1e-6 * scale && scale > 0.0 {
            n.try_normalize()
        } else {
            None
        }
    }

    /// The sub-patch over `[u0, u0+du] × [v0, v0+dv]` (by de Casteljau at the cell's bounds).
    pub fn sub_patch(&self, u0: f32, v0: f32, du: f32, dv: f32) -> Bezier {
        // Restrict each row in u, then each column in v, with the blossom-free two-cut method:
        // cut at a then rescale the right part at (b−a)/(1−a).
        let cut = |p: [Vec3; 4], a: f32, b: f32| -> [Vec3; 4] {
            let right = split_at(p, a).1;
            let t = if a < 1.0 { (b - a) / (1.0 - a) } else { 1.0 };
            split_at(right, t).0
        };
        let mut rows = [[Vec3::ZERO; 4]; 4];
        for (r, row) in rows.iter_mut().enumerate() {
            let p = [
                self.cp[4 * r],
                self.cp[4 * r + 1],
                self.cp[4 * r + 2],
                self.cp[4 * r + 3],
            ];
            *row = cut(p, u0, u0 + du);
        }
        let mut cp = [Vec3::ZERO; 16];
        for c in 0..4 {
            let col = cut(
                [rows[0][c], rows[1][c], rows[2][c], rows[3][c]],
                v0,
                v0 + dv,
            );
            for r in 0..4 {
                cp[4 * r + c] = col[r];
            }
        }
        Bezier { cp }
    }

    /// The box of the control points.
    pub fn bounds(&self) -> Aabb {
        Aabb::of(&self.cp)
    }

    /// The nearest intersection with `t_min < t < t_max` of the ray `o + t d` (d unit length).
    pub fn intersect(
        &self,
        o: Vec3,
        d: Vec3,
        t_min: f32,
        t_max: f32,
        sub: &Subdivision,
    ) -> Option<BezierHit> {
        self.intersect_in(None, o, d, t_min, t_max, sub)
    }

    /// [`Bezier::intersect`] starting from `tree`, this patch's precomputed subdivision
    /// ([`Bezier::build_tree`]; ignored if built for another `sub`): the same hit, without
    /// splitting the stored levels again.
    pub fn intersect_in(
        &self,
        tree: Option<&BezierTree<'_>>,
        o: Vec3,
        d: Vec3,
        t_min: f32,
        t_max: f32,
        sub: &Subdivision,
    ) -> Option<BezierHit> {
        let tree = tree.filter(|t| t.sub == *sub && !t.nodes.is_empty());
        let ray = SlabRay::new(o, d);
        let root = tree.map_or_else(|| self.bounds(), |t| t.nodes[0].bounds);
        let flat_tol = sub.flatness * root.size();
        let enter = ray.enter(&root, t_min, t_max)?;
        // heapless: nothing is initialised up front (an array of STACK nodes would copy 11 KiB
        // per ray)
        let mut stack: heapless::Vec<Node, STACK> = heapless::Vec::new();
        let mut owned: heapless::Vec<[Vec3; 16], STACK> = heapless::Vec::new();
        if tree.is_none() {
            let _ = owned.push(self.cp);
        }
        let _ = stack.push(Node {
            at: if tree.is_some() { 0 } else { OWNED },
            u0: 0.0,
            v0: 0.0,
            size: 1.0,
            depth: 0,
            enter,
            extent: root.size(),
        });
        let (nodes, cps) = tree.map_or((&[][..], &[][..]), |t| (t.nodes, t.cps));
        let mut best: Option<BezierHit> = None;
        let mut best_t = t_max;
        let mut popped;
        while let Some(node) = stack.pop() {
            let stored = nodes.get(node.at as usize);
            let cp = match cps.get(node.at as usize) {
                Some(cp) => cp,
                None => {
                    popped = owned.pop().unwrap_or(self.cp);
                    &popped
                }
            };
            if node.enter >= best_t {
                continue;
            }
            let leaf = match stored {
                Some(stored) => stored.leaf,
                None => is_leaf(cp, node.depth, node.extent, sub, flat_tol),
            };
            if leaf {
                if let Some((t, s, r)) = leaf_hit(cp, o, d, t_min, best_t) {
                    best_t = t;
                    best = Some(BezierHit {
                        t,
                        u: node.u0 + s * node.size,
                        v: node.v0 + r * node.size,
                    });
                }
                continue;
            }
            // four children, pushed far-to-near so the nearest is examined first
            let first = stored.map_or(0, |n| n.children);
            let split = (first == 0).then(|| quarter(cp));
            let boxes: [Aabb; 4] = match &split {
                Some(q) => core::array::from_fn(|k| box_of(&q[k])),
                None => core::array::from_fn(|k| nodes[first as usize + k].bounds),
            };
            let (order, n) = far_to_near(ray.enter4(&boxes, t_min, best_t));
            for &(e, k) in &order[..n] {
                // depth-first with at most 3 siblings pending per level: STACK is never exceeded
                let at = match &split {
                    Some(q) => {
                        let _ = owned.push(q[k]);
                        OWNED
                    }
                    None => first + k as u32,
                };
                let _ = stack.push(node.child(k, at, e, boxes[k].size()));
            }
        }
        best
    }

    /// Stores this patch's subdivision for `sub` in `nodes` and `cps` (their control points),
    /// level by level, as far as both hold (a node's four children are stored together or not
    /// at all): see [`BezierTree`].
    pub fn build_tree<'s>(
        &self,
        sub: &Subdivision,
        nodes: &'s mut [TreeNode],
        cps: &'s mut [[Vec3; 16]],
    ) -> BezierTree<'s> {
        let cap = nodes.len().min(cps.len()).min(u32::MAX as usize);
        let root = self.bounds();
        let flat_tol = sub.flatness * root.size();
        let mut len = 0usize;
        if cap > 0 {
            nodes[0] = TreeNode {
                bounds: root,
                children: 0,
                leaf: is_leaf(&self.cp, 0, root.size(), sub, flat_tol),
            };
            cps[0] = self.cp;
            len = 1;
        }
        // level by level: node i's depth follows from where each level ends
        let (mut level_end, mut level) = (len, 0u32);
        let mut i = 0;
        while i < len {
            if i == level_end {
                level += 1;
                level_end = len;
            }
            if !nodes[i].leaf && len + 4 <= cap {
                nodes[i].children = len as u32;
                for child in quarter(&cps[i]) {
                    let bounds = box_of(&child);
                    nodes[len] = TreeNode {
                        bounds,
                        children: 0,
                        leaf: is_leaf(&child, level + 1, bounds.size(), sub, flat_tol),
                    };
                    cps[len] = child;
                    len += 1;
                }
            }
            i += 1;
        }
        BezierTree {
            nodes: &nodes[..len],
            cps: &cps[..len],
            sub: *sub,
        }
    }
}

fn split_at(p: [Vec3; 4], t: f32) -> ([Vec3; 4], [Vec3; 4]) {
    let l = |a: Vec3, b: Vec3| a.lerp(b, t);
    let p01 = l(p[0], p[1]);
    let p12 = l(p[1], p[2]);
    let p23 = l(p[2], p[3]);
    let a = l(p01, p12);
    let b = l(p12, p23);
    let c = l(a, b);
    ([p[0], p01, a, c], [c, b, p23, p[3]])
}

/// The box of a sub-patch's control points, as [`Aabb::of`] but by plain comparisons:
/// control points are finite (checked by [`Bezier::new`]), so `f32::min`'s NaN handling, four
/// times the instructions, only ever chose a zero's sign. A per-ray split computes four.
#[inline]
fn box_of(cp: &[Vec3; 16]) -> Aabb {
    let (mut min, mut max) = (cp[0], cp[0]);
    for p in &cp[1..] {
        min.x = if p.x < min.x { p.x } else { min.x };
        min.y = if p.y < min.y { p.y } else { min.y };
        min.z = if p.z < min.z { p.z } else { min.z };
        max.x = if p.x > max.x { p.x } else { max.x };
        max.y = if p.y > max.y { p.y } else { max.y };
        max.z = if p.z > max.z { p.z } else { max.z };
    }
    Aabb { min, max }
}

/// How far the control points stray from the bilinear map of the four corners (max norm).
fn flatness(cp: &[Vec3; 16]) -> f32 {
    let (p00, p10, p01, p11) = (cp[0], cp[3], cp[12], cp[15]);
    let mut worst = 0.0f32;
    for r in 0..4 {
        let v = r as f32 / 3.0;
        let a = p00.lerp(p01, v);
        let b = p10.lerp(p11, v);
        for c in 0..4 {
            let d = cp[4 * r + c] - a.lerp(b, c as f32 / 3.0);
            worst = worst.max(d.x.abs().max(d.y.abs()).max(d.z.abs()));
        }
    }
    worst
}

/// The four children of a patch at the parametric midpoints: index bit 0 = upper u half,
/// bit 1 = upper v half.
fn quarter(cp: &[Vec3; 16]) -> [[Vec3; 16]; 4] {
    let mut left = [Vec3::ZERO; 16];
    let mut right = [Vec3::ZERO; 16];
    for r in 0..4 {
        let (a, b) = split([cp[4 * r], cp[4 * r + 1], cp[4 * r + 2], cp[4 * r + 3]]);
        left[4 * r..4 * r + 4].copy_from_slice(&a);
        right[4 * r..4 * r + 4].copy_from_slice(&b);
    }
    let mut out = [[Vec3::ZERO; 16]; 4];
    for (h, half) in [left, right].iter().enumerate() {
        for c in 0..4 {
            let (a, b) = split([half[c], half[4 + c], half[8 + c], half[12 + c]]);
            for r in 0..4 {
                out[h][4 * r + c] = a[r];
                out[2 + h][4 * r + c] = b[r];
            }
        }
    }
    out
}

/// Ray against the leaf's bilinear corner patch, as the two triangles (P00, P10, P11) and
/// (P00, P11, P01): returns t and the leaf-local (s, r) in [0,1]². Two-sided.
fn leaf_hit(cp: &[Vec3; 16], o: Vec3, d: Vec3, t_min: f32, t_max: f32) -> Option<(f32, f32, f32)> {
    let (p00, p10, p01, p11) = (cp[0], cp[3], cp[12], cp[15]);
    let mut best: Option<(f32, f32, f32)> = None;
    let mut best_t = t_max;
    // triangle A: P00 → P10 → P11 maps (s, r) = (b1 + b2, b2)
    if let Some((t, b1, b2)) = triangle(o, d, p00, p10, p11) {
        if t > t_min && t < best_t {
            best_t = t;
            best = Some((t, b1 + b2, b2));
        }
    }
    // triangle B: P00 → P11 → P01 maps (s, r) = (b1, b1 + b2)
    if let Some((t, b1, b2)) = triangle(o, d, p00, p11, p01) {
        if t > t_min && t < best_t {
            best = Some((t, b1, b1 + b2));
        }
    }
    best.map(|(t, s, r)| (t, s.clamp(0.0, 1.0), r.clamp(0.0, 1.0)))
}

/// Möller–Trumbore, two-sided, with a small tolerance on the barycentric bounds so that rays
/// through a shared leaf edge are not lost between two leaves. Degenerate triangles miss.
fn triangle(o: Vec3, d: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Option<(f32, f32, f32)> {
    const EPS: f32 = 1e-6;
    let e1 = b - a;
    let e2 = c - a;
    let p = d.cross(e2);
    let det = e1.dot(p);
    let scale = e1.length() * e2.length();
    if det.is_nan() || det.abs() <= 1e-12 * scale {
        return None;
    }
    let inv = 1.0 / det;
    let s = o - a;
    let b1 = s.dot(p) * inv;
    if !(-EPS..=1.0 + EPS).contains(&b1) {
        return None;
    }
    let q = s.cross(e1);
    let b2 = d.dot(q) * inv;
    if b2 < -EPS || b1 + b2 > 1.0 + EPS {
        return None;
    }
    Some((e2.dot(q) * inv, b1, b2))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flat() -> Bezier {
        let mut cp = [Vec3::ZERO; 16];
        for r in 0..4 {
            for c in 0..4 {
                cp[4 * r + c] = Vec3::new(c as f32 / 3.0, r as f32 / 3.0, 0.0);
            }
        }
        Bezier { cp }
    }

    #[test]
    fn a_flat_patch_is_the_unit_square() {
        let b = flat();
        let p = b.point(0.3, 0.8);
        assert!((p - Vec3::new(0.3, 0.8, 0.0)).length() < 1e-6);
        assert!((b.normal(0.5, 0.5).unwrap() - Vec3::Z).length() < 1e-6);
        let h = b
            .intersect(
                Vec3::new(0.3, 0.8, 1.0),
                Vec3::new(0.0, 0.0, -1.0),
                0.0,
                f32::INFINITY,
                &Subdivision::default(),
            )
            .unwrap();
        assert!(
            (h.t - 1.0).abs() < 1e-5 && (h.u - 0.3).abs() < 1e-4 && (h.v - 0.8).abs() < 1e-4,
            "{h:?}"
        );
        // parallel to a slab, outside it: miss without NaN
        assert!(b
            .intersect(
                Vec3::new(0.5, 2.0, 1.0),
                Vec3::new(0.0, 0.0, -1.0),
                0.0,
                f32::INFINITY,
                &Subdivision::default()
            )
            .is_none());
    }

    #[test]
    fn sub_patches_match_the_parent() {
        let mut b = flat();
        b.cp[5].z = 0.7;
        b.cp[10].z = -0.4;
        let s = b.sub_patch(0.25, 0.5, 0.5, 0.25);
        for (u, v) in [(0.0, 0.0), (0.3, 0.9), (1.0, 1.0)] {
            let a = s.point(u, v);
            let want = b.point(0.25 + 0.5 * u, 0.5 + 0.25 * v);
            assert!((a - want).length() < 1e-5);
        }
        let q = quarter(&b.cp);
        let want = b.sub_patch(0.5, 0.5, 0.5, 0.5);
        for (a, b) in q[3].iter().zip(&want.cp) {
            assert!((*a - *b).length() < 1e-6);
        }
    }

    /// A curved patch: a bump with twisted corners, so that boxes overlap and rays descend
    /// into several children.
    fn bumpy() -> Bezier {
        let mut b = flat();
        b.cp[5].z = 0.9;
        b.cp[6].z = -0.5;
        b.cp[9].z = 0.4;
        b.cp[10].z = 1.1;
        b.cp[3].z = 0.3;
        b.cp[12].z = -0.2;
        b
    }

    #[test]
    fn a_stored_tree_gives_the_hits_of_per_ray_subdivision_bit_for_bit() {
        let b = bumpy();
        let sub = Subdivision::default();
        let mut state = 0x9e37_79b9_u32;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            state as f32 / u32::MAX as f32
        };
        // trees cut short at every level, down to the whole tree
        for cap in [1usize, 3, 5, 21, 85, 341, 1365, 5461] {
            let mut nodes = std::vec![TreeNode::default(); cap];
            let mut cps = std::vec![[Vec3::ZERO; 16]; cap];
            let tree = b.build_tree(&sub, &mut nodes, &mut cps);
            assert!(tree.len() <= cap && (cap < 5 || tree.len() >= 5));
            let mut hits = 0;
            for _ in 0..400 {
                let o = Vec3::new(next() * 2.0 - 0.5, next() * 2.0 - 0.5, 2.0 + next());
                let target = Vec3::new(next(), next(), next() * 0.6 - 0.1);
                let d = (target - o).try_normalize().unwrap();
                let want = b.intersect(o, d, 0.0, f32::INFINITY, &sub);
                let got = b.intersect_in(Some(&tree), o, d, 0.0, f32::INFINITY, &sub);
                assert_eq!(
                    want.map(|h| (h.t.to_bits(), h.u.to_bits(), h.v.to_bits())),
                    got.map(|h| (h.t.to_bits(), h.u.to_bits(), h.v.to_bits())),
                    "{cap} nodes, ray {o:?} {d:?}"
                );
                hits += want.is_some() as usize;
            }
            assert!(hits > 200, "{hits} of 400 rays hit");
        }
        // a tree built for another subdivision is not used (the hits are those of `sub`)
        let coarse = Subdivision {
            max_depth: 3,
            ..sub
        };
        let mut nodes = [TreeNode::default(); 85];
        let mut cps = [[Vec3::ZERO; 16]; 85];
        let tree = b.build_tree(&coarse, &mut nodes, &mut cps);
        let (o, d) = (Vec3::new(0.4, 0.6, 3.0), Vec3::new(0.0, 0.0, -1.0));
        assert_eq!(
            b.intersect_in(Some(&tree), o, d, 0.0, f32::INFINITY, &sub),
            b.intersect(o, d, 0.0, f32::INFINITY, &sub)
        );
    }
}
