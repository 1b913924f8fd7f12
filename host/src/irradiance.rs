//! Irradiance at arbitrary points (the convention of Radiance's `rtrace -I`): the hemisphere is
//! placed at the point around the given direction and every ray gathers the radiosity where it
//! lands, so `E = Σ δD_j · B(hit)` (with L = B/π for diffuse surfaces, ∫L cos dω = Σ δD B).

use crate::radiosity::Grid;
use hemi_kernel::accel::Accelerator;
use hemi_kernel::geometry::Vec3;
use hemi_kernel::hemisphere::Hemisphere;
use hemi_kernel::rotation::Rotation;

/// Irradiance (W/m² per channel) at `point` for a surface facing `normal`; emitters included.
pub fn irradiance<A: Accelerator>(
    accel: &mut A,
    hemi: &Hemisphere<'_>,
    grids: &[Grid],
    point: Vec3,
    normal: Vec3,
) -> [f64; 3] {
    let rot = Rotation::onto(normal);
    let rings = hemi.rings();
    let mut e = [0.0f64; 3];
    accel.cast_rings(point, &rot, hemi, 0..rings.len(), true, |j, _, hit| {
        if let Some(h) = hit.filter(|h| h.front) {
            let b = grids[h.patch as usize].at(h.u, h.v);
            let w = rings[j].delta_ff as f64;
            for c in 0..3 {
                e[c] += w * b[c];
            }
        }
    });
    e
}
