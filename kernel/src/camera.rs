//! The pinhole camera of pass 2 (paper §5): eye rays through pixel positions. It lives in the
//! kernel because the engine derives pixel rays itself from a short descriptor (a pixel range),
//! which keeps requests on the slow uplink tiny.

use crate::geometry::Vec3;

/// A pinhole camera with square pixels.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Camera {
    /// Eye position: the shared origin of all eye rays.
    pub eye: Vec3,
    /// Unit view direction.
    pub forward: Vec3,
    /// Unit vector to the image's right.
    pub right: Vec3,
    /// Unit vector to the image's top.
    pub up: Vec3,
    /// tan(fov_y / 2).
    pub tan_half_fov: f32,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
}

impl Camera {
    /// A camera at `eye` looking at `look_at`, `up` giving the image's vertical; `None` when the
    /// view direction is zero or parallel to `up`.
    pub fn look_at(
        eye: Vec3,
        look_at: Vec3,
        up: Vec3,
        fov_y_deg: f32,
        width: u32,
        height: u32,
    ) -> Option<Camera> {
        let forward = (look_at - eye).try_normalize()?;
        let right = forward.cross(up).try_normalize()?;
        let up = right.cross(forward);
        Some(Camera {
            eye,
            forward,
            right,
            up,
            tan_half_fov: libm::tanf(0.5 * fov_y_deg.to_radians()),
            width,
            height,
        })
    }

    /// The unit direction through image position (`x`, `y`) in pixels, (0, 0) the top-left corner
    /// of the image, (width, height) the bottom-right.
    pub fn direction(&self, x: f32, y: f32) -> Vec3 {
        let h = self.height as f32;
        let sx = (2.0 * x - self.width as f32) / h * self.tan_half_fov;
        let sy = (h - 2.0 * y) / h * self.tan_half_fov;
        let d = self.forward + self.right * sx + self.up * sy;
        d.try_normalize().unwrap_or(self.forward)
    }

    /// Sub-pixel offset `s` of `spp` (in [0,1)²): the R2 low-discrepancy sequence, so any number
    /// of samples per pixel covers the pixel evenly; a single sample sits at the centre.
    pub fn subpixel(s: u32, spp: u32) -> (f32, f32) {
        if spp <= 1 {
            return (0.5, 0.5);
        }
        const A1: f64 = 0.754_877_666_246_692_8;
        const A2: f64 = 0.569_840_290_998_053_3;
        let frac = |x: f64| x - libm::floor(x);
        (
            frac(0.5 + A1 * s as f64) as f32,
            frac(0.5 + A2 * s as f64) as f32,
        )
    }
}
