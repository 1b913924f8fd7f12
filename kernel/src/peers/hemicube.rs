//! The hemicube of Cohen & Greenberg 1985 ("The Hemi-Cube", SIGGRAPH '85), the paper's baseline.
//!
//! A unit cube's upper half is placed on the sample point: the top face z = 1 with
//! x, y ∈ [−1, 1], cut into n × n pixels, and four side faces (x = ±1 or y = ±1, z ∈ [0, 1]),
//! each n × n/2 pixels, so 3n² pixels in all. Every pixel carries its delta form factor, the
//! point form factor of the pixel's centre (C&G 1985, eq. 9 and 10; ΔA = (2/n)²):
//!
//! ```text
//! top face  (x, y, 1):  ΔF = ΔA / (π (x² + y² + 1)²)
//! side face (1, y, z):  ΔF = z ΔA / (π (y² + z² + 1)²)      (and its three turns)
//! ```
//!
//! The original projects every patch onto the five faces with a z-buffer (the "item buffer").
//! Here the item buffer is filled by casting one ray from the sample point through each pixel
//! centre with the accelerator's `cast_from`: a z-buffer samples each pixel at its centre too,
//! so the item buffer is the same up to the rasteriser's edge rules, and the comparison with
//! the hemisphere then runs on the same intersection code, the same engines (soft, model) and
//! literally the same number of rays — what an equal-rays chart needs. A projection rasteriser
//! would also need near-plane clipping and a per-face frustum test that nothing else in the
//! kernel has.
//!
//! The delta form factors are the centre-point values as published, not normalised: they sum
//! to 1 only as n grows ([`Hemicube::delta_sum`]); that bias is part of the baseline.

use super::{cast_weighted, PeerError, Placement};
use crate::accel::Accelerator;
use crate::form_row::FormRow;
use crate::geometry::Vec3;
use crate::optics::Optics;
use crate::rotation::Rotation;
use crate::tracer::ShotStats;
use core::f64::consts::PI;

/// A hemicube of resolution n (n × n on the top face, n × n/2 on each side face).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Hemicube {
    n: u32,
}

/// A pixel: its direction through the centre (not normalised) and its delta form factor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pixel {
    /// The centre of the pixel on the unit hemicube, in the hemicube's frame (+z = normal).
    pub centre: Vec3,
    /// ΔF of the pixel.
    pub delta: f32,
}

impl Hemicube {
    /// A hemicube of resolution `n`, which must be even and at least 2 (the side faces have
    /// n/2 rows).
    pub fn new(n: u32) -> Result<Hemicube, PeerError> {
        if n < 2 || !n.is_multiple_of(2) || n > 4096 {
            return Err(PeerError::BadParameters);
        }
        Ok(Hemicube { n })
    }

    /// The even resolution whose 3n² rays come closest to `rays` (the equal-rays match with a
    /// hemisphere of R circles: `rays = ray_count(R)`).
    pub fn for_rays(rays: u32) -> Hemicube {
        let n = libm::sqrt(rays as f64 / 3.0);
        let n = (2.0 * libm::round(n / 2.0)).max(2.0) as u32;
        Hemicube { n: n.min(4096) }
    }

    /// n.
    pub fn resolution(&self) -> u32 {
        self.n
    }

    /// Rays (pixels) per hemicube: n² + 4 · n · n/2 = 3n².
    pub fn ray_count(&self) -> u32 {
        3 * self.n * self.n
    }

    /// Pixel `k` (0 ≤ k < 3n²): the top face first, row-major, then the side faces +x, +y, −x,
    /// −y, each n columns by n/2 rows.
    pub fn pixel(&self, k: u32) -> Pixel {
        let n = self.n;
        let step = 2.0 / n as f64;
        let da = step * step;
        let top = n * n;
        if k < top {
            let x = -1.0 + (k % n) as f64 * step + 0.5 * step;
            let y = -1.0 + (k / n) as f64 * step + 0.5 * step;
            let r = x * x + y * y + 1.0;
            return Pixel {
                centre: Vec3::new(x as f32, y as f32, 1.0),
                delta: (da / (PI * r * r)) as f32,
            };
        }
        let k = k - top;
        let per_face = n * (n / 2);
        let face = k / per_face;
        let k = k % per_face;
        let a = -1.0 + (k % n) as f64 * step + 0.5 * step; // along the face
        let z = (k / n) as f64 * step + 0.5 * step; // up the face
        let r = a * a + z * z + 1.0;
        let delta = (z * da / (PI * r * r)) as f32;
        let (a, z) = (a as f32, z as f32);
        let centre = match face {
            0 => Vec3::new(1.0, a, z),
            1 => Vec3::new(-a, 1.0, z),
            2 => Vec3::new(-1.0, -a, z),
            _ => Vec3::new(a, -1.0, z),
        };
        Pixel { centre, delta }
    }

    /// Σ ΔF over all pixels: 1 in the limit, below 1 at small n (the centre-point rule).
    pub fn delta_sum(&self) -> f64 {
        (0..self.ray_count())
            .map(|k| self.pixel(k).delta as f64)
            .sum()
    }
}

/// Shoots the hemicube `cube` at `at` and adds each pixel's ΔF to the diffuse patch its ray
/// reaches first (the item buffer), into `row` (one entry per diffuse column; the caller zeroes
/// it). `batch` is direction scratch of any non-zero length (the rays of one `cast_from`).
pub fn shoot_hemicube<A: Accelerator, R: FormRow + ?Sized>(
    accel: &mut A,
    cube: &Hemicube,
    optics: &Optics<'_>,
    at: &Placement,
    batch: &mut [Vec3],
    row: &mut R,
) -> Result<ShotStats, PeerError> {
    let rot = Rotation::onto_spun(at.normal, at.spin);
    cast_weighted(
        accel,
        optics,
        at,
        cube.ray_count(),
        batch,
        |k| {
            let c = cube.pixel(k).centre;
            rot.apply(c.try_normalize().unwrap_or(Vec3::Z))
        },
        |k| cube.pixel(k).delta,
        row,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn delta_form_factors_approach_one() {
        let mut last = 0.0;
        for n in [8, 32, 128] {
            let s = Hemicube::new(n).unwrap().delta_sum();
            assert!((s - 1.0).abs() < 0.02, "n={n}: {s}");
            assert!(
                (s - 1.0).abs() < (last - 1.0f64).abs() || last == 0.0,
                "n={n}: {s}"
            );
            last = s;
        }
    }

    #[test]
    fn pixels_cover_the_upper_half_once() {
        let c = Hemicube::new(6).unwrap();
        assert_eq!(c.ray_count(), 108);
        for k in 0..c.ray_count() {
            let p = c.pixel(k).centre;
            assert!(p.z > 0.0 && p.x.abs() <= 1.0 && p.y.abs() <= 1.0 && p.z <= 1.0);
            assert!(p.x.abs() == 1.0 || p.y.abs() == 1.0 || p.z == 1.0);
        }
        assert_eq!(Hemicube::for_rays(10297).resolution(), 58);
        assert!(Hemicube::new(7).is_err());
    }
}
