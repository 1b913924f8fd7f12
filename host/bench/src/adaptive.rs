//! `hemi bench adaptive`: the error of the radiosity field against the rows computed, adaptive
//! against uniform sampling, against a very finely sampled uniform reference
//! (docs/ACCURACY.md, "Adaptive patch sampling").
//!
//! The error is what pass 2 shows: the radiosity B(u,v) that the vertex grids of §4.3 give over
//! the surfaces, compared with the reference's grids, as a relative L1 norm of luminance over
//! the area of all diffuse patches that do not emit,
//!
//! ```text
//!     error = ∫ |Y(u,v) − Y_ref(u,v)| dA / ∫ Y_ref(u,v) dA,
//! ```
//!
//! integrated by the midpoint rule on an M×M lattice per patch (M = 4·K_ref, so every cell of
//! the reference is sampled 16 times). Emitters are left out: their E dwarfs what they reflect
//! and would dilute the error of the surfaces around them.

use crate::chart::{log_log, Series};
use anyhow::Result;
use hemi::adaptive::gradient::luminance;
use hemi::adaptive::{refine, AdaptiveSettings, Refined, Test};
use hemi::pass1::form_factors;
use hemi::radiosity::{grids, Grid};
use hemi::scene::Scene;
use hemi::settings::Pass1Settings;
use hemi_kernel::patch::Shape;
use hemi_kernel::sampling::grid_sample;
use std::io::Write;
use std::path::Path;
use std::time::Instant;

/// What to compare.
#[derive(Clone, Debug)]
pub struct BenchSettings {
    /// K of the uniform reference.
    pub reference: u32,
    /// K of the uniform runs.
    pub uniform: Vec<u32>,
    /// The adaptive runs' initial guess K.
    pub initial: u32,
    /// Margins of the adaptive runs (the points of each chart line).
    pub margins: Vec<f64>,
    /// The adaptive runs' depth limits (one chart line each, per test).
    pub depths: Vec<u32>,
    /// The gradient tests of the adaptive runs.
    pub tests: Vec<Test>,
    /// Where to keep the reference's grids between runs (read if it holds this scene, K and R;
    /// written otherwise).
    pub reference_cache: Option<std::path::PathBuf>,
}

/// The reference as cached by [`BenchSettings::reference_cache`], with what identifies it.
#[derive(serde::Serialize, serde::Deserialize)]
struct CachedReference {
    key: String,
    rows: usize,
    seconds: f64,
    grids: Vec<Grid>,
}

/// What a cached reference must match: the scene's geometry and materials, K and R.
fn reference_key(scene: &Scene, settings: &Pass1Settings, k: u32) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |x: f64| {
        for byte in x.to_bits().to_le_bytes() {
            h = (h ^ byte as u64).wrapping_mul(0x100_0000_01b3);
        }
    };
    for (i, p) in scene.patches.iter().enumerate() {
        eat(p.area as f64);
        let m = scene.material_of(i);
        m.diffuse.iter().chain(&m.emission).for_each(|&x| eat(x));
    }
    format!(
        "K {k} R {} rule {:?} method {:?} patches {} scene {h:016x}",
        settings.circles,
        settings.rule,
        settings.method,
        scene.patches.len()
    )
}

/// Relative L1 error of the luminance of `got` against `reference` over the diffuse,
/// non-emitting patches of `scene` (see the module documentation), on `m`×`m` points a patch.
pub fn field_error(scene: &Scene, got: &[Grid], reference: &[Grid], m: u32) -> f64 {
    field_errors(scene, got, reference, m).0
}

/// The relative L1 error of [`field_error`] and the relative RMS error
/// (∫ (Y − Y_ref)² dA / A)^½ / (∫ Y_ref dA / A), which weighs large local errors (a missed
/// shadow edge) more.
pub fn field_errors(scene: &Scene, got: &[Grid], reference: &[Grid], m: u32) -> (f64, f64) {
    let (mut diff, mut sq, mut total, mut area) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for (i, p) in scene.patches.iter().enumerate() {
        let mat = scene.material_of(i);
        if !mat.is_diffuse() || mat.emission.iter().any(|e| *e > 0.0) {
            continue;
        }
        for b in 0..m {
            for a in 0..m {
                // the area of the lattice cell, on any polygon; Bezier cells are taken as equal
                let (u, v, w) = match &p.shape {
                    Shape::Polygon(poly) => {
                        let s = grid_sample(poly, m, a, b);
                        (s.u, s.v, s.weight as f64 * p.area as f64)
                    }
                    Shape::Bezier(_) => (
                        (a as f32 + 0.5) / m as f32,
                        (b as f32 + 0.5) / m as f32,
                        p.area as f64 / (m * m) as f64,
                    ),
                };
                let y = luminance(&got[i].at(u, v));
                let yr = luminance(&reference[i].at(u, v));
                diff += w * (y - yr).abs();
                sq += w * (y - yr) * (y - yr);
                total += w * yr;
                area += w;
            }
        }
    }
    if total > 0.0 {
        (diff / total, (sq / area).sqrt() / (total / area))
    } else {
        (diff, sq.sqrt())
    }
}

/// The uniform K×K reference's grids, its rows and the seconds it took: from `cache` if that
/// holds this scene, K and R, else computed (and written to `cache`).
pub fn reference(
    scene: &Scene,
    settings: &Pass1Settings,
    k: u32,
    cache: Option<&Path>,
) -> Result<(Vec<Grid>, usize, f64)> {
    let key = reference_key(scene, settings, k);
    let cached: Option<CachedReference> = cache
        .and_then(|p| std::fs::read(p).ok())
        .and_then(|b| serde_json::from_slice::<CachedReference>(&b).ok())
        .filter(|c| c.key == key);
    if let Some(c) = cached {
        return Ok((c.grids, c.rows, c.seconds));
    }
    let t0 = Instant::now();
    let (grids, rows) = uniform_grids(
        scene,
        &Pass1Settings {
            samples: k,
            ..*settings
        },
    )?;
    let seconds = t0.elapsed().as_secs_f64();
    if let Some(path) = cache {
        let c = CachedReference {
            key,
            rows,
            seconds,
            grids,
        };
        std::fs::write(path, serde_json::to_vec(&c)?)?;
        return Ok((c.grids, rows, seconds));
    }
    Ok((grids, rows, seconds))
}

fn uniform_grids(scene: &Scene, settings: &Pass1Settings) -> Result<(Vec<Grid>, usize)> {
    let ff = form_factors(&hemi::backend::soft(scene, settings)?, &|_| {})?;
    let sol = hemi::solve::gauss_seidel_scene(scene, ff.channels(), &Default::default())?;
    Ok((grids(scene, &ff, &sol), ff.elements.len()))
}

/// One measured configuration.
#[derive(Clone, Debug)]
pub struct Measured {
    /// "uniform" or "adaptive".
    pub sampling: &'static str,
    /// The settings, as a table cell.
    pub setting: String,
    /// Rows computed (hemispheres shot).
    pub rows: usize,
    /// Relative L1 error against the reference.
    pub error: f64,
    /// Relative RMS error against the reference.
    pub rms: f64,
    /// Wall time of pass 1 and the solves.
    pub seconds: f64,
}

/// Runs the comparison on `scene`, writes a markdown table and a summary to `out`, and the
/// chart to `svg` if given (with `command` as its note). Returns the measurements.
pub fn adaptive_vs_uniform(
    scene: &Scene,
    settings: &Pass1Settings,
    bench: &BenchSettings,
    out: &mut impl Write,
    svg: Option<&Path>,
    command: &str,
) -> Result<Vec<Measured>> {
    let cache = bench.reference_cache.as_deref();
    let (reference, ref_rows, ref_seconds) = reference(scene, settings, bench.reference, cache)?;
    let m = 4 * bench.reference;
    writeln!(
        out,
        "reference: uniform K = {}, R = {}: {ref_rows} rows, {ref_seconds:.1} s; error = relative L1 of luminance over {m}×{m} points per patch\n",
        bench.reference, settings.circles
    )?;
    writeln!(
        out,
        "| sampling | setting | rows computed | L1 error | RMS error | seconds |"
    )?;
    writeln!(out, "|---|---|---|---|---|---|")?;
    let field = Field {
        scene,
        reference: &reference,
        m,
    };
    let mut all = Vec::new();
    let mut series = vec![uniform_runs(&field, settings, bench, out, &mut all)?];
    for &test in &bench.tests {
        for &depth in &bench.depths {
            series.push(adaptive_runs(
                &field,
                settings,
                bench,
                (test, depth),
                out,
                &mut all,
            )?);
        }
    }
    summary(out, &all, bench)?;
    if let Some(path) = svg {
        let chart = log_log(
            "Radiosity error against rows computed",
            "rows computed (hemispheres shot)",
            "relative L1 error of B(u,v)",
            command,
            &series,
        );
        std::fs::write(path, chart)?;
    }
    Ok(all)
}

/// The reference field the runs are measured against.
struct Field<'a> {
    scene: &'a Scene,
    reference: &'a [Grid],
    /// Points per patch side the error is measured over.
    m: u32,
}

/// The name of a gradient test in the tables.
fn test_name(test: Test) -> &'static str {
    match test {
        Test::Surplus => "surplus",
        Test::Spread => "spread (paper)",
    }
}

/// The uniform runs, one table row each; their chart line.
fn uniform_runs(
    field: &Field<'_>,
    settings: &Pass1Settings,
    bench: &BenchSettings,
    out: &mut impl Write,
    all: &mut Vec<Measured>,
) -> Result<Series> {
    let mut uniform = Series {
        name: "uniform K×K".into(),
        points: vec![],
    };
    for &k in &bench.uniform {
        let t = Instant::now();
        let at_k = Pass1Settings {
            samples: k,
            ..*settings
        };
        let (g, rows) = uniform_grids(field.scene, &at_k)?;
        let (error, rms) = field_errors(field.scene, &g, field.reference, field.m);
        let r = Measured {
            sampling: "uniform",
            setting: format!("K = {k}"),
            rows,
            error,
            rms,
            seconds: t.elapsed().as_secs_f64(),
        };
        uniform.points.push((r.rows as f64, r.error));
        row(out, &r)?;
        all.push(r);
    }
    Ok(uniform)
}

/// The adaptive runs of one test and depth over every margin, one table row each; their
/// chart line.
fn adaptive_runs(
    field: &Field<'_>,
    settings: &Pass1Settings,
    bench: &BenchSettings,
    (test, depth): (Test, u32),
    out: &mut impl Write,
    all: &mut Vec<Measured>,
) -> Result<Series> {
    let name = test_name(test);
    let mut s = Series {
        name: format!("{name}, depth {depth}"),
        points: vec![],
    };
    let initial = Pass1Settings {
        samples: bench.initial,
        ..*settings
    };
    for &margin in &bench.margins {
        let t = Instant::now();
        let adaptive = AdaptiveSettings {
            margin,
            max_depth: depth,
            test,
            ..AdaptiveSettings::default()
        };
        let backend = hemi::backend::soft(field.scene, &initial)?;
        let refined: Refined = refine(&backend, &adaptive, &|_| {})?;
        let g = grids(field.scene, &refined.form_factors, &refined.solution);
        let (error, rms) = field_errors(field.scene, &g, field.reference, field.m);
        let r = Measured {
            sampling: "adaptive",
            setting: format!(
                "{name}, K = {}, max depth {depth}, margin {margin}",
                bench.initial
            ),
            rows: refined.rows_computed(),
            error,
            rms,
            seconds: t.elapsed().as_secs_f64(),
        };
        s.points.push((r.rows as f64, r.error));
        row(out, &r)?;
        all.push(r);
    }
    s.points.sort_by(|a, b| a.0.total_cmp(&b.0));
    Ok(s)
}

/// An error measure of a run (L1 or RMS).
type Measure<'a> = &'a dyn Fn(&Measured) -> f64;

/// At the error of each uniform run, the fewest rows an adaptive run of each test needed to
/// match it, in L1 and in RMS (measured runs; in brackets where the curves cross it).
fn summary(out: &mut impl Write, all: &[Measured], bench: &BenchSettings) -> Result<()> {
    writeln!(
        out,
        "\n| uniform | its rows | its L1 / RMS error | test | fewest adaptive rows at ≤ its L1 error | ratio | fewest at ≤ its RMS error | ratio |"
    )?;
    writeln!(out, "|---|---|---|---|---|---|---|---|")?;
    for u in all.iter().filter(|r| r.sampling == "uniform") {
        for &test in &bench.tests {
            let name = test_name(test);
            let l1: Measure<'_> = &|r| r.error;
            let rms: Measure<'_> = &|r| r.rms;
            let (l1_rows, l1_ratio) = fewest(all, name, u, l1);
            let (rms_rows, rms_ratio) = fewest(all, name, u, rms);
            let l1_ratio = l1_ratio + &crossing(all, name, &bench.depths, u, l1);
            let rms_ratio = rms_ratio + &crossing(all, name, &bench.depths, u, rms);
            writeln!(
                out,
                "| {} | {} | {:.3} % / {:.3} % | {name} | {l1_rows} | {l1_ratio} | {rms_rows} | {rms_ratio} |",
                u.setting,
                u.rows,
                100.0 * u.error,
                100.0 * u.rms,
            )?;
        }
    }
    Ok(())
}

/// The adaptive run of test `name` with the fewest rows at no more than `u`'s error, and the
/// ratio of rows.
fn fewest(all: &[Measured], name: &str, u: &Measured, err: Measure<'_>) -> (String, String) {
    all.iter()
        .filter(|r| r.sampling == "adaptive" && r.setting.starts_with(name) && err(r) <= err(u))
        .min_by_key(|r| r.rows)
        .map_or(("none reaches it".to_string(), "–".to_string()), |a| {
            (
                format!("{} ({})", a.rows, a.setting),
                format!("{:.2}×", u.rows as f64 / a.rows as f64),
            )
        })
}

/// Where the test's curves (one per depth, by rows) cross `u`'s error, log-log interpolated
/// between the two measured margins around it, as a ratio of rows (empty if none crosses).
fn crossing(
    all: &[Measured],
    name: &str,
    depths: &[u32],
    u: &Measured,
    err: Measure<'_>,
) -> String {
    let mut best = f64::INFINITY;
    for &depth in depths {
        let tag = format!("max depth {depth},");
        let mut line: Vec<&Measured> = all
            .iter()
            .filter(|r| {
                r.sampling == "adaptive" && r.setting.starts_with(name) && r.setting.contains(&tag)
            })
            .collect();
        line.sort_by_key(|r| r.rows);
        for w in line.windows(2) {
            let (e1, e2, t) = (err(w[0]), err(w[1]), err(u));
            if e1 > t && e2 <= t && e2 > 0.0 {
                let f = (t.ln() - e1.ln()) / (e2.ln() - e1.ln());
                let (r1, r2) = ((w[0].rows as f64).ln(), (w[1].rows as f64).ln());
                best = best.min((r1 + f * (r2 - r1)).exp());
                break;
            }
        }
    }
    if best.is_finite() {
        format!(" ({:.2}× interpolated)", u.rows as f64 / best)
    } else {
        String::new()
    }
}

fn row(out: &mut impl Write, r: &Measured) -> Result<()> {
    writeln!(
        out,
        "| {} | {} | {} | {:.3} % | {:.3} % | {:.2} |",
        r.sampling,
        r.setting,
        r.rows,
        100.0 * r.error,
        100.0 * r.rms,
        r.seconds
    )?;
    out.flush()?;
    Ok(())
}
