//! Cosine-weighted Monte Carlo hemisphere sampling: the textbook estimator of a point form
//! factor. Directions are drawn with density cos θ / π (Malley's method: a uniform point of the
//! unit disc lifted onto the hemisphere), so the point form factor (2.4),
//! `F = ∫_patch cos θ / π dω`, is the probability that a direction reaches the patch, and every
//! ray carries the same weight 1/N.
//!
//! **Stratified** (the default of `--method monte-carlo`): the unit square (u₁, u₂) is cut
//! into a × b cells, one jittered sample per cell, a = ⌊√N⌋, b = ⌊N/a⌋ (so a·b ≤ N rays are
//! shot; [`MonteCarlo::ray_count`] says how many). Through Malley's map, u₁ stratifies
//! sin²θ — exactly the projected-solid-angle bands of the hemisphere's [`crate::hemisphere::DeltaRule::Band`]
//! rule — and u₂ the azimuth. **Plain**: N independent directions, the O(N^-1/2) baseline.
//!
//! The random numbers are a stateless hash (SplitMix64) of (seed, ray index), so a shot is a
//! pure function of its inputs: reproducible, and the same on every engine and thread.

use super::{cast_weighted, PeerError, Placement};
use crate::accel::Accelerator;
use crate::form_row::FormRow;
use crate::geometry::Vec3;
use crate::optics::Optics;
use crate::rotation::Rotation;
use crate::tracer::ShotStats;

/// Monte Carlo sampling of the hemisphere with about `rays` cosine-weighted directions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MonteCarlo {
    a: u32,
    b: u32,
    stratified: bool,
}

impl MonteCarlo {
    /// `rays` directions (stratified: the largest a·b ≤ rays of the grid above).
    pub fn new(rays: u32, stratified: bool) -> Result<MonteCarlo, PeerError> {
        if rays == 0 {
            return Err(PeerError::BadParameters);
        }
        if !stratified {
            return Ok(MonteCarlo {
                a: rays,
                b: 1,
                stratified,
            });
        }
        let a = (libm::sqrt(rays as f64) as u32).max(1);
        Ok(MonteCarlo {
            a,
            b: (rays / a).max(1),
            stratified,
        })
    }

    /// Directions per shot.
    pub fn ray_count(&self) -> u32 {
        self.a * self.b
    }

    /// Whether the directions are stratified.
    pub fn stratified(&self) -> bool {
        self.stratified
    }

    /// Direction `k` for `seed`, in the frame of the normal (+z).
    pub fn direction(&self, seed: u64, k: u32) -> Vec3 {
        let h = splitmix(seed ^ (k as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15));
        let (x1, x2) = (unit(h), unit(splitmix(h)));
        let (u1, u2) = if self.stratified {
            (
                ((k % self.a) as f64 + x1) / self.a as f64,
                ((k / self.a) as f64 + x2) / self.b as f64,
            )
        } else {
            (x1, x2)
        };
        // Malley: r = √u₁ on the disc, φ = 2π u₂; z = √(1 − r²) = cos θ
        let r = libm::sqrt(u1);
        let (s, c) = libm::sincos(core::f64::consts::TAU * u2);
        Vec3::new(
            (r * c) as f32,
            (r * s) as f32,
            libm::sqrt((1.0 - u1).max(0.0)) as f32,
        )
    }
}

fn splitmix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

fn unit(h: u64) -> f64 {
    (h >> 11) as f64 / (1u64 << 53) as f64
}

/// Shoots `mc` at `at` with random stream `seed` (the host uses the sample point's index) and
/// adds 1/N per ray to the diffuse patch each reaches, into `row` (the caller zeroes it).
pub fn shoot_monte_carlo<A: Accelerator, R: FormRow + ?Sized>(
    accel: &mut A,
    mc: &MonteCarlo,
    optics: &Optics<'_>,
    at: &Placement,
    seed: u64,
    batch: &mut [Vec3],
    row: &mut R,
) -> Result<ShotStats, PeerError> {
    let rot = Rotation::onto_spun(at.normal, at.spin);
    let w = 1.0 / mc.ray_count() as f32;
    cast_weighted(
        accel,
        optics,
        at,
        mc.ray_count(),
        batch,
        |k| rot.apply(mc.direction(seed, k)),
        |_| w,
        row,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn directions_are_unit_upper_and_cosine_distributed() {
        for stratified in [true, false] {
            let mc = MonteCarlo::new(4096, stratified).unwrap();
            let n = mc.ray_count();
            assert!(n <= 4096 && n > 4000);
            let mut mean_z = 0.0;
            for k in 0..n {
                let d = mc.direction(7, k);
                assert!((d.length() - 1.0).abs() < 1e-5 && d.z >= 0.0);
                mean_z += d.z as f64 / n as f64;
            }
            // E[cos θ] under the density cos θ / π is 2/3
            let tol = if stratified { 2e-3 } else { 2e-2 };
            assert!((mean_z - 2.0 / 3.0).abs() < tol, "{stratified}: {mean_z}");
        }
    }
}
