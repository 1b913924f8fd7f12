//! The gradient test of paper §4.3: a 4-sample window placed on the patch, the differences of
//! its intensities compared against a margin.
//!
//! Window (a, b) of a k×k level holds the samples (a, b), (a+1, b), (a, b+1), (a+1, b+1); there
//! are (k−1)² of them, overlapping, so every pair of neighbouring samples is compared. A window
//! fails when the spread of its four luminances exceeds the margin times their mean:
//!
//! ```text
//!     max Y − min Y > margin · mean Y,     Y = 0.2126 R + 0.7152 G + 0.0722 B
//! ```
//!
//! Relative, because the eye judges a step in brightness by its ratio to the brightness around
//! it (the paper: "against a prespecified margin", relative here to the local intensity), so one
//! margin serves the bright floor under a light and a dimly lit wall alike. Luminance, because
//! the three channels of one element share their form factors and differ only by the
//! reflectances and the colours of the patches seen; a change of hue at constant luminance is not
//! what shadows and penumbrae are made of. A window that is black throughout (mean 0) passes.
//!
//! The local intensity is floored at a fraction `floor` of the patch's mean luminance (over the
//! level's samples): in a window darker than that, the margin is taken relative to the floor.
//! Purely local, a margin asks for the same *relative* accuracy in a shadow core or a dark
//! corner as in the light, where the same relative step is a far smaller difference of
//! radiance. It is also where the hemisphere's discretisation noise is largest relative to the
//! light (docs/ACCURACY.md, "Element-level noise": dark corners are lit at grazing angles), so
//! a purely local margin refines noise there. On the Cornell box a floor at the patch mean
//! (1.0) reaches the same radiosity error with 15–25 % fewer rows (docs/ACCURACY.md); 0 is the
//! purely local test.
//!
//! [`failing_windows_surplus`] is the same window and margin over other differences: each
//! sample's difference from the linear interpolation of the level before (its hierarchical
//! surplus), which measures the interpolation error directly instead of the slope (see
//! [`super::Test`] for why and when).

/// Rec. 709 luminance of an RGB radiosity.
pub fn luminance(b: &[f64; 3]) -> f64 {
    0.2126 * b[0] + 0.7152 * b[1] + 0.0722 * b[2]
}

/// Whether four luminances differ by more than `margin` times their mean.
pub fn window_fails(y: [f64; 4], margin: f64) -> bool {
    window_fails_against(y, margin, 0.0)
}

/// Whether four luminances differ by more than `margin` times their mean or `floor`, whichever
/// is larger.
pub fn window_fails_against(y: [f64; 4], margin: f64, floor: f64) -> bool {
    let lo = y.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = y.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let mean = 0.25 * (y[0] + y[1] + y[2] + y[3]);
    hi - lo > margin * mean.max(floor)
}

/// `floor` times the mean luminance of a level's values: the least intensity a margin is
/// taken relative to.
fn floor_of(y: &[f64], floor: f64) -> f64 {
    floor * y.iter().sum::<f64>() / y.len() as f64
}

/// The gradient test over a k×k level of element radiosities (v-major): for each window
/// (a, b), 0 ≤ a, b ≤ k−2, v-major ((k−1)² entries), whether it fails; the local intensity is
/// floored at `floor` times the level's mean (module documentation). A level of one sample has
/// no window and nothing fails.
pub fn failing_windows(k: usize, values: &[[f64; 3]], margin: f64, floor: f64) -> Vec<bool> {
    assert_eq!(values.len(), k * k, "k×k values");
    if k < 2 {
        return Vec::new();
    }
    let y: Vec<f64> = values.iter().map(luminance).collect();
    let least = floor_of(&y, floor);
    let w = k - 1;
    (0..w * w)
        .map(|i| {
            let (a, b) = (i % w, i / w);
            window_fails_against(
                [
                    y[b * k + a],
                    y[b * k + a + 1],
                    y[(b + 1) * k + a],
                    y[(b + 1) * k + a + 1],
                ],
                margin,
                least,
            )
        })
        .collect()
}

/// The surplus variant: window (a, b) fails when one of its four samples differs from what the
/// level before predicted for it (`predicted`, the linear interpolation of [`super::lattice`])
/// by more than `margin` times the window's mean luminance (floored as in [`failing_windows`]).
/// Interpolated samples have no surplus; a computed sample's surplus is the interpolation error
/// the coarser level made there.
pub fn failing_windows_surplus(
    k: usize,
    values: &[[f64; 3]],
    predicted: &[[f64; 3]],
    margin: f64,
    floor: f64,
) -> Vec<bool> {
    assert_eq!(values.len(), k * k, "k×k values");
    assert_eq!(predicted.len(), k * k, "k×k predictions");
    if k < 2 {
        return Vec::new();
    }
    let y: Vec<f64> = values.iter().map(luminance).collect();
    let s: Vec<f64> = values
        .iter()
        .zip(predicted)
        .map(|(v, p)| (luminance(v) - luminance(p)).abs())
        .collect();
    let least = floor_of(&y, floor);
    let w = k - 1;
    (0..w * w)
        .map(|i| {
            let (a, b) = (i % w, i / w);
            let idx = [
                b * k + a,
                b * k + a + 1,
                (b + 1) * k + a,
                (b + 1) * k + a + 1,
            ];
            let mean = (0.25 * idx.iter().map(|&j| y[j]).sum::<f64>()).max(least);
            idx.iter().map(|&j| s[j]).fold(0.0, f64::max) > margin * mean
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_uniform_level_passes_any_margin() {
        let v = vec![[0.3, 0.2, 0.1]; 16];
        assert!(failing_windows(4, &v, 0.0, 1.0).iter().all(|f| !f));
        assert!(failing_windows(4, &vec![[0.0; 3]; 16], 0.0, 1.0)
            .iter()
            .all(|f| !f));
    }

    #[test]
    fn the_margin_is_relative_to_the_local_intensity() {
        // a 10 % step fails a 5 % margin and passes a 20 % one, bright or dim alike
        for scale in [1e-3, 1.0, 1e3] {
            let y = [scale, scale, 1.1 * scale, 1.1 * scale];
            assert!(window_fails(y, 0.05));
            assert!(!window_fails(y, 0.2));
        }
    }

    #[test]
    fn a_dark_window_is_judged_against_the_floor() {
        // a 50 % step at 1 % of the patch's light: fails the purely local test, passes a 10 %
        // margin floored at the patch mean (the step is 0.5 % of it)
        let y = [0.01, 0.01, 0.015, 0.015];
        assert!(window_fails_against(y, 0.1, 0.0));
        assert!(!window_fails_against(y, 0.1, 1.0));
        assert!(window_fails_against([0.5, 0.5, 1.5, 1.5], 0.1, 1.0));
    }

    #[test]
    fn only_the_windows_across_a_step_fail() {
        // k = 4, a step in u between columns 1 and 2: windows a = 1 fail, a = 0 and 2 pass
        let v: Vec<[f64; 3]> = (0..16)
            .map(|i| if i % 4 < 2 { [1.0; 3] } else { [0.2; 3] })
            .collect();
        let f = failing_windows(4, &v, 0.1, 0.0);
        for (i, failed) in f.iter().enumerate() {
            assert_eq!(*failed, i % 3 == 1, "window {i}");
        }
    }
}
