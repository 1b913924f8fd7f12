//! `hemi render --show-samples`: the sample points adaptive patch sampling shot (paper §4.2),
//! drawn over the rendered image as dots coloured by the level they were shot at, so a figure
//! shows where the rows went (the paper's picture 4).
//!
//! A point is drawn where the camera sees it: projected through the pinhole and kept only if
//! the eye ray towards it reaches its own patch within 1 % of its distance (the published
//! Cornell walls are warped by 0.4 %, so a planar point and the hit differ a little; points
//! behind other surfaces are hidden, as they would be in a photograph of markers on the surfaces).

use crate::adaptive::PatchReport;
use crate::render::Image;
use hemi_kernel::accel::{Accelerator, Ray};
use hemi_kernel::camera::Camera;
use hemi_kernel::geometry::Vec3;

/// Dot colours by level (0 = the initial guess), sRGB.
pub const LEVEL_COLOURS: [[u8; 3]; 6] = [
    [255, 255, 255],
    [255, 230, 0],
    [255, 140, 0],
    [230, 30, 30],
    [200, 0, 200],
    [0, 170, 255],
];

/// Where the camera sees `p`: the continuous pixel position, or `None` behind the eye.
pub fn project(camera: &Camera, p: Vec3) -> Option<(f32, f32)> {
    let d = p - camera.eye;
    let z = d.dot(camera.forward);
    if z <= 0.0 {
        return None;
    }
    let h = camera.height as f32;
    let sx = d.dot(camera.right) / z / camera.tan_half_fov;
    let sy = d.dot(camera.up) / z / camera.tan_half_fov;
    // the inverse of Camera::direction: sx = (2x − w)/h, sy = (h − 2y)/h
    Some((0.5 * (sx * h + camera.width as f32), 0.5 * (h - sy * h)))
}

fn linear(c: u8) -> f32 {
    let x = c as f32 / 255.0;
    if x <= 0.04045 {
        x / 12.92
    } else {
        ((x + 0.055) / 1.055).powf(2.4)
    }
}

/// Draws every computed sample point of `reports` that the camera sees onto `img` as a dot of
/// `radius` pixels with a dark rim, in the colour of its level; `exposure` (stops) is the one the
/// image will be written with, so the dots come out in their sRGB colours. `accel` answers the
/// visibility rays. Returns the number of dots drawn.
pub fn draw_samples<A: Accelerator>(
    img: &mut Image,
    camera: &Camera,
    reports: &[PatchReport],
    accel: &mut A,
    exposure: f64,
    radius: f32,
) -> usize {
    let scale = 2f64.powf(-exposure) as f32;
    let colour = |c: [u8; 3]| c.map(|x| linear(x) * scale);
    let rim = colour([20, 20, 20]);
    let mut drawn = 0;
    for (i, r) in reports.iter().enumerate() {
        for s in &r.computed {
            let p = s.point.position;
            let Some((x, y)) = project(camera, p) else {
                continue;
            };
            if x < 0.0 || y < 0.0 || x >= camera.width as f32 || y >= camera.height as f32 {
                continue;
            }
            let to = p - camera.eye;
            let dist = to.length();
            let Some(dir) = to.try_normalize() else {
                continue;
            };
            // front side only, and nothing in between
            if dir.dot(s.point.normal) >= 0.0 {
                continue;
            }
            let visible = accel
                .nearest_hit(
                    &Ray {
                        origin: camera.eye,
                        dir,
                    },
                    f32::INFINITY,
                )
                .is_some_and(|h| h.patch as usize == i && (h.t - dist).abs() < 1e-2 * dist);
            if !visible {
                continue;
            }
            let fill = colour(LEVEL_COLOURS[(s.depth as usize).min(LEVEL_COLOURS.len() - 1)]);
            let outer = radius + 1.0;
            let (x0, x1) = ((x - outer).floor() as i64, (x + outer).ceil() as i64);
            let (y0, y1) = ((y - outer).floor() as i64, (y + outer).ceil() as i64);
            for py in y0.max(0)..y1.min(camera.height as i64) {
                for px in x0.max(0)..x1.min(camera.width as i64) {
                    let d = ((px as f32 + 0.5 - x).powi(2) + (py as f32 + 0.5 - y).powi(2)).sqrt();
                    let c = if d <= radius {
                        fill
                    } else if d <= outer {
                        rim
                    } else {
                        continue;
                    };
                    img.pixels[py as usize * img.width as usize + px as usize] = c;
                }
            }
            drawn += 1;
        }
    }
    drawn
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn projection_inverts_the_camera_rays() {
        let cam = Camera::look_at(
            Vec3::new(1.0, 2.0, -5.0),
            Vec3::new(0.5, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            40.0,
            320,
            200,
        )
        .unwrap();
        for (x, y) in [(0.5, 0.5), (160.0, 100.0), (300.25, 17.5), (12.0, 190.0)] {
            let p = cam.eye + cam.direction(x, y) * 7.0;
            let (px, py) = project(&cam, p).unwrap();
            assert!((px - x).abs() < 1e-3 && (py - y).abs() < 1e-3, "{x},{y}");
        }
        assert!(project(&cam, cam.eye - cam.forward).is_none());
    }
}
