//! Measurements of the accelerator model (ignored by default: run in release):
//!
//! `cargo test --release -p hemi-tests --test model_perf -- --ignored --nocapture`
//!
//! - cycles per ray and per hemisphere (R = 16 and 64) on the Cornell box, through the driver;
//! - simulation speed (model clocks per host second);
//! - the CORDIC error against iterations and word width, with latency and an area proxy, and
//!   which configurations are on the Pareto front.

use hemi_hdl_model::cordic::CordicConfig;
use hemi_hdl_model::{ModelAccelerator, ModelConfig};
use hemi_kernel::accel::Accelerator;
use hemi_kernel::hemisphere::{DeltaRule, OwnedHemisphere};
use hemi_kernel::rotation::{spin_for_sample, Rotation};
use std::time::Instant;

#[test]
#[ignore = "measurement: run in release with --ignored --nocapture"]
fn cycles_per_ray_and_simulation_speed_on_the_cornell_box() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let scene = hemi::scene::load(&root.join("scenes/cornell.toml")).unwrap();
    let patches = scene.kernel_patches();
    println!("\nCornell box: {} patches", patches.len());
    println!("| R | (u,v) | rays/hemisphere | hemispheres | cycles/hemisphere | cycles/ray | model Mcycles/s (3 runs, best first) | host µs/hemisphere (best) |");
    println!("|---|---|---|---|---|---|---|---|");
    for circles in [16u32, 64] {
        let hemi = OwnedHemisphere::new(circles, DeltaRule::Band).unwrap();
        let view = hemi.view();
        let points: Vec<_> = (0..patches.len())
            .flat_map(|i| hemi::shots::sample_points(&scene, i, 2))
            .collect();
        // pass 1 casts without (u,v) (MODE.NO_UV); eye rays and frustums on curved patches ask
        // for them
        for want_uv in [false, true] {
            let mut speeds = Vec::new();
            let mut best_secs = f64::INFINITY;
            let (mut cycles, mut rays, mut hits) = (0u64, 0u64, 0u64);
            for _ in 0..3 {
                let mut model = ModelAccelerator::new(&patches, ModelConfig::default()).unwrap();
                let (c0, r0) = (model.cycles(), model.rays());
                hits = 0;
                let t0 = Instant::now();
                for (q, p) in points.iter().enumerate() {
                    let rot = Rotation::onto_spun(p.normal, spin_for_sample(q as u32));
                    model.cast_rings(
                        p.position,
                        &rot,
                        &view,
                        0..view.rings().len(),
                        want_uv,
                        |_, _, h| {
                            hits += h.is_some() as u64;
                        },
                    );
                }
                let secs = t0.elapsed().as_secs_f64();
                cycles = model.cycles() - c0;
                rays = model.rays() - r0;
                speeds.push(cycles as f64 / secs / 1e6);
                best_secs = best_secs.min(secs);
            }
            speeds.sort_by(|a, b| b.total_cmp(a));
            let n = points.len() as f64;
            println!(
                "| {circles} | {} | {} | {} | {:.0} | {:.1} | {} | {:.0} |",
                if want_uv { "yes" } else { "no" },
                view.ray_count(),
                points.len(),
                cycles as f64 / n,
                cycles as f64 / rays as f64,
                speeds
                    .iter()
                    .map(|s| format!("{s:.1}"))
                    .collect::<Vec<_>>()
                    .join(", "),
                best_secs / n * 1e6
            );
            // the published box is open at the front: about half the rays leave it
            assert!(hits > rays / 4, "{hits} of {rays}");
        }
    }
}

#[test]
#[ignore = "measurement: run in release with --ignored --nocapture"]
fn cycles_per_ray_on_the_teapot_and_per_bezier_patch_test() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let scene = hemi::scene::load(&root.join("scenes/teapot.toml")).unwrap();
    let patches = scene.kernel_patches();
    println!(
        "\nteapot scene: {} patches (2 quads, {} Bezier), 16 sample points per Bezier patch, K = 2 on the quads",
        patches.len(),
        patches.len() - 2
    );
    println!("| R | hemispheres | rays/hemisphere | cycles/hemisphere | cycles/ray | Bezier tests/ray | clocks/Bezier test | steps/test | leaves/test | model Mcycles/s |");
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for circles in [8u32, 16] {
        let hemi = OwnedHemisphere::new(circles, DeltaRule::Band).unwrap();
        let view = hemi.view();
        let mut model = ModelAccelerator::new(&patches, ModelConfig::default()).unwrap();
        let points: Vec<_> = (0..patches.len())
            .flat_map(|i| {
                hemi::shots::sample_points(&scene, i, 2)
                    .into_iter()
                    .map(move |p| (i, p))
            })
            .collect();
        let (c0, r0, b0) = (model.cycles(), model.rays(), model.bezier_stats());
        let t0 = Instant::now();
        for (q, (i, p)) in points.iter().enumerate() {
            let rot = Rotation::onto_spun(p.normal, spin_for_sample(q as u32));
            model.set_origin_patch(Some(*i as u32));
            model.cast_rings(
                p.position,
                &rot,
                &view,
                0..view.rings().len(),
                false,
                |_, _, _| {},
            );
        }
        let secs = t0.elapsed().as_secs_f64();
        let cycles = model.cycles() - c0;
        let rays = model.rays() - r0;
        let b = model.bezier_stats();
        let jobs = (b.jobs - b0.jobs) as f64;
        let n = points.len() as f64;
        println!(
            "| {circles} | {} | {} | {:.0} | {:.1} | {:.2} | {:.1} | {:.1} | {:.2} | {:.1} |",
            points.len(),
            view.ray_count(),
            cycles as f64 / n,
            cycles as f64 / rays as f64,
            jobs / rays as f64,
            (b.clocks - b0.clocks) as f64 / jobs,
            (b.steps - b0.steps) as f64 / jobs,
            (b.leaves - b0.leaves) as f64 / jobs,
            cycles as f64 / secs / 1e6,
        );
    }
}

/// Clocks of one Bezier patch test (root box hit) against the subdivision depth and the
/// control-point width, over rays aimed at the teapot's patches one patch at a time: the
/// figure to compare with Pulleyblank & Kapenga's 15 µs (12-bit) to 140 µs (24-bit).
#[test]
#[ignore = "measurement: run in release with --ignored --nocapture"]
fn clocks_per_bezier_patch_test_against_depth_and_width() {
    use hemi_kernel::accel::Ray;
    use hemi_kernel::geometry::Vec3;
    use hemi_kernel::patch::Patch;
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let scene = hemi::scene::load(&root.join("scenes/teapot.toml")).unwrap();
    let beziers = scene.bezier_patches();
    println!(
        "\nOne Bezier patch test (rays aimed at random points of each teapot patch, 64 per patch)"
    );
    println!("| depth | Wc | flatness | clocks/test (mean) | clocks/test (max) | steps | leaves | µs at 100 MHz (mean) |");
    println!("|---|---|---|---|---|---|---|---|");
    for (depth, width, flatness) in [
        (6, 12, 0.0f32),
        (8, 16, 0.0),
        (10, 20, 0.0),
        (10, 24, 0.0),
        (10, 26, 0.0),
        (12, 26, 0.0),
        (10, 26, 1e-4),
    ] {
        let cfg = ModelConfig {
            subdivision_depth: depth,
            coord_width: width,
            flatness,
            ..ModelConfig::default()
        };
        let (mut jobs, mut clocks, mut steps, mut leaves, mut worst) =
            (0u64, 0u64, 0u64, 0u64, 0u64);
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut rnd = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f32 / (1u64 << 53) as f32
        };
        for b in &beziers {
            let mut model = ModelAccelerator::new(&[Patch::bezier(*b)], cfg).unwrap();
            for _ in 0..64 {
                let (u, v) = (0.05 + 0.9 * rnd(), 0.05 + 0.9 * rnd());
                let Some(n) = b.normal(u, v) else { continue };
                let tilt = Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5) * 0.8;
                let Some(dir) = (-n + tilt).try_normalize() else {
                    continue;
                };
                let o = b.point(u, v) - dir * (0.5 + 2.5 * rnd());
                let before = model.bezier_stats();
                model.nearest_hit(&Ray { origin: o, dir }, f32::INFINITY);
                let after = model.bezier_stats();
                if after.jobs > before.jobs {
                    jobs += 1;
                    let c = after.clocks - before.clocks;
                    clocks += c;
                    worst = worst.max(c);
                    steps += after.steps - before.steps;
                    leaves += after.leaves - before.leaves;
                }
            }
        }
        let mean = clocks as f64 / jobs as f64;
        println!(
            "| {depth} | {width} | {flatness} | {mean:.1} | {worst} | {:.1} | {:.2} | {:.2} |",
            steps as f64 / jobs as f64,
            leaves as f64 / jobs as f64,
            mean / 100.0
        );
    }
}

#[test]
#[ignore = "measurement: run in release with --ignored --nocapture"]
fn cordic_pareto_front() {
    let mut rows = Vec::new();
    for width in (12..=32).step_by(2) {
        for iterations in (4..=30).step_by(2) {
            let cfg = CordicConfig { iterations, width };
            if cfg.is_valid() {
                // area proxy: the rotator's 3 pipes × n stages × 3 W-bit adders (x, y, z)
                let area = 3 * iterations * 3 * width;
                rows.push((cfg, hemi_bench::cordic_rotation_error(cfg, 20_000), area));
            }
        }
    }
    println!("\nCORDIC rotation error (20 000 angles over the full circle) against n and W");
    println!("| W | n | latency (clocks) | area proxy (adder bits) | worst error | Pareto |");
    println!("|---|---|---|---|---|---|");
    for &(cfg, err, area) in &rows {
        let dominated = rows
            .iter()
            .any(|&(_, e, a)| a <= area && e <= err && (a < area || e < err));
        if !dominated {
            println!(
                "| {} | {} | {} | {} | {:.2e} | yes |",
                cfg.width,
                cfg.iterations,
                cfg.latency(),
                area,
                err
            );
        }
    }
    println!(
        "(dominated configurations omitted; {} measured)",
        rows.len()
    );
}
