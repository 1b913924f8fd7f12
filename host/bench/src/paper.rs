//! `hemi bench paper-fig9`: the paper's figure 9 on the Cornell box. (a) Two radiosity values
//! (red channel, b_R) converging as the number of hemisphere circles R grows; (b) hemisphere
//! rays against R. The reference of (a) is a converged run of a different method: stratified
//! Monte Carlo at a much larger ray budget, at the same K.

use crate::chart::linear::linear;
use crate::chart::{log_log, Series};
use anyhow::{Context, Result};
use hemi::method::Method;
use hemi::pass1::form_factors;
use hemi::scene::Scene;
use hemi::settings::Pass1Settings;
use hemi::solve::{direct, SceneParts};
use hemi_kernel::hemisphere::ray_count;
use std::io::Write;
use std::path::Path;
use std::time::Instant;

fn radiosity(scene: &Scene, settings: &Pass1Settings) -> Result<(Vec<[f64; 3]>, u64, f64)> {
    let t0 = Instant::now();
    let ff = form_factors(&hemi::backend::soft(scene, settings)?, &|_| {})?;
    let secs = t0.elapsed().as_secs_f64();
    // the dense solve: the chart shows pass 1's error alone, not a solver's tolerance
    let parts = SceneParts::new(scene, ff.channels());
    let sol = direct::solve(&parts.system(ff.channels())?)?;
    Ok((sol.radiosity, ff.stats.rays, secs))
}

/// Prints the table of fig. 9a/9b and writes `fig9a.svg` and `fig9b.svg` into `svg_dir`.
pub fn bench_fig9(
    scene: &Scene,
    patches: &[&str],
    samples: u32,
    circles: &[u32],
    reference_circles: u32,
    out: &mut impl Write,
    svg_dir: Option<&Path>,
) -> Result<()> {
    let ids: Vec<usize> = patches
        .iter()
        .map(|p| {
            scene
                .patch_index(p)
                .with_context(|| format!("no patch `{p}` in the scene"))
        })
        .collect::<Result<_>>()?;
    let base = Pass1Settings {
        samples,
        ..Pass1Settings::default()
    };
    let (refb, ref_rays, ref_secs) = radiosity(
        scene,
        &Pass1Settings {
            circles: reference_circles,
            method: Method::MonteCarlo { stratified: true },
            ..base
        },
    )?;
    writeln!(
        out,
        "reference: stratified Monte Carlo, {} rays per shot (budget of R = {reference_circles}), K = {samples}: {ref_rays} rays, {ref_secs:.2} s",
        Method::MonteCarlo { stratified: true }.rays_for(reference_circles)
    )?;
    for (p, &i) in patches.iter().zip(&ids) {
        writeln!(out, "reference b_R({p}) = {:.5}", refb[i][0])?;
    }
    write!(out, "\n| R | rays per hemisphere | 8R²/π |")?;
    for p in patches {
        write!(out, " b_R({p}) | error |")?;
    }
    writeln!(out, " pass 1 s |")?;
    write!(out, "|---|---|---|")?;
    for _ in patches {
        write!(out, "---|---|")?;
    }
    writeln!(out, "---|")?;
    let mut values: Vec<Series> = patches
        .iter()
        .map(|p| Series {
            name: format!("b_R({p})"),
            points: vec![],
        })
        .collect();
    let mut rays = Series {
        name: "rays per hemisphere".into(),
        points: vec![],
    };
    let mut approx = Series {
        name: "8R²/π".into(),
        points: vec![],
    };
    for &r in circles {
        let (b, _, secs) = radiosity(scene, &Pass1Settings { circles: r, ..base })?;
        let n = ray_count(r);
        let a = 8.0 * (r * r) as f64 / std::f64::consts::PI;
        write!(out, "| {r} | {n} | {a:.0} |")?;
        for (k, &i) in ids.iter().enumerate() {
            write!(
                out,
                " {:.5} | {:.3} % |",
                b[i][0],
                100.0 * (b[i][0] - refb[i][0]).abs() / refb[i][0]
            )?;
            values[k].points.push((r as f64, b[i][0]));
        }
        writeln!(out, " {secs:.3} |")?;
        rays.points.push((r as f64, n as f64));
        approx.points.push((r as f64, a));
    }
    if let Some(dir) = svg_dir {
        let refs: Vec<(f64, String)> = patches
            .iter()
            .zip(&ids)
            .map(|(p, &i)| (refb[i][0], format!("ref. {p}")))
            .collect();
        std::fs::write(
            dir.join("fig9a.svg"),
            linear(
                "Fig. 9a: radiosity (red) converging as R grows",
                "hemisphere circles R",
                "b_R (W/m²)",
                &format!("Cornell box, K = {samples}, dense solve; dashed: stratified Monte Carlo at {} rays per shot", Method::MonteCarlo { stratified: true }.rays_for(reference_circles)),
                &values,
                &refs,
            ),
        )?;
        std::fs::write(
            dir.join("fig9b.svg"),
            log_log(
                "Fig. 9b: hemisphere rays against R",
                "hemisphere circles R",
                "rays per hemisphere",
                "counted: Σ_j N_j of (3.1) rounded to multiples of four; line: the estimate 8R²/π",
                &[rays, approx],
            ),
        )?;
    }
    Ok(())
}
