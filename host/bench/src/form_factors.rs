//! Form factors against Howell's closed forms over R and K: error and cost, a markdown table
//! and optionally the chart of docs/ACCURACY.md.

use crate::chart::{log_log, Series};
use anyhow::Result;
use hemi::pass1::form_factors;
use hemi::scene::{self, Scene};
use hemi::settings::Pass1Settings;
use std::io::Write;

/// The table of `hemi bench form-factors`: every (R, K) over the closed-form cases.
pub fn bench_form_factors(
    out: &mut impl Write,
    circles: &[u32],
    samples: &[u32],
    svg: Option<&std::path::Path>,
) -> Result<()> {
    let mut series: Vec<Series> = samples
        .iter()
        .map(|k| Series {
            name: format!(
                "K = {k} (R = {}..{})",
                circles.first().unwrap_or(&0),
                circles.last().unwrap_or(&0)
            ),
            points: vec![],
        })
        .collect();
    let cases = hemi::analytic::howell_cases();
    let scenes: Vec<Scene> = cases
        .iter()
        .map(|(n, src, _)| scene::parse(src, n))
        .collect::<Result<_>>()?;
    writeln!(
        out,
        "| R | K | rays per hemisphere | max error | mean error | rays | seconds |"
    )?;
    writeln!(out, "|---|---|---|---|---|---|---|")?;
    for &r in circles {
        for (ki, &k) in samples.iter().enumerate() {
            let settings = Pass1Settings {
                circles: r,
                samples: k,
                ..Pass1Settings::default()
            };
            let (mut worst, mut sum, mut rays) = (0.0f64, 0.0f64, 0u64);
            let t0 = std::time::Instant::now();
            for (scene, (_, _, want)) in scenes.iter().zip(&cases) {
                let ff = form_factors(&hemi::backend::soft(scene, &settings)?, &|_| {})?;
                let e = (ff.matrix[0][1] - want).abs() / want;
                worst = worst.max(e);
                sum += e;
                rays += ff.stats.rays as u64;
            }
            let secs = t0.elapsed().as_secs_f64();
            writeln!(
                out,
                "| {r} | {k} | {} | {:.3} % | {:.3} % | {rays} | {secs:.3} |",
                hemi_kernel::hemisphere::ray_count(r),
                100.0 * worst,
                100.0 * sum / cases.len() as f64
            )?;
            series[ki].points.push((rays as f64, worst));
        }
    }
    if let Some(path) = svg {
        let chart = log_log(
            "Form factors: error against rays cast",
            "rays (five cases together)",
            "max relative error of F_12",
            "reference: Howell C-11 and C-14 closed forms; soft backend, band δD rule",
            &series,
        );
        std::fs::write(path, chart)?;
    }
    Ok(())
}
