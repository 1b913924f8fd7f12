//! Continuity across patch seams: where two patches of one material meet along an edge of a
//! smooth surface (the teapot's body, a ceiling cut around its lamp), the radiosity is one
//! function of position, but each patch's grid extends its own samples to its edge (by a
//! parabola, §4.3), so the two grids disagree there and pass 2 shows a step. Welding gives
//! every grid vertex on such a seam the mean of the coincident vertices: the field is then
//! continuous across the seam, as on one patch.
//!
//! Vertices are coincident when their positions agree to a small fraction of the scene's size;
//! they are welded only between patches of the same material whose normals there agree (a
//! floor meets a wall in a crease whose two sides are lit differently, and a lamp meets the
//! ceiling with another exitance).

use crate::grid::Grid;
use crate::scene::{Scene, Sides};
use hemi_kernel::geometry::Vec3;
use hemi_kernel::patch::{Patch, Shape};
use std::collections::HashMap;

/// The normals of welded vertices agree at least this much (cos of about 11°).
const SMOOTH: f32 = 0.98;

/// Welds the boundary vertices of `grids` (one per scene patch) across the scene's seams.
pub fn weld(scene: &Scene, grids: &mut [Grid]) {
    let tolerance = 1e-4 * scene.extent();
    if !(tolerance > 0.0 && tolerance.is_finite()) {
        return;
    }
    let mut at: HashMap<(i64, i64, i64), Vec<Vertex>> = HashMap::new();
    for (i, grid) in grids.iter().enumerate() {
        for v in boundary(scene, i, grid.k()) {
            at.entry(key(v.position, tolerance)).or_default().push(v);
        }
    }
    let mut partners: HashMap<(usize, usize, usize), Vec<usize>> = HashMap::new();
    for group in at.values() {
        for (v, with) in weld_group(scene, grids, group) {
            partners.insert((v.patch, v.i, v.j), with);
        }
    }
    follow_coarser_edges(scene, grids, &partners);
}

/// Where a patch meets a coarser one (refinement doubles k patch by patch,
/// `crate::field::refine`), only every other vertex of its edge has a partner; the ones between
/// are made to follow the coarser edge, which is linear between its vertices, so the two edges
/// are one line and there is no step at the T-junctions. `partners` holds, per welded vertex
/// (patch, i, j), the patches it was welded with.
fn follow_coarser_edges(
    scene: &Scene,
    grids: &mut [Grid],
    partners: &HashMap<(usize, usize, usize), Vec<usize>>,
) {
    for (p, grid) in grids.iter_mut().enumerate() {
        let k = grid.k();
        if scene.patches[p].sides != Sides::Opaque || k < 2 {
            continue;
        }
        let edges: [Vec<(usize, usize)>; 4] = [
            (0..=k).map(|t| (t, 0)).collect(),
            (0..=k).map(|t| (t, k)).collect(),
            (0..=k).map(|t| (0, t)).collect(),
            (0..=k).map(|t| (k, t)).collect(),
        ];
        for edge in &edges {
            let anchors: Vec<usize> = (0..=k)
                .filter(|&t| partners.contains_key(&(p, edge[t].0, edge[t].1)))
                .collect();
            for pair in anchors.windows(2) {
                let (t0, t1) = (pair[0], pair[1]);
                let (a, b) = (edge[t0], edge[t1]);
                let shared = partners[&(p, a.0, a.1)]
                    .iter()
                    .any(|q| partners[&(p, b.0, b.1)].contains(q));
                if t1 - t0 < 2 || !shared {
                    continue;
                }
                let (va, vb) = (grid.vertex(a.0, a.1), grid.vertex(b.0, b.1));
                for (t, &(i, j)) in edge.iter().enumerate().take(t1).skip(t0 + 1) {
                    let f = (t - t0) as f64 / (t1 - t0) as f64;
                    grid.set_vertex(i, j, [0, 1, 2].map(|c| va[c] + f * (vb[c] - va[c])));
                }
            }
        }
    }
}

/// A vertex of a patch's grid: the patch, its (i, j), and where it is.
#[derive(Clone, Copy, Debug)]
struct Vertex {
    patch: usize,
    i: usize,
    j: usize,
    position: Vec3,
    normal: Vec3,
}

/// The vertices on the boundary of patch `i`'s k×k-cell grid (fronts of opaque patches only:
/// the sides of a translucent sheet pair up point by point already).
fn boundary(scene: &Scene, i: usize, k: usize) -> Vec<Vertex> {
    let p = &scene.patches[i];
    if p.sides != Sides::Opaque || k < 2 {
        return Vec::new();
    }
    let patch = Patch { shape: p.shape };
    let mut out = Vec::new();
    for j in 0..=k {
        for a in 0..=k {
            if a != 0 && a != k && j != 0 && j != k {
                continue;
            }
            let (u, v) = (a as f32 / k as f32, j as f32 / k as f32);
            let position = match &p.shape {
                Shape::Polygon(poly) => poly.point(u, v),
                Shape::Bezier(b) => b.point(u, v),
            };
            let normal = patch.normal_at(u, v);
            out.push(Vertex {
                patch: i,
                i: a,
                j,
                position,
                normal,
            });
        }
    }
    out
}

/// Averages one group of coincident vertices: each vertex with those of the other patches of
/// its material whose normals agree with its own. Returns the vertices welded, each with the
/// patches it was welded with.
fn weld_group(scene: &Scene, grids: &mut [Grid], group: &[Vertex]) -> Vec<(Vertex, Vec<usize>)> {
    let mut welded = Vec::new();
    if group.len() < 2 {
        return welded;
    }
    let values: Vec<[f64; 3]> = group
        .iter()
        .map(|v| grids[v.patch].vertex(v.i, v.j))
        .collect();
    for (n, v) in group.iter().enumerate() {
        let material = scene.patches[v.patch].material;
        let (mut sum, mut count, mut with) = (values[n], 1.0, Vec::new());
        for (m, w) in group.iter().enumerate() {
            let same = scene.patches[w.patch].material == material;
            if m != n && w.patch != v.patch && same && v.normal.dot(w.normal) >= SMOOTH {
                for c in 0..3 {
                    sum[c] += values[m][c];
                }
                count += 1.0;
                with.push(w.patch);
            }
        }
        if count > 1.0 {
            grids[v.patch].set_vertex(v.i, v.j, sum.map(|s| s / count));
            welded.push((*v, with));
        }
    }
    welded
}

/// The position quantised to cells of `tolerance`: a seam's two vertices, which coincide to far
/// less than that, land in one cell (a pair that happens to straddle a cell's face stays
/// unwelded).
fn key(p: Vec3, tolerance: f32) -> (i64, i64, i64) {
    let q = |x: f32| (x / tolerance).round() as i64;
    (q(p.x), q(p.y), q(p.z))
}
