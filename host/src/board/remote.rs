//! The passes on boards: pass 1, pass 2 and irradiance queries cut into link jobs for a
//! [`Farm`], and the answers put together exactly as the in-process passes put theirs
//! (same order of sums, same arithmetic), so a board running the same kernel on the same
//! accelerator gives the same bits as `--backend model` (or `soft`).

use anyhow::{bail, Context, Result};
use hemi_kernel::camera::Camera;
use hemi_kernel::geometry::Vec3;
use hemi_kernel::hemisphere::{ray_count, rays_on_ring, DeltaRule};
use hemi_kernel::jobs::rows_per_job;
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

/// Gives the farm the scene and settings (uploaded to each board before its next job), with
/// the optics table of a specular scene (protocol 3). Returns the scene patch of each
/// form-factor column (boards answer rows over diffuse columns, as the in-process tracer).
///
/// Irradiance through specular surfaces goes as `Query` jobs (protocol 4; [`irradiance`]).
pub fn set_up(
    farm: &Farm,
    scene: &Scene,
    settings: &Pass1Settings,
    camera: Option<Camera>,
    spp: u32,
) -> Result<Vec<usize>> {
    crate::optics::check(&settings.specular)?;
    anyhow::ensure!(
        settings.method == crate::method::Method::Hemisphere,
        "boards shoot the hemisphere only (--method hemisphere)"
    );
    let hemi = hemi_kernel::hemisphere::OwnedHemisphere::new(settings.circles, settings.rule)
        .map_err(|e| anyhow::anyhow!("--circles: {e:?}"))?;
    let optics = crate::optics::SceneOptics::new(scene, &hemi.view())?;
    let specular = optics.view().has_specular();
    // The optics table (specular surfaces, and the back sides of translucent sheets, which are
    // named past the patches and have columns of their own) goes to protocol-4 boards only: say
    // so here, before any upload, rather than as a failed upload.
    if specular || scene.has_translucency() {
        if let Some(old) = farm.hellos().into_iter().flatten().find(|h| h.protocol < 4) {
            bail!(
                "specular and translucent scenes on boards need protocol 4; a board speaks \
                 protocol {} ({}): flash a newer firmware",
                old.protocol,
                old.build
            );
        }
    }
    let cap = farm.capacities().map_or(u16::MAX, |c| c.max_patches);
    anyhow::ensure!(
        optics.columns.len() <= usize::from(cap),
        "{} form-factor columns (diffuse patches and back sides): the boards hold {cap}",
        optics.columns.len()
    );
    let patches = scene
        .kernel_patches()
        .into_iter()
        .zip(scene.patches.iter().map(|p| p.area))
        .collect();
    let surfaces = optics
        .surfaces
        .iter()
        .enumerate()
        .filter(|(i, s)| **s != hemi_kernel::optics::Surface::diffuse(*i as u32))
        .map(|(i, s)| Ok((u16::try_from(i).context("too many patches")?, *s)))
        .collect::<Result<_>>()?;
    // The board's stack: the host's --stack if it fits, else as many frames as the board holds
    // (what a full stack cuts is counted on the board, `TraceStats::overflows`).
    let cap = farm.capacities().map_or(u16::MAX, |c| c.stack_depth);
    let stack = u16::try_from(settings.specular.stack).unwrap_or(u16::MAX);
    if specular && stack > cap {
        eprintln!(
            "boards: --stack {stack} > the board's {cap} frames: the boards use {cap} (frustums \
             a full stack cuts are counted)"
        );
    }
    farm.set_setup(Setup {
        patches,
        config: config(settings, camera, spp)?,
        surfaces,
        weights: optics.weights.clone(),
        tracing: hemi_kernel::link::TraceSettings {
            threshold: settings.specular.threshold,
            max_bounces: settings.specular.max_bounces,
            stack: stack.min(cap),
        },
    })?;
    Ok(optics.columns)
}

/// The board's name for scene patch `i`: its index among the uploaded (front) patches, or, for
/// the back side of a translucent sheet, the patch count plus its front's index (protocol 4).
fn board_patch(scene: &Scene, i: usize) -> Result<u16> {
    let index = match scene.patches[i].sides {
        crate::scene::Sides::Back { front } => scene.fronts() + front,
        _ => i,
    };
    u16::try_from(index).context("too many patches")
}

/// The scene patch a board's weighted report names (the inverse of [`board_patch`]).
fn reported_patch(scene: &Scene, patch: u16) -> Result<usize> {
    let p = usize::from(patch);
    match p.checked_sub(scene.fronts()) {
        None => Ok(p),
        Some(front) if front < scene.fronts() => scene
            .twin(front)
            .context("a board reported the back of an opaque patch"),
        Some(_) => bail!("a board answered a hit on an unknown patch"),
    }
}

/// The scene patch whose radiosity a board's ray hit shows: the front it hit, or the back side
/// of a translucent sheet hit from behind; `None` for the back of an opaque patch (as the
/// tracer's diffuse sink sees it).
fn seen_patch(scene: &Scene, hit: &RayHit) -> Option<usize> {
    let i = usize::from(hit.patch);
    // (an index past the patches is left to the caller's "unknown patch" error)
    let translucent = i < scene.patches.len() && scene.twin(i).is_some();
    (hit.front || translucent).then(|| scene.side_seen(u32::from(hit.patch), hit.front))
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
    if !farm.specular() {
        return;
    }
    for (i, t) in farm.trace_stats().into_iter().enumerate() {
        if let Ok(t) = t {
            eprintln!(
                "board {i}: {what}: {} frustums, {} frustum rays; stack high-water {}/{} frames \
                 (capacity {}); cut: {} below Δ, {} too deep, {} overflows, weight {:.2e}; {} \
                 extra hemisphere casts (park of {})",
                t.frustums,
                t.frustum_rays,
                t.stack_high_water,
                t.stack_frames,
                t.stack_capacity,
                t.below_threshold,
                t.too_deep,
                t.overflows,
                t.cut_weight,
                t.recasts,
                t.pending_capacity
            );
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
    let columns = set_up(farm, scene, settings, None, 1)?;
    let n = scene.patches.len();
    let per_job = u32::from(rows_per_job(n));
    let mut jobs = Vec::new();
    for i in 0..n {
        let count = sample_count(scene, i, settings.samples) as u32;
        let mut first = 0;
        while first < count {
            let c = per_job.min(count - first);
            jobs.push(Request::Shoot {
                patch: board_patch(scene, i)?,
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
        let i = reported_patch(scene, *patch)?;
        let points = points_of[i].get_or_insert_with(|| sample_points(scene, i, settings.samples));
        for (r, row) in scene_rows(&rows, *count, &columns, n)?
            .into_iter()
            .enumerate()
        {
            elements.push(ElementRow {
                patch: i,
                point: points[usize::from(*first) + r],
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

/// A form-factor row over scene patches: (j, F per channel) where non-zero.
type SparseRow = Vec<(u32, [f32; 3])>;

/// The `count` sparse rows of a `Rows` answer over scene patches: the board's columns mapped
/// through `columns`, as `pass1::shoot_rows` maps them.
fn scene_rows(
    rows: &hemi_kernel::link::Rows,
    count: u16,
    columns: &[usize],
    n: usize,
) -> Result<Vec<SparseRow>> {
    anyhow::ensure!(
        rows.lens.len() == usize::from(count),
        "a board answered {} rows for {count} sample points",
        rows.lens.len()
    );
    let mut entries = rows.entries.iter();
    rows.lens
        .iter()
        .map(|len| {
            let row: Vec<(u32, [f32; 3])> = entries
                .by_ref()
                .take(usize::from(*len))
                .filter_map(|&(c, f)| Some((*columns.get(usize::from(c))? as u32, f)))
                .collect();
            anyhow::ensure!(
                row.len() == usize::from(*len) && row.iter().all(|&(j, _)| (j as usize) < n),
                "a board answered a malformed row"
            );
            Ok(row)
        })
        .collect()
}

/// Adaptive sampling (paper §4) on the boards: the host runs the refinement (the solves, the
/// gradient tests, the interpolated rows) and the boards shoot every row it computes, as
/// `ShootLevel` jobs (protocol 4) over runs of consecutive cells of one patch's lattice. The
/// boards place the points with the kernel's `lattice_sample`, as the host does, so the result
/// is the in-process `refine_with`'s on the same engine.
pub fn refine(
    farm: &Farm,
    scene: &Scene,
    settings: &Pass1Settings,
    adaptive: &crate::adaptive::AdaptiveSettings,
    progress: &(dyn Fn(crate::adaptive::Progress) + Sync),
) -> Result<crate::adaptive::Refined> {
    use crate::adaptive::Shot;
    anyhow::ensure!(settings.samples >= 1, "--samples must be at least 1");
    let columns = set_up(farm, scene, settings, None, 1)?;
    if let Some(old) = farm.hellos().into_iter().flatten().find(|h| h.protocol < 4) {
        bail!(
            "--adaptive on boards needs protocol 4 (ShootLevel jobs); a board speaks protocol {} \
             ({}): flash a newer firmware",
            old.protocol,
            old.build
        );
    }
    let n = scene.patches.len();
    let per_job = u32::from(rows_per_job(n));
    let rays = ray_count(settings.circles);
    let source = |shots: &[Shot], done: &(dyn Fn(u64) + Sync)| {
        // one job per run of consecutive cells of one lattice, at most `per_job` long
        let mut jobs = Vec::new();
        let mut spans: Vec<(usize, u16)> = Vec::new();
        let mut s = 0;
        while s < shots.len() {
            let first = shots[s];
            let mut c = 1;
            while s + c < shots.len()
                && (c as u32) < per_job
                && shots[s + c].patch == first.patch
                && shots[s + c].k == first.k
                && shots[s + c].q == first.q + c as u32
            {
                c += 1;
            }
            jobs.push(Request::ShootLevel {
                patch: board_patch(scene, first.patch)?,
                k: u16::try_from(first.k).context("lattice too fine for a board")?,
                first: u16::try_from(first.q).context("lattice too fine for a board")?,
                count: c as u16,
            });
            spans.push((s, c as u16));
            s += c;
        }
        let answers = farm.run(&jobs, &|j| {
            if let Some((_, c)) = spans.get(j) {
                done(u64::from(*c));
            }
        })?;
        let mut elements = Vec::with_capacity(shots.len());
        let mut stats = ShotStats::default();
        for (&(s, count), answer) in spans.iter().zip(answers) {
            let Response::Rows(rows) = answer else {
                bail!("a board answered a ShootLevel job with something else");
            };
            for (r, row) in scene_rows(&rows, count, &columns, n)?
                .into_iter()
                .enumerate()
            {
                let shot = &shots[s + r];
                elements.push(ElementRow {
                    patch: shot.patch,
                    point: shot.point,
                    row,
                });
                stats.rays += rays;
            }
        }
        Ok((elements, stats))
    };
    crate::adaptive::refine_from(scene, settings, adaptive, &source, progress)
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
    if farm.specular() {
        let out = render_rows(farm, scene, grids, camera, spp, progress)?;
        if std::env::var_os("HEMI_BOARD_STATS").is_some() {
            report(farm, "after pass 2");
        }
        return Ok(out);
    }
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
            if let Some((hit, seen)) = hit.and_then(|h| Some((h, seen_patch(scene, &h)?))) {
                let grid = grids
                    .get(seen)
                    .context("a board answered a hit on an unknown patch")?;
                // weight 1 per eye ray in a diffuse scene
                crate::render::shade(&mut pixels[p], [1.0; 3], grid.at(hit.u, hit.v), spp);
            }
        }
    }
    Ok(rendered(w, h, pixels))
}

/// A board's image: the boards' specular counters are read with `TraceStats`, not per render.
fn rendered(width: u32, height: u32, pixels: Vec<[f32; 3]>) -> crate::render::Rendered {
    crate::render::Rendered {
        image: Image {
            width,
            height,
            pixels,
        },
        specular: Default::default(),
    }
}

/// Pass 2 through specular surfaces: one `TraceRow` job per image row (the board traces the
/// row as one `trace_pixels` call, as `render::render_with` does, so frustums are spun alike),
/// then more for rows with more weighted hits than one answer holds; the hits are shaded here in
/// the order the tracer made them, with render_with's arithmetic.
fn render_rows(
    farm: &Farm,
    scene: &Scene,
    grids: &[Grid],
    camera: &Camera,
    spp: u32,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<crate::render::Rendered> {
    use hemi_kernel::link::{WeightedHit, MAX_WEIGHTED};
    let (w, h) = (camera.width, camera.height);
    anyhow::ensure!(
        u64::from(w) * u64::from(spp) <= 1 << 16,
        "a board traces rows of at most 65536 eye rays through mirrors (width × spp)"
    );
    let row_id = |y: u32| u16::try_from(y).context("image too tall for row jobs");
    let mut jobs = (0..h)
        .map(|y| {
            Ok(Request::TraceRow {
                row: row_id(y)?,
                skip: 0,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    let answers = farm.run(&jobs, &|_| progress(1))?;
    let mut per_row: Vec<Vec<WeightedHit>> = vec![Vec::new(); h as usize];
    let mut totals = vec![0u32; h as usize];
    fn take(
        jobs: &[Request],
        answers: Vec<Response>,
        per_row: &mut [Vec<WeightedHit>],
        totals: &mut [u32],
    ) -> Result<()> {
        for (job, answer) in jobs.iter().zip(answers) {
            let (Request::TraceRow { row, skip }, Response::Weighted(got)) = (job, answer) else {
                bail!("a board answered a TraceRow job with something else");
            };
            let y = usize::from(*row);
            anyhow::ensure!(
                per_row[y].len() == usize::from(*skip),
                "row {y}: answers out of order"
            );
            totals[y] = got.total;
            per_row[y].extend(got.hits.iter().copied());
        }
        Ok(())
    }
    take(&jobs, answers, &mut per_row, &mut totals)?;
    // the rows with more reports than one answer: the rest, a window per job
    jobs.clear();
    for (y, &t) in totals.iter().enumerate() {
        let mut skip = MAX_WEIGHTED as u32;
        while skip < t {
            jobs.push(Request::TraceRow {
                row: row_id(y as u32)?,
                skip: u16::try_from(skip).context("too many hits in one row")?,
            });
            skip += MAX_WEIGHTED as u32;
        }
    }
    if !jobs.is_empty() {
        let answers = farm.run(&jobs, &|_| {})?;
        take(&jobs, answers, &mut per_row, &mut totals)?;
    }
    let mut pixels = vec![[0.0f32; 3]; (u64::from(w) * u64::from(h)) as usize];
    for (y, hits) in per_row.iter().enumerate() {
        anyhow::ensure!(
            hits.len() == totals[y] as usize,
            "row {y}: {} of {} reports",
            hits.len(),
            totals[y]
        );
        for hit in hits {
            let x = u32::from(hit.ray) / spp;
            anyhow::ensure!(x < w, "a board answered a ray outside the row");
            let grid = grids
                .get(reported_patch(scene, hit.patch)?)
                .context("a board answered a hit on an unknown patch")?;
            let px = &mut pixels[y * w as usize + x as usize];
            crate::render::shade(px, hit.weight, grid.at(hit.u, hit.v), spp);
        }
    }
    Ok(rendered(w, h, pixels))
}

/// Irradiance through specular surfaces (protocol 4): the board shoots the whole hemisphere as
/// `irradiance::irradiance` does (one `tracer::shoot` call, so frustums are spun and parked
/// alike) and answers the weighted reports a window at a time; they are summed here in the
/// order the tracer made them, with the in-process arithmetic.
fn irradiance_through_mirrors(
    farm: &Farm,
    scene: &Scene,
    grids: &[Grid],
    point: Vec3,
    normal: Vec3,
) -> Result<[f64; 3]> {
    use hemi_kernel::link::MAX_WEIGHTED;
    if let Some(old) = farm.hellos().into_iter().flatten().find(|h| h.protocol < 4) {
        bail!(
            "irradiance through specular surfaces on boards needs protocol 4 (Query jobs); a \
             board speaks protocol {} ({}): flash a newer firmware",
            old.protocol,
            old.build
        );
    }
    let query = |skip: u32| -> Result<Request> {
        Ok(Request::Query {
            point,
            normal,
            skip: u16::try_from(skip).context("too many reports for one query")?,
        })
    };
    let mut hits = Vec::new();
    let first = farm.run(&[query(0)?], &|_| {})?;
    let Some(Response::Weighted(got)) = first.into_iter().next() else {
        bail!("a board answered a Query job with something else");
    };
    let total = got.total;
    hits.extend(got.hits.iter().copied());
    // the rest, a window per job (each shoots the hemisphere again)
    let rest = (1..total.div_ceil(MAX_WEIGHTED as u32))
        .map(|w| query(w * MAX_WEIGHTED as u32))
        .collect::<Result<Vec<_>>>()?;
    for answer in farm.run(&rest, &|_| {})? {
        let Response::Weighted(got) = answer else {
            bail!("a board answered a Query job with something else");
        };
        anyhow::ensure!(got.total == total, "a query's reports changed between jobs");
        hits.extend(got.hits.iter().copied());
    }
    anyhow::ensure!(
        hits.len() == total as usize,
        "{} of {total} reports",
        hits.len()
    );
    let mut e = [0.0f64; 3];
    for hit in &hits {
        let grid = grids
            .get(reported_patch(scene, hit.patch)?)
            .context("a board answered a hit on an unknown patch")?;
        let b = grid.at(hit.u, hit.v);
        for c in 0..3 {
            e[c] += hit.weight[c] as f64 * b[c];
        }
    }
    Ok(e)
}

/// Irradiance at `point` facing `normal` (as `irradiance::irradiance`), from `Gather` jobs, or
/// `Query` jobs when the scene has specular surfaces.
pub fn irradiance(
    farm: &Farm,
    scene: &Scene,
    circles: u32,
    rule: DeltaRule,
    grids: &[Grid],
    point: Vec3,
    normal: Vec3,
) -> Result<[f64; 3]> {
    if farm.specular() {
        return irradiance_through_mirrors(farm, scene, grids, point, normal);
    }
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
        for (hit, seen) in hits
            .iter()
            .flatten()
            .filter_map(|h| Some((h, seen_patch(scene, h)?)))
        {
            let grid = grids
                .get(seen)
                .context("a board answered a hit on an unknown patch")?;
            let b = grid.at(hit.u, hit.v);
            for c in 0..3 {
                e[c] += w * b[c];
            }
        }
    }
    Ok(e)
}
