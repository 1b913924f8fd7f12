//! Direct light from the emitters at a point, by exact form factors with shadow rays.
//!
//! A hemisphere of R circles sees a small lamp through a handful of rays, so the light it
//! gathers from it jumps with R and with the point (a quantisation of a few per cent at the
//! Cornell box's floor). Here each emitting polygon j is cut into m × m cells; a cell's form
//! factor from the point is exact, by Lambert's contour integral over its edges,
//!
//! ```text
//!     F_cell = 1/(2π) Σ_k θ_k · n·(a_k × a_k+1)/|a_k × a_k+1|,    a_k the unit vectors to its corners,
//! ```
//!
//! (the cell clipped to the point's horizon first), one shadow ray to its centre says whether
//! it is seen, and the light it sends is its radiosity there, B_j(u,v) of the emitter's grid:
//! `E_direct = Σ_cells V · F_cell · B_j`. Unoccluded, the sum is the polygon's exact form
//! factor. A cell on a shadow's edge (its ray's verdict differs from a neighbour's) would be
//! counted all in or all out, which for a point that sees a sliver of the lamp past an edge
//! (the paper screen's cube, under the screen's top) is off by tens of per cent: it is cut
//! into [`EDGE_SPLIT`]² cells with a ray each, so a penumbra is resolved to 1/64 of the lamp.
//! A sliver along the lamp's rim, which no cell centre sees, is found by probes on the rim.
//! The rest of the light — everything but the
//! emitters' own surfaces seen directly — still comes from the hemisphere ([`crate::irradiance`]).

use crate::backend::Backend;
use crate::grid::Grid;
use crate::scene::Scene;
use hemi_kernel::accel::Ray;
use hemi_kernel::geometry::{Polygon, Vec3};
use hemi_kernel::patch::Shape;
use rayon::prelude::*;

/// Where the emitters' direct light comes from, at a point query and in the field's sweeps.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Direct {
    /// From the hemisphere's rays, as all other light (the paper's gather).
    Hemisphere,
    /// From exact form factors to the emitting polygons with shadow rays (this module), where
    /// [`applies`]; the hemisphere elsewhere.
    #[default]
    Exact,
}

/// Whether exact direct light can be had on `backend`'s scene: single rays for the shadows,
/// and no specular surface (a mirror's image of a lamp only the hemisphere's frustums see, and
/// a hemisphere's report does not say whether it came through a mirror).
pub fn applies(backend: &dyn Backend) -> bool {
    let specular = backend
        .scene()
        .materials
        .iter()
        .any(|m| m.reflects() || m.transmits());
    backend.casts_single_rays() && !specular
}

/// Cells per side of an emitter: 64 shadow rays per emitter and point.
pub const CELLS: u32 = 8;

/// The scene's emitters that direct light is computed for: the polygons that emit.
#[derive(Clone, Debug)]
pub struct Emitters {
    /// (scene patch, its polygon).
    list: Vec<(usize, Polygon)>,
    /// Per scene patch: whether it is one of `list` (its direct light is not gathered again).
    handled: Vec<bool>,
    /// How far from a surface a shadow ray starts, and how close to the cell it may end.
    epsilon: f32,
}

impl Emitters {
    /// The emitting polygons of `scene` (a Bezier emitter stays with the hemisphere).
    pub fn of(scene: &Scene) -> Emitters {
        let mut handled = vec![false; scene.patches.len()];
        let mut list = Vec::new();
        for (i, p) in scene.patches.iter().enumerate().take(scene.fronts()) {
            if let Shape::Polygon(poly) = p.shape {
                let lit = scene.material_of(i).emission.iter().any(|e| *e > 0.0);
                if lit {
                    handled[i] = true;
                    list.push((i, poly));
                }
            }
        }
        let epsilon = scene.ray_offset();
        Emitters {
            list,
            handled,
            epsilon,
        }
    }

    /// Whether the light of scene patch `side` seen directly is computed here.
    pub fn handles(&self, side: usize) -> bool {
        self.handled.get(side).copied().unwrap_or(false)
    }

    /// Per scene patch, whether its light seen directly is computed here (see [`Emitters::handles`]).
    pub fn handled(&self) -> &[bool] {
        &self.handled
    }

    /// The direct irradiance from every emitter, per channel, at each (point, normal), with
    /// every point's shadow rays cast in one request ([`Emitters::paths`], then
    /// [`DirectPaths::irradiance`]).
    pub fn irradiance(
        &self,
        backend: &dyn Backend,
        grids: &[Grid],
        at: &[(Vec3, Vec3)],
    ) -> anyhow::Result<Vec<[f64; 3]>> {
        self.paths(backend, at)?.irradiance(grids)
    }

    /// The emitter cells each (point, normal) sees, with their form factors: the geometry and
    /// the shadows, which do not change while the field's sweeps change the emitters' radiosity.
    /// A cell whose shadow ray disagrees with a neighbour's (or with a probe on the lamp's rim)
    /// holds a shadow's edge, and one ray would count it all in or all out: it is cut into
    /// [`EDGE_SPLIT`]² cells with a ray each.
    pub fn paths(&self, backend: &dyn Backend, at: &[(Vec3, Vec3)]) -> anyhow::Result<DirectPaths> {
        // the cells' form factors are most of the work for a small lamp: every core takes a share
        let cells: Vec<Vec<Cell>> = at.par_iter().map(|&(p, n)| self.cells(p, n)).collect();
        // the cells' centres and their rim probes in one request
        let probes: Vec<Vec<(usize, Cell)>> = at
            .iter()
            .zip(&cells)
            .map(|(&(p, n), c)| rim_probes(&self.list, c, p, n))
            .collect();
        let cast: Vec<Vec<Cell>> = cells
            .iter()
            .zip(&probes)
            .map(|(c, p)| c.iter().copied().chain(p.iter().map(|(_, r)| *r)).collect())
            .collect();
        let visible = self.shadow_rays(backend, at, &cast)?;
        let (edges, mut seen): (Vec<Vec<Cell>>, Vec<Vec<Cell>>) = at
            .par_iter()
            .zip(&cells)
            .zip(&probes)
            .zip(&visible)
            .map(|(((&(p, n), cells), probes), visible)| {
                let (centres, rims) = visible.split_at(cells.len());
                let edge = on_shadow_edge(cells, centres, probes, rims);
                self.sort_cells(cells, centres, &edge, p, n)
            })
            .unzip();
        let visible = self.shadow_rays(backend, at, &edges)?;
        for ((kept, finer), visible) in seen.iter_mut().zip(edges).zip(visible) {
            kept.extend(
                finer
                    .into_iter()
                    .zip(visible)
                    .filter(|(_, v)| *v)
                    .map(|(c, _)| c),
            );
        }
        Ok(DirectPaths { seen })
    }

    /// One point's cells after their shadow rays: (the finer cells of those on a shadow's edge,
    /// to be cast again; the seen cells off any edge).
    fn sort_cells(
        &self,
        cells: &[Cell],
        visible: &[bool],
        edge: &[bool],
        p: Vec3,
        n: Vec3,
    ) -> (Vec<Cell>, Vec<Cell>) {
        let mut finer = Vec::new();
        let mut kept = Vec::new();
        for ((cell, &v), &e) in cells.iter().zip(visible).zip(edge) {
            match (e, v) {
                (true, _) => finer.extend(self.split(cell, p, n)),
                (false, true) => kept.push(*cell),
                (false, false) => {}
            }
        }
        (finer, kept)
    }

    /// Casts one shadow ray from each point to the centre of each of its cells (all points in
    /// one request) and says which cells it reached.
    fn shadow_rays(
        &self,
        backend: &dyn Backend,
        at: &[(Vec3, Vec3)],
        cells: &[Vec<Cell>],
    ) -> anyhow::Result<Vec<Vec<bool>>> {
        let mut rays = Vec::new();
        for (&(point, normal), cells) in at.iter().zip(cells) {
            let origin = point + normal * self.epsilon;
            rays.extend(cells.iter().map(|c| Ray {
                origin,
                dir: (c.centre - origin).try_normalize().unwrap_or(normal),
            }));
        }
        let mut hits = backend.nearest(&rays)?.into_iter();
        let mut out = Vec::with_capacity(at.len());
        for (&(point, normal), cells) in at.iter().zip(cells) {
            let origin = point + normal * self.epsilon;
            let reached = cells.iter().zip(hits.by_ref()).map(|(cell, hit)| {
                let distance = (cell.centre - origin).length();
                hit.is_some_and(|h| {
                    h.patch as usize == cell.patch && h.t > distance - 10.0 * self.epsilon
                })
            });
            out.push(reached.collect());
        }
        Ok(out)
    }

    /// Every emitter cell in front of the point, with its exact form factor.
    fn cells(&self, point: Vec3, normal: Vec3) -> Vec<Cell> {
        let mut out = Vec::new();
        for (emitter, &(patch, poly)) in self.list.iter().enumerate() {
            // emitters shine from their front only
            if (point - poly.v[0]).dot(poly.normal) <= 0.0 {
                continue;
            }
            for b in 0..CELLS {
                for a in 0..CELLS {
                    let cell = cell_of(&poly, (emitter, patch), (a, b), CELLS);
                    out.extend(cell.seen_from(point, normal));
                }
            }
        }
        out
    }

    /// The [`EDGE_SPLIT`]² cells `cell` is cut into, with their form factors from the point.
    fn split(&self, cell: &Cell, point: Vec3, normal: Vec3) -> Vec<Cell> {
        let Some(&(_, poly)) = self.list.get(cell.emitter) else {
            return Vec::new();
        };
        let n = cell.n * EDGE_SPLIT;
        let (a0, b0) = (cell.a * EDGE_SPLIT, cell.b * EDGE_SPLIT);
        (0..EDGE_SPLIT * EDGE_SPLIT)
            .filter_map(|k| {
                let (a, b) = (a0 + k % EDGE_SPLIT, b0 + k / EDGE_SPLIT);
                cell_of(&poly, (cell.emitter, cell.patch), (a, b), n).seen_from(point, normal)
            })
            .collect()
    }
}

/// Which cells lie on a shadow's edge: a cell whose shadow ray's verdict differs from that of a
/// cell next to it on the same emitter (cells of the first lattice, [`CELLS`] per side), or
/// from that of one of its rim probes ([`rim_probes`], with their verdicts `rims`).
fn on_shadow_edge(
    cells: &[Cell],
    visible: &[bool],
    probes: &[(usize, Cell)],
    rims: &[bool],
) -> Vec<bool> {
    let mut edge = by_neighbours(cells, visible);
    for (&(i, _), &v) in probes.iter().zip(rims) {
        edge[i] |= v != visible[i];
    }
    edge
}

/// The cells whose shadow ray's verdict differs from a neighbour's.
fn by_neighbours(cells: &[Cell], visible: &[bool]) -> Vec<bool> {
    let verdict: std::collections::HashMap<(usize, u32, u32), bool> = cells
        .iter()
        .zip(visible)
        .map(|(c, &v)| ((c.patch, c.a, c.b), v))
        .collect();
    cells
        .iter()
        .zip(visible)
        .map(|(c, &v)| {
            let (a, b) = (c.a as i64, c.b as i64);
            [(a - 1, b), (a + 1, b), (a, b - 1), (a, b + 1)]
                .iter()
                .filter(|(x, y)| *x >= 0 && *y >= 0)
                .filter_map(|&(x, y)| verdict.get(&(c.patch, x as u32, y as u32)))
                .any(|&w| w != v)
        })
        .collect()
}

/// Where a cell on an emitter's rim is probed: the midpoint of each of its outer edges, 2 %
/// of a cell inside (closer, a ray aimed at the lamp may meet the coplanar ceiling beside it,
/// and every rim cell would be split for nothing). A point that sees only a sliver of the lamp
/// along its rim (an occluder's edge nearly parallel to the lamp's, less than half a cell in)
/// has every cell centre blocked, so no two neighbours disagree; a probe on the rim that
/// disagrees with its cell's centre marks the cell as on a shadow's edge all the same (on the
/// Cornell box's floor by the red wall, in the tall block's penumbra, the direct light was 27 %
/// low without them). The probes are copies of their cell with the centre moved (only the
/// centre is cast), with the cell's index. A probe below the point's horizon (`p`, `n`) is not
/// cast: it cannot be seen, so it would disagree with a visible centre and split a cell whose
/// clipped form factor is already exact.
fn rim_probes(list: &[(usize, Polygon)], cells: &[Cell], p: Vec3, n: Vec3) -> Vec<(usize, Cell)> {
    let mut out = Vec::new();
    for (i, c) in cells.iter().enumerate() {
        let Some((_, poly)) = list.get(c.emitter) else {
            continue;
        };
        let d = 1.0 / c.n as f32;
        let inset = 0.02 * d;
        let (um, vm) = ((c.a as f32 + 0.5) * d, (c.b as f32 + 0.5) * d);
        let last = c.n - 1;
        let rim = [
            (c.a == 0).then_some((inset, vm)),
            (c.a == last).then_some((1.0 - inset, vm)),
            (c.b == 0).then_some((um, inset)),
            (c.b == last).then_some((um, 1.0 - inset)),
        ];
        for (u, v) in rim.into_iter().flatten() {
            let centre = poly.point(u, v);
            if (centre - p).dot(n) > 0.0 {
                out.push((i, Cell { centre, ..*c }));
            }
        }
    }
    out
}

/// The emitter cells some points see (after their shadow rays), with their form factors.
#[derive(Clone, Debug)]
pub struct DirectPaths {
    seen: Vec<Vec<Cell>>,
}

impl DirectPaths {
    /// Points held.
    pub fn len(&self) -> usize {
        self.seen.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.seen.is_empty()
    }

    /// The paths of points picked from `sources` in the order `picks` gives, as (source,
    /// point): how a refined element list keeps the shadow rays of the elements it kept.
    pub fn assemble(sources: &[&DirectPaths], picks: &[(usize, usize)]) -> DirectPaths {
        DirectPaths {
            seen: picks
                .iter()
                .map(|&(s, p)| sources[s].seen[p].clone())
                .collect(),
        }
    }

    /// Each point's direct irradiance, `Σ_cells F_cell · B_emitter(u, v)` over the cells it
    /// sees, with the emitters' radiosity read off `grids`.
    pub fn irradiance(&self, grids: &[Grid]) -> anyhow::Result<Vec<[f64; 3]>> {
        self.seen
            .iter()
            .map(|cells| {
                let mut e = [0.0f64; 3];
                for cell in cells {
                    let b = crate::grid::grid_of(grids, cell.patch)?.at(cell.u, cell.v);
                    for c in 0..3 {
                        e[c] += cell.form_factor * b[c];
                    }
                }
                Ok(e)
            })
            .collect()
    }
}

/// One cell of an emitter: cell (a, b) of its n×n lattice in (u, v).
#[derive(Clone, Copy, Debug)]
struct Cell {
    /// Index into [`Emitters`]' list, and the scene patch.
    emitter: usize,
    patch: usize,
    a: u32,
    b: u32,
    n: u32,
    corners: [Vec3; 4],
    centre: Vec3,
    u: f32,
    v: f32,
    form_factor: f64,
}

impl Cell {
    /// The cell with its form factor from `point` (normal `normal`), if it is above the
    /// point's horizon.
    fn seen_from(self, point: Vec3, normal: Vec3) -> Option<Cell> {
        let form_factor = form_factor(point, normal, &self.corners);
        (form_factor > 0.0).then_some(Cell {
            form_factor,
            ..self
        })
    }
}

/// Cells per side a cell on a shadow's edge is cut into: the edge is then resolved to
/// 1/([`CELLS`]·`EDGE_SPLIT`) of the emitter.
pub const EDGE_SPLIT: u32 = 8;

/// Cell (a, b) of the n×n lattice of `poly`'s (u,v) map (emitter `emitter`, scene patch `patch`).
fn cell_of(poly: &Polygon, (emitter, patch): (usize, usize), (a, b): (u32, u32), n: u32) -> Cell {
    let d = 1.0 / n as f32;
    let (u0, v0) = (a as f32 * d, b as f32 * d);
    let corners = [
        poly.point(u0, v0),
        poly.point(u0 + d, v0),
        poly.point(u0 + d, v0 + d),
        poly.point(u0, v0 + d),
    ];
    let (u, v) = (u0 + 0.5 * d, v0 + 0.5 * d);
    Cell {
        emitter,
        patch,
        a,
        b,
        n,
        corners,
        centre: poly.point(u, v),
        u,
        v,
        form_factor: 0.0,
    }
}

type V3 = [f64; 3];

fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn f64s(v: Vec3) -> V3 {
    [v.x as f64, v.y as f64, v.z as f64]
}

/// The form factor from a differential area at `point` (normal `normal`) to the planar polygon
/// `corners`, by Lambert's contour integral, over the part of the polygon above the point's
/// horizon (clipped to it). Zero for a polygon wholly below it.
pub fn form_factor(point: Vec3, normal: Vec3, corners: &[Vec3]) -> f64 {
    let (p, n) = (f64s(point), f64s(normal));
    let rel: Vec<V3> = corners.iter().map(|c| sub(f64s(*c), p)).collect();
    let clipped = clip_to_horizon(&rel, n);
    if clipped.len() < 3 {
        return 0.0;
    }
    let mut sum = 0.0;
    for k in 0..clipped.len() {
        let (a, b) = (clipped[k], clipped[(k + 1) % clipped.len()]);
        let (la, lb) = (dot(a, a).sqrt(), dot(b, b).sqrt());
        if la == 0.0 || lb == 0.0 {
            continue;
        }
        let g = cross(a, b);
        let lg = dot(g, g).sqrt();
        if lg == 0.0 {
            continue; // a collapsed edge (a triangle's cells near its apex)
        }
        let theta = (dot(a, b) / (la * lb)).clamp(-1.0, 1.0).acos();
        sum += theta * dot(n, g) / lg;
    }
    (sum / (2.0 * std::f64::consts::PI)).abs()
}

/// The polygon `rel` (corners relative to the point) clipped to the half-space above the
/// tangent plane of normal `n` (Sutherland–Hodgman against one plane).
fn clip_to_horizon(rel: &[V3], n: V3) -> Vec<V3> {
    let eps = 1e-12;
    let mut out = Vec::with_capacity(rel.len() + 1);
    for k in 0..rel.len() {
        let (a, b) = (rel[k], rel[(k + 1) % rel.len()]);
        let (da, db) = (dot(a, n), dot(b, n));
        if da > eps {
            out.push(a);
        }
        if (da > eps) != (db > eps) {
            let t = da / (da - db);
            out.push([
                a[0] + t * (b[0] - a[0]),
                a[1] + t * (b[1] - a[1]),
                a[2] + t * (b[2] - a[2]),
            ]);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_square_straight_above_gives_howells_b3() {
        // unit square at height 1, its corner above the point: Howell's B-3 closed form
        let corners = [
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(0.0, 1.0, 1.0),
        ];
        let f = form_factor(Vec3::ZERO, Vec3::new(0.0, 0.0, 1.0), &corners);
        let want = crate::analytic::element_to_parallel_rectangle_corner(1.0, 1.0, 1.0);
        assert!((f - want).abs() < 1e-6 * want, "{f} vs {want}");
    }

    #[test]
    fn a_polygon_below_the_horizon_gives_nothing_and_one_across_it_half() {
        let n = Vec3::new(0.0, 0.0, 1.0);
        let below = [
            Vec3::new(-1.0, -1.0, -1.0),
            Vec3::new(1.0, -1.0, -1.0),
            Vec3::new(1.0, 1.0, -1.0),
            Vec3::new(-1.0, 1.0, -1.0),
        ];
        assert_eq!(form_factor(Vec3::ZERO, n, &below), 0.0);
        // a vertical wall across the horizon: only its upper half is seen
        let wall = [
            Vec3::new(-1.0, 1.0, -1.0),
            Vec3::new(1.0, 1.0, -1.0),
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(-1.0, 1.0, 1.0),
        ];
        let upper = [
            Vec3::new(-1.0, 1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(-1.0, 1.0, 1.0),
        ];
        let (a, b) = (
            form_factor(Vec3::ZERO, n, &wall),
            form_factor(Vec3::ZERO, n, &upper),
        );
        assert!(a > 0.0 && (a - b).abs() < 1e-9, "{a} vs {b}");
    }
}
