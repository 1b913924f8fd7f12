//! `hemi bench methods`: the paper's hemisphere against its peers — the hemicube of Cohen &
//! Greenberg 1985 and cosine-weighted Monte Carlo (stratified and plain) — at equal rays per
//! shot, against Howell's closed form B-3 (element to a parallel rectangle, by superposition).
//!
//! Point form factors isolate the direction sampling: patch-to-patch form factors add the K×K
//! quadrature error (4.3), which is the same for every method.

use crate::chart::{log_log, Series};
use anyhow::Result;
use hemi::analytic::element_to_offset_rectangle;
use hemi::backend::SoftEngine;
use hemi::method::{Method, Shooter};
use hemi::optics::{Scratch, SpecularSettings};
use hemi_kernel::geometry::{Polygon, Vec3};
use hemi_kernel::hemisphere::{DeltaRule, OwnedHemisphere};
use hemi_kernel::optics::{Optics, Surface};
use hemi_kernel::patch::Patch;
use hemi_kernel::sampling::SamplePoint;
use std::io::Write;
use std::path::Path;
use std::time::Instant;

/// Fixed-seed configurations: (x0, y0, a, b, c) of a rectangle over an element at the origin.
fn configurations(n: usize) -> Vec<(f64, f64, f64, f64, f64)> {
    let mut rng = super::rng::XorShift::new(0x2545_f491_4f6c_dd1d);
    let mut rnd = move || rng.f64();
    (0..n)
        .map(|_| {
            let (a, b, c) = (0.2 + 2.0 * rnd(), 0.2 + 2.0 * rnd(), 0.3 + 1.5 * rnd());
            (-a * rnd(), -b * rnd(), a, b, c)
        })
        .collect()
}

/// One method at one R over the configurations: (rays per shot, RMS relative error, max
/// relative error, ns per ray).
fn measure(
    method: Method,
    circles: u32,
    cases: &[(f64, f64, f64, f64, f64)],
) -> Result<(u32, f64, f64, f64)> {
    let hemi =
        OwnedHemisphere::new(circles, DeltaRule::Band).map_err(|e| anyhow::anyhow!("{e}"))?;
    let view = hemi.view();
    let mut scratch = Scratch::new(0, &SpecularSettings::default());
    let mut shooter = Shooter::new(method, circles);
    let (mut sq, mut worst, mut rays) = (0.0f64, 0.0f64, 0u64);
    let mut secs = 0.0;
    // a tilted frame, so no method's axes line up with the rectangle's edges
    let (ex, ey, ez) = (
        Vec3::new(0.6, 0.8, 0.0),
        Vec3::new(-0.48, 0.36, 0.8),
        Vec3::new(0.64, -0.48, 0.6),
    );
    for (q, &(x0, y0, a, b, c)) in cases.iter().enumerate() {
        let want = element_to_offset_rectangle(x0, y0, a, b, c);
        let (x0, y0, a, b, c) = (x0 as f32, y0 as f32, a as f32, b as f32, c as f32);
        let at = |x: f32, y: f32, z: f32| ex * x + ey * y + ez * z;
        let target = Polygon::quad([
            at(x0, y0, c),
            at(x0, y0 + b, c),
            at(x0 + a, y0 + b, c),
            at(x0 + a, y0, c),
        ])
        .map_err(|e| anyhow::anyhow!("{e:?}"))?;
        let patches = [Patch::polygon(target)];
        let surfaces = [Surface::diffuse(0)];
        let optics =
            Optics::new(&patches, &surfaces, &[], circles).map_err(|e| anyhow::anyhow!("{e:?}"))?;
        let mut engine = SoftEngine::new(&patches);
        let point = SamplePoint {
            position: Vec3::ZERO,
            normal: ez,
            u: 0.5,
            v: 0.5,
            weight: 1.0,
        };
        let mut row = [[0.0f32; 3]];
        let t0 = Instant::now();
        // patch index 1 is no patch: nothing is left out
        let stats = shooter.shoot(
            &mut engine,
            &view,
            &optics,
            &mut scratch.view(),
            &point,
            q as u32,
            1,
            &mut row[..],
        )?;
        secs += t0.elapsed().as_secs_f64();
        rays += stats.rays;
        let e = (row[0][0] as f64 - want) / want;
        sq += e * e;
        worst = worst.max(e.abs());
    }
    Ok((
        method.rays_for(circles),
        (sq / cases.len() as f64).sqrt(),
        worst,
        1e9 * secs / rays.max(1) as f64,
    ))
}

/// Prints a markdown table and writes `methods-error.svg` into `svg_dir`.
pub fn bench_methods(
    circles: &[u32],
    cases: usize,
    out: &mut impl Write,
    svg_dir: Option<&Path>,
) -> Result<()> {
    let configs = configurations(cases);
    let methods = [
        Method::Hemisphere,
        Method::Hemicube,
        Method::MonteCarlo { stratified: true },
        Method::MonteCarlo { stratified: false },
    ];
    writeln!(
        out,
        "| method | R (budget) | rays per shot | RMS error | max error | ns per ray (1 thread) |"
    )?;
    writeln!(out, "|---|---|---|---|---|---|")?;
    let mut series: Vec<Series> = methods
        .iter()
        .map(|m| Series {
            name: m.name().to_string(),
            points: vec![],
        })
        .collect();
    for &r in circles {
        for (mi, &m) in methods.iter().enumerate() {
            let (rays, rms, worst, ns) = measure(m, r, &configs)?;
            writeln!(
                out,
                "| {} | {r} | {rays} | {:.3} % | {:.3} % | {ns:.1} |",
                m.name(),
                100.0 * rms,
                100.0 * worst
            )?;
            series[mi].points.push((rays as f64, rms));
        }
    }
    if let Some(dir) = svg_dir {
        let chart = log_log(
            "Point form factors: four methods at equal rays",
            "rays per shot (hemisphere of R circles; the peers matched to it)",
            "RMS relative error",
            &format!("reference: Howell B-3 by superposition; {cases} fixed-seed rectangles, tilted frame, soft backend"),
            &series,
        );
        std::fs::write(dir.join("methods-error.svg"), chart)?;
    }
    Ok(())
}
