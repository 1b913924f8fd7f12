//! `hemi bench quality`: what each `--quality` preset chooses on a scene, what it costs there
//! (pass-1 rays and seconds, measured), and the worst form-factor error it reaches on the five
//! Howell configurations of `hemi bench form-factors` (measured, against the closed forms).

use anyhow::Result;
use hemi::analytic::howell_cases;
use hemi::pass1::form_factors;
use hemi::quality::{choose, Quality};
use hemi::scene::{parse, Scene};
use hemi::settings::Pass1Settings;
use std::io::Write;
use std::time::Instant;

/// The five Howell cases of `hemi bench form-factors`: (scene, F_01).
pub fn howell_scenes() -> Result<Vec<(Scene, f64)>> {
    howell_cases()
        .into_iter()
        .map(|(_, src, want)| Ok((parse(&src, "howell.toml")?, want)))
        .collect()
}

/// Worst relative error of F_01 over the Howell cases at `settings`.
pub fn howell_worst(settings: &Pass1Settings) -> Result<f64> {
    let mut worst = 0.0f64;
    for (scene, want) in howell_scenes()? {
        let ff = form_factors(&hemi::backend::soft(&scene, settings)?, &|_| {})?;
        worst = worst.max((ff.matrix[0][1] - want).abs() / want);
    }
    Ok(worst)
}

/// Prints one row per preset for `scene` (named `label`).
pub fn bench_quality(scene: &Scene, label: &str, out: &mut impl Write) -> Result<()> {
    writeln!(out, "| preset | target | R | K | predicted worst error | measured worst error (Howell) | {label}: pass-1 rays | {label}: pass-1 s |")?;
    writeln!(out, "|---|---|---|---|---|---|---|---|")?;
    for q in [Quality::Draft, Quality::Default, Quality::High] {
        let p = choose(q, scene);
        let settings = Pass1Settings {
            circles: p.circles,
            samples: p.samples,
            ..Pass1Settings::default()
        };
        let measured = howell_worst(&settings)?;
        let t0 = Instant::now();
        let ff = form_factors(&hemi::backend::soft(scene, &settings)?, &|_| {})?;
        let secs = t0.elapsed().as_secs_f64();
        writeln!(
            out,
            "| {q:?} | {:.1} % | {} | {} | {:.2} % | {:.3} % | {:.3e} | {secs:.2} |",
            100.0 * q.target(),
            p.circles,
            p.samples,
            100.0 * p.error,
            100.0 * measured,
            ff.stats.rays as f64
        )?;
    }
    Ok(())
}
