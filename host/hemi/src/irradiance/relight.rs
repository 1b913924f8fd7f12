//! The lamps' light at far hits, evaluated afresh where the grid cannot carry it.
//!
//! A grid of cells h wide interpolates the radiosity bilinearly, which is right where the light
//! is smooth and wrong across a shadow's edge: a penumbra narrower than a cell is smeared over
//! the cells on both sides, so the umbra next to it reads too bright. The near field
//! ([`super::near`]) looks again at the hits within a few cells of the query point; beyond it,
//! a block's shadow on the floor is still read off the floor's grid, and a face that looks out
//! over that shadow (the short block's front face, 40 mm above the floor) gathers it 4–7 % too
//! bright.
//!
//! The light of a shadow's edge is the emitters' direct light, which is known exactly at any
//! point ([`crate::direct`]). So the field keeps, beside each patch's radiosity grid B, the grid
//! of its part that is direct light reflected once, ρD ([`crate::field::Field::direct`]), and a
//! hit in a cell where that grid misses its own samples by more than [`MISS`] of the cell's
//! radiosity ([`crate::grid::misses`]: a linear fall it carries exactly, a penumbra it does not)
//! reads
//!
//! ```text
//!     B(x) = B̃(x) − ρD̃(x) + ρ D(x),      D(x) = Σ_cells V · F_cell · B_emitter   (exact)
//! ```
//!
//! — the grid for everything but the direct light (the indirect light, which is smooth), and
//! the exact direct light at the hit. Hits are grouped by sub-cell as the near field groups them,
//! and each sub-cell is evaluated once, at its centre, for all the queries asked together (the
//! near field's queries, side by side, see the same edges); a sub-cell crossed by a line where
//! one surface stands on another once a side of it. A group's error is about
//! Σ w · (the grid's miss around its cell); the groups are evaluated largest first until those
//! left sum to [`BUDGET`] of the query's irradiance, so the work goes where
//! the error is — a shadow's edge that fills the view — and a far edge a few rays see costs
//! nothing.

use super::near::{lifted, sub_cell, SPLIT};
use crate::backend::{Backend, Seen};
use crate::direct::Emitters;
use crate::field::Reflected;
use crate::grid::{corners, Grid};
use crate::scene::Scene;
use hemi_kernel::accel::Ray;
use hemi_kernel::geometry::Vec3;
use std::collections::BTreeMap;

/// A hit's direct light is evaluated afresh when the grid of the reflected direct light misses
/// its own samples around the hit's cell by more than this fraction of the cell's radiosity
/// ([`crate::grid::misses`]): a shadow's edge, not the smooth fall of a lamp's light.
pub const MISS: f64 = 0.01;

/// The relighting of a query stops when the groups left could move its irradiance by less
/// than this fraction in every channel (their Σ w · miss, about their error).
pub const BUDGET: f64 = 2e-3;

/// The budget of the near field's own evaluations ([`super::near`]), whose light is a part of
/// their query's. Measured on the Cornell box's 41 points by the blocks and corners: RMS 0.59 %
/// without relighting them, 0.55 % at 0.05 for 15 % more time, and at [`BUDGET`] 40 % more time
/// for no better answers (the floor by a block's foot was 0.2 % darker).
pub const NEAR_BUDGET: f64 = 0.05;

/// Which hits of some queries are relit, and where the exact direct light is wanted.
#[derive(Debug, Default)]
pub struct Relit {
    /// Per query, (index into its `seen` list, evaluation it reads).
    pub hits: Vec<Vec<(usize, usize)>>,
    /// The evaluations: (side, u, v of a sub-cell's centre).
    pub points: Vec<(usize, f32, f32)>,
}

impl Relit {
    /// Finds the hits of each query in `seen` that land in a cell of `direct` (the reflected
    /// direct light per side) where it is not smooth, leaving out those `skip` says are
    /// handled otherwise (the emitters, the near field's hits), and keeps the groups that
    /// could move the query's irradiance `scale` most, until what is left could move it by
    /// less than [`BUDGET`].
    pub fn of(
        scene: &Scene,
        grids: &[Grid],
        direct: &Reflected,
        seen: &[Vec<Seen>],
        scale: &[[f64; 3]],
        budget: f64,
        skip: impl Fn(usize, usize, &Seen) -> bool,
    ) -> Relit {
        let mut relit = Relit::default();
        // one evaluation per sub-cell for all queries: neighbouring queries (a near field's)
        // see the same shadow edges, and a value at a sub-cell's centre is the same whoever asks
        let mut evaluations: BTreeMap<Key, usize> = BTreeMap::new();
        for (n, (reports, scale)) in seen.iter().zip(scale).enumerate() {
            let mut groups: BTreeMap<Key, Group> = BTreeMap::new();
            for (r, s) in reports.iter().enumerate() {
                if skip(n, r, s) || scene.twin(s.side).is_some() {
                    continue;
                }
                let Some(b) = grids.get(s.side) else {
                    continue;
                };
                let Some(miss) = miss_at(b, direct, s, MISS) else {
                    continue;
                };
                let key = (
                    s.side,
                    sub_cell(b.k(), s.u, s.v),
                    b.cuts().region(b.k(), s.u, s.v),
                );
                let g = groups.entry(key).or_default();
                g.hits.push(r);
                for ((p, w), m) in g.potential.iter_mut().zip(s.weight).zip(miss) {
                    *p += w as f64 * m;
                }
            }
            relit.hits.push(Vec::new());
            for (key, g) in select(groups, scale, budget) {
                let next = relit.points.len();
                let at = *evaluations.entry(key).or_insert(next);
                if at == next {
                    let (u, v) = evaluated_at(&grids[key.0], key, &g.hits, reports);
                    relit.points.push((key.0, u, v));
                }
                relit.hits[n].extend(g.hits.iter().map(|&r| (r, at)));
            }
        }
        relit
    }

    /// The correction each evaluation adds to the radiosity its grid gives,
    /// `ρD(x) − ρD̃(x)` per channel, with the exact direct light D of `emitters` (their
    /// radiosity read off `grids`), all points' shadow rays in one request; `None` where the
    /// sub-cell's centre lies buried in another body (five probe rays meet backs), whose light
    /// is not the surface's.
    pub fn corrections(
        &self,
        backend: &dyn Backend,
        emitters: &Emitters,
        grids: &[Grid],
        direct: &Reflected,
    ) -> anyhow::Result<Vec<Option<[f64; 3]>>> {
        if self.points.is_empty() {
            return Ok(Vec::new());
        }
        let at = lifted(backend.scene(), &self.points);
        let buried = buried(backend, &at)?;
        let add = direct_corrections(backend, emitters, grids, direct, &self.points)?;
        Ok(add
            .into_iter()
            .zip(buried)
            .map(|(d, buried)| (!buried).then_some(d))
            .collect())
    }
}

/// `ρD(x) − ρD̃(x)` per channel at each (side, u, v): the exact direct light D of `emitters`
/// (their radiosity read off `grids`) against the field's grid of it, every point's shadow rays
/// in one request per chunk. The one evaluation relighting does, for queries and pass 2 alike.
pub fn direct_corrections(
    backend: &dyn Backend,
    emitters: &Emitters,
    grids: &[Grid],
    direct: &Reflected,
    points: &[(usize, f32, f32)],
) -> anyhow::Result<Vec<[f64; 3]>> {
    const CHUNK: usize = 4096;
    let scene = backend.scene();
    let mut out = Vec::with_capacity(points.len());
    for chunk in points.chunks(CHUNK) {
        let exact = emitters.irradiance(backend, grids, &lifted(scene, chunk))?;
        for (&(side, u, v), d) in chunk.iter().zip(exact) {
            let rho = scene.material_of(side).diffuse;
            let grid = crate::grid::grid_of(&direct.grids, side)?.at(u, v);
            out.push([0, 1, 2].map(|c| rho[c] * d[c] - grid[c]));
        }
    }
    Ok(out)
}

/// Whether each (point, normal) lies inside another body: every one of five rays, along the
/// normal and tilted 60° from it four ways, meets the back of a patch first (a floor's
/// sub-cell under a block, whose shadow rays would call it dark).
fn buried(backend: &dyn Backend, at: &[(Vec3, Vec3)]) -> anyhow::Result<Vec<bool>> {
    const PROBES: usize = 5;
    let mut rays = Vec::with_capacity(at.len() * PROBES);
    for &(p, n) in at {
        let helper = if n.x.abs() < 0.9 {
            Vec3::new(1.0, 0.0, 0.0)
        } else {
            Vec3::new(0.0, 1.0, 0.0)
        };
        let t = n.cross(helper).try_normalize().unwrap_or(helper);
        let b = n.cross(t);
        let (c, s) = (0.5f32, 0.866_025_4f32);
        for d in [
            n,
            n * c + t * s,
            n * c - t * s,
            n * c + b * s,
            n * c - b * s,
        ] {
            rays.push(Ray { origin: p, dir: d });
        }
    }
    let hits = backend.nearest(&rays)?;
    Ok(hits
        .chunks(PROBES)
        .map(|h| h.iter().all(|h| h.is_some_and(|h| !h.front)))
        .collect())
}

/// A group's place: (side, sub-cell, region of the side's contact lines). A sub-cell that a
/// line where one surface stands on another crosses is two groups, one a side
/// ([`crate::grid::Cuts::region`]): the floor on either side of a screen's foot sees other
/// lamps.
type Key = (usize, u32, u64);

/// Where a group is evaluated: its sub-cell's centre, the same point whoever asks, unless that
/// lies across a contact line from the group's hits; then the mean of the points of an 8 × 8
/// lattice over the sub-cell on the hits' side (about that part's centroid, and still a point
/// fixed by the sub-cell and the side, so an answer does not depend on the queries asked with
/// it). Only a sliver no lattice point falls in takes the mean of its hits.
fn evaluated_at(grid: &Grid, (_, cell, region): Key, hits: &[usize], seen: &[Seen]) -> (f32, f32) {
    const LATTICE: u32 = 8;
    let k = grid.k();
    let (u, v) = sub_cell_centre(k, cell);
    let on_side = |(u, v): (f32, f32)| grid.cuts().region(k, u, v) == region;
    if on_side((u, v)) {
        return (u, v);
    }
    let size = 1.0 / (k as f32 * SPLIT as f32);
    let step = |i: u32| ((i as f32 + 0.5) / LATTICE as f32 - 0.5) * size;
    let lattice = (0..LATTICE * LATTICE).map(|i| (u + step(i % LATTICE), v + step(i / LATTICE)));
    mean(lattice.filter(|&p| on_side(p)))
        .or_else(|| mean(hits.iter().map(|&r| (seen[r].u, seen[r].v))))
        .unwrap_or((u, v))
}

/// The mean of some (u, v), if there are any.
fn mean(points: impl Iterator<Item = (f32, f32)>) -> Option<(f32, f32)> {
    let (mut su, mut sv, mut n) = (0.0f64, 0.0f64, 0usize);
    for (u, v) in points {
        (su, sv, n) = (su + f64::from(u), sv + f64::from(v), n + 1);
    }
    (n > 0).then(|| ((su / n as f64) as f32, (sv / n as f64) as f32))
}

/// The hits of one sub-cell of a side that one query sees on a shadow's edge.
#[derive(Debug, Default)]
struct Group {
    /// Indices into the query's `seen` list.
    hits: Vec<usize>,
    /// Σ w · miss per channel: about what the hits' light is off by.
    potential: [f64; 3],
}

/// The groups worth evaluating, most potential first, until the potential of those left,
/// relative to the query's irradiance `scale` in each channel, sums to at most [`BUDGET`].
fn select(
    groups: BTreeMap<Key, Group>,
    scale: &[f64; 3],
    budget: f64,
) -> impl Iterator<Item = (Key, Group)> {
    let relative = |g: &Group| {
        (0..3)
            .map(|c| g.potential[c] / scale[c].max(f64::MIN_POSITIVE))
            .fold(0.0, f64::max)
    };
    let mut ranked: Vec<_> = groups
        .into_iter()
        .map(|(k, g)| (relative(&g), k, g))
        .collect();
    ranked.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    let mut left: f64 = ranked.iter().map(|r| r.0).sum();
    ranked
        .into_iter()
        .take_while(move |r| {
            let keep = left > budget;
            left -= r.0;
            keep
        })
        .map(|(_, k, g)| (k, g))
}

/// The (u, v) of the centre of sub-cell `index` of a k×k grid ([`sub_cell`]'s numbering).
fn sub_cell_centre(k: usize, index: u32) -> (f32, f32) {
    let n = k as u32 * SPLIT;
    let at = |i: u32| (i as f32 + 0.5) / n as f32;
    (at(index % n), at(index / n))
}

/// How far the grid of the reflected direct light misses its samples around the cell of `b`
/// that `s` lands in (per channel), if that is more than `threshold` ([`MISS`] for queries) of
/// the cell's radiosity.
pub fn miss_at(b: &Grid, direct: &Reflected, s: &Seen, threshold: f64) -> Option<[f64; 3]> {
    let (Some(d), Some(misses)) = (direct.grids.get(s.side), direct.misses.get(s.side)) else {
        return None;
    };
    let k = b.k();
    if d.k() != k || misses.len() != k * k {
        return None;
    }
    let cell = corners(k, s.u, s.v);
    let ((a, j), _) = cell[0];
    let miss = misses[j * k + a].map(f64::from);
    let top = cell
        .iter()
        .flat_map(|&((i, j), _)| b.vertex(i, j))
        .fold(0.0f64, f64::max);
    (miss.iter().fold(0.0f64, |a, &x| a.max(x)) > threshold * top).then_some(miss)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend::Path;

    /// A sub-cell that a contact line crosses is evaluated at its centre for the hits on the
    /// centre's side, and for the hits across the line at a point of their side that does not
    /// depend on which of them were seen.
    #[test]
    fn a_group_across_a_contact_line_is_evaluated_on_its_side() {
        let k = 10;
        // the line at u = 0.515 crosses sub-cell 20 of row 20 (u in [0.5, 0.525)), right of
        // its centre at 0.5125
        let grid = Grid::with_cuts(k, &vec![[1.0; 3]; k * k], &[[[0.515, 0.2], [0.515, 0.8]]]);
        let cell = sub_cell(k, 0.52, 0.51);
        let (cu, cv) = sub_cell_centre(k, cell);
        let hit = |u: f32| Seen {
            side: 0,
            u,
            v: 0.51,
            weight: [1.0; 3],
            path: Path::Direct,
        };
        let seen = [hit(0.52), hit(0.522), hit(0.501)];
        let cuts = grid.cuts();
        let behind = (0, cell, cuts.region(k, 0.52, 0.51));
        let before = (0, cell, cuts.region(k, 0.501, 0.51));
        assert_eq!(sub_cell(k, 0.501, 0.51), cell);
        assert_ne!(behind.2, before.2);
        assert_eq!(evaluated_at(&grid, before, &[2], &seen), (cu, cv));
        let (u, v) = evaluated_at(&grid, behind, &[0, 1], &seen);
        assert_eq!(cuts.region(k, u, v), behind.2, "on the hits' side: {u} {v}");
        // the part of the sub-cell right of the line, [0.515, 0.525) × the row: its centroid
        assert!((u - 0.52).abs() < 1e-3 && (v - cv).abs() < 1e-6, "{u} {v}");
        // a point fixed by the sub-cell and the side, whichever of its hits a query saw
        assert_eq!(evaluated_at(&grid, behind, &[1], &seen), (u, v));
    }
}
