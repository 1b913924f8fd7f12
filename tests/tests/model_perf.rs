//! Measurements of the accelerator model (ignored by default: run in release):
//!
//! `cargo test --release -p hemi-tests --test model_perf -- --ignored --nocapture`
//!
//! - cycles per ray and per hemisphere (R = 16 and 64) on the Cornell box, through the driver;
//! - simulation speed (model clocks per host second);
//! - the CORDIC error against iterations and word width, with latency and an area proxy, and
//!   which configurations are on the Pareto front.

use hemi_hdl_model::cordic::{CordicConfig, CordicPipe, CordicSlot, Mode};
use hemi_hdl_model::format::{Angle, Unit};
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
    println!("| R | rays/hemisphere | hemispheres | cycles/hemisphere | cycles/ray | model Mcycles/s | host µs/hemisphere |");
    println!("|---|---|---|---|---|---|---|");
    for circles in [16u32, 64] {
        let hemi = OwnedHemisphere::new(circles, DeltaRule::Band).unwrap();
        let view = hemi.view();
        let mut model = ModelAccelerator::new(&patches, ModelConfig::default()).unwrap();
        let points: Vec<_> = (0..patches.len())
            .flat_map(|i| hemi::pass1::sample_points(&scene, i, 2))
            .collect();
        let (c0, r0) = (model.cycles(), model.rays());
        let t0 = Instant::now();
        let mut hits = 0u64;
        for (q, p) in points.iter().enumerate() {
            let rot = Rotation::onto_spun(p.normal, spin_for_sample(q as u32));
            model.cast_rings(
                p.position,
                &rot,
                &view,
                0..view.rings().len(),
                false,
                |_, _, h| {
                    hits += h.is_some() as u64;
                },
            );
        }
        let secs = t0.elapsed().as_secs_f64();
        let cycles = model.cycles() - c0;
        let rays = model.rays() - r0;
        let n = points.len() as f64;
        println!(
            "| {circles} | {} | {} | {:.0} | {:.1} | {:.1} | {:.0} |",
            view.ray_count(),
            points.len(),
            cycles as f64 / n,
            cycles as f64 / rays as f64,
            cycles as f64 / secs / 1e6,
            secs / n * 1e6
        );
        // the published box is open at the front: about half the rays leave it
        assert!(hits > rays / 4, "{hits} of {rays}");
    }
}

fn worst_error(cfg: CordicConfig, n: usize) -> f64 {
    let mut rot: CordicPipe<u32> = CordicPipe::new(Mode::Rotate, cfg);
    let mut worst = 0.0f64;
    let angle = |i: usize| (i as f64 / n as f64 * 2.0 - 1.0) * std::f64::consts::PI;
    let mut got = 0;
    let mut i = 0;
    while got < n {
        let input = (i < n).then(|| CordicSlot {
            x: Unit::from_num(0.8),
            y: Unit::from_num(0.6),
            z: Angle::from_num(angle(i)),
            zero: false,
            payload: i as u32,
        });
        i += 1;
        if let Some(s) = rot.tick(input) {
            let a = angle(s.payload as usize);
            let (xr, yr) = (0.8 * a.cos() - 0.6 * a.sin(), 0.8 * a.sin() + 0.6 * a.cos());
            let e =
                ((s.x.to_num::<f64>() - xr).powi(2) + (s.y.to_num::<f64>() - yr).powi(2)).sqrt();
            worst = worst.max(e);
            got += 1;
        }
    }
    worst
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
                rows.push((cfg, worst_error(cfg, 20_000), area));
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
