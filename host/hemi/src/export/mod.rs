//! The solution as meshes for viewers: every patch's radiosity grid (paper §4.3) as a mesh with
//! the radiosity B at each vertex, written as PLY ([`ply`]) or binary glTF ([`gltf`]).
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

/// The automatic exposure of the meshes' vertex radiances, by the rule the renderer uses for
/// its pixels ([`crate::render::image::exposure_for`]).
pub fn auto_exposure(meshes: &[PatchMesh]) -> f64 {
    let pi = std::f32::consts::PI;
    crate::render::image::exposure_for(
        meshes
            .iter()
            .flat_map(|m| m.radiosity.iter().map(move |b| b.map(|x| x / pi))),
    )
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
