//! One patch's radiosity grid as a triangle mesh on the patch's surface.

use crate::radiosity::{grid_of, Grid};
use crate::scene::{Scene, Sides};
use hemi_kernel::geometry::Vec3;
use hemi_kernel::patch::Shape;

/// Mesh steps per grid cell of a Bezier patch: its 4×4 grid becomes 16×16 quads, enough for a
/// smooth teapot, while a planar patch needs no more than its grid (both its map and its light
/// are bilinear in each cell).
pub const BEZIER_STEPS: usize = 4;

/// One patch as a mesh: vertices with their radiosity, and triangles whose front (counter-
/// clockwise) side is the patch's lit side.
#[derive(Clone, Debug, PartialEq)]
pub struct PatchMesh {
    /// The patch's name (a translucent sheet's back side is `name:back`).
    pub name: String,
    /// Vertex positions, in the scene's units and axes.
    pub positions: Vec<[f32; 3]>,
    /// B at each vertex, W/m² per channel (linear).
    pub radiosity: Vec<[f32; 3]>,
    /// Vertex indices, counter-clockwise seen from the lit side.
    pub triangles: Vec<[u32; 3]>,
}

/// Every scene patch's mesh, in scene order (back sides of translucent sheets after the fronts,
/// facing the other way), from the radiosity field `grids` (one per scene patch).
pub fn meshes(scene: &Scene, grids: &[Grid]) -> anyhow::Result<Vec<PatchMesh>> {
    anyhow::ensure!(
        grids.len() == scene.patches.len(),
        "{} radiosity grids for {} patches",
        grids.len(),
        scene.patches.len()
    );
    let tolerance = (scene.extent() * 1e-6).powi(2);
    (0..scene.patches.len())
        .map(|i| Ok(patch_mesh(scene, i, grid_of(grids, i)?, tolerance)))
        .collect()
}

/// Patch `i` over an n×n lattice in (u, v): the grid's vertices on a polygon, [`BEZIER_STEPS`]
/// times finer on a Bezier patch. Triangles with less than `tolerance` of doubled area squared
/// (a triangle's collapsed edge, a Bezier pole) are left out.
fn patch_mesh(scene: &Scene, i: usize, grid: &Grid, tolerance: f32) -> PatchMesh {
    let p = &scene.patches[i];
    let (n, point): (usize, Box<dyn Fn(f32, f32) -> Vec3>) = match p.shape {
        Shape::Polygon(poly) => (grid.k(), Box::new(move |u, v| poly.point(u, v))),
        Shape::Bezier(b) => (grid.k() * BEZIER_STEPS, Box::new(move |u, v| b.point(u, v))),
    };
    let mut positions = Vec::with_capacity((n + 1) * (n + 1));
    let mut radiosity = Vec::with_capacity((n + 1) * (n + 1));
    for b in 0..=n {
        for a in 0..=n {
            let (u, v) = (a as f32 / n as f32, b as f32 / n as f32);
            positions.push(point(u, v).to_array());
            radiosity.push(grid.at(u, v).map(|x| x as f32));
        }
    }
    let back = matches!(p.sides, Sides::Back { .. });
    let at = |a: usize, b: usize| (b * (n + 1) + a) as u32;
    let mut triangles = Vec::with_capacity(2 * n * n);
    for b in 0..n {
        for a in 0..n {
            let (c00, c10, c11, c01) = (at(a, b), at(a + 1, b), at(a + 1, b + 1), at(a, b + 1));
            for t in [[c00, c10, c11], [c00, c11, c01]] {
                if doubled_area_squared(&positions, t) > tolerance {
                    triangles.push(if back { [t[0], t[2], t[1]] } else { t });
                }
            }
        }
    }
    PatchMesh {
        name: p.name.clone(),
        positions,
        radiosity,
        triangles,
    }
}

/// |(b − a) × (c − a)|² of triangle `t`.
fn doubled_area_squared(positions: &[[f32; 3]], t: [u32; 3]) -> f32 {
    let p = |k: usize| Vec3::from_array(positions[t[k] as usize]);
    let n = (p(1) - p(0)).cross(p(2) - p(0));
    n.dot(n)
}

/// The area of triangle `t`.
pub fn area(positions: &[[f32; 3]], t: [u32; 3]) -> f32 {
    0.5 * doubled_area_squared(positions, t).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCENE: &str = r#"
[[material]]
name = "m"
diffuse = [0.5, 0.5, 0.5]

[[quad]]
name = "q"
material = "m"
vertices = [[0,0,0],[2,0,0],[2,1,0],[0,1,0]]

[[triangle]]
name = "t"
material = "m"
vertices = [[0,0,1],[1,0,1],[0,1,1]]
"#;

    #[test]
    fn a_quad_is_its_grid_and_a_triangle_drops_its_collapsed_edge() {
        let scene = crate::scene::parse(SCENE, "t.toml").unwrap();
        let samples: Vec<[f64; 3]> = (0..4).map(|q| [q as f64; 3]).collect();
        let grids = vec![Grid::from_samples(2, &samples); 2];
        let m = meshes(&scene, &grids).unwrap();
        assert_eq!(m[0].positions.len(), 9);
        assert_eq!(m[0].triangles.len(), 8);
        assert_eq!(m[0].positions[8], [2.0, 1.0, 0.0]);
        assert_eq!(m[0].radiosity[4], grids[0].vertex(1, 1).map(|x| x as f32));
        // the top row of cells has one real triangle each, the other has two points at P2
        assert_eq!(m[1].triangles.len(), 6);
        for t in &m[0].triangles {
            let p = |k: usize| Vec3::from_array(m[0].positions[t[k] as usize]);
            let n = (p(1) - p(0)).cross(p(2) - p(0));
            assert!(n.z > 0.0, "counter-clockwise about the quad's normal +z");
        }
    }
}
