//! The discretised hemisphere of paper §3.2 and its delta form factors (§3.1).
//!
//! Rays leave the sample point on circles ("rings") at polar angle θ_j = jΔθ, Δθ = 2π/M, with
//! M = 4R rays on the horizon circle for R circles. Ring j carries
//!
//! ```text
//! N_j = round(M sin jΔθ)            (3.1), rounded to a multiple of four, N_0 = 1
//! ```
//!
//! rays evenly spaced in azimuth. Every ray of a ring has the same delta form factor δD_j, so the
//! table stores one δD per ring, and, as the paper's remark allows, the azimuth directions of one
//! quarter only: the other three quarters are the same directions turned by 90°, 180° and 270°.
//!
//! The horizon ring (j = R) is not shot: its rays graze the surface and carry zero weight in the
//! paper's rule (cos χ = 0).

use crate::geometry::Vec3;

/// The largest number of circles a table may have (bounds the ring storage).
pub const MAX_CIRCLES: usize = 1024;

/// How the one delta form factor per ring is chosen.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum DeltaRule {
    /// The paper's rule (§3.1): δD_j = cos θ_j / K with K = Σ_j N_j cos θ_j. It assumes every ray
    /// stands for the same solid angle ΔA, which the rounding of N_j to a multiple of four breaks
    /// near the pole (ring 1 of R = 64 gets 8 rays for 6.3 "ideal" ones).
    Paper,
    /// The exact projected solid angle of ring j's band, shared by its N_j rays:
    /// δD_j = (sin²θ_hi − sin²θ_lo) / N_j, with the band [θ_j − Δθ/2, θ_j + Δθ/2] (the pole cap
    /// [0, Δθ/2] for j = 0; the last shot ring's band reaches the horizon). This is the limit of
    /// Σ cos χ ΔA / π over the band, so it is the same quantity as the paper's, without the
    /// equal-area assumption; the bands tile the hemisphere, so the δD sum to exactly 1.
    Band,
}

/// One circle of the hemisphere.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Ring {
    /// cos θ_j
    pub cos_theta: f32,
    /// sin θ_j
    pub sin_theta: f32,
    /// N_j, the number of rays on this ring (1 for the pole, else a multiple of 4).
    pub count: u32,
    /// Index of this ring's first quarter direction in the quarter table.
    pub first: u32,
    /// δD_j, the delta form factor of each ray of this ring.
    pub delta_ff: f32,
}

/// Why a hemisphere table could not be built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HemisphereError {
    /// R must be at least 2 (a pole and one ring).
    TooFewCircles,
    /// R exceeds [`MAX_CIRCLES`] or the storage given.
    TooManyCircles,
    /// The quarter-direction storage given is too small.
    StorageTooSmall,
}

impl core::fmt::Display for HemisphereError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            HemisphereError::TooFewCircles => write!(f, "a hemisphere needs at least 2 circles"),
            HemisphereError::TooManyCircles => {
                write!(f, "a hemisphere has at most {MAX_CIRCLES} circles")
            }
            HemisphereError::StorageTooSmall => {
                write!(
                    f,
                    "the storage given is too small for the hemisphere's table"
                )
            }
        }
    }
}

/// Number of rays on ring `j` of a hemisphere with `circles` circles: (3.1), rounded to a
/// multiple of four (at least 4 off the pole).
pub fn rays_on_ring(circles: u32, j: u32) -> u32 {
    if j == 0 {
        return 1;
    }
    let m = 4.0 * circles as f64;
    let theta = j as f64 * core::f64::consts::FRAC_PI_2 / circles as f64;
    let ideal = m * libm::sin(theta);
    let n = 4.0 * libm::round(ideal / 4.0);
    if n < 4.0 {
        4
    } else {
        n as u32
    }
}

/// Total rays shot per hemisphere for `circles` circles (paper fig. 9b); about 8R²/π.
pub fn ray_count(circles: u32) -> u32 {
    (0..circles).map(|j| rays_on_ring(circles, j)).sum()
}

/// Entries the quarter-direction table needs for `circles` circles.
pub fn quarter_len(circles: u32) -> usize {
    (1..circles)
        .map(|j| rays_on_ring(circles, j) as usize / 4)
        .sum()
}

/// Fills `rings` (R entries: j = 0..R-1) and `quarter` (the azimuth (cos φ, sin φ) of the first
/// quarter of each ring) for `circles` = R. Returns the number of quarter entries used.
///
/// Computed in f64 and stored in f32, so that every build of the table (host, firmware, HDL
/// model's ROM) holds the same bits.
pub fn build_into(
    circles: u32,
    rule: DeltaRule,
    rings: &mut [Ring],
    quarter: &mut [[f32; 2]],
) -> Result<usize, HemisphereError> {
    if circles < 2 {
        return Err(HemisphereError::TooFewCircles);
    }
    let r = circles as usize;
    if r > MAX_CIRCLES || rings.len() < r {
        return Err(HemisphereError::TooManyCircles);
    }
    if quarter.len() < quarter_len(circles) {
        return Err(HemisphereError::StorageTooSmall);
    }
    let dtheta = core::f64::consts::FRAC_PI_2 / circles as f64;
    let mut first = 0usize;
    let mut k_paper = 0.0f64;
    for (j, ring) in rings.iter_mut().take(r).enumerate() {
        let theta = j as f64 * dtheta;
        let n = rays_on_ring(circles, j as u32);
        k_paper += n as f64 * libm::cos(theta);
        let lo = if j == 0 { 0.0 } else { theta - 0.5 * dtheta };
        let hi = if j + 1 == r {
            core::f64::consts::FRAC_PI_2
        } else {
            theta + 0.5 * dtheta
        };
        let band = sq(libm::sin(hi)) - sq(libm::sin(lo));
        *ring = Ring {
            cos_theta: libm::cos(theta) as f32,
            sin_theta: libm::sin(theta) as f32,
            count: n,
            first: first as u32,
            // Paper rule is normalised below once K is known.
            delta_ff: match rule {
                DeltaRule::Band => (band / n as f64) as f32,
                DeltaRule::Paper => libm::cos(theta) as f32,
            },
        };
        if j > 0 {
            let quarter_n = n as usize / 4;
            let dphi = 2.0 * core::f64::consts::PI / n as f64;
            for (k, q) in quarter[first..first + quarter_n].iter_mut().enumerate() {
                // Half-step azimuth offset: no ray of any ring lies on the frame's x or y axis,
                // which are often parallel to scene edges.
                let phi = (k as f64 + 0.5) * dphi;
                *q = [libm::cos(phi) as f32, libm::sin(phi) as f32];
            }
            first += quarter_n;
        }
    }
    if rule == DeltaRule::Paper {
        for ring in rings.iter_mut().take(r) {
            ring.delta_ff = (ring.delta_ff as f64 / k_paper) as f32;
        }
    }
    Ok(first)
}

fn sq(x: f64) -> f64 {
    x * x
}

/// A read-only view of a built hemisphere table.
#[derive(Clone, Copy, Debug)]
pub struct Hemisphere<'a> {
    rings: &'a [Ring],
    quarter: &'a [[f32; 2]],
    rule: DeltaRule,
}

impl<'a> Hemisphere<'a> {
    /// Wraps tables filled by [`build_into`].
    pub fn new(rings: &'a [Ring], quarter: &'a [[f32; 2]], rule: DeltaRule) -> Self {
        Hemisphere {
            rings,
            quarter,
            rule,
        }
    }
    /// R, the number of circles shot (the pole counts as one).
    pub fn circles(&self) -> u32 {
        self.rings.len() as u32
    }
    /// The rule the delta form factors follow.
    pub fn rule(&self) -> DeltaRule {
        self.rule
    }
    /// The rings, pole first.
    pub fn rings(&self) -> &'a [Ring] {
        self.rings
    }
    /// Total number of rays.
    pub fn ray_count(&self) -> u32 {
        self.rings.iter().map(|r| r.count).sum()
    }
    /// Direction of ray `k` of ring `j` in the hemisphere's own frame (+z up), derived from the
    /// quarter table by a quarter turn.
    #[inline]
    pub fn direction(&self, j: usize, k: u32) -> Vec3 {
        let ring = &self.rings[j];
        if j == 0 {
            return Vec3::Z;
        }
        let (c, s) = self.azimuth(ring, k);
        Vec3::new(ring.sin_theta * c, ring.sin_theta * s, ring.cos_theta)
    }
    /// The stored first-quarter azimuths (cos φ, sin φ) of `ring` (empty for the pole).
    #[inline]
    pub fn quarter_of(&self, ring: &Ring) -> &'a [[f32; 2]] {
        let start = ring.first as usize;
        let len = (ring.count / 4) as usize;
        self.quarter.get(start..start + len).unwrap_or(&[])
    }

    /// (cos φ_k, sin φ_k) of ray `k` on `ring`.
    #[inline]
    pub fn azimuth(&self, ring: &Ring, k: u32) -> (f32, f32) {
        let quarter_n = ring.count / 4;
        if quarter_n == 0 {
            return (1.0, 0.0);
        }
        self.azimuth_in_quarter(ring, k / quarter_n, k % quarter_n)
    }

    /// (cos φ, sin φ) of ray `r` of quarter `quarter` of `ring` (k = quarter·N_j/4 + r): the
    /// stored first-quarter direction turned by `quarter` right angles. Lets a caller walking a
    /// ring keep (quarter, r) incrementally instead of dividing per ray.
    #[inline(always)]
    pub fn azimuth_in_quarter(&self, ring: &Ring, quarter: u32, r: u32) -> (f32, f32) {
        let [c, s] = self.quarter[(ring.first + r) as usize];
        match quarter & 3 {
            0 => (c, s),
            1 => (-s, c),
            2 => (-c, -s),
            _ => (s, -c),
        }
    }
}

/// A hemisphere table that owns its storage (host builds only).
#[cfg(any(test, feature = "std"))]
#[derive(Clone, Debug)]
pub struct OwnedHemisphere {
    rings: std::vec::Vec<Ring>,
    quarter: std::vec::Vec<[f32; 2]>,
    rule: DeltaRule,
}

#[cfg(any(test, feature = "std"))]
impl OwnedHemisphere {
    /// Builds the table for `circles` circles.
    pub fn new(circles: u32, rule: DeltaRule) -> Result<Self, HemisphereError> {
        let mut rings = std::vec![Ring::default(); circles.clamp(2, MAX_CIRCLES as u32) as usize];
        let mut quarter = std::vec![[0.0; 2]; quarter_len(circles.min(MAX_CIRCLES as u32))];
        build_into(circles, rule, &mut rings, &mut quarter)?;
        Ok(OwnedHemisphere {
            rings,
            quarter,
            rule,
        })
    }
    /// The read-only view the tracer takes.
    pub fn view(&self) -> Hemisphere<'_> {
        Hemisphere::new(&self.rings, &self.quarter, self.rule)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_follow_3_1_and_are_multiples_of_four() {
        for r in [2u32, 8, 16, 64, 100] {
            for j in 1..r {
                let n = rays_on_ring(r, j);
                assert_eq!(n % 4, 0);
                let ideal =
                    4.0 * r as f64 * (j as f64 * core::f64::consts::FRAC_PI_2 / r as f64).sin();
                assert!(
                    (n as f64 - ideal).abs() <= 2.0 + 1e-9,
                    "r={r} j={j} n={n} ideal={ideal}"
                );
            }
        }
        // about 8R²/π rays (fig. 9b)
        let r = 64;
        let n = ray_count(r) as f64;
        let approx = 8.0 * (r * r) as f64 / core::f64::consts::PI;
        assert!((n / approx - 1.0).abs() < 0.02, "{n} vs {approx}");
    }

    #[test]
    fn delta_form_factors_sum_to_one_under_both_rules() {
        for rule in [DeltaRule::Paper, DeltaRule::Band] {
            let h = OwnedHemisphere::new(32, rule).unwrap();
            let sum: f64 = h
                .view()
                .rings()
                .iter()
                .map(|r| r.delta_ff as f64 * r.count as f64)
                .sum();
            assert!((sum - 1.0).abs() < 1e-6, "{rule:?}: {sum}");
        }
    }

    #[test]
    fn directions_are_unit_and_quarter_symmetric() {
        let h = OwnedHemisphere::new(16, DeltaRule::Band).unwrap();
        let v = h.view();
        for (j, ring) in v.rings().iter().enumerate() {
            for k in 0..ring.count {
                let d = v.direction(j, k);
                assert!((d.length() - 1.0).abs() < 1e-6);
                assert!(d.z >= 0.0);
                if j > 0 {
                    let q = v.direction(j, (k + ring.count / 4) % ring.count);
                    assert!((q.x + d.y).abs() < 1e-6 && (q.y - d.x).abs() < 1e-6);
                }
            }
        }
    }

    #[test]
    fn refuses_bad_sizes() {
        assert_eq!(
            OwnedHemisphere::new(1, DeltaRule::Band).unwrap_err(),
            HemisphereError::TooFewCircles
        );
        let mut rings = [Ring::default(); 4];
        let mut q = [[0.0; 2]; 1];
        assert_eq!(
            build_into(4, DeltaRule::Band, &mut rings, &mut q),
            Err(HemisphereError::StorageTooSmall)
        );
    }
}
