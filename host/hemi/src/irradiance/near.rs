//! The near field of a point query: the surfaces close to the point, looked at again.
//!
//! A query's hemisphere reads the radiosity where each ray lands off the patch grids, which
//! are bilinear over K×K cells. Across the room that is enough: a cell at distance d subtends
//! about (h/d)² of the hemisphere, h the cell's size, so its interpolation error is a small
//! part of the sum. Next to the point it is not: in a corner, or 5 mm from a block standing on
//! the floor, the nearest few cells fill half the hemisphere, and they are where the light
//! changes fastest (the corner's darkening, the contact shadow), which a grid of cells as big
//! as the distance smooths out. The query then reads their light too bright and too flat.
//!
//! So a ray that lands within a few cell sizes ([`NEAR`] by default) of the query point does not read the grid:
//! the radiosity there is computed afresh, as a query of its own at the hit,
//!
//! ```text
//!     B(x) = E + ρ H(x)  [+ τ H_twin(x) on a translucent sheet],
//! ```
//!
//! with H(x) the same irradiance computation one level down (its own direct light, its own
//! near field, `levels − 1` deep). Hits are grouped by the sub-cell of their patch's grid they
//! fall in ([`SPLIT`] × [`SPLIT`] per cell), and each group is evaluated once, at the mean
//! (u, v) of its hits: a point the rays saw, so it is never buried under another body, and
//! one evaluation per sub-cell bounds the work by the near area, not by the rays. A query's
//! own near hits are grouped per query ([`Grouping::PerQuery`]); the evaluations' near hits,
//! one level down, are grouped over all the evaluations of that query ([`Grouping::Shared`]).

use crate::backend::{Query, Seen};
use crate::grid::Grid;
use crate::scene::{Scene, Sides};
use hemi_kernel::geometry::Vec3;
use hemi_kernel::patch::{Patch, Shape};
use std::collections::BTreeMap;

/// A hit is in the near field by default when it is closer to the query point than this many
/// cell sizes (√area / K) of the grid it lands on.
pub const NEAR: f32 = 3.0;

/// How far each level's near field reaches, as a fraction of the level above's: the light a
/// grid cannot carry is closest to a contact line or a corner, so the deeper levels look only
/// there. At the floor 1 mm in front of the Cornell box's short block (Radiance 6.0a, 1,024
/// estimates) two levels of 3 cells read +1.0 / +3.3 / +4.2 %; four levels of 3, 1.5, 0.75
/// and 0.38 cells read +0.1 / +1.0 / +1.5 % (docs/ACCURACY.md, "Mirror images, finer
/// queries, deeper near fields"), with [`SHARED_BUDGET`] bounding what the levels below cost.
pub const SHRINK: f32 = 0.5;

/// Sub-cells per cell side the near hits are grouped by.
pub const SPLIT: u32 = 4;

/// Where a query's near hits are, and what to evaluate for them.
#[derive(Debug, Default)]
pub struct NearField {
    /// Per query, (index into its `seen` list, evaluation it reads).
    pub hits: Vec<Vec<(usize, usize)>>,
    /// The evaluations: (side, mean u, mean v).
    pub points: Vec<(usize, f32, f32)>,
    /// Per evaluation, the query whose hits made its group (with [`Grouping::Shared`], the
    /// first of them): the evaluations of one query are contiguous.
    pub owners: Vec<usize>,
}

/// Whose hits one evaluation may serve.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Grouping {
    /// Each query's own (the queries asked: one's answer does not depend on the others').
    PerQuery,
    /// Every query of the request: the evaluations one level down of a single query's near
    /// field, which look at the same few sub-cells by a corner or a block's foot from points a
    /// few millimetres apart. One evaluation per sub-cell for all of them is what makes a
    /// second level affordable (per evaluation, it cost minutes on one Cornell-box point).
    Shared,
}

impl NearField {
    /// Finds the near hits of each query in `seen` (its hemisphere's reports) on `grids`,
    /// leaving out the reports `skip` says are handled otherwise.
    pub fn of(
        scene: &Scene,
        grids: &[Grid],
        queries: &[Query],
        seen: &[Vec<Seen>],
        cells: f32,
        grouping: Grouping,
        skip: impl Fn(&Seen) -> bool,
    ) -> NearField {
        // (owner, side, sub-cell) → (evaluation, Σu, Σv, count): the owner is the query
        // (per query, a query's answer does not depend on what else is asked with it) or 0
        // (shared by the request, which then holds one query's evaluations only)
        let mut groups: BTreeMap<GroupKey, Group> = BTreeMap::new();
        let mut hits = Vec::with_capacity(queries.len());
        for (n, (q, reports)) in queries.iter().zip(seen).enumerate() {
            let mut near = Vec::new();
            for (r, s) in reports.iter().enumerate() {
                let Some(grid) = grids.get(s.side) else {
                    continue;
                };
                if skip(s) || !is_near(scene, grid.k(), s, q.point, cells) {
                    continue;
                }
                let owner = match grouping {
                    Grouping::PerQuery => n,
                    Grouping::Shared => 0,
                };
                let key = (
                    owner,
                    s.side,
                    sub_cell(grid.k(), s.u, s.v),
                    grid.cuts().region(grid.k(), s.u, s.v),
                );
                let next = groups.len();
                let g = groups.entry(key).or_insert((next, 0.0, 0.0, 0, 0.0));
                g.1 += s.u as f64;
                g.2 += s.v as f64;
                g.3 += 1;
                g.4 += s.weight.iter().fold(0.0f32, |a, &w| a.max(w)) as f64;
                near.push((r, g.0));
            }
            hits.push(near);
        }
        let kept = match grouping {
            Grouping::PerQuery => heaviest(&groups, usize::MAX),
            Grouping::Shared => heaviest(&groups, SHARED_BUDGET),
        };
        for near in &mut hits {
            near.retain_mut(|(_, g)| match kept[*g] {
                Some(k) => {
                    *g = k;
                    true
                }
                None => false,
            });
        }
        let n = kept.iter().flatten().count();
        let mut points = vec![(0, 0.0, 0.0); n];
        let mut owners = vec![0; n];
        for ((owner, side, ..), (g, su, sv, count, _)) in groups {
            let Some(k) = kept[g] else { continue };
            let c = count as f64;
            points[k] = (side, (su / c) as f32, (sv / c) as f32);
            owners[k] = owner;
        }
        NearField {
            hits,
            points,
            owners,
        }
    }
}

/// The most evaluations one request's shared near field makes (the levels below a query's
/// own): on a coarse grid (a room's floor, 0.75 m cells) a few cells take in metres of
/// surface, and each level below would multiply the sub-cells evaluated; past this many, the
/// ones its rays weigh least read their grids.
pub const SHARED_BUDGET: usize = 64;

/// Per group (by its index), its new index if it is among the `budget` heaviest (by the rays'
/// weight, ties to the earlier group), numbered in the groups' order; `None` if not.
fn heaviest(groups: &BTreeMap<GroupKey, Group>, budget: usize) -> Vec<Option<usize>> {
    if groups.len() <= budget {
        return (0..groups.len()).map(Some).collect();
    }
    let mut by_weight: Vec<(usize, f64)> = groups.values().map(|g| (g.0, g.4)).collect();
    by_weight.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    let mut chosen: Vec<usize> = by_weight.iter().take(budget).map(|&(g, _)| g).collect();
    chosen.sort_unstable();
    let mut kept = vec![None; groups.len()];
    for (k, g) in chosen.into_iter().enumerate() {
        kept[g] = Some(k);
    }
    kept
}

/// A group of near hits: (query, side, sub-cell, region of the side's contact lines). The
/// region keeps apart the hits on either side of a line where one surface stands on another
/// ([`crate::grid::Cuts::region`]): one evaluation at their mean would give the light of one
/// side to both. A floor runs under a translucent screen, and the evaluations one level down
/// see it from both sides at once: the lit side's hits took the dark side's light, and the
/// camera side read 2 % too dark (docs/ACCURACY.md, "Near hits kept to their side").
type GroupKey = (usize, usize, u32, u64);

/// What is known of a group: (its evaluation's index, Σu, Σv, hits, Σ of its rays' weights).
type Group = (usize, f64, f64, u32, f64);

/// Whether `s` landed within `near` cell sizes of `point`.
fn is_near(scene: &Scene, k: usize, s: &Seen, point: Vec3, near: f32) -> bool {
    let patch = &scene.patches[s.side];
    let cell = patch.area.sqrt() / k as f32;
    let (hit, _) = surface_at(scene, s.side, s.u, s.v);
    (hit - point).length() < near * cell
}

/// The index of the sub-cell of a k×k grid that (u, v) falls in ([`SPLIT`] per cell side).
pub(crate) fn sub_cell(k: usize, u: f32, v: f32) -> u32 {
    let n = k as u32 * SPLIT;
    slot(n, v) * n + slot(n, u)
}

/// Which of `n` equal slots of [0, 1] the parameter `t` falls in (the last one's right end
/// included; `t` outside [0, 1] taken to its end).
pub(crate) fn slot(n: u32, t: f32) -> u32 {
    ((t.clamp(0.0, 1.0) * n as f32) as u32).min(n.saturating_sub(1))
}

/// The (point, normal) of each (side, u, v), lifted off the surface as rays start.
pub(crate) fn lifted(scene: &Scene, points: &[(usize, f32, f32)]) -> Vec<(Vec3, Vec3)> {
    let lift = scene.ray_offset();
    points
        .iter()
        .map(|&(side, u, v)| {
            let (p, n) = surface_at(scene, side, u, v);
            (p + n * lift, n)
        })
        .collect()
}

/// The point of scene side `side` at (u, v) and the side's normal there (a back side of a
/// translucent sheet faces the other way from its front).
pub fn surface_at(scene: &Scene, side: usize, u: f32, v: f32) -> (Vec3, Vec3) {
    let (at, flip) = match scene.patches[side].sides {
        Sides::Back { front } => (front, true),
        _ => (side, false),
    };
    let patch = Patch {
        shape: scene.patches[at].shape,
    };
    let point = match &patch.shape {
        Shape::Polygon(p) => p.point(u, v),
        Shape::Bezier(b) => b.point(u, v),
    };
    let normal = patch.normal_at(u, v);
    (point, if flip { -normal } else { normal })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend::Path;

    /// A screen stands across a floor; two queries, one either side of it, see the floor in
    /// the one sub-cell its foot crosses. Shared by the request, each side still gets an
    /// evaluation of its own, on its own side: one at the mean of both would read one side's
    /// light for the other's hits.
    #[test]
    fn near_hits_across_a_contact_line_are_evaluated_apart() {
        let src = "[[material]]\nname = \"white\"\ndiffuse = [0.5, 0.5, 0.5]\n\n\
            [[quad]]\nname = \"floor\"\nmaterial = \"white\"\n\
            vertices = [[0, 0, 0], [0, 0, 1], [1, 0, 1], [1, 0, 0]]\n\n\
            [[quad]]\nname = \"screen\"\nmaterial = \"white\"\n\
            vertices = [[0.2, 0, 0.52], [0.2, 0.5, 0.52], [0.8, 0.5, 0.52], [0.8, 0, 0.52]]\n";
        let scene = crate::scene::parse(src, "screen.toml").unwrap();
        let k = 8;
        let cuts = crate::contact::cuts(&scene);
        let [[a, b]] = cuts[0][..] else {
            panic!("one contact line across the floor: {:?}", cuts[0]);
        };
        let grids = vec![
            Grid::with_cuts(k, &vec![[1.0; 3]; k * k], &cuts[0]),
            Grid::from_samples(k, &vec![[1.0; 3]; k * k]),
        ];
        // a point either side of the line's middle, 0.004 off it in (u, v)
        let (mid, along) = (
            [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])],
            [b[0] - a[0], b[1] - a[1]],
        );
        let len = along[0].hypot(along[1]);
        let off = |s: f64| {
            (
                (mid[0] - s * 0.004 * along[1] / len) as f32,
                (mid[1] + s * 0.004 * along[0] / len) as f32,
            )
        };
        let sides = [off(1.0), off(-1.0)];
        assert_eq!(
            sub_cell(k, sides[0].0, sides[0].1),
            sub_cell(k, sides[1].0, sides[1].1)
        );
        let queries: Vec<Query> = sides
            .iter()
            .map(|&(u, v)| {
                let (p, n) = surface_at(&scene, 0, u, v);
                Query {
                    point: p + n * 0.01,
                    normal: n,
                }
            })
            .collect();
        let seen: Vec<Vec<Seen>> = sides
            .iter()
            .map(|&(u, v)| {
                vec![Seen {
                    side: 0,
                    u,
                    v,
                    weight: [0.1; 3],
                    path: Path::Direct,
                }]
            })
            .collect();
        let near = NearField::of(
            &scene,
            &grids,
            &queries,
            &seen,
            NEAR,
            Grouping::Shared,
            |_| false,
        );
        assert_eq!(near.points.len(), 2, "{:?}", near.points);
        for (n, &(u, v)) in sides.iter().enumerate() {
            let (_, evaluation) = near.hits[n][0];
            assert_eq!(near.points[evaluation], (0, u, v));
        }
    }
}
