//! Vectors for the culling unit's ray side (`hdl-model/rtl/cull_ray.v`): the model's
//! [`CullUnit::ray_bin`] (whether a hemisphere ray is culled, and its azimuth sector and polar
//! band) on reference directions, for the testbench to feed the RTL one a clock and compare in
//! order. The model gives the unit no clocks of its own (it runs beside the rotator), so the
//! answers are compared, not clocks.
//!
//! File lines (decimal): `R x y z culled sector band` (the direction's Q2.30 words; sector and
//! band 0 for a ray that is not culled, whose RTL outputs are not compared).
//!
//! Workloads: the reference directions of pass 1's hemispheres (several circle counts), random
//! unit directions over the whole sphere, random words of any size, and directions placed on
//! the edges of what the unit decides: the culling thresholds (z = 0, sin θ = 2^-5), the sector
//! and band boundaries and the wrap of φ at ±π.

use crate::rng::XorShift;
use crate::rtl::cordic::unit_word;
use hemi_hdl_model::format::Unit;
use hemi_hdl_model::intersect::cull::CullUnit;
use hemi_kernel::hemisphere::{DeltaRule, OwnedHemisphere};
use std::f64::consts::PI;
use std::fmt::Write as _;

/// What a file holds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    /// `R` lines.
    pub rays: usize,
    /// Rays the model culls (their sector and band compared).
    pub culled: usize,
}

/// The vectors for a unit of `sectors` sectors: the hemispheres of `circles` circles each, sweeps
/// across every sector and band boundary, then `random` random directions, words and boundary
/// cases.
pub fn vectors(sectors: u32, circles: &[u32], random: usize, seed: u64) -> (String, Counts) {
    let unit = CullUnit::new(sectors);
    let mut out = Vectors {
        unit,
        text: String::new(),
        counts: Counts::default(),
    };
    for &r in circles {
        let Ok(hemi) = OwnedHemisphere::new(r, DeltaRule::Band) else {
            continue;
        };
        let view = hemi.view();
        for (j, ring) in view.rings().iter().enumerate() {
            for k in 0..ring.count {
                let d = view.direction(j, k);
                out.ray([d.x, d.y, d.z].map(unit_word));
            }
        }
    }
    let mut rng = XorShift::new(seed ^ 0x2545_f491_4f6c_dd1d);
    for d in sweeps(&mut rng, sectors) {
        out.ray(d);
    }
    for n in 0..random {
        let d = match n % 4 {
            0 => sphere(&mut rng),
            1 => on_a_boundary(&mut rng, sectors),
            2 => [0; 3].map(|_| rng.bits() as i32 >> (rng.bits() % 32)),
            _ => at_a_threshold(&mut rng),
        };
        out.ray(d);
    }
    (out.text, out.counts)
}

/// The file being written ([`super::UnitVectors`]).
type Vectors = super::UnitVectors<Counts>;

impl Vectors {
    fn ray(&mut self, d: [i32; 3]) {
        let bin = self.unit.ray_bin(d.map(Unit::from_bits));
        let (culled, (s, b)) = (bin.is_some() as u8, bin.unwrap_or((0, 0)));
        self.counts.rays += 1;
        self.counts.culled += culled as usize;
        let _ = writeln!(self.text, "R {} {} {} {culled} {s} {b}", d[0], d[1], d[2]);
    }
}

/// Q2.30 words of the unit direction at polar angle `theta` and azimuth `phi`.
fn direction(theta: f64, phi: f64) -> [i32; 3] {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    [st * cp, st * sp, ct].map(|c| unit_word(c as f32))
}

/// Steps of a sweep across a boundary, and the step: 3·10⁻⁶ rad, under one LSB of the culling
/// vectorings' angles (2^-17 rad at 20 bits), over ±3.8·10⁻⁴ rad, twice the vectorings' error,
/// so that the model's angle crosses the boundary inside every sweep. (The angles a vectoring of
/// 14 stages returns are sums of ±atan 2^-i, about 10⁻⁴ rad apart, so a threshold off by a few
/// LSBs changes an answer only where such a sum falls between the two thresholds: the sweeps
/// catch an RTL whose angles or thresholds are off by more than that spacing.)
const SWEEP: i32 = 128;
const SWEEP_STEP: f64 = 3e-6;

/// Directions swept across every sector boundary in φ (the wrap at ±π among them; at a random
/// θ each) and every band boundary in θ (at a random φ each).
fn sweeps(rng: &mut XorShift, sectors: u32) -> Vec<[i32; 3]> {
    let mut out = Vec::new();
    for k in 0..sectors {
        let (theta, phi) = (
            0.05 + 1.4 * rng.f64(),
            k as f64 * 2.0 * PI / sectors as f64 - PI,
        );
        for i in -SWEEP..=SWEEP {
            out.push(direction(theta, phi + i as f64 * SWEEP_STEP));
        }
    }
    for k in 1..16 {
        let (theta, phi) = (k as f64 * PI / 32.0, 2.0 * PI * rng.f64());
        for i in -SWEEP..=SWEEP {
            out.push(direction(theta + i as f64 * SWEEP_STEP, phi));
        }
    }
    out
}

/// A random unit direction over the whole sphere.
fn sphere(rng: &mut XorShift) -> [i32; 3] {
    let z = 2.0 * rng.f64() - 1.0;
    direction(z.acos(), 2.0 * PI * rng.f64())
}

/// A direction a few LSBs from a sector boundary in φ (the wrap at ±π among them) or a band
/// boundary in θ, each word then nudged by up to ±8.
fn on_a_boundary(rng: &mut XorShift, sectors: u32) -> [i32; 3] {
    let near = |rng: &mut XorShift| (rng.bits() % 17) as i64 as f64 - 8.0;
    let (theta, phi) = if rng.chance(0.5) {
        let k = rng.bits() % sectors as u64;
        let phi = k as f64 * 2.0 * PI / sectors as f64 - PI;
        (PI / 2.0 * rng.f64(), phi + near(rng) * 1e-9)
    } else {
        let k = rng.bits() % 17;
        (
            k as f64 * PI / 32.0 + near(rng) * 1e-9,
            2.0 * PI * rng.f64(),
        )
    };
    direction(theta, phi).map(|w| w.saturating_add(near(rng) as i32))
}

/// A direction at the culling's own thresholds: z at or next to 0, ρ at or next to 2^25, and
/// the extremes of the words.
fn at_a_threshold(rng: &mut XorShift) -> [i32; 3] {
    let pick = |rng: &mut XorShift, from: &[i32]| from[(rng.bits() % from.len() as u64) as usize];
    let rho = pick(
        rng,
        &[
            (1 << 25) - 1,
            1 << 25,
            (1 << 25) + 1,
            1 << 30,
            i32::MAX,
            0,
            1,
        ],
    );
    let other = pick(rng, &[0, 1, -1, rho, -rho, rho / 2]);
    let sign = if rng.chance(0.5) { -1 } else { 1 };
    let (x, y) = if rng.chance(0.5) {
        (sign * rho, other)
    } else {
        (other, sign * rho)
    };
    let z = pick(rng, &[0, -1, 1, 1 << 30, i32::MIN, i32::MAX]);
    let x = if rng.chance(0.1) { i32::MIN } else { x };
    [x, y, z]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_workload_holds_culled_and_unculled_rays() {
        let (text, c) = vectors(32, &[8], 400, 1);
        assert_eq!(text.lines().count(), c.rays);
        assert!(c.culled > 200 && c.culled < c.rays, "{c:?}");
    }
}
