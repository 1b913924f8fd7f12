//! Where one surface stands on another: the lines across a patch that its radiosity grid must
//! not interpolate across.
//!
//! A partition standing on a floor, or a block's foot, cuts the floor into parts that see
//! different light (behind a screen lit from behind, the floor is twenty times brighter than in
//! front of it). The grid of §4.3 blends each vertex from the samples around it and each point
//! from the vertices around it, so near such a line it carries light from one side to the other:
//! the light leak of classic radiosity, here a bright band of about a cell in front of the
//! screen, which every point that sees it reads (3–8 % too much light on the dark side of a
//! partition, halving with the cell; docs/ACCURACY.md, "Light leaking under a partition").
//!
//! The lines are found from the geometry alone: an edge of another polygon that lies in the
//! patch's plane, not along one of its own edges (where a wall meets the floor at its border),
//! from a polygon that is not coplanar with it. They are kept in the patch's (u, v) and handed
//! to its grid ([`crate::grid::Grid::with_cuts`]), which blends only what lies on the same side.
//! Curved patches neither cut nor are cut.

use crate::scene::Scene;
use hemi_kernel::geometry::{Polygon, Vec3};

/// A line across a patch, from one (u, v) to another.
pub type Cut = [[f64; 2]; 2];

/// Above this many patches the search (every edge against every patch, pruned by boxes) is
/// not made, and grids blend across contacts as the paper's do.
pub const MAX_PATCHES: usize = 6_000;

/// How close to a patch's plane an edge must lie, as a fraction of the scene's size.
const ON_PLANE: f64 = 1e-5;
/// A cut shorter than this in (u, v) is dropped.
const BORDER: f64 = 1e-3;

/// The cuts across each patch of `scene` (empty lists for most), in scene order.
pub fn cuts(scene: &Scene) -> Vec<Vec<Cut>> {
    let polys: Vec<Option<&Polygon>> = scene.patches.iter().map(|p| p.polygon()).collect();
    if polys.len() > MAX_PATCHES {
        return vec![Vec::new(); polys.len()];
    }
    let tol = scene_size(&polys) * ON_PLANE;
    let boxes: Vec<Option<(Vec3, Vec3)>> = polys.iter().map(|p| p.map(bounds)).collect();
    (0..polys.len())
        .map(|i| {
            let (Some(receiver), Some(bounds)) = (polys[i], boxes[i]) else {
                return Vec::new();
            };
            let others = polys
                .iter()
                .zip(&boxes)
                .enumerate()
                .filter_map(|(j, pair)| match pair {
                    (Some(p), Some(b)) if j != i && overlaps(b, &bounds, tol) => Some(*p),
                    _ => None,
                });
            cuts_across(receiver, others, tol)
        })
        .collect()
}

/// The cuts `others` (the polygons near it) make across `receiver`: their edges within `tol`
/// of its plane, not along its own edges, from polygons not coplanar with it (a coplanar
/// neighbour's edges are the receiver's own border, or a decal).
fn cuts_across<'p>(
    receiver: &Polygon,
    others: impl Iterator<Item = &'p Polygon>,
    tol: f64,
) -> Vec<Cut> {
    let Some(frame) = receiver.uv_frame() else {
        return Vec::new();
    };
    let on = |p: Vec3| f64::from(receiver.normal.dot(p - receiver.v[0])).abs() <= tol;
    let mut out: Vec<Cut> = Vec::new();
    for other in others {
        if f64::from(receiver.normal.dot(other.normal)).abs() > 0.999 {
            continue;
        }
        for edge in edges(other) {
            if !(on(edge[0]) && on(edge[1])) || along_border(receiver, edge, tol) {
                continue;
            }
            let cut = edge.map(|p| {
                let (u, v) = frame.uv_of(p);
                [f64::from(u), f64::from(v)]
            });
            let seen = out.contains(&cut) || out.contains(&[cut[1], cut[0]]);
            if crosses_inside(&cut) && !seen {
                out.push(cut);
            }
        }
    }
    out
}

/// Twice the signed area of the triangle p, q, r in (u, v): positive when r lies left of the
/// line from p to q.
pub fn orient(p: [f64; 2], q: [f64; 2], r: [f64; 2]) -> f64 {
    (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])
}

/// Whether the straight path from `a` to `b` crosses `cut` (strictly: touching an end or
/// running along it does not count).
pub fn crosses(a: [f64; 2], b: [f64; 2], cut: &Cut) -> bool {
    let [c, d] = *cut;
    orient(a, b, c) * orient(a, b, d) < 0.0 && orient(c, d, a) * orient(c, d, b) < 0.0
}

/// Whether a cut is long enough to matter in (u, v).
fn crosses_inside(cut: &Cut) -> bool {
    let [p, q] = *cut;
    (p[0] - q[0]).hypot(p[1] - q[1]) > BORDER
}

/// Whether `edge` runs along one of `poly`'s own edges (both ends within `tol` of its line):
/// a wall's foot along the floor's border, a neighbour's shared edge.
fn along_border(poly: &Polygon, edge: [Vec3; 2], tol: f64) -> bool {
    edges(poly).any(|[a, b]| {
        let Some(dir) = (b - a).try_normalize() else {
            return false;
        };
        let off = |p: Vec3| {
            let d = p - a;
            f64::from((d - dir * d.dot(dir)).length())
        };
        off(edge[0]) <= tol && off(edge[1]) <= tol
    })
}

/// The polygon's edges as pairs of corners.
fn edges(p: &Polygon) -> impl Iterator<Item = [Vec3; 2]> + '_ {
    let n = p.sides as usize;
    (0..n).map(move |i| [p.v[i], p.v[(i + 1) % n]])
}

fn bounds(p: &Polygon) -> (Vec3, Vec3) {
    let mut lo = p.v[0];
    let mut hi = p.v[0];
    for v in &p.v[..p.sides as usize] {
        lo = Vec3::new(lo.x.min(v.x), lo.y.min(v.y), lo.z.min(v.z));
        hi = Vec3::new(hi.x.max(v.x), hi.y.max(v.y), hi.z.max(v.z));
    }
    (lo, hi)
}

/// Whether two boxes overlap, each grown by `pad`.
fn overlaps(a: &(Vec3, Vec3), b: &(Vec3, Vec3), pad: f64) -> bool {
    let pad = pad as f32;
    (0..3).all(|k| a.0[k] - pad <= b.1[k] + pad && b.0[k] - pad <= a.1[k] + pad)
}

/// The diagonal of the polygons' bounds.
fn scene_size(polys: &[Option<&Polygon>]) -> f64 {
    let mut all = polys.iter().flatten().map(|p| bounds(p));
    let Some(first) = all.next() else { return 1.0 };
    let (lo, hi) = all.fold(first, |(lo, hi), (l, h)| {
        (
            Vec3::new(lo.x.min(l.x), lo.y.min(l.y), lo.z.min(l.z)),
            Vec3::new(hi.x.max(h.x), hi.y.max(h.y), hi.z.max(h.z)),
        )
    });
    f64::from((hi - lo).length()).max(1e-30)
}

#[cfg(test)]
mod tests {
    use super::{crosses, cuts};
    use crate::scene::load;

    /// The paper screen stands on the floor: one cut across the floor, where the screen meets
    /// it, and none along the walls' feet (the floor's border) or across the walls.
    #[test]
    fn a_screen_on_a_floor_cuts_the_floor_only() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../scenes/paper-screen.toml"
        );
        let scene = load(std::path::Path::new(path)).unwrap();
        let all = cuts(&scene);
        let floor = scene
            .patches
            .iter()
            .position(|p| p.name == "floor")
            .unwrap();
        assert_eq!(all[floor].len(), 1 + 4, "{:?}", all[floor]);
        for (i, c) in all.iter().enumerate() {
            if i != floor {
                assert!(c.is_empty(), "{}: {c:?}", scene.patches[i].name);
            }
        }
        // the screen's foot: from x = 0.5 to 3.5 at z = 2 of a floor 4 wide and 6.5 deep
        let foot = all[floor].iter().find(|c| {
            let d = (c[0][0] - c[1][0]).abs().max((c[0][1] - c[1][1]).abs());
            (d - 0.75).abs() < 1e-4 || (d - 3.0 / 6.5).abs() < 1e-4
        });
        assert!(foot.is_some(), "{:?}", all[floor]);
    }

    /// The Cornell box: the blocks' feet cut its floor, four lines each, and nothing else is
    /// cut (the walls' feet, the ceiling's pieces around the lamp, the red wall's two halves
    /// run along each other's borders or are coplanar).
    #[test]
    fn the_blocks_cut_the_cornell_floor_only() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/cornell.toml");
        let scene = load(std::path::Path::new(path)).unwrap();
        let all = cuts(&scene);
        for (p, c) in scene.patches.iter().zip(&all) {
            let want = if p.name == "floor" { 8 } else { 0 };
            assert_eq!(c.len(), want, "{}: {c:?}", p.name);
        }
    }

    #[test]
    fn crossing_is_strict() {
        let cut = [[0.0, 0.5], [1.0, 0.5]];
        assert!(crosses([0.5, 0.0], [0.5, 1.0], &cut));
        assert!(!crosses([0.5, 0.0], [0.5, 0.5], &cut), "touching");
        assert!(!crosses([1.5, 0.0], [1.5, 1.0], &cut), "beyond the end");
        assert!(!crosses([0.0, 0.0], [1.0, 0.0], &cut), "parallel");
    }
}
