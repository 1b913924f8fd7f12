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
//! into [`EDGE_SPLIT`]² cells with a ray each, so a penumbra is resolved to 1/64 of the lamp
//! (at the points queried, those of the finer cells that still disagree with a neighbour are
//! cut into [`SECOND_SPLIT`]² again: 1/256, [`Emitters::with_sharper_edges`]).
//! A sliver along the lamp's rim, which no cell centre sees, is found by probes on the rim.
//! A lamp's image in a perfect plane mirror is a source of the same kind ([`Emitters`]). The
//! rest of the light — everything but the emitters seen directly or once in such a mirror —
//! still comes from the hemisphere ([`crate::irradiance`]).

use crate::backend::{Backend, Skip};
use crate::grid::Grid;
use crate::scene::Scene;
use hemi_kernel::accel::{Hit, Ray};
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
/// and nothing that transmits specularly (a lamp seen through a sheet of glass is a path the
/// shadow rays do not follow). Mirrors are allowed: a lamp's image in a perfect plane mirror is
/// a source of its own ([`Emitters`]), and the light reaching the point through glossy or
/// curved mirrors, or through more than one mirror, still comes from the hemisphere.
pub fn applies(backend: &dyn Backend) -> bool {
    let transmits = backend.scene().materials.iter().any(|m| m.transmits());
    backend.casts_single_rays() && !transmits
}

/// Cells per side of an emitter: 64 shadow rays per emitter and point.
pub const CELLS: u32 = 8;

/// The scene's sources of direct light: the polygons that emit, and their images in the perfect
/// plane mirrors in front of which they shine.
///
/// A perfect mirror of reflectance k_r shows a point the lamp's image, the lamp reflected
/// about the mirror's plane, through the mirror's outline: the light of that path is k_r times
/// what the image would send, with the image's exact form factor, seen where a shadow ray to
/// the image meets the mirror's front and goes on, reflected, to the lamp (Radiance's virtual
/// sources). The mirror's outline cuts the image as an occluder's edge cuts a lamp, and the
/// cells it cuts are split as any shadow's edge is.
#[derive(Clone, Debug)]
pub struct Emitters {
    /// The lamps and their images.
    list: Vec<Source>,
    /// The reports whose light this computes: the lamps seen directly or in the mirrors of
    /// `list`.
    skip: Skip,
    /// How far from a surface a shadow ray starts, and how close to the cell it may end.
    epsilon: f32,
    /// Whether the cells cut on a shadow's edge are cut again where their own rays disagree,
    /// and into how many a side ([`Emitters::with_sharper_edges`]).
    second_split: Option<u32>,
}

/// A source of direct light: an emitting polygon, or its image in a perfect plane mirror.
#[derive(Clone, Copy, Debug)]
struct Source {
    /// The emitter's scene patch, whose grid gives the light.
    patch: usize,
    /// The polygon the cells are cut from: the emitter's, or its image (the emitter's vertices
    /// reflected, in the same order, so a cell's (u, v) is the emitter's).
    poly: Polygon,
    /// The mirror the image is seen in.
    mirror: Option<Mirror>,
}

/// A perfect plane mirror.
#[derive(Clone, Copy, Debug)]
struct Mirror {
    /// Its scene patch.
    patch: usize,
    /// A point of its plane, and the normal of its reflecting (front) side.
    point: Vec3,
    normal: Vec3,
    /// k_r per channel.
    k: [f64; 3],
}

impl Mirror {
    /// `q` reflected about the mirror's plane.
    fn reflect(&self, q: Vec3) -> Vec3 {
        q - self.normal * (2.0 * (q - self.point).dot(self.normal))
    }

    /// The image of emitter `poly` in the mirror, if some of it is in front of the mirror by
    /// more than `epsilon` (a lamp in the mirror's own plane, or a mirror that emits, has no
    /// image but one made of rounding).
    fn image(&self, poly: &Polygon, epsilon: f32) -> Option<Polygon> {
        let front = poly
            .v
            .iter()
            .any(|&v| (v - self.point).dot(self.normal) > epsilon);
        front.then(|| Polygon {
            v: poly.v.map(|v| self.reflect(v)),
            normal: poly.normal - self.normal * (2.0 * poly.normal.dot(self.normal)),
            ..*poly
        })
    }
}

impl Emitters {
    /// The emitting polygons of `scene` (a Bezier emitter stays with the hemisphere), and their
    /// images in its perfect plane mirrors (infinite Phong power, no frustum angle of their own).
    pub fn of(scene: &Scene) -> Emitters {
        let epsilon = scene.ray_offset();
        let mut sides = vec![false; scene.patches.len()];
        let mut list = Vec::new();
        for (i, p) in scene.patches.iter().enumerate().take(scene.fronts()) {
            if let Shape::Polygon(poly) = p.shape {
                let lit = scene.material_of(i).emission.iter().any(|e| *e > 0.0);
                if lit {
                    sides[i] = true;
                    list.push(Source {
                        patch: i,
                        poly,
                        mirror: None,
                    });
                }
            }
        }
        let mirrors = mirrors(scene);
        let lamps = list.len();
        for m in &mirrors {
            for k in 0..lamps {
                let lamp = list[k];
                if let Some(poly) = m.image(&lamp.poly, epsilon) {
                    list.push(Source {
                        poly,
                        mirror: Some(*m),
                        ..lamp
                    });
                }
            }
        }
        let mut in_mirror = vec![false; scene.patches.len()];
        for m in &mirrors {
            in_mirror[m.patch] = true;
        }
        Emitters {
            list,
            skip: Skip {
                sides,
                mirrors: in_mirror,
            },
            epsilon,
            second_split: None,
        }
    }

    /// These emitters with the cells on a shadow's edge cut a second time where their own
    /// rays still disagree ([`SECOND_SPLIT`]² each): a penumbra resolved to 1/256 of the lamp
    /// rather than 1/64, for the direct light at the points a user asks about. A floor point
    /// 2 mm before a tower sees only a 10 cm strip of a 1 m lamp past the tower's face, and the
    /// strip's edge falls inside one 1.6 cm row of the first cut: its direct light read 4–8 %
    /// high, the irradiance 2.3–4.0 % (docs/ACCURACY.md, "Sharper shadow edges for the
    /// queries"). The field's elements, whose values are read between their vertices, keep one
    /// cut (a second would cost the Cornell field 3 s of its 7), and so do the near fields'
    /// evaluations, for time, not for their answers.
    pub fn with_sharper_edges(mut self) -> Emitters {
        self.second_split = Some(SECOND_SPLIT);
        self
    }

    /// Whether scene patch `side` is an emitter whose light is computed here (seen directly,
    /// or in a perfect mirror).
    pub fn handles(&self, side: usize) -> bool {
        self.skip.sides.get(side).copied().unwrap_or(false)
    }

    /// Per scene patch, whether it is such an emitter ([`Emitters::handles`]).
    pub fn handled(&self) -> &[bool] {
        &self.skip.sides
    }

    /// The reports of a gather whose light is computed here, and so must be left out of it.
    pub fn skip(&self) -> &Skip {
        &self.skip
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
    /// [`EDGE_SPLIT`]² cells with a ray each (and with [`Emitters::with_sharper_edges`] the
    /// ones of those that disagree with a neighbour into [`SECOND_SPLIT`]² again).
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
        let (mut edges, mut seen): (Vec<Vec<Cell>>, Vec<Vec<Cell>>) = at
            .par_iter()
            .zip(&cells)
            .zip(&probes)
            .zip(&visible)
            .map(|(((&(p, n), cells), probes), visible)| {
                let (centres, rims) = visible.split_at(cells.len());
                let edge = on_shadow_edge(cells, centres, probes, rims);
                self.sort_cells(cells, centres, &edge, p, n, EDGE_SPLIT)
            })
            .unzip();
        if let Some(factor) = self.second_split {
            edges = self.cut_again(backend, at, edges, &mut seen, factor)?;
        }
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
        let seen = seen
            .into_iter()
            .map(|cells| cells.iter().map(Lit::of).collect())
            .collect();
        Ok(DirectPaths { seen })
    }

    /// Casts the shadow rays of the cells of a first cut (`edges`, per point) and cuts those
    /// whose verdict differs from a neighbour's into `factor`² (returned, to be cast); the
    /// others join `seen` if visible.
    fn cut_again(
        &self,
        backend: &dyn Backend,
        at: &[(Vec3, Vec3)],
        edges: Vec<Vec<Cell>>,
        seen: &mut [Vec<Cell>],
        factor: u32,
    ) -> anyhow::Result<Vec<Vec<Cell>>> {
        let visible = self.shadow_rays(backend, at, &edges)?;
        let (next, kept): (Vec<Vec<Cell>>, Vec<Vec<Cell>>) = at
            .par_iter()
            .zip(&edges)
            .zip(&visible)
            .map(|((&(p, n), cells), visible)| {
                let edge = by_neighbours(cells, visible);
                self.sort_cells(cells, visible, &edge, p, n, factor)
            })
            .unzip();
        for (s, k) in seen.iter_mut().zip(kept) {
            s.extend(k);
        }
        Ok(next)
    }

    /// One point's cells after their shadow rays: (the `factor`² cells of each of those on a
    /// shadow's edge, to be cast again; the seen cells off any edge).
    fn sort_cells(
        &self,
        cells: &[Cell],
        visible: &[bool],
        edge: &[bool],
        p: Vec3,
        n: Vec3,
        factor: u32,
    ) -> (Vec<Cell>, Vec<Cell>) {
        let mut finer = Vec::new();
        let mut kept = Vec::new();
        for ((cell, &v), &e) in cells.iter().zip(visible).zip(edge) {
            match (e, v) {
                (true, _) => finer.extend(self.split(cell, p, n, factor)),
                (false, true) => kept.push(*cell),
                (false, false) => {}
            }
        }
        (finer, kept)
    }

    /// Casts one shadow ray from each point to the centre of each of its cells (all points in
    /// one request) and says which cells it reached. A ray to an image's cell must meet its
    /// mirror's front first, and a second ray, from there to the emitter's own cell (all of
    /// them in one more request), must reach it.
    fn shadow_rays(
        &self,
        backend: &dyn Backend,
        at: &[(Vec3, Vec3)],
        cells: &[Vec<Cell>],
    ) -> anyhow::Result<Vec<Vec<bool>>> {
        let origins: Vec<Vec3> = at.iter().map(|&(p, n)| p + n * self.epsilon).collect();
        let flat: Vec<(Vec3, &Cell)> = origins
            .iter()
            .zip(cells)
            .flat_map(|(&o, cells)| cells.iter().map(move |c| (o, c)))
            .collect();
        let rays: Vec<Ray> = flat.iter().map(|&(o, c)| ray_to(o, c.centre)).collect();
        let hits = backend.nearest(&rays)?;
        // the rays that go on from a mirror: (index in `flat`, the ray on, the distance on)
        let mut on: Vec<(usize, Ray, f32)> = Vec::new();
        let mut reached = Vec::with_capacity(flat.len());
        for (i, ((origin, cell), hit)) in flat.iter().zip(&hits).enumerate() {
            let distance = (cell.centre - *origin).length();
            let Some(m) = self.list[cell.source].mirror else {
                reached.push(self.reaches(*hit, cell.patch, distance));
                continue;
            };
            reached.push(false);
            let in_mirror = |h: &Hit| h.patch as usize == m.patch && h.front && h.t < distance;
            if let Some(h) = hit.filter(in_mirror) {
                let at_mirror = *origin + rays[i].dir * h.t + m.normal * self.epsilon;
                let lamp = m.reflect(cell.centre);
                on.push((i, ray_to(at_mirror, lamp), (lamp - at_mirror).length()));
            }
        }
        let rays_on: Vec<Ray> = on.iter().map(|&(_, r, _)| r).collect();
        for (&(i, _, distance), hit) in on.iter().zip(backend.nearest(&rays_on)?) {
            reached[i] = self.reaches(hit, flat[i].1.patch, distance);
        }
        let mut reached = reached.into_iter();
        Ok(cells
            .iter()
            .map(|c| reached.by_ref().take(c.len()).collect())
            .collect())
    }

    /// Whether a shadow ray's `hit` is the cell of scene patch `patch` at `distance`.
    fn reaches(&self, hit: Option<Hit>, patch: usize, distance: f32) -> bool {
        hit.is_some_and(|h| h.patch as usize == patch && h.t > distance - 10.0 * self.epsilon)
    }

    /// Every source cell in front of the point, with its exact form factor.
    fn cells(&self, point: Vec3, normal: Vec3) -> Vec<Cell> {
        let mut out = Vec::new();
        for (source, s) in self.list.iter().enumerate() {
            // emitters shine from their front only (an image from its reflected front)
            if (point - s.poly.v[0]).dot(s.poly.normal) <= 0.0 {
                continue;
            }
            for b in 0..CELLS {
                for a in 0..CELLS {
                    let cell = cell_of(s, source, (a, b), CELLS);
                    out.extend(cell.seen_from(point, normal));
                }
            }
        }
        out
    }

    /// The `factor`² cells `cell` is cut into, with their form factors from the point.
    fn split(&self, cell: &Cell, point: Vec3, normal: Vec3, factor: u32) -> Vec<Cell> {
        let Some(source) = self.list.get(cell.source) else {
            return Vec::new();
        };
        let n = cell.n * factor;
        let (a0, b0) = (cell.a * factor, cell.b * factor);
        (0..factor * factor)
            .filter_map(|k| {
                let (a, b) = (a0 + k % factor, b0 + k / factor);
                cell_of(source, cell.source, (a, b), n).seen_from(point, normal)
            })
            .collect()
    }
}

/// The perfect plane mirrors of `scene`: front polygons whose material reflects with an
/// infinite Phong power and no frustum angle of its own, whose frustum is then a single ray at
/// every R ([`crate::optics::lobe_size`] 0) — the queries' own hemispheres may be finer than
/// pass 1's, and a lobe that is a single ray at one R and a ring at another would have its
/// light both imaged and gathered.
fn mirrors(scene: &Scene) -> Vec<Mirror> {
    let mut out = Vec::new();
    for (i, p) in scene.patches.iter().enumerate().take(scene.fronts()) {
        let m = scene.material_of(i);
        if !m.reflects() || !m.phong.is_infinite() || m.frustum_deg.is_some() {
            continue;
        }
        if let Shape::Polygon(poly) = p.shape {
            out.push(Mirror {
                patch: i,
                point: poly.v[0],
                normal: poly.normal,
                k: m.specular,
            });
        }
    }
    out
}

/// The ray from `origin` towards `target`.
fn ray_to(origin: Vec3, target: Vec3) -> Ray {
    Ray {
        origin,
        dir: (target - origin).try_normalize().unwrap_or(Vec3::Z),
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
        .map(|(c, &v)| ((c.source, c.a, c.b), v))
        .collect();
    cells
        .iter()
        .zip(visible)
        .map(|(c, &v)| {
            let (a, b) = (c.a as i64, c.b as i64);
            [(a - 1, b), (a + 1, b), (a, b - 1), (a, b + 1)]
                .iter()
                .filter(|(x, y)| *x >= 0 && *y >= 0)
                .filter_map(|&(x, y)| verdict.get(&(c.source, x as u32, y as u32)))
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
fn rim_probes(list: &[Source], cells: &[Cell], p: Vec3, n: Vec3) -> Vec<(usize, Cell)> {
    let mut out = Vec::new();
    for (i, c) in cells.iter().enumerate() {
        let Some(Source { poly, .. }) = list.get(c.source) else {
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
    seen: Vec<Vec<Lit>>,
}

/// What a point keeps of a cell it sees: whose light, where on the emitter, and how much of it
/// arrives (`k · F_cell` per channel). The geometry is not kept: a field holds these for every
/// element, and only the emitters' radiosity changes between its sweeps.
#[derive(Clone, Copy, Debug)]
struct Lit {
    patch: u32,
    u: f32,
    v: f32,
    share: [f64; 3],
}

impl Lit {
    fn of(cell: &Cell) -> Lit {
        Lit {
            patch: cell.patch as u32,
            u: cell.u,
            v: cell.v,
            share: cell.weight.map(|k| k * cell.form_factor),
        }
    }
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

    /// Each point's direct irradiance, `Σ_cells k · F_cell · B_emitter(u, v)` over the cells it
    /// sees (k the mirror's reflectance for an image's cell, else 1), with the emitters'
    /// radiosity read off `grids`.
    pub fn irradiance(&self, grids: &[Grid]) -> anyhow::Result<Vec<[f64; 3]>> {
        self.seen
            .iter()
            .map(|cells| {
                let mut e = [0.0f64; 3];
                for cell in cells {
                    let b = crate::grid::grid_of(grids, cell.patch as usize)?.at(cell.u, cell.v);
                    for c in 0..3 {
                        e[c] += cell.share[c] * b[c];
                    }
                }
                Ok(e)
            })
            .collect()
    }
}

/// One cell of a source: cell (a, b) of its n×n lattice in (u, v).
#[derive(Clone, Copy, Debug)]
struct Cell {
    /// Index into [`Emitters`]' list, and the emitter's scene patch.
    source: usize,
    patch: usize,
    /// What the path passes on per channel: a mirror's k_r for an image's cell, else 1.
    weight: [f64; 3],
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

/// Sub-cells per side of a first cut's cell on a shadow's edge that is cut again
/// ([`Emitters::with_sharper_edges`]).
pub const SECOND_SPLIT: u32 = 4;

/// Cell (a, b) of the n×n lattice of source `s`'s (u,v) map (`source` its index).
fn cell_of(s: &Source, source: usize, (a, b): (u32, u32), n: u32) -> Cell {
    let poly = &s.poly;
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
        source,
        patch: s.patch,
        weight: s.mirror.map_or([1.0; 3], |m| m.k),
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

    /// A black sheet hides a square lamp from the point but a strip along one edge, 5.3 of the
    /// first cut's 64 columns wide: the column the sheet's edge crosses is counted by its
    /// centre, which is hidden, so one cut reads the strip as 5 columns (5.7 % low); cut again
    /// into quarters, as 5.25 (0.9 %).
    #[test]
    fn a_second_cut_sharpens_a_shadows_edge() {
        let w = 5.3 / 64.0;
        let (p, n) = (Vec3::new(0.5, 0.5, 0.01), Vec3::new(0.0, 0.0, 1.0));
        // seen from p, the sheet's edge (at z = 0.5) covers the lamp (at z = 1) up to 1 − w
        let edge = 0.5 + (0.5 - w) * (0.49 / 0.99);
        let src = format!(
            "[[material]]\nname = \"lamp\"\ndiffuse = [0, 0, 0]\nemission = [1, 1, 1]\n\
             [[material]]\nname = \"black\"\ndiffuse = [0, 0, 0]\n\
             [[quad]]\nname = \"lamp\"\nmaterial = \"lamp\"\n\
             vertices = [[0, 0, 1], [0, 1, 1], [1, 1, 1], [1, 0, 1]]\n\
             [[quad]]\nname = \"sheet\"\nmaterial = \"black\"\n\
             vertices = [[-1, -1, 0.5], [-1, 2, 0.5], [{edge}, 2, 0.5], [{edge}, -1, 0.5]]\n"
        );
        let scene = crate::scene::parse(&src, "strip.toml").unwrap();
        let backend = crate::backend::soft(&scene, &Default::default()).unwrap();
        let grids: Vec<Grid> = (0..scene.patches.len())
            .map(|_| Grid::from_samples(2, &[[1.0; 3]; 4]))
            .collect();
        let strip = [
            Vec3::new(1.0 - w as f32, 0.0, 1.0),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(1.0 - w as f32, 1.0, 1.0),
        ];
        let want = form_factor(p, n, &strip);
        let error = |em: Emitters| {
            let got = em.irradiance(&backend, &grids, &[(p, n)]).unwrap()[0][0];
            (got - want) / want
        };
        let (once, twice) = (
            error(Emitters::of(&scene)),
            error(Emitters::of(&scene).with_sharper_edges()),
        );
        println!("strip past a sheet: one cut {once:+.4}, two cuts {twice:+.4}");
        assert!(once < -0.04, "one cut: {once:.4}");
        assert!(twice.abs() < 0.015, "two cuts: {twice:.4} (one: {once:.4})");
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
