//! The one seam between the kernel and the hardware: an accelerator rotates hemisphere rays onto a
//! normal (paper §3.4) and finds the nearest hit of a ray among the loaded patches (§6.1).
//!
//! Three implementations exist across the workspace: [`soft`] (f32, here), the HDL model
//! (`hemi-hdl-model`, bit-accurate fixed point with cycle counts) and the memory-mapped registers
//! of the board (`hemi-firmware`). The tracer is generic over this trait and never knows which
//! one it drives.

pub mod bvh;
pub mod either;
pub mod simd;
pub mod soft;
pub mod wide_bvh;

use crate::geometry::Vec3;
use crate::hemisphere::Hemisphere;
use crate::rotation::Rotation;
use core::ops::Range;

/// A ray `origin + t dir`, `dir` unit length, `t > 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Where the ray starts.
    pub origin: Vec3,
    /// Unit direction.
    pub dir: Vec3,
}

/// The nearest intersection of a ray with the loaded patches.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Index of the patch hit.
    pub patch: u32,
    /// Distance along the ray.
    pub t: f32,
    /// Parametric u of the hit on the patch (valid when asked for).
    pub u: f32,
    /// Parametric v of the hit on the patch.
    pub v: f32,
    /// Whether the ray hit the front side (the side the patch emits and reflects from).
    pub front: bool,
}

/// One hemisphere of a batch ([`Accelerator::cast_hemispheres`]): where it stands, how it is
/// turned, and the patch it stands on (left out, as [`Accelerator::set_origin_patch`] names it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HemiShot {
    /// The sample point.
    pub origin: Vec3,
    /// The frame the reference hemisphere is turned onto.
    pub rot: Rotation,
    /// The patch the point lies on, if any.
    pub origin_patch: Option<u32>,
}

/// A ray engine. Methods take `&mut self` because hardware ones have state (FIFOs, counters).
pub trait Accelerator {
    /// Rot_{θ,φ}(d): one direction of the reference hemisphere onto the frame `rot`.
    fn rotate(&mut self, rot: &Rotation, d: Vec3) -> Vec3;

    /// Names the patch the following hemisphere casts start on, so the engine leaves it out: a
    /// patch does not see itself (F_ii = 0, as in the paper's patch form factors; for a planar
    /// patch that holds anyway). `None` lifts it. Engines that cannot skip may ignore this.
    fn set_origin_patch(&mut self, patch: Option<u32>) {
        let _ = patch;
    }

    /// The nearest hit of `ray` with `t < t_max` among the loaded patches, with (u,v).
    fn nearest_hit(&mut self, ray: &Ray, t_max: f32) -> Option<Hit>;

    /// Casts rays that share `origin` (eye rays, paper §5) and reports `sink(i, hit)` for each
    /// direction `dirs[i]`. The provided method casts them one by one.
    fn cast_from<F: FnMut(usize, Option<Hit>)>(
        &mut self,
        origin: Vec3,
        dirs: &[Vec3],
        want_uv: bool,
        mut sink: F,
    ) {
        let _ = want_uv;
        for (i, &dir) in dirs.iter().enumerate() {
            sink(i, self.nearest_hit(&Ray { origin, dir }, f32::INFINITY));
        }
    }

    /// Casts rings `rings` of the hemisphere `hemi`, placed at `origin` and turned by `rot`, and
    /// reports every ray's nearest hit as `sink(ring, k, hit)`. (u,v) are filled in only when
    /// `want_uv`. Frustums (paper §3.3) are the first rings of the same table.
    ///
    /// The provided method rotates and casts ray by ray; engines that can exploit the shared
    /// origin and the fixed direction table override it.
    fn cast_rings<F: FnMut(usize, u32, Option<Hit>)>(
        &mut self,
        origin: Vec3,
        rot: &Rotation,
        hemi: &Hemisphere<'_>,
        rings: Range<usize>,
        want_uv: bool,
        mut sink: F,
    ) {
        let _ = want_uv;
        for j in rings {
            let ring = hemi.rings()[j];
            for k in 0..ring.count {
                let dir = self.rotate(rot, hemi.direction(j, k));
                sink(j, k, self.nearest_hit(&Ray { origin, dir }, f32::INFINITY));
            }
        }
    }

    /// Casts rings `rings` of `hemi` for every shot of `shots` and reports each ray's nearest hit
    /// as `sink(shot, ring, k, hit)`, each shot's rays in ring order (an engine may report a
    /// shot it cannot cast, such as one out of its range, before earlier ones); leaves no origin
    /// patch named.
    ///
    /// The provided method casts the shots one by one with [`Accelerator::cast_rings`]. A
    /// pipelined engine overrides it so that the next hemisphere's rays enter while the last
    /// ones of the previous are still in flight: one `cast_rings` per hemisphere would drain
    /// the pipeline every time, because it returns only with the last result.
    fn cast_hemispheres<F: FnMut(usize, usize, u32, Option<Hit>)>(
        &mut self,
        shots: &[HemiShot],
        hemi: &Hemisphere<'_>,
        rings: Range<usize>,
        want_uv: bool,
        mut sink: F,
    ) {
        for (s, shot) in shots.iter().enumerate() {
            self.set_origin_patch(shot.origin_patch);
            self.cast_rings(
                shot.origin,
                &shot.rot,
                hemi,
                rings.clone(),
                want_uv,
                |j, k, h| sink(s, j, k, h),
            );
        }
        self.set_origin_patch(None);
    }
}
