//! Frustums of paper §3.3: a cone of rays around a reflection (or transmission) axis, made of the
//! first k+1 rings of the same hemisphere table, each ray weighted by the discretised Phong lobe.
//!
//! For frustum size k (rings 0..=k) and Phong power n the weight of every ray on ring j is
//!
//! ```text
//! W_jk = cos^n(jΔθ) / Σ_{i=0..k} cos^n(iΔθ) N_i                       (§3.3, DeltaRule::Paper)
//! W_jk = cos^n(jΔθ) Ω_j / Σ_{i=0..k} cos^n(iΔθ) Ω_i N_i                (DeltaRule::Band)
//! ```
//!
//! where Ω_j is the solid angle of one ray of ring j (its band's solid angle over N_j). The
//! paper's form assumes every ray stands for the same solid angle; hemi's rings are rounded to a
//! multiple of four rays, which breaks that near the axis (ring 1 has 8 rays for 6.3 ideal ones),
//! so the band form, like the hemisphere's own δD, weights each ray by the solid angle it really
//! covers. Both are normalised: Σ_j N_j W_jk = 1, so a frustum passes on exactly the weight it is
//! given (k_r × the weight of the ray that spawned it) and a lossless mirror conserves energy.
//!
//! ## Frustum size from the Phong power
//!
//! A cone of half-angle α holds the fraction 1 − cos^{n+1} α of the lobe cos^n. hemi chooses the
//! smallest k whose cone (to the outer edge of ring k's band, (k + ½)Δθ) leaves out at most
//! [`LOBE_CUT`] of the lobe; what is left out is folded back in by the normalisation. n = ∞ (a
//! perfect mirror) and lobes narrower than the pole's band give k = 0: one ray, the mirror ray.
//! A scene may instead give the frustum's angle directly (the paper's picture 1 lists its four
//! floors by angle: 8°, 6°, 4°, 2°); then k = round(angle / Δθ).

use crate::hemisphere::{DeltaRule, Hemisphere};

/// The fraction of the Phong lobe a frustum may leave out (5 %): below it the frustum's rays grow
/// as ln(1/cut)/n while the image changes less than the sampling noise of pass 2.
pub const LOBE_CUT: f64 = 0.05;

/// Frustum size k (the last ring, 0-based) for Phong power `n` on a hemisphere of `circles`
/// circles. `n = ∞` or any lobe narrower than the pole's band gives 0 (a single mirror ray);
/// n = 0 gives the whole hemisphere (k = R − 1).
pub fn size_for_phong(n: f32, circles: u32) -> u32 {
    let last = circles.saturating_sub(1);
    if n.is_nan() || n < 0.0 || circles < 2 {
        return 0;
    }
    if n.is_infinite() {
        return 0;
    }
    let dtheta = core::f64::consts::FRAC_PI_2 / circles as f64;
    // cos^{n+1} α ≤ cut  ⇔  α ≥ acos(cut^{1/(n+1)})
    let alpha = libm::acos(libm::pow(LOBE_CUT, 1.0 / (n as f64 + 1.0)));
    // smallest k with (k + ½)Δθ ≥ α
    let k = libm::ceil(alpha / dtheta - 0.5);
    if k <= 0.0 {
        0
    } else {
        (k as u32).min(last)
    }
}

/// Frustum size k for a cone of half-angle `degrees`: the ring nearest that angle.
pub fn size_for_angle(degrees: f32, circles: u32) -> u32 {
    let last = circles.saturating_sub(1);
    if degrees.is_nan() || degrees <= 0.0 || circles < 2 {
        return 0;
    }
    let dtheta = 90.0 / circles as f64;
    let k = libm::round(degrees as f64 / dtheta);
    (k as u32).min(last)
}

/// Rays in a frustum of size `k` (rings 0..=k) of `hemi`.
pub fn ray_count(hemi: &Hemisphere<'_>, k: u32) -> u32 {
    hemi.rings()
        .iter()
        .take(k as usize + 1)
        .map(|r| r.count)
        .sum()
}

/// Why a lobe table could not be filled.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LobeError {
    /// The frustum has more rings than the hemisphere.
    TooLarge,
    /// The output slice is shorter than k + 1.
    StorageTooSmall,
}

/// Fills `out[j]` (j = 0..=k) with the per-ray weight W_jk of a frustum of size `k` and Phong
/// power `n` (∞ for a perfect mirror: all weight on the axis ray), under the hemisphere's own
/// [`DeltaRule`]. Computed in f64 and stored in f32 so host and firmware hold the same bits.
pub fn lobe_weights(
    hemi: &Hemisphere<'_>,
    n: f32,
    k: u32,
    out: &mut [f32],
) -> Result<(), LobeError> {
    let rings = hemi.rings();
    let k = k as usize;
    if k >= rings.len() {
        return Err(LobeError::TooLarge);
    }
    if out.len() <= k {
        return Err(LobeError::StorageTooSmall);
    }
    if n.is_infinite() || k == 0 {
        out[0] = 1.0;
        out[1..=k].iter_mut().for_each(|w| *w = 0.0);
        return Ok(());
    }
    let dtheta = core::f64::consts::FRAC_PI_2 / hemi.circles() as f64;
    let n = n.max(0.0) as f64;
    let raw = |j: usize| -> f64 {
        let theta = j as f64 * dtheta;
        let lobe = libm::pow(libm::cos(theta), n);
        match hemi.rule() {
            DeltaRule::Paper => lobe,
            DeltaRule::Band => {
                let lo = if j == 0 { 0.0 } else { theta - 0.5 * dtheta };
                let hi = theta + 0.5 * dtheta;
                lobe * (libm::cos(lo) - libm::cos(hi)) / rings[j].count as f64
            }
        }
    };
    let total: f64 = (0..=k).map(|j| raw(j) * rings[j].count as f64).sum();
    for (j, w) in out.iter_mut().take(k + 1).enumerate() {
        *w = if total > 0.0 {
            (raw(j) / total) as f32
        } else {
            0.0
        };
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hemisphere::OwnedHemisphere;

    #[test]
    fn weights_are_normalised_under_both_rules() {
        for rule in [DeltaRule::Paper, DeltaRule::Band] {
            let h = OwnedHemisphere::new(45, rule).unwrap();
            let v = h.view();
            for (n, k) in [(10.0, 20), (300.0, 4), (0.0, 44), (5000.0, 1)] {
                let mut w = [0.0f32; 64];
                lobe_weights(&v, n, k, &mut w).unwrap();
                let sum: f64 = (0..=k as usize)
                    .map(|j| w[j] as f64 * v.rings()[j].count as f64)
                    .sum();
                assert!((sum - 1.0).abs() < 1e-5, "{rule:?} n={n} k={k}: {sum}");
                // the lobe falls off away from the axis (under the band rule the per-ray solid
                // angles differ by rounding, so only the paper's equal-area rule is monotone)
                if rule == DeltaRule::Paper {
                    assert!(w[0] >= w[k as usize]);
                }
            }
        }
    }

    #[test]
    fn a_mirror_is_one_ray() {
        let h = OwnedHemisphere::new(32, DeltaRule::Band).unwrap();
        assert_eq!(size_for_phong(f32::INFINITY, 32), 0);
        assert_eq!(size_for_phong(1e9, 32), 0);
        let mut w = [9.0f32; 4];
        lobe_weights(&h.view(), f32::INFINITY, 3, &mut w).unwrap();
        assert_eq!(w, [1.0, 0.0, 0.0, 0.0]);
        assert_eq!(ray_count(&h.view(), 0), 1);
    }

    #[test]
    fn frustums_shrink_as_the_power_grows() {
        let mut last = u32::MAX;
        for n in [0.0, 1.0, 10.0, 100.0, 1000.0, 10000.0] {
            let k = size_for_phong(n, 64);
            assert!(k <= last, "n={n}: k={k} after {last}");
            last = k;
        }
        // n = 0: all but the last LOBE_CUT of the hemisphere (cos α ≤ 0.05: α ≥ 87.1°)
        assert_eq!(size_for_phong(0.0, 64), 62);
        // the cone leaves out at most LOBE_CUT of the lobe
        for n in [3.0f32, 40.0, 400.0] {
            let k = size_for_phong(n, 64);
            let alpha = (k as f64 + 0.5) * core::f64::consts::FRAC_PI_2 / 64.0;
            assert!(
                alpha.cos().powf(n as f64 + 1.0) <= LOBE_CUT + 1e-12,
                "n={n}"
            );
        }
    }

    #[test]
    fn picture_one_frustum_angles() {
        // Δθ = 1° (R = 90): the paper's picture 1 quotes 195, 121, 61, 19 rays for 8°, 6°, 4°,
        // 2°; (3.1) with rounding to multiples of four gives these (docs/ACCURACY.md compares).
        let h = OwnedHemisphere::new(90, DeltaRule::Band).unwrap();
        let counts: [u32; 4] =
            [8.0, 6.0, 4.0, 2.0].map(|a| ray_count(&h.view(), size_for_angle(a, 90)));
        std::println!(
            "R = 90: frustum rays at 8°, 6°, 4°, 2°: {counts:?} (paper: 195, 121, 61, 19)"
        );
        for r in [32u32, 48, 64] {
            let hr = OwnedHemisphere::new(r, DeltaRule::Band).unwrap();
            let c = [8.0, 6.0, 4.0, 2.0].map(|a| ray_count(&hr.view(), size_for_angle(a, r)));
            std::println!("R = {r}: {c:?}");
        }
        assert_eq!(counts.map(|c| c > 0), [true; 4]);
        assert!(counts[0] > counts[1] && counts[1] > counts[2] && counts[2] > counts[3]);
        assert!((15..=25).contains(&counts[3]), "{counts:?}");
    }

    #[test]
    fn refuses_bad_sizes() {
        let h = OwnedHemisphere::new(8, DeltaRule::Band).unwrap();
        let mut w = [0.0f32; 4];
        assert_eq!(
            lobe_weights(&h.view(), 5.0, 8, &mut w),
            Err(LobeError::TooLarge)
        );
        assert_eq!(
            lobe_weights(&h.view(), 5.0, 5, &mut w),
            Err(LobeError::StorageTooSmall)
        );
    }
}
