//! The solution as meshes for viewers: every patch's radiosity grid (paper §4.3) as a mesh with
//! the radiosity B at each vertex, written as PLY ([`write_ply`]) or binary glTF ([`write_glb`]).
//!
//! The radiosity solution is view independent, so once it is solved it can be looked at from
//! anywhere in Blender, MeshLab or a glTF viewer instead of only through pass 2's camera. A
//! polygon's mesh is its (K+1)×(K+1) vertex grid itself (the grid pass 2 interpolates); a curved
//! (Bezier) patch is tessellated finer than its grid ([`BEZIER_STEPS`] per grid cell), its
//! vertices on the surface and their radiosity interpolated from the grid, so the silhouette is
//! smooth while the light is exactly the grid's. Each vertex carries B in W/m² as linear floats
//! and a display colour: the radiance B/π at an exposure, clipped to [0, 1], which is what the
//! rendered PNG shows at that exposure.

mod gltf;
mod mesh;
mod ply;

pub use gltf::write_glb;
pub use mesh::{meshes, PatchMesh, BEZIER_STEPS};
pub use ply::write_ply;

/// The display value of radiosity `b` at `exposure` stops: radiance B/π × 2^exposure, linear,
/// clipped to [0, 1] (glTF's COLOR_0 is linear; PLY's 8-bit colours are its sRGB encoding).
pub fn display(b: [f32; 3], exposure: f64) -> [f32; 3] {
    let scale = 2f64.powf(exposure) / std::f64::consts::PI;
    b.map(|x| (x as f64 * scale).clamp(0.0, 1.0) as f32)
}

/// The automatic exposure of the meshes, by the rule the renderer applies to its pixels
/// ([`crate::render::image::auto_exposure`]) with every vertex weighted by the area around it
/// (a third of its triangles'): the lamp's few vertices then weigh what the lamp's few pixels
/// do, instead of a twentieth of the vertices of a small scene.
pub fn auto_exposure(meshes: &[PatchMesh]) -> f64 {
    use crate::render::image::{luminance, EXPOSED_LEVEL, EXPOSED_PERCENTILE};
    let mut lum: Vec<(f32, f64)> = Vec::new();
    for m in meshes {
        let mut area = vec![0.0f64; m.positions.len()];
        for t in &m.triangles {
            let a = mesh::area(&m.positions, *t) as f64 / 3.0;
            for &i in t {
                area[i as usize] += a;
            }
        }
        let radiance = m
            .radiosity
            .iter()
            .map(|b| luminance(b) / std::f32::consts::PI);
        lum.extend(radiance.zip(area).filter(|&(l, a)| l > 0.0 && a > 0.0));
    }
    lum.sort_by(|a, b| a.0.total_cmp(&b.0));
    let total: f64 = lum.iter().map(|(_, a)| a).sum();
    let mut below = 0.0;
    for (l, a) in lum {
        below += a;
        if below >= EXPOSED_PERCENTILE * total {
            return (EXPOSED_LEVEL / l as f64).log2();
        }
    }
    0.0
}

/// A mesh format's writer: [`write_ply`] or [`write_glb`] (meshes, exposure in stops).
pub type Writer = fn(&mut dyn std::io::Write, &[PatchMesh], f64) -> std::io::Result<()>;

/// Writes `meshes` to the file `path` with `write`, the error naming the file.
pub fn write_file(
    path: &std::path::Path,
    meshes: &[PatchMesh],
    exposure: f64,
    write: Writer,
) -> anyhow::Result<()> {
    use anyhow::Context;
    let file =
        std::fs::File::create(path).with_context(|| format!("cannot create {}", path.display()))?;
    let mut out = std::io::BufWriter::new(file);
    write(&mut out, meshes, exposure)
        .and_then(|()| std::io::Write::flush(&mut out))
        .with_context(|| format!("cannot write {}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A square of side `s` at uniform radiosity `b`.
    fn square(s: f32, b: f32) -> PatchMesh {
        PatchMesh {
            name: "square".into(),
            positions: vec![[0.0, 0.0, 0.0], [s, 0.0, 0.0], [s, s, 0.0], [0.0, s, 0.0]],
            radiosity: vec![[b; 3]; 4],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
        }
    }

    #[test]
    fn a_small_bright_lamp_does_not_set_the_exposure_of_a_large_wall() {
        // the lamp has as many vertices as the wall but 1/10 000 of its area
        let meshes = [square(100.0, std::f32::consts::PI), square(1.0, 1e3)];
        let ev = auto_exposure(&meshes);
        assert!((ev - 0.85f64.log2()).abs() < 1e-6, "{ev}");
        assert_eq!(display([std::f32::consts::PI; 3], ev), [0.85; 3]);
    }
}
