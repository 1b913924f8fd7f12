//! `--quality draft|default|high`: R and K from a target form-factor error and the scene's size.
//!
//! The error model is fitted to the measured table of docs/ACCURACY.md
//! (`hemi bench form-factors`, worst case of five Howell configurations): the K×K midpoint
//! rule over the emitter (4.3) and the hemisphere's discretisation add up,
//!
//! ```text
//! e(R, K) ≈ a / K² + b / R²,   a = 0.7, b = 7
//! ```
//!
//! (K-limited rows: 4 %·4² = 0.64, 1.17 %·8² = 0.75, 0.27 %·16² = 0.69; R-limited rows at K = 32:
//! 3.2 %·16² = 8.2, 0.67 %·32² = 6.8, 0.094 %·64² = 3.9 — b is the conservative end). Pass 1
//! costs P·K²·8R²/π rays, so for a target e the cheapest split minimises K²R² under
//! a/K² + b/R² = e, which is the even split a/K² = b/R² = e/2:
//! `K = √(2a/e)`, `R = √(2b/e)`.
//!
//! The scene's size enters through a ray budget per preset: a scene with many patches gets a
//! smaller K (then R) until P·K²·rays(R) fits, and the command says so. The preset's cost on
//! the Cornell box is measured in docs/PERFORMANCE.md.
//!
//! Under `--adaptive` a preset sets R as above and, instead of K, the gradient test's margin and
//! the depth limit ([`Quality::adaptive`]); the initial guess stays `--samples` (2 by default).
//! Each pair is the adaptive run that reaches about the field error of the uniform K the preset
//! picks, measured on the Cornell box (docs/ACCURACY.md, "Adaptive patch sampling").

use crate::scene::Scene;
use crate::settings::Pass1Settings;
use crate::shots::sample_count;
use anyhow::{bail, Result};
use hemi_kernel::hemisphere::ray_count;

/// A quality preset.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quality {
    /// A quick look: 3 % target, at most 2·10⁸ rays (about 2 s of pass 1 on 2 cores).
    Draft,
    /// The accuracy tests' target: 0.5 %, at most 10¹⁰ rays.
    Default,
    /// 0.1 %, no ray budget.
    High,
}

const A: f64 = 0.7;
const B: f64 = 7.0;

impl Quality {
    /// The target worst form-factor error.
    pub fn target(self) -> f64 {
        match self {
            Quality::Draft => 0.03,
            Quality::Default => 0.005,
            Quality::High => 0.001,
        }
    }

    /// Under `--adaptive`: the gradient test's margin and the most levels beyond the initial
    /// guess. Draft 0.3 and 3 (at most 16×16 from 2×2; the field error of uniform K ≈ 8), default
    /// 0.15 and 4 (32×32; about uniform K = 16's), high 0.05 and 5 (64×64; below uniform
    /// K = 32's).
    pub fn adaptive(self) -> (f64, u32) {
        match self {
            Quality::Draft => (0.3, 3),
            Quality::Default => (0.15, 4),
            Quality::High => (0.05, 5),
        }
    }

    /// The name `--quality` takes.
    pub fn name(self) -> &'static str {
        match self {
            Quality::Draft => "draft",
            Quality::Default => "default",
            Quality::High => "high",
        }
    }

    /// The ray budget of pass 1.
    pub fn ray_budget(self) -> f64 {
        match self {
            Quality::Draft => 2e8,
            Quality::Default => 1e10,
            Quality::High => f64::INFINITY,
        }
    }
}

impl std::str::FromStr for Quality {
    type Err = anyhow::Error;
    fn from_str(s: &str) -> Result<Quality> {
        let all = [Quality::Draft, Quality::Default, Quality::High];
        match all.into_iter().find(|q| q.name() == s) {
            Some(q) => Ok(q),
            None => bail!("--quality {s}: expected draft, default or high"),
        }
    }
}

/// The modelled worst form-factor error at (R, K).
pub fn predicted_error(circles: u32, samples: u32) -> f64 {
    A / (samples as f64).powi(2) + B / (circles as f64).powi(2)
}

/// What a preset chose, and why.
#[derive(Clone, Debug)]
pub struct Preset {
    /// R.
    pub circles: u32,
    /// K.
    pub samples: u32,
    /// Pass-1 rays at this R and K on the scene.
    pub rays: f64,
    /// The modelled worst error.
    pub error: f64,
    /// One line for stderr.
    pub why: String,
}

/// Pass-1 rays for `scene` at R and K.
pub fn rays(scene: &Scene, circles: u32, samples: u32) -> f64 {
    let points: usize = (0..scene.patches.len())
        .map(|i| sample_count(scene, i, samples))
        .sum();
    points as f64 * ray_count(circles) as f64
}

/// Chooses R and K for `quality` on `scene`.
pub fn choose(quality: Quality, scene: &Scene) -> Preset {
    let e = quality.target();
    let mut samples = ((2.0 * A / e).sqrt().ceil() as u32).clamp(1, 256);
    let mut circles = ((2.0 * B / e).sqrt().ceil() as u32).clamp(4, 1024);
    let mut why = format!(
        "--quality {}: target {:.1} %: K = {samples}, R = {circles} in place of any --samples \
         and --circles (e ≈ 0.7/K² + 7/R²)",
        quality.name(),
        100.0 * e
    );
    let budget = quality.ray_budget();
    let first = rays(scene, circles, samples);
    if first > budget {
        // over budget: lower K first (cost ∝ K², and patches that many are small, so their
        // quadrature error is relatively smaller), then R, never below K = 2 / R = 8
        while rays(scene, circles, samples) > budget && samples > 2 {
            samples -= 1;
        }
        while rays(scene, circles, samples) > budget && circles > 8 {
            circles -= 4;
        }
        why += &format!(
            "; {:.2e} rays on {} patches exceed the budget {budget:.0e}: K = {samples}, R = {circles} instead",
            first,
            scene.patches.len()
        );
    }
    let r = rays(scene, circles, samples);
    let error = predicted_error(circles, samples);
    why += &format!(
        "; {r:.2e} pass-1 rays, predicted worst form-factor error {:.2} %",
        100.0 * error
    );
    Preset {
        circles,
        samples,
        rays: r,
        error,
        why,
    }
}

/// Applies `quality` to `settings` for `scene`.
pub fn apply(quality: Quality, scene: &Scene, settings: &mut Pass1Settings) -> Preset {
    let p = choose(quality, scene);
    settings.circles = p.circles;
    settings.samples = p.samples;
    p
}

/// Applies `quality` under `--adaptive`: R as [`apply`] would choose it (its ray budget counted
/// at the preset's K, so an upper bound on what a uniform run would cost); K, the initial guess,
/// is left alone. The margin and depth come from [`Quality::adaptive`].
pub fn apply_adaptive(quality: Quality, scene: &Scene, settings: &mut Pass1Settings) -> Preset {
    let mut p = choose(quality, scene);
    settings.circles = p.circles;
    let (margin, depth) = quality.adaptive();
    p.why += &format!(
        "; --adaptive: R = {}, initial guess K = {} kept, margin {margin}, max depth {depth}",
        p.circles, settings.samples
    );
    p
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_meet_their_targets_and_order_by_cost() {
        let scene = crate::scene::parse(
            "[[material]]\nname = \"m\"\ndiffuse = [0.5, 0.5, 0.5]\n[[quad]]\nname = \"a\"\nmaterial = \"m\"\nvertices = [[0,0,0],[1,0,0],[1,1,0],[0,1,0]]\n",
            "t.toml",
        )
        .unwrap();
        let mut last = 0.0;
        for q in [Quality::Draft, Quality::Default, Quality::High] {
            let p = choose(q, &scene);
            assert!(p.error <= q.target() * 1.0001, "{q:?}: {p:?}");
            assert!(p.rays > last, "{q:?}: {p:?}");
            last = p.rays;
        }
    }

    #[test]
    fn adaptive_presets_tighten_in_order() {
        let (d, h) = (Quality::Draft.adaptive(), Quality::High.adaptive());
        let m = Quality::Default.adaptive();
        assert!(d.0 > m.0 && m.0 > h.0, "margins {d:?} {m:?} {h:?}");
        assert!(d.1 < m.1 && m.1 < h.1, "depths {d:?} {m:?} {h:?}");
    }
}
