//! The lamps' light at a query's near hits, on groups as fine as the hits' distance asks.
//!
//! The near field ([`super::near`]) evaluates each group of near hits once, at their mean,
//! and every hit of the group reads that value. A group is a quarter of a cell (4 × 3 cm on
//! an office floor at 32 × 32), and that is right for the light a hemisphere gathers, which
//! is smooth; it is wrong for the lamps' direct light where a shadow's edge crosses the group
//! close to the query point. A table leg's face 1 cm above the floor sees the leg's shadow
//! and the table's penumbra on the floor in front of it, over a few centimetres: the groups
//! smeared them, and the face read 1.1–1.4 % dark against Radiance (docs/ACCURACY.md,
//! "An office, held out").
//!
//! The direct light is known exactly at any point ([`crate::direct`]) and costs a few
//! hundred shadow rays, not a hemisphere. So a query's own near hits keep their group's
//! evaluation for everything but the direct light, and take that at a finer group of their
//! own,
//!
//! ```text
//!     B(x) = B(x_g) − ρ D(x_g) + ρ D(x_f),
//! ```
//!
//! x_g the group's evaluation point, x_f the mean of the hits in x's finer group: the group's
//! sub-cell halved until it is no wider than [`FRACTION`] of its distance from the query
//! point (at most [`HALVINGS`] times). A hit at distance d then reads the direct light of a
//! patch about d/8 wide, which subtends the same angle at every distance, so the work grows
//! with the log of the near field's depth, not its area. Only the hits in a cell where a
//! shadow's edge may lie are split (where the field's grid of reflected direct light misses
//! its own samples, as [`super::relight`] asks): elsewhere the direct light is as smooth as
//! the rest. Only the query's own level does this: the levels below are one term of one
//! group each (split as well, in a build, four probe points moved by at most 0.02 % for 6 %
//! more time).

use super::near::{lifted, slot, surface_at, NearField, SPLIT};
use crate::backend::{Backend, Query, Seen};
use crate::direct::Emitters;
use crate::grid::Grid;
use crate::scene::Scene;
use hemi_kernel::geometry::Vec3;
use std::collections::BTreeMap;

/// A finer group is no wider than this fraction of its distance from the query point. A
/// point 1 cm above a 5 cm penumbra reads 0.3–0.5 % off its closed form at 1/8 and up to
/// 1.1 % at 1/4, for the same time on the office's points (tests/tests/field.rs,
/// `a_penumbra_in_the_near_field_is_read_at_the_hits_own_scale`).
pub const FRACTION: f32 = 0.125;

/// The most halvings of a near group's sub-cell: 2¹² per side, 0.03 mm on a 1 m patch at
/// K = 2, so the limit is the distance, not this. The finer groups are never more
/// than the near hits, each holding at least one.
pub const HALVINGS: u32 = 12;

/// The finer groups of a request's near hits.
#[derive(Debug, Default)]
pub struct Finer {
    /// Per query, per near hit (in the near field's order), its finer group if it was split.
    pub hits: Vec<Vec<Option<usize>>>,
    /// Per finer group, the near field's evaluation its hits read.
    pub groups: Vec<usize>,
    /// Per finer group, where its direct light is evaluated: (side, mean u, mean v).
    pub points: Vec<(usize, f32, f32)>,
}

/// A finer group: (near evaluation, halvings, column, row at that many halvings).
type Key = (usize, u32, u32, u32);

impl Finer {
    /// Splits the near hits of `near` (over `queries`' reports `seen`) into finer groups,
    /// leaving out those where `smooth` says the direct light is (they read their group's
    /// evaluation as it is).
    pub fn of(
        scene: &Scene,
        grids: &[Grid],
        queries: &[Query],
        seen: &[Vec<Seen>],
        near: &NearField,
        smooth: impl Fn(&Seen) -> bool,
    ) -> Finer {
        let mut sums: BTreeMap<Key, (usize, f64, f64, u32)> = BTreeMap::new();
        let mut hits = Vec::with_capacity(queries.len());
        for ((q, reports), near_hits) in queries.iter().zip(seen).zip(&near.hits) {
            let mut own = Vec::with_capacity(near_hits.len());
            for &(r, g) in near_hits {
                let s = &reports[r];
                let Some(grid) = grids.get(s.side).filter(|_| !smooth(s)) else {
                    own.push(None);
                    continue;
                };
                let key = key_of(scene, grid.k(), s, q.point, g);
                let next = sums.len();
                let e = sums.entry(key).or_insert((next, 0.0, 0.0, 0));
                (e.1, e.2, e.3) = (e.1 + f64::from(s.u), e.2 + f64::from(s.v), e.3 + 1);
                own.push(Some(e.0));
            }
            hits.push(own);
        }
        let mut finer = Finer {
            hits,
            groups: vec![0; sums.len()],
            points: vec![(0, 0.0, 0.0); sums.len()],
        };
        for ((g, ..), (f, su, sv, n)) in sums {
            let side = near.points[g].0;
            finer.groups[f] = g;
            finer.points[f] = (side, (su / n as f64) as f32, (sv / n as f64) as f32);
        }
        finer
    }

    /// What each finer group adds to its near evaluation's radiosity, `ρD(x_f) − ρD(x_g)` per
    /// channel, with the exact direct light of `emitters`; every point's shadow rays in one
    /// request. The evaluation at x_g computed D(x_g) the same way, so a finer group at the
    /// evaluation's own point adds nothing.
    pub fn corrections(
        &self,
        backend: &dyn Backend,
        emitters: &Emitters,
        grids: &[Grid],
        near: &NearField,
    ) -> anyhow::Result<Vec<[f64; 3]>> {
        if self.points.is_empty() {
            return Ok(Vec::new());
        }
        let scene = backend.scene();
        // the evaluations some finer group reads, each once
        let mut coarse: BTreeMap<usize, usize> = BTreeMap::new();
        for &g in &self.groups {
            let next = self.points.len() + coarse.len();
            coarse.entry(g).or_insert(next);
        }
        let mut at = self.points.clone();
        at.extend(coarse.keys().map(|&g| near.points[g]));
        let d = emitters.irradiance(backend, grids, &lifted(scene, &at))?;
        Ok(self
            .points
            .iter()
            .zip(&d)
            .zip(&self.groups)
            .map(|((&(side, ..), f), g)| {
                let rho = scene.material_of(side).diffuse;
                let x_g = d[coarse[g]];
                [0, 1, 2].map(|c| rho[c] * (f[c] - x_g[c]))
            })
            .collect())
    }
}

/// The finer group of near hit `s` of evaluation `g`, seen from `point`: its sub-cell halved
/// until it is no wider than [`FRACTION`] of the hit's distance (at most [`HALVINGS`] times).
fn key_of(scene: &Scene, k: usize, s: &Seen, point: Vec3, g: usize) -> Key {
    let patch = &scene.patches[s.side];
    let width = patch.area.sqrt() / (k as f32 * SPLIT as f32);
    let (hit, _) = surface_at(scene, s.side, s.u, s.v);
    let distance = (hit - point).length();
    let mut halvings = 0;
    while halvings < HALVINGS && width / (1u32 << halvings) as f32 > FRACTION * distance {
        halvings += 1;
    }
    let n = ((k as u64 * u64::from(SPLIT)) << halvings).clamp(1, u64::from(u32::MAX)) as u32;
    (g, halvings, slot(n, s.u), slot(n, s.v))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend::Path;
    use crate::irradiance::near::{Grouping, NEAR};

    /// Two hits 4 mm apart in one near group: apart for a query 1 cm above them, together
    /// for one 1 m away, where the lamps' light cannot tell them apart.
    #[test]
    fn finer_groups_shrink_with_their_distance_from_the_query() {
        let src = "[[material]]\nname = \"white\"\ndiffuse = [0.5, 0.5, 0.5]\n\n\
            [[quad]]\nname = \"floor\"\nmaterial = \"white\"\n\
            vertices = [[0, 0, 0], [0, 0, 1], [1, 0, 1], [1, 0, 0]]\n";
        let scene = crate::scene::parse(src, "floor.toml").unwrap();
        let k = 2;
        let grids = vec![Grid::from_samples(k, &vec![[1.0; 3]; k * k])];
        let hit = |u: f32| Seen {
            side: 0,
            u,
            v: 0.3,
            weight: [0.1; 3],
            path: Path::Direct,
        };
        let (a, b) = (0.300, 0.304);
        let (p, _) = surface_at(&scene, 0, a, 0.3);
        let groups = |height: f32| {
            let queries = [Query {
                point: p + Vec3::new(0.0, height, 0.0),
                normal: Vec3::new(0.0, -1.0, 0.0),
            }];
            let seen = [vec![hit(a), hit(b)]];
            let near = NearField::of(
                &scene,
                &grids,
                &queries,
                &seen,
                1e3 * NEAR,
                Grouping::PerQuery,
                |_| false,
            );
            assert_eq!(near.points.len(), 1, "one sub-cell: {:?}", near.points);
            Finer::of(&scene, &grids, &queries, &seen, &near, |_| false).points
        };
        let close = groups(0.01);
        assert_eq!(close.len(), 2, "{close:?}");
        assert_eq!(close[0].0, 0);
        let far = groups(1.0);
        assert_eq!(far.len(), 1, "{far:?}");
        assert!((far[0].1 - 0.302).abs() < 1e-6, "the hits' mean: {far:?}");
    }
}
