//! Placing the hemisphere on a surface (paper §3.4): the reference hemisphere points along +z and
//! is turned onto the normal n by two plane rotations, the same two a pair of CORDICs perform:
//!
//! ```text
//! φ = atan2(n_y, n_x),   θ = atan2(n_x cos φ + n_y sin φ, n_z)
//! Rot_{θ,φ}: first about y by θ (the x–z plane), then about z by φ (the x–y plane)
//! ```
//!
//! A third plane rotation, a spin ψ about the hemisphere's own axis applied first, turns the
//! azimuth origin of the rings. The paper has no spin (ψ = 0); hemi gives each sample point of a
//! patch a different ψ (see [`spin_for_sample`]) so that the boundary errors of neighbouring
//! sample points do not line up with the same ring structure and cancel in (4.3) instead of
//! adding up (measured in docs/ACCURACY.md).
//!
//! `atan2` (CORDIC vectoring mode) is total: normals along any axis (n_x = n_y = 0, n_z = 0, ±z)
//! give finite angles, so no NaN can reach the rays.

use crate::geometry::Vec3;

/// The two rotations that carry +z onto a unit normal, kept as cosines and sines (what a
/// rotation-mode CORDIC consumes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rotation {
    /// cos φ (azimuth of the normal)
    pub cos_phi: f32,
    /// sin φ
    pub sin_phi: f32,
    /// cos θ (polar angle of the normal)
    pub cos_theta: f32,
    /// sin θ
    pub sin_theta: f32,
    /// cos ψ (spin about the hemisphere's axis, applied first)
    pub cos_psi: f32,
    /// sin ψ
    pub sin_psi: f32,
}

/// The golden-ratio spin of sample `index`: ψ = 2π·frac(index·(√5−1)/2), a low-discrepancy
/// sequence, so any run of consecutive sample points spreads its azimuth origins evenly.
pub fn spin_for_sample(index: u32) -> f32 {
    const GOLDEN: f64 = 0.618_033_988_749_894_8;
    let f = index as f64 * GOLDEN;
    ((f - libm::floor(f)) * core::f64::consts::TAU) as f32
}

impl Rotation {
    /// No rotation: the hemisphere stays along +z.
    pub const IDENTITY: Rotation = Rotation {
        cos_phi: 1.0,
        sin_phi: 0.0,
        cos_theta: 1.0,
        sin_theta: 0.0,
        cos_psi: 1.0,
        sin_psi: 0.0,
    };

    /// The rotation that takes +z onto `normal` (need not be exactly unit; must be non-zero).
    pub fn onto(normal: Vec3) -> Rotation {
        Self::onto_spun(normal, 0.0)
    }

    /// The rotation that first spins the hemisphere by `spin` about +z, then takes +z onto
    /// `normal`.
    pub fn onto_spun(normal: Vec3, spin: f32) -> Rotation {
        let (sin_psi, cos_psi) = libm::sincosf(spin);
        let phi = libm::atan2f(normal.y, normal.x);
        let (sin_phi, cos_phi) = libm::sincosf(phi);
        let theta = libm::atan2f(normal.x * cos_phi + normal.y * sin_phi, normal.z);
        let (sin_theta, cos_theta) = libm::sincosf(theta);
        Rotation {
            cos_phi,
            sin_phi,
            cos_theta,
            sin_theta,
            cos_psi,
            sin_psi,
        }
    }

    /// Rot_{θ,φ}(d): a direction of the reference hemisphere into scene space.
    #[inline]
    pub fn apply(&self, d: Vec3) -> Vec3 {
        // ψ about z (the spin) ...
        let d = Vec3::new(
            d.x * self.cos_psi - d.y * self.sin_psi,
            d.x * self.sin_psi + d.y * self.cos_psi,
            d.z,
        );
        // ... θ about y (x–z plane) ...
        let x1 = d.x * self.cos_theta + d.z * self.sin_theta;
        let z1 = -d.x * self.sin_theta + d.z * self.cos_theta;
        // ... then φ about z (x–y plane).
        Vec3::new(
            x1 * self.cos_phi - d.y * self.sin_phi,
            x1 * self.sin_phi + d.y * self.cos_phi,
            z1,
        )
    }

    /// The inverse rotation: a scene-space vector into the hemisphere's frame. The software
    /// accelerator turns the few patch vertices this way instead of turning thousands of rays
    /// the other way; the two are the same rotation.
    #[inline]
    pub fn invert(&self, w: Vec3) -> Vec3 {
        let x1 = w.x * self.cos_phi + w.y * self.sin_phi;
        let y = -w.x * self.sin_phi + w.y * self.cos_phi;
        let x = x1 * self.cos_theta - w.z * self.sin_theta;
        let z = x1 * self.sin_theta + w.z * self.cos_theta;
        Vec3::new(
            x * self.cos_psi + y * self.sin_psi,
            -x * self.sin_psi + y * self.cos_psi,
            z,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vec3, b: Vec3, eps: f32) -> bool {
        (a - b).length() < eps
    }

    #[test]
    fn z_goes_onto_normal_for_every_axis_and_diagonal() {
        let normals = [
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(0.0, 0.0, -1.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, -1.0, 0.0),
            Vec3::new(0.0, -0.0, -1.0),
            Vec3::new(1.0, 1.0, 1.0) / 3f32.sqrt(),
            Vec3::new(-0.3, 0.5, -0.81).try_normalize().unwrap(),
        ];
        for (i, n) in normals.into_iter().enumerate() {
            let r = Rotation::onto_spun(n, spin_for_sample(i as u32));
            let z = r.apply(Vec3::Z);
            assert!(z.is_finite());
            assert!(close(z, n, 1e-6), "{n:?} -> {z:?}");
            // orthonormal: x and y stay unit and perpendicular to n
            let x = r.apply(Vec3::new(1.0, 0.0, 0.0));
            let y = r.apply(Vec3::new(0.0, 1.0, 0.0));
            assert!(x.dot(n).abs() < 1e-6 && y.dot(n).abs() < 1e-6 && x.dot(y).abs() < 1e-6);
            assert!(close(
                r.invert(r.apply(Vec3::new(0.2, -0.4, 0.7))),
                Vec3::new(0.2, -0.4, 0.7),
                1e-6
            ));
        }
    }
}
