//! Pass 2's ray casting (paper §5): eye rays through a range of pixels. Each ray that reaches the
//! front of a diffuse patch is reported with the patch and the hit's (u,v), so the host can
//! interpolate that patch's radiosity grid (the diffuse colour). A ray that reaches a specular
//! patch places a frustum there, recursively (§5), and every frustum ray that reaches a diffuse
//! patch is reported the same way with its weight (the specular colour); the recursion is
//! bounded by contribution (Δ) and by the skeleton stack's depth, as in pass 1.

use crate::accel::{Accelerator, Hit};
use crate::camera::Camera;
use crate::geometry::Vec3;
use crate::hemisphere::Hemisphere;
use crate::optics::Optics;
use crate::specular::{spawns, Pending, SpecularStats};
use crate::tracer::TraceScratch;

/// Traces `spp` eye rays through each pixel of `pixels` (row-major indices into the image) and
/// reports `sink(pixel, sample, hit, weight)` for every ray, primary or frustum, that reaches
/// the front of a diffuse patch; `weight` is per channel and relative to the eye ray (1 for a
/// direct view). `hemi` is the table frustums are cut from; `dirs` is batch storage.
#[expect(
    clippy::too_many_arguments,
    reason = "the inputs of one pass-2 job, §5"
)]
pub fn trace_pixels<A: Accelerator, F: FnMut(u32, u32, &Hit, [f32; 3])>(
    accel: &mut A,
    camera: &Camera,
    optics: &Optics<'_>,
    hemi: &Hemisphere<'_>,
    scratch: &mut TraceScratch<'_>,
    pixels: core::ops::Range<u32>,
    spp: u32,
    dirs: &mut [Vec3],
    mut sink: F,
) -> SpecularStats {
    let spp = spp.max(1);
    let (pending, mut walker) = scratch.split(optics, hemi, true);
    let room = if optics.has_specular() {
        dirs.len().min(pending.len())
    } else {
        dirs.len()
    };
    let per_batch = (room as u32 / spp).max(1);
    let mut start = pixels.start;
    while start < pixels.end {
        let end = (start + per_batch).min(pixels.end);
        let mut n = 0;
        for p in start..end {
            let (x, y) = (p % camera.width, p / camera.width);
            for s in 0..spp {
                let (ox, oy) = Camera::subpixel(s, spp);
                if let Some(d) = dirs.get_mut(n) {
                    *d = camera.direction(x as f32 + ox, y as f32 + oy);
                    n += 1;
                }
            }
        }
        let mut parked = 0usize;
        accel.cast_from(camera.eye, &dirs[..n], true, |i, hit| {
            let Some(h) = hit else { return };
            let (p, s) = (start + i as u32 / spp, i as u32 % spp);
            if optics.surface(h.patch).column_for(h.front).is_some() {
                sink(p, s, &h, [1.0; 3]);
            }
            if spawns(optics, &h) {
                if let Some(slot) = pending.get_mut(parked) {
                    *slot = Pending {
                        tag: i as u32,
                        k: 0,
                        hit: h,
                    };
                    parked += 1;
                }
            }
        });
        for q in pending.iter().take(parked) {
            let i = q.tag;
            let (p, s) = (start + i / spp, i % spp);
            let dir = dirs[i as usize];
            walker.follow(accel, camera.eye, dir, &q.hit, 1.0, &mut |h, w, _| {
                sink(p, s, h, w)
            });
        }
        start = end;
    }
    walker.stats
}
