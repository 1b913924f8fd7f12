//! The passes on boards: pass 1, pass 2 and irradiance queries cut into link jobs for a
//! [`Farm`], and the answers put together exactly as the in-process passes put theirs
//! (same order of sums, same arithmetic), so a board running the same kernel on the same
//! accelerator gives the same bits as `--backend model` (or `soft`).

use anyhow::{bail, Context, Result};
use hemi_kernel::camera::Camera;
use hemi_kernel::geometry::Vec3;
use hemi_kernel::hemisphere::{ray_count, rays_on_ring, DeltaRule};
use hemi_kernel::link::engine::rows_per_job;
use hemi_kernel::link::{AccelKind, JobConfig, RayHit, Request, Response, MAX_HITS};
use hemi_kernel::tracer::ShotStats;

use super::jobs::{Farm, Setup};
use crate::pass1::{sample_count, sample_points, ElementRow, FormFactors, Pass1Settings};
use crate::radiosity::Grid;
use crate::render::Image;
use crate::scene::Scene;

/// The engine boards should use: `HEMI_BOARD_ACCEL=soft` asks for their soft fallback (for
/// measurements), otherwise each board's own.
pub fn requested_accel() -> AccelKind {
    match std::env::var("HEMI_BOARD_ACCEL").as_deref() {
        Ok("soft") => AccelKind::Soft,
        _ => AccelKind::None,
    }
}

fn config(settings: &Pass1Settings, camera: Option<Camera>, spp: u32) -> Result<JobConfig> {
    Ok(JobConfig {
        circles: u16::try_from(settings.circles).context("--circles")?,
        rule: settings.rule,
        samples: u16::try_from(settings.samples).context("--samples")?,
        spp: u16::try_from(spp).context("--spp")?,
        camera,
        accel: requested_accel(),
    })
}

/// Gives the farm the scene and settings (uploaded to each board before its next job).
/// Boards run diffuse scenes: the optics table (specular surfaces, lobes) is not uploaded yet.
pub fn set_up(
    farm: &Farm,
    scene: &Scene,
    settings: &Pass1Settings,
    camera: Option<Camera>,
    spp: u32,
) -> Result<()> {
    crate::translucent::refuse(scene, "a board")?;
    let hemi = hemi_kernel::hemisphere::OwnedHemisphere::new(settings.circles, settings.rule)
        .map_err(|e| anyhow::anyhow!("--circles: {e:?}"))?;
    let optics = crate::optics::SceneOptics::new(scene, &hemi.view())?;
    if optics.view().has_specular() {
        bail!(
            "the scene has specular surfaces: boards run diffuse scenes only so far \
             (use --backend soft or model)"
        );
    }
    let patches = scene
        .kernel_patches()
        .into_iter()
        .zip(scene.patches.iter().map(|p| p.area))
        .collect();
    farm.set_setup(Setup {
        patches,
        config: config(settings, camera, spp)?,
    })
}

/// Prints each board's engine counters to stderr (jobs, rays, CPU ticks per ray, stack, link
/// bytes): what `docs/PERFORMANCE.md`'s firmware section is measured with.
pub fn report(farm: &Farm, what: &str) {
    for (i, s) in farm.engine_stats().into_iter().enumerate() {
        match s {
            Ok(s) => eprintln!(
                "board {i}: {what}: {:?} engine, {} jobs ({} repeated, {} refused), {} rays, \
                 {} SysTick ticks = {:.1} ticks/ray, {} accelerator cycles, stack {} of {} bytes, \
                 link {} bytes in / {} bytes out, {} damaged frames",
                s.accel.unwrap_or(AccelKind::None),
                s.jobs,
                s.repeats,
                s.refused,
                s.rays,
                s.cpu_ticks,
                s.cpu_ticks as f64 / s.rays.max(1) as f64,
                s.accel_cycles,
                s.stack_high_water,
                s.stack_size,
                s.link.bytes_rx,
                s.link.bytes_tx,
                s.link.bad_crc + s.link.bad_framing + s.link.too_long
            ),
            Err(e) => eprintln!("board {i}: no counters: {e:#}"),
        }
    }
}

/// Pass 1 on the boards: one `Shoot` job per few sample points of a patch.
pub fn form_factors(
    farm: &Farm,
    scene: &Scene,
    settings: &Pass1Settings,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<FormFactors> {
    anyhow::ensure!(settings.samples >= 1, "--samples must be at least 1");
    set_up(farm, scene, settings, None, 1)?;
    let n = scene.patches.len();
    let per_job = u32::from(rows_per_job(n));
    let mut jobs = Vec::new();
    for i in 0..n {
        let count = sample_count(scene, i, settings.samples) as u32;
        let mut first = 0;
        while first < count {
            let c = per_job.min(count - first);
            jobs.push(Request::Shoot {
                patch: i as u16,
                first: u16::try_from(first).context("too many samples per patch")?,
                count: c as u16,
            });
            first += c;
        }
    }
    // progress in sample points, as the in-process pass reports it
    let answers = farm.run(&jobs, &|k| {
        if let Some(Request::Shoot { count, .. }) = jobs.get(k) {
            progress(u64::from(*count));
        }
    })?;
    let mut elements = Vec::new();
    let mut stats = ShotStats::default();
    let rays = ray_count(settings.circles);
    let mut points_of: Vec<Option<Vec<_>>> = vec![None; n];
    for (job, answer) in jobs.iter().zip(answers) {
        let (
            Request::Shoot {
                patch,
                first,
                count,
            },
            Response::Rows(rows),
        ) = (job, answer)
        else {
            bail!("a board answered a Shoot job with something else");
        };
        let i = usize::from(*patch);
        let points = points_of[i].get_or_insert_with(|| sample_points(scene, i, settings.samples));
        anyhow::ensure!(
            rows.lens.len() == usize::from(*count),
            "a board answered {} rows for {count} sample points",
            rows.lens.len()
        );
        let mut entries = rows.entries.iter();
        for (r, len) in rows.lens.iter().enumerate() {
            let q = usize::from(*first) + r;
            let row: Vec<(u32, [f32; 3])> = entries
                .by_ref()
                .take(usize::from(*len))
                .map(|&(j, f)| (u32::from(j), f))
                .collect();
            anyhow::ensure!(
                row.len() == usize::from(*len) && row.iter().all(|&(j, _)| (j as usize) < n),
                "a board answered a malformed row"
            );
            elements.push(ElementRow {
                patch: i,
                point: points[q],
                row,
            });
            stats.rays += rays;
        }
    }
    // As pass1::form_factors_with: per channel, one matrix if the channels agree.
    let mut rgb = [
        vec![vec![0.0f64; n]; n],
        vec![vec![0.0f64; n]; n],
        vec![vec![0.0f64; n]; n],
    ];
    for e in &elements {
        for &(j, f) in &e.row {
            for (c, m) in rgb.iter_mut().enumerate() {
                m[e.patch][j as usize] += e.point.weight as f64 * f[c] as f64;
            }
        }
    }
    let (matrix, tinted) = if rgb[0] == rgb[1] && rgb[1] == rgb[2] {
        let [r, _, _] = rgb;
        (r, None)
    } else {
        let mean = (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| (rgb[0][i][j] + rgb[1][i][j] + rgb[2][i][j]) / 3.0)
                    .collect()
            })
            .collect();
        (mean, Some(rgb))
    };
    Ok(FormFactors {
        elements,
        matrix,
        tinted,
        samples: settings.samples,
        stats,
    })
}

/// Pass 2 on the boards: `Trace` jobs over pixel ranges; the hits are shaded here as
/// `render::render_with` shades them.
pub fn render(
    farm: &Farm,
    scene: &Scene,
    settings: &Pass1Settings,
    grids: &[Grid],
    camera: &Camera,
    spp: u32,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<crate::render::Rendered> {
    let spp = spp.max(1);
    anyhow::ensure!(
        spp as usize <= MAX_HITS,
        "--spp {spp}: a board traces at most {MAX_HITS} rays per pixel"
    );
    set_up(farm, scene, settings, Some(*camera), spp)?;
    let (w, h) = (camera.width, camera.height);
    let total = u64::from(w) * u64::from(h);
    anyhow::ensure!(total <= u64::from(u32::MAX), "image too large");
    let per_job = (MAX_HITS as u32 / spp).max(1);
    let mut jobs = Vec::new();
    let mut first = 0u32;
    while u64::from(first) < total {
        let count = per_job.min((total - u64::from(first)) as u32);
        jobs.push(Request::Trace {
            first,
            count: count as u16,
        });
        first += count;
    }
    // progress in image rows, as the in-process pass reports it
    let pixels_done = std::sync::atomic::AtomicU64::new(0);
    let answers = farm.run(&jobs, &|k| {
        if let Some(Request::Trace { count, .. }) = jobs.get(k) {
            let c = u64::from(*count);
            let before = pixels_done.fetch_add(c, std::sync::atomic::Ordering::Relaxed);
            let w = u64::from(w.max(1));
            progress((before + c) / w - before / w);
        }
    })?;
    let mut pixels = vec![[0.0f32; 3]; total as usize];
    for (job, answer) in jobs.iter().zip(answers) {
        let (Request::Trace { first, count }, Response::Hits(hits)) = (job, answer) else {
            bail!("a board answered a Trace job with something else");
        };
        anyhow::ensure!(
            hits.len() == usize::from(*count) * spp as usize,
            "a board answered {} hits for {count} pixels",
            hits.len()
        );
        for (k, hit) in hits.iter().enumerate() {
            let p = *first as usize + k / spp as usize;
            if let Some(hit) = hit.filter(|h| h.front) {
                let grid = grids
                    .get(usize::from(hit.patch))
                    .context("a board answered a hit on an unknown patch")?;
                let b = grid.at(hit.u, hit.v);
                let px = &mut pixels[p];
                // weight 1 per eye ray in a diffuse scene, in render_with's arithmetic
                let weight = [1.0f32; 3];
                for c in 0..3 {
                    px[c] += (weight[c] as f64 * b[c] / std::f64::consts::PI / spp as f64) as f32;
                }
            }
        }
    }
    Ok(crate::render::Rendered {
        image: Image {
            width: w,
            height: h,
            pixels,
        },
        specular: Default::default(),
    })
}

/// Irradiance at `point` facing `normal` (as `irradiance::irradiance`), from `Gather` jobs.
pub fn irradiance(
    farm: &Farm,
    circles: u32,
    rule: DeltaRule,
    grids: &[Grid],
    point: Vec3,
    normal: Vec3,
) -> Result<[f64; 3]> {
    let hemi = hemi_kernel::hemisphere::OwnedHemisphere::new(circles, rule)
        .map_err(|e| anyhow::anyhow!("--circles: {e:?}"))?;
    let view = hemi.view();
    let mut jobs = Vec::new();
    for j in 0..circles {
        let on_ring = rays_on_ring(circles, j);
        let mut k = 0;
        while k < on_ring {
            let count = (MAX_HITS as u32).min(on_ring - k);
            jobs.push(Request::Gather {
                point,
                normal,
                ring: j as u16,
                first: k as u16,
                count: count as u16,
            });
            k += count;
        }
    }
    let answers = farm.run(&jobs, &|_| {})?;
    let mut e = [0.0f64; 3];
    for (job, answer) in jobs.iter().zip(answers) {
        let (Request::Gather { ring, count, .. }, Response::Hits(hits)) = (job, answer) else {
            bail!("a board answered a Gather job with something else");
        };
        anyhow::ensure!(hits.len() == usize::from(*count), "short Gather answer");
        let w = view.rings()[usize::from(*ring)].delta_ff as f64;
        for hit in hits.iter().flatten().filter(|h: &&RayHit| h.front) {
            let grid = grids
                .get(usize::from(hit.patch))
                .context("a board answered a hit on an unknown patch")?;
            let b = grid.at(hit.u, hit.v);
            for c in 0..3 {
                e[c] += w * b[c];
            }
        }
    }
    Ok(e)
}
