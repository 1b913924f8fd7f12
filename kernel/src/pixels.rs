//! Pass 2's ray casting (paper §5): eye rays through a range of pixels, each reported with the
//! patch it hits and the hit's (u,v) so the host can interpolate that patch's radiosity grid.
//! Specular colour by frustums joins here with issue "Specular".

use crate::accel::{Accelerator, Hit};
use crate::camera::Camera;

/// Traces `spp` eye rays through each pixel of `pixels` (row-major indices into the image) and
/// reports `sink(pixel, sample, hit)`.
pub fn trace_pixels<A: Accelerator, F: FnMut(u32, u32, Option<Hit>)>(
    accel: &mut A,
    camera: &Camera,
    pixels: core::ops::Range<u32>,
    spp: u32,
    dirs: &mut [crate::geometry::Vec3],
    mut sink: F,
) {
    let per_batch = (dirs.len() as u32 / spp.max(1)).max(1);
    let mut start = pixels.start;
    while start < pixels.end {
        let end = (start + per_batch).min(pixels.end);
        let mut n = 0;
        for p in start..end {
            let (x, y) = (p % camera.width, p / camera.width);
            for s in 0..spp.max(1) {
                let (ox, oy) = Camera::subpixel(s, spp);
                dirs[n] = camera.direction(x as f32 + ox, y as f32 + oy);
                n += 1;
            }
        }
        let spp = spp.max(1);
        accel.cast_from(camera.eye, &dirs[..n], true, |i, hit| {
            sink(start + i as u32 / spp, i as u32 % spp, hit);
        });
        start = end;
    }
}
