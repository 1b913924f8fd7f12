//! Pass-1 hemisphere rays per second of the soft backend, on one thread and on all, and the
//! accelerator trait's provided ray-by-ray path for comparison.

use anyhow::Result;
use hemi::backend::SoftEngine;
use hemi::pass1::form_factors;
use hemi::scene::Scene;
use hemi::settings::Pass1Settings;
use hemi_kernel::accel::{Accelerator, Ray};
use hemi_kernel::geometry::Vec3;
use hemi_kernel::hemisphere::OwnedHemisphere;
use std::io::Write;

/// One machine-readable line per thread count: the best of `repeat` runs of pass 1.
pub fn rays_per_second(
    scene: &Scene,
    label: &str,
    settings: &Pass1Settings,
    repeat: u32,
    out: &mut impl Write,
) -> Result<()> {
    let all = rayon::current_num_threads();
    let backend = hemi::backend::soft(scene, settings)?;
    for threads in [1, all] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()?;
        let mut best = f64::INFINITY;
        let mut rays = 0;
        for _ in 0..repeat.max(1) {
            let t0 = std::time::Instant::now();
            let ff = pool.install(|| form_factors(&backend, &|_| {}))?;
            best = best.min(t0.elapsed().as_secs_f64());
            rays = ff.stats.rays;
        }
        writeln!(
            out,
            "scene={label} backend=soft circles={} samples={} threads={threads} rays={rays} \
             seconds={best:.4} rays_per_second={:.0}",
            settings.circles,
            settings.samples,
            rays as f64 / best
        )?;
    }
    Ok(())
}

/// The same line for the ray-by-ray path ([`per_ray`]) on one thread.
pub fn rays_per_second_per_ray(
    scene: &Scene,
    label: &str,
    settings: &Pass1Settings,
    out: &mut impl Write,
) -> Result<()> {
    let (rays, secs) = per_ray(scene, settings)?;
    writeln!(
        out,
        "scene={label} backend=soft-per-ray circles={} samples={} threads=1 rays={rays} \
         seconds={secs:.4} rays_per_second={:.0}",
        settings.circles,
        settings.samples,
        rays as f64 / secs
    )?;
    Ok(())
}

/// An engine that exposes only `rotate` and `nearest_hit` of the soft engine, so the tracer runs
/// the trait's provided ray-by-ray `cast_rings`.
struct PerRay<A>(A);

impl<A: Accelerator> Accelerator for PerRay<A> {
    fn rotate(&mut self, rot: &hemi_kernel::rotation::Rotation, d: Vec3) -> Vec3 {
        self.0.rotate(rot, d)
    }
    fn nearest_hit(&mut self, ray: &Ray, t_max: f32) -> Option<hemi_kernel::accel::Hit> {
        self.0.nearest_hit(ray, t_max)
    }
}

/// Rays cast and seconds for the first 64 sample points through `PerRay` (the trait's provided ray-by-ray path).
pub fn per_ray(scene: &Scene, settings: &Pass1Settings) -> Result<(u64, f64)> {
    let hemi = OwnedHemisphere::new(settings.circles, settings.rule)
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    let view = hemi.view();
    let patches = scene.kernel_patches();
    let optics = hemi::optics::SceneOptics::new(scene, &view)?;
    let mut scratch =
        hemi::optics::Scratch::new(hemi::optics::pending_for(&view), &settings.specular);
    let mut row = vec![[0.0f32; 3]; optics.columns.len()];
    let points: Vec<_> = (0..patches.len())
        .flat_map(|i| {
            hemi::shots::sample_points(scene, i, settings.samples)
                .into_iter()
                .map(move |p| (i, p))
        })
        .take(64)
        .collect();
    let t0 = std::time::Instant::now();
    let mut rays = 0u64;
    for (q, (i, p)) in points.iter().enumerate() {
        let mut engine = PerRay(SoftEngine::new(&patches));
        let spin = hemi_kernel::rotation::spin_for_sample(q as u32);
        rays += hemi_kernel::tracer::shoot_hemisphere(
            &mut engine,
            &view,
            &optics.view(),
            &mut scratch.view(),
            p.position,
            p.normal,
            spin,
            Some(*i as u32),
            &mut row[..],
        )
        .rays as u64;
    }
    Ok((rays, t0.elapsed().as_secs_f64()))
}
