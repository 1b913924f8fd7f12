//! Benchmarks that regenerate figures of docs/ACCURACY.md and docs/PERFORMANCE.md (speed is
//! measured here, never asserted in tests).

pub mod adaptive;
pub mod chart;
pub mod form_factors;
pub mod lanes;
pub mod methods;
pub mod paper;
pub mod quality;
pub mod rays;
pub mod rng;
pub mod rtl;
pub mod scale;
pub mod solvers;
pub mod trace;

use anyhow::Result;
use hemi::analytic::bezier_newton;
use hemi::pass1::form_factors;
use hemi::scene::{Scene, ScenePatch};
use hemi::settings::Pass1Settings;
use hemi::solve::SolveSettings;
use hemi_kernel::geometry::{Bezier, Polygon, Subdivision, Vec3};
use hemi_kernel::patch::Shape;
use std::io::Write;
use std::time::Instant;

/// Rays aimed at random points of random patches from 0.5 to 3 units away, within about 40° of
/// the normal, with the f64 Newton reference of each: (patch, origin, direction, t, u, v).
fn aimed_rays(patches: &[Bezier], n: usize) -> Vec<(usize, Vec3, Vec3, f64, f64, f64)> {
    let mut rng = rng::XorShift::new(0x9e37_79b9_7f4a_7c15);
    let mut rnd = move || rng.f32();
    let mut out = Vec::new();
    while out.len() < n {
        let i = (rnd() * patches.len() as f32) as usize % patches.len();
        let b = &patches[i];
        let (u, v) = (0.05 + 0.9 * rnd(), 0.05 + 0.9 * rnd());
        let Some(nrm) = b.normal(u, v) else { continue };
        let tilt = Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5) * 0.8;
        let Some(dir) = (-nrm + tilt).try_normalize() else {
            continue;
        };
        let o = b.point(u, v) - dir * (0.5 + 2.5 * rnd());
        if let Some((t, ru, rv)) = bezier_newton(
            b,
            o.to_array().map(|x| x as f64),
            dir.to_array().map(|x| x as f64),
        ) {
            out.push((i, o, dir, t, ru, rv));
        }
    }
    out
}

/// Intersection error against subdivision depth and flatness, and the cost per ray: a markdown
/// table. Errors are against the Newton reference, relative to the scene's Bezier extent.
pub fn bezier_accuracy(
    scene: &Scene,
    out: &mut impl Write,
    svg: Option<&std::path::Path>,
) -> Result<()> {
    let patches = scene.bezier_patches();
    anyhow::ensure!(!patches.is_empty(), "the scene has no Bezier patches");
    let size = patches.iter().fold(0.0f32, |m, b| m.max(b.bounds().size())) as f64;
    let rays = aimed_rays(&patches, 2000);
    writeln!(out, "| max depth | flatness | worst t error / size | mean t error / size | worst (u,v) error | ns per ray |")?;
    writeln!(out, "|---|---|---|---|---|---|")?;
    let mut settings: Vec<Subdivision> = (2..=12)
        .step_by(2)
        .map(|d| Subdivision {
            max_depth: d,
            min_box: 0.0,
            flatness: 0.0,
        })
        .collect();
    settings.extend([1e-3, 1e-4, 1e-5].map(|f| Subdivision {
        flatness: f,
        ..Subdivision::default()
    }));
    let mut by_depth = crate::chart::Series {
        name: "depth 2..12, no flatness".into(),
        points: vec![],
    };
    let mut by_flat = crate::chart::Series {
        name: "flatness 1e-3..1e-5".into(),
        points: vec![],
    };
    for sub in settings {
        let t0 = Instant::now();
        let hits: Vec<_> = rays
            .iter()
            .map(|(i, o, d, ..)| patches[*i].intersect(*o, *d, 0.0, f32::INFINITY, &sub))
            .collect();
        let ns = t0.elapsed().as_nanos() as f64 / rays.len() as f64;
        let (mut worst_t, mut sum_t, mut worst_uv, mut n) = (0.0f64, 0.0f64, 0.0f64, 0usize);
        for (h, (_, _, _, t, u, v)) in hits.iter().zip(&rays) {
            // a nearer fold of the same patch is a legitimate nearest hit: not compared
            let Some(h) = h else {
                worst_t = f64::INFINITY;
                continue;
            };
            if (h.t as f64) < t - 1e-3 * size {
                continue;
            }
            let e = (h.t as f64 - t).abs() / size;
            worst_t = worst_t.max(e);
            sum_t += e;
            worst_uv = worst_uv.max((h.u as f64 - u).abs().max((h.v as f64 - v).abs()));
            n += 1;
        }
        writeln!(
            out,
            "| {} | {} | {:.2e} | {:.2e} | {:.2e} | {:.0} |",
            sub.max_depth,
            sub.flatness,
            worst_t,
            sum_t / n.max(1) as f64,
            worst_uv,
            ns
        )?;
        if worst_t.is_finite() {
            let series = if sub.flatness == 0.0 {
                &mut by_depth
            } else {
                &mut by_flat
            };
            series.points.push((ns, worst_t));
        }
    }
    if let Some(path) = svg {
        let chart = crate::chart::log_log(
            "Bezier intersection: error against cost",
            "ns per ray (one thread)",
            "worst |t − t_ref| / teapot size",
            "reference: f64 Newton on P(u,v) = o + t·d from a dense seed; 2000 rays on scenes/teapot.toml",
            &[by_depth, by_flat],
        );
        std::fs::write(path, chart)?;
    }
    Ok(())
}

/// The scene with every Bezier patch replaced by 2n² triangles on an n×n grid of surface points.
pub fn tessellate(scene: &Scene, n: usize) -> Scene {
    let mut out = scene.clone();
    out.patches.clear();
    // back sides of translucent sheets are made again for the new patches at the end
    let fronts = &scene.patches[..scene.fronts()];
    for p in fronts {
        match p.shape {
            Shape::Polygon(_) => out.patches.push(ScenePatch {
                sides: hemi::scene::Sides::Opaque,
                ..p.clone()
            }),
            Shape::Bezier(b) => {
                let at = |i: usize, j: usize| b.point(i as f32 / n as f32, j as f32 / n as f32);
                for j in 0..n {
                    for i in 0..n {
                        let (a, c, d, e) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                        for (k, tri) in [[a, c, d], [a, d, e]].iter().enumerate() {
                            if let Ok(poly) = Polygon::triangle(*tri) {
                                out.patches.push(ScenePatch {
                                    name: format!("{}/{i}.{j}.{k}", p.name),
                                    material: p.material,
                                    area: poly.area,
                                    shape: Shape::Polygon(poly),
                                    sides: hemi::scene::Sides::Opaque,
                                });
                            }
                        }
                    }
                }
            }
        }
    }
    hemi::scene::translucent::add_back_sides(&mut out.materials, &mut out.patches);
    out
}

fn area_mean(scene: &Scene, b: &[[f64; 3]], pick: impl Fn(&ScenePatch) -> bool) -> [f64; 3] {
    let (mut s, mut a) = ([0.0; 3], 0.0);
    for (p, v) in scene.patches.iter().zip(b) {
        if pick(p) {
            for c in 0..3 {
                s[c] += v[c] * p.area as f64;
            }
            a += p.area as f64;
        }
    }
    s.map(|x| x / a.max(1e-30))
}

/// The paper's claim (§8): the teapot as Bezier patches with 16 samples each against the same
/// teapot tessellated into triangles. Prints pass-1 time, elements, matrix size and memory, and
/// the area-mean radiosity of the teapot for both.
pub fn bezier_vs_tessellated(
    scene: &Scene,
    settings: &Pass1Settings,
    n: usize,
    out: &mut impl Write,
) -> Result<()> {
    writeln!(out, "| model | patches | elements (hemispheres) | F non-zeros | F + rows memory | pass 1 s | teapot mean B (r, g, b) |")?;
    writeln!(out, "|---|---|---|---|---|---|---|")?;
    // As in the paper: 16 sample points per Bezier patch against one per triangle; polygons
    // (the floor too, in both runs) get K = 1.
    let s = Pass1Settings {
        samples: 1,
        ..*settings
    };
    for (label, sc) in [
        ("Bezier, 16 samples per patch".to_string(), scene.clone()),
        (
            format!("{} triangles per patch, 1 sample each", 2 * n * n),
            tessellate(scene, n),
        ),
    ] {
        let t0 = Instant::now();
        let ff = form_factors(&hemi::backend::soft(&sc, &s)?, &|_| {})?;
        let secs = t0.elapsed().as_secs_f64();
        let np = sc.patches.len();
        let rows: usize = ff.elements.iter().map(|e| e.row.len()).sum();
        // the sparse F and the element rows ((column, 3 × f32) per entry)
        let bytes = ff.matrix_bytes() + rows * 16;
        let sol = hemi::solve::gauss_seidel_scene(&sc, ff.channels(), &SolveSettings::default())?;
        let teapot = area_mean(&sc, &sol.radiosity, |p| p.name.starts_with("teapot"));
        writeln!(
            out,
            "| {label} | {np} | {} | {} | {:.2} MiB | {secs:.2} | {:.4}, {:.4}, {:.4} |",
            ff.elements.len(),
            ff.nonzeros(),
            bytes as f64 / (1 << 20) as f64,
            teapot[0],
            teapot[1],
            teapot[2]
        )?;
    }
    Ok(())
}

/// Worst rotation error of a CORDIC pipe of configuration `cfg` over `n` angles of the full
/// circle (a unit vector (0.8, 0.6) turned by each), against f64.
pub fn cordic_rotation_error(cfg: hemi_hdl_model::cordic::CordicConfig, n: usize) -> f64 {
    use hemi_hdl_model::cordic::{CordicPipe, CordicSlot, Mode};
    use hemi_hdl_model::format::{Angle, Unit};
    let mut pipe: CordicPipe<u32> = CordicPipe::new(Mode::Rotate, cfg);
    let angle = |i: usize| (i as f64 / n as f64 * 2.0 - 1.0) * std::f64::consts::PI;
    let (mut worst, mut got, mut i) = (0.0f64, 0, 0);
    while got < n {
        let input = (i < n).then(|| CordicSlot {
            x: Unit::from_num(0.8),
            y: Unit::from_num(0.6),
            z: Angle::from_num(angle(i)),
            zero: false,
            payload: i as u32,
        });
        i += 1;
        if let Some(s) = pipe.tick(input) {
            let a = angle(s.payload as usize);
            let (xr, yr) = (0.8 * a.cos() - 0.6 * a.sin(), 0.8 * a.sin() + 0.6 * a.cos());
            let e = (s.x.to_num::<f64>() - xr).hypot(s.y.to_num::<f64>() - yr);
            worst = worst.max(e);
            got += 1;
        }
    }
    worst
}

/// The accelerator model's CORDIC: worst rotation error against iterations n and word width W,
/// with the pipe's latency in clocks and an area proxy (the rotator's 3 pipes × n stages × 3
/// W-bit adders); a markdown table of every configuration and, with `svg`, the chart of error
/// against the area proxy, one line per W (n rising along it), with the Pareto front. (Against
/// latency alone, n + 4 clocks whatever W, the widest word always wins: area is the cost that
/// separates the configurations.)
pub fn cordic_pareto(out: &mut impl Write, svg: Option<&std::path::Path>) -> Result<()> {
    use hemi_hdl_model::cordic::CordicConfig;
    let mut rows = Vec::new();
    for width in (12..=32).step_by(4) {
        for iterations in (4..=30).step_by(2) {
            let cfg = CordicConfig { iterations, width };
            if cfg.is_valid() {
                let area = 3 * iterations * 3 * width;
                rows.push((cfg, cordic_rotation_error(cfg, 20_000), area));
            }
        }
    }
    writeln!(
        out,
        "| W | n | latency (clocks) | area proxy (adder bits) | worst error | Pareto (error vs area) |"
    )?;
    writeln!(out, "|---|---|---|---|---|---|")?;
    let mut series: Vec<crate::chart::Series> = Vec::new();
    let mut front = crate::chart::Series {
        name: "Pareto front".into(),
        points: vec![],
    };
    for &(cfg, err, area) in &rows {
        let dominated = rows
            .iter()
            .any(|&(_, e, a)| a <= area && e <= err && (a < area || e < err));
        writeln!(
            out,
            "| {} | {} | {} | {} | {:.2e} | {} |",
            cfg.width,
            cfg.iterations,
            cfg.latency(),
            area,
            err,
            if dominated { "" } else { "yes" }
        )?;
        let name = format!("W = {}", cfg.width);
        match series.iter_mut().find(|s| s.name == name) {
            Some(s) => s.points.push((area as f64, err)),
            None => series.push(crate::chart::Series {
                name,
                points: vec![(area as f64, err)],
            }),
        }
        if !dominated {
            front.points.push((area as f64, err));
        }
    }
    front.points.sort_by(|a, b| a.0.total_cmp(&b.0));
    series.push(front);
    if let Some(path) = svg {
        let chart = crate::chart::log_log(
            "Accelerator CORDIC: error against area, n and W",
            "area proxy: 3 pipes × n stages × 3 W-bit adders (bits)",
            "worst |v − v_ref|",
            "reference: f64 rotation of (0.8, 0.6) by 20 000 angles over the full circle; hdl-model CORDIC pipe",
            &series,
        );
        std::fs::write(path, chart)?;
    }
    Ok(())
}
