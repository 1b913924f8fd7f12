//! The meshes as one binary PLY file (little endian): MeshLab and Blender read its positions,
//! triangles and 8-bit sRGB vertex colours, and the radiosity rides along as three float vertex
//! properties `radiosity_r/g/b`. A PLY writer is a header and two loops, so it is written here
//! rather than taken from a crate.

use super::{display, PatchMesh};
use crate::render::image::srgb8;
use std::io::{Result, Write};

/// Writes `meshes` as PLY, the colours at `exposure` stops. Faces carry the index of their
/// patch (`patch`, in the order of `meshes`), so a viewer can select one patch.
pub fn write_ply(out: &mut dyn Write, meshes: &[PatchMesh], exposure: f64) -> Result<()> {
    let vertices: usize = meshes.iter().map(|m| m.positions.len()).sum();
    let faces: usize = meshes.iter().map(|m| m.triangles.len()).sum();
    write!(
        out,
        "ply\nformat binary_little_endian 1.0\n\
         comment hemi radiosity solution: radiosity_r/g/b is B in W/m^2 per channel (linear);\n\
         comment red/green/blue is the radiance B/pi at {exposure:+.2} EV, sRGB-encoded\n\
         element vertex {vertices}\n\
         property float x\nproperty float y\nproperty float z\n\
         property uchar red\nproperty uchar green\nproperty uchar blue\n\
         property float radiosity_r\nproperty float radiosity_g\nproperty float radiosity_b\n\
         element face {faces}\n\
         property list uchar uint vertex_indices\nproperty uint patch\n\
         end_header\n"
    )?;
    for m in meshes {
        for (p, b) in m.positions.iter().zip(&m.radiosity) {
            for x in p {
                out.write_all(&x.to_le_bytes())?;
            }
            out.write_all(&display(*b, exposure).map(|c| srgb8(c as f64)))?;
            for x in b {
                out.write_all(&x.to_le_bytes())?;
            }
        }
    }
    let mut first = 0u32;
    for (patch, m) in meshes.iter().enumerate() {
        for t in &m.triangles {
            out.write_all(&[3])?;
            for i in t {
                out.write_all(&(first + i).to_le_bytes())?;
            }
            out.write_all(&(patch as u32).to_le_bytes())?;
        }
        first += m.positions.len() as u32;
    }
    Ok(())
}
