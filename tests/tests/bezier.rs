//! Bezier patches (paper §6.1, §7) on the Newell teapot: nearest hits against an independent
//! Newton reference, patch areas against Gauss–Legendre quadrature, and the hard places (poles,
//! silhouettes, rays parallel to a slab).

// Vector code in f64 arrays: p[k], c[k] read as the formulas do.

use hemi::analytic::{bezier_eval as eval, bezier_newton as newton};
use hemi::backend::SoftEngine;
use hemi::scene::load;
use hemi_bench::rng::XorShift;
use hemi_kernel::accel::{Accelerator, Ray};
use hemi_kernel::geometry::{Bezier, Subdivision, Vec3};
use hemi_kernel::patch::{Patch, Shape};
use hemi_kernel::sampling::bezier_area;
use std::path::Path;

fn teapot() -> Vec<Bezier> {
    let scene = load(Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../scenes/teapot.toml"
    )))
    .unwrap();
    scene.bezier_patches()
}

#[test]
fn nearest_hits_match_a_newton_reference() {
    // Rays aimed at a random point of a random patch from 0.5 to 3 units away, within 40° of its
    // normal; the reference is Newton's solution from a dense seed.
    let patches = teapot();
    let sub = Subdivision::default();
    let mut rng = XorShift::new(0x9e37_79b9_7f4a_7c15);
    let (mut compared, mut worst_t, mut worst_uv) = (0, 0.0f64, 0.0f64);
    let mut dropped = [0usize; 4];
    for _ in 0..3000 {
        let b = &patches[(rng.f64() * patches.len() as f64) as usize % patches.len()];
        let (u, v) = (0.05 + 0.9 * rng.f64(), 0.05 + 0.9 * rng.f64());
        let Some(n) = b.normal(u as f32, v as f32) else {
            dropped[0] += 1;
            continue;
        };
        let target = b.point(u as f32, v as f32);
        let tilt = Vec3::new(
            rng.f64() as f32 - 0.5,
            rng.f64() as f32 - 0.5,
            rng.f64() as f32 - 0.5,
        ) * 0.8;
        let Some(dir) = (-n + tilt).try_normalize() else {
            continue;
        };
        if dir.dot(n) > -0.6 {
            dropped[1] += 1;
            continue;
        }
        let o = target - dir * (0.5 + 2.5 * rng.f64() as f32);
        let Some((t_ref, u_ref, v_ref)) = newton(
            b,
            o.to_array().map(|x| x as f64),
            dir.to_array().map(|x| x as f64),
        ) else {
            dropped[2] += 1;
            continue;
        };
        let hit = b
            .intersect(o, dir, 0.0, f32::INFINITY, &sub)
            .expect("a ray Newton says hits the patch must hit");
        // Newton may converge to a farther root where the patch folds over; compare only where
        // the hemi hit is not nearer than the reference (it is the nearest-hit mode)
        if (hit.t as f64) < t_ref - 1e-3 {
            dropped[3] += 1;
            continue;
        }
        worst_t = worst_t.max((hit.t as f64 - t_ref).abs());
        worst_uv = worst_uv.max(
            (hit.u as f64 - u_ref)
                .abs()
                .max((hit.v as f64 - v_ref).abs()),
        );
        compared += 1;
    }
    println!("dropped (singular normal, too oblique, no Newton root, nearer fold): {dropped:?}");
    println!(
        "{compared} rays: worst |t − t_ref| = {worst_t:.2e}, worst (u,v) error = {worst_uv:.2e}"
    );
    assert!(compared > 1500, "{compared}");
    // the teapot is 6 units across; default subdivision (depth ≤ 10, flatness 1e-4)
    assert!(worst_t < 2e-3, "t error {worst_t}");
    assert!(worst_uv < 5e-3, "uv error {worst_uv}");
}

#[test]
fn patch_areas_match_high_order_quadrature() {
    // 24×24-point Gauss–Legendre in f64 (nodes by Newton on P_24) against the kernel's
    // 16 cells × 4×4 points in f32.
    let n = 24;
    let mut nodes = vec![];
    for i in 0..n {
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 0.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
            let dx = p1 / dp;
            x -= dx;
            if dx.abs() < 1e-15 {
                break;
            }
        }
        nodes.push(((x + 1.0) / 2.0, 1.0 / ((1.0 - x * x) * dp * dp)));
    }
    let mut worst = 0.0f64;
    for b in teapot() {
        let mut a = 0.0;
        for &(x, wx) in &nodes {
            for &(y, wy) in &nodes {
                let (_, pu, pv) = eval(&b, x, y);
                let c = [
                    pu[1] * pv[2] - pu[2] * pv[1],
                    pu[2] * pv[0] - pu[0] * pv[2],
                    pu[0] * pv[1] - pu[1] * pv[0],
                ];
                a += wx * wy * (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
            }
        }
        let got = bezier_area(&b) as f64;
        worst = worst.max((got - a).abs() / a);
    }
    println!("teapot patch areas: worst relative error {worst:.2e}");
    assert!(worst < 1e-4, "{worst}");
}

#[test]
fn poles_silhouettes_and_axis_parallel_rays_hit_where_they_should() {
    let patches: Vec<Patch> = teapot().into_iter().map(Patch::bezier).collect();
    let mut engine = SoftEngine::new(&patches);
    // Straight down onto the lid knob's pole (where four patches meet in one point), and just
    // beside it: the direction has zero x and y components (rays parallel to two slabs).
    let top = patches
        .iter()
        .map(|p| p.bounds().max.z)
        .fold(f32::MIN, f32::max);
    for off in [0.0, 1e-5, 1e-3, 0.05] {
        let h = engine
            .nearest_hit(
                &Ray {
                    origin: Vec3::new(off, off * 0.5, 10.0),
                    dir: Vec3::new(0.0, 0.0, -1.0),
                },
                f32::INFINITY,
            )
            .unwrap_or_else(|| panic!("missed the knob at offset {off}"));
        assert!(
            h.t.is_finite() && (10.0 - h.t - top).abs() < 0.02,
            "offset {off}: t {}",
            h.t
        );
        assert!(h.front);
    }
    // Straight up into the bottom's pole.
    let h = engine
        .nearest_hit(
            &Ray {
                origin: Vec3::new(0.0, 0.0, -5.0),
                dir: Vec3::new(0.0, 0.0, 1.0),
            },
            f32::INFINITY,
        )
        .expect("missed the bottom's pole");
    assert!((h.t - 5.0).abs() < 0.02 && h.front, "{h:?}");
    // Silhouette of the upper body, seen along y: rays at x just inside the largest |x| of the
    // surface at that height hit, just outside miss. (The cubic "circles" of the teapot bulge
    // between seams, so the silhouette along y is the |x| at the seam, not the largest radius.)
    let mut r = 0.0f32;
    for b in &patches[4..8] {
        let Shape::Bezier(b) = b.shape else {
            unreachable!()
        };
        for i in 0..=1000 {
            r = r.max(b.point(i as f32 / 1000.0, 0.5).x.abs());
        }
    }
    let z = {
        let Shape::Bezier(b) = patches[4].shape else {
            unreachable!()
        };
        b.point(0.0, 0.5).z
    };
    for x in [0.0, 0.5 * r, 0.9 * r, 0.99 * r, 0.999 * r] {
        let h = engine.nearest_hit(
            &Ray {
                origin: Vec3::new(x, -10.0, z),
                dir: Vec3::new(0.0, 1.0, 0.0),
            },
            f32::INFINITY,
        );
        assert!(h.is_some(), "x = {x} (radius {r}) must hit");
    }
    let h = engine.nearest_hit(
        &Ray {
            origin: Vec3::new(1.01 * r, -10.0, z),
            dir: Vec3::new(0.0, 1.0, 0.0),
        },
        f32::INFINITY,
    );
    assert!(h.is_none(), "outside the silhouette: {h:?}");
    // No NaN anywhere in a sweep of grazing rays.
    for i in 0..200 {
        let a = i as f32 * 0.0314;
        let o = Vec3::new(
            5.0 * a.cos(),
            5.0 * a.sin(),
            0.05 + 3.0 * (i as f32 / 200.0),
        );
        if let Some(h) = engine.nearest_hit(
            &Ray {
                origin: o,
                dir: (Vec3::new(0.0, 0.0, o.z) - o).try_normalize().unwrap(),
            },
            f32::INFINITY,
        ) {
            assert!(h.t.is_finite() && h.u.is_finite() && h.v.is_finite());
        }
    }
}
