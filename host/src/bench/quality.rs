//! `hemi bench quality`: what each `--quality` preset chooses on a scene, what it costs there
//! (pass-1 rays and seconds, measured), and the worst form-factor error it reaches on the five
//! Howell configurations of `hemi bench form-factors` (measured, against the closed forms).

use crate::analytic::{opposed_rectangles, perpendicular_common_edge};
use crate::pass1::{form_factors, Pass1Settings};
use crate::quality::{choose, Quality};
use crate::scene::{parse, Scene};
use anyhow::Result;
use std::io::Write;
use std::time::Instant;

fn quad(name: &str, v: [[f64; 3]; 4]) -> String {
    let vs: Vec<String> = v
        .iter()
        .map(|p| format!("[{}, {}, {}]", p[0], p[1], p[2]))
        .collect();
    format!(
        "[[quad]]\nname = \"{name}\"\nmaterial = \"m\"\nvertices = [{}]\n",
        vs.join(", ")
    )
}

/// The five Howell cases: (scene, F_01).
pub fn howell_scenes() -> Result<Vec<(Scene, f64)>> {
    let mat = "[[material]]\nname = \"m\"\ndiffuse = [0.5, 0.5, 0.5]\n";
    let opposed = |a: f64, b: f64, c: f64| {
        mat.to_string()
            + &quad(
                "p1",
                [[0.0, 0.0, 0.0], [a, 0.0, 0.0], [a, b, 0.0], [0.0, b, 0.0]],
            )
            + &quad("p2", [[0.0, 0.0, c], [0.0, b, c], [a, b, c], [a, 0.0, c]])
    };
    let perpendicular = |l: f64, w: f64, h: f64| {
        mat.to_string()
            + &quad(
                "floor",
                [[0.0, 0.0, 0.0], [0.0, 0.0, w], [l, 0.0, w], [l, 0.0, 0.0]],
            )
            + &quad(
                "wall",
                [[0.0, 0.0, 0.0], [l, 0.0, 0.0], [l, h, 0.0], [0.0, h, 0.0]],
            )
    };
    [
        (opposed(1.0, 1.0, 1.0), opposed_rectangles(1.0, 1.0, 1.0)),
        (opposed(1.0, 1.0, 3.0), opposed_rectangles(1.0, 1.0, 3.0)),
        (opposed(2.0, 1.0, 0.5), opposed_rectangles(2.0, 1.0, 0.5)),
        (
            perpendicular(1.0, 1.0, 1.0),
            perpendicular_common_edge(1.0, 1.0, 1.0),
        ),
        (
            perpendicular(1.0, 2.0, 1.0),
            perpendicular_common_edge(1.0, 2.0, 1.0),
        ),
    ]
    .into_iter()
    .map(|(src, want)| Ok((parse(&src, "howell.toml")?, want)))
    .collect()
}

/// Worst relative error of F_01 over the Howell cases at `settings`.
pub fn howell_worst(settings: &Pass1Settings) -> Result<f64> {
    let mut worst = 0.0f64;
    for (scene, want) in howell_scenes()? {
        let ff = form_factors(&scene, settings, &|_| {})?;
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
        let ff = form_factors(scene, &settings, &|_| {})?;
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
