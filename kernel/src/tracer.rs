//! Pass 1's inner loop (paper §3.1, §3.4): place the hemisphere on a sample point and add each
//! ray's delta form factor to the patch it hits first.
//!
//! A ray that reaches the front of patch j adds δD_j of its ring to F_iq,j; a ray that reaches a
//! back side is blocked and adds nothing (one-sided patches), and a ray that leaves the scene
//! adds nothing either, so a row sums to the fraction of the hemisphere that sees front sides.

use crate::accel::Accelerator;
use crate::geometry::Vec3;
use crate::hemisphere::Hemisphere;
use crate::rotation::Rotation;

/// What one hemisphere shot did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ShotStats {
    /// Rays cast.
    pub rays: u32,
    /// Rays that hit a front side.
    pub front_hits: u32,
    /// Rays blocked by a back side.
    pub back_hits: u32,
}

impl core::ops::AddAssign for ShotStats {
    fn add_assign(&mut self, o: ShotStats) {
        self.rays += o.rays;
        self.front_hits += o.front_hits;
        self.back_hits += o.back_hits;
    }
}

/// Shoots the hemisphere `hemi` from `origin` around `normal`, spun by `spin` about the normal
/// (see [`crate::rotation::spin_for_sample`]), and accumulates the element-to-patch form factors
/// F_iq,j into `row` (one entry per patch; the caller zeroes it). `origin_patch` is the patch
/// the sample point lies on, which the hemisphere does not see (F_ii = 0).
pub fn shoot_hemisphere<A: Accelerator>(
    accel: &mut A,
    hemi: &Hemisphere<'_>,
    origin: Vec3,
    normal: Vec3,
    spin: f32,
    origin_patch: Option<u32>,
    row: &mut [f32],
) -> ShotStats {
    let rot = Rotation::onto_spun(normal, spin);
    let rings = hemi.rings();
    let mut stats = ShotStats::default();
    accel.set_origin_patch(origin_patch);
    accel.cast_rings(origin, &rot, hemi, 0..rings.len(), false, |j, _k, hit| {
        stats.rays += 1;
        if let Some(hit) = hit {
            if hit.front {
                stats.front_hits += 1;
                if let Some(slot) = row.get_mut(hit.patch as usize) {
                    *slot += rings[j].delta_ff;
                }
            } else {
                stats.back_hits += 1;
            }
        }
    });
    accel.set_origin_patch(None);
    stats
}
