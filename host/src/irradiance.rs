//! Irradiance at arbitrary points (the convention of Radiance's `rtrace -I`): the hemisphere is
//! placed at the point around the given direction and every ray gathers the radiosity where it
//! lands, directly or through specular surfaces, so `E = Σ δD_j · w · B(hit)` (with L = B/π for
//! diffuse surfaces, ∫L cos dω = Σ δD B; w is what mirrors on the way pass on).

use crate::radiosity::Grid;
use crate::scene::Scene;
use hemi_kernel::accel::Accelerator;
use hemi_kernel::geometry::Vec3;
use hemi_kernel::hemisphere::Hemisphere;
use hemi_kernel::optics::Optics;
use hemi_kernel::tracer::{shoot, Shot, TraceScratch};

/// Irradiance (W/m² per channel) at `point` for a surface facing `normal`; emitters included.
/// `grids` are per scene patch (the back sides of translucent sheets included).
#[allow(
    clippy::too_many_arguments,
    reason = "the inputs of one irradiance query"
)]
pub fn irradiance<A: Accelerator>(
    accel: &mut A,
    hemi: &Hemisphere<'_>,
    optics: &Optics<'_>,
    scratch: &mut TraceScratch<'_>,
    scene: &Scene,
    grids: &[Grid],
    point: Vec3,
    normal: Vec3,
) -> [f64; 3] {
    let mut e = [0.0f64; 3];
    let shot = Shot {
        origin: point,
        normal,
        spin: 0.0,
        origin_patch: None,
        want_uv: true,
    };
    shoot(accel, hemi, optics, scratch, &shot, |h, w| {
        let b = grids[scene.side_seen(h.patch, h.front)].at(h.u, h.v);
        for c in 0..3 {
            e[c] += w[c] as f64 * b[c];
        }
    });
    e
}
