//! Eye rays on boards: `Trace` jobs over pixel ranges in a diffuse scene, one `TraceRow` job
//! per image row through specular surfaces (the board traces the row as one `trace_pixels`
//! call, as the in-process engines do, so frustums are spun alike), then more for rows with
//! more weighted hits than one answer holds.

use super::Boards;
use crate::index::{seen_patch, BoardPatch};
use anyhow::{bail, Context, Result};
use hemi::backend::{Path, Progress, RowSink, Seen};
use hemi_kernel::camera::Camera;
use hemi_kernel::link::{Request, Response, WeightedHit, MAX_HITS, MAX_WEIGHTED};
use hemi_kernel::specular::SpecularStats;
use std::ops::Range;

impl Boards<'_> {
    /// What the eye rays of `rows` saw, as [`hemi::backend::Backend::trace`].
    pub(super) fn trace_rows(
        &self,
        camera: &Camera,
        spp: u32,
        rows: Range<u32>,
        sink: &RowSink<'_>,
        done: &Progress<'_>,
    ) -> Result<SpecularStats> {
        let spp = spp.max(1);
        anyhow::ensure!(
            spp as usize <= MAX_HITS,
            "--spp {spp}: a board traces at most {MAX_HITS} rays per pixel"
        );
        self.set_up(Some(*camera), spp)?;
        let first = rows.start;
        let reports = if self.farm.specular() {
            self.weighted_rows(camera, spp, rows, done)?
        } else {
            self.pixel_rows(camera, spp, rows, done)?
        };
        for (y, row) in (first..).zip(&reports) {
            sink(y, row);
        }
        // the boards' frustum counters are read with `TraceStats`, not per request
        Ok(SpecularStats::default())
    }

    /// A diffuse scene: `Trace` jobs over the pixels of `rows`, weight 1 per eye ray.
    fn pixel_rows(
        &self,
        camera: &Camera,
        spp: u32,
        rows: Range<u32>,
        done: &Progress<'_>,
    ) -> Result<Vec<Vec<(u32, Seen)>>> {
        let w = camera.width;
        let (start, end) = (
            u64::from(rows.start) * u64::from(w),
            u64::from(rows.end) * u64::from(w),
        );
        anyhow::ensure!(end <= u64::from(u32::MAX), "image too large");
        let per_job = (MAX_HITS as u32 / spp).max(1);
        let mut jobs = Vec::new();
        let mut first = start as u32;
        while u64::from(first) < end {
            let count = per_job.min((end - u64::from(first)) as u32);
            jobs.push(Request::Trace {
                first,
                count: count as u16,
            });
            first += count;
        }
        // progress in image rows, as the in-process engines report it
        let pixels_done = std::sync::atomic::AtomicU64::new(start);
        let answers = self.farm.run(&jobs, &|k| {
            if let Some(Request::Trace { count, .. }) = jobs.get(k) {
                let c = u64::from(*count);
                let before = pixels_done.fetch_add(c, std::sync::atomic::Ordering::Relaxed);
                let w = u64::from(w.max(1));
                done((before + c) / w - before / w);
            }
        })?;
        let mut out = vec![Vec::new(); rows.len()];
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
                let p = *first + k as u32 / spp;
                let Some((hit, side)) = hit.and_then(|h| Some((h, seen_patch(self.scene, &h)?)))
                else {
                    continue;
                };
                let seen = Seen {
                    side,
                    u: hit.u,
                    v: hit.v,
                    weight: [1.0; 3],
                    path: Path::Other,
                };
                out[(p / w - rows.start) as usize].push((p, seen));
            }
        }
        Ok(out)
    }

    /// Through specular surfaces: `TraceRow` jobs, a window of weighted reports at a time.
    fn weighted_rows(
        &self,
        camera: &Camera,
        spp: u32,
        rows: Range<u32>,
        done: &Progress<'_>,
    ) -> Result<Vec<Vec<(u32, Seen)>>> {
        let w = camera.width;
        anyhow::ensure!(
            u64::from(w) * u64::from(spp) <= 1 << 16,
            "a board traces rows of at most 65536 eye rays through mirrors (width × spp)"
        );
        let row_id = |y: u32| u16::try_from(y).context("image too tall for row jobs");
        let jobs = rows
            .clone()
            .map(|y| {
                Ok(Request::TraceRow {
                    row: row_id(y)?,
                    skip: 0,
                })
            })
            .collect::<Result<Vec<_>>>()?;
        let mut per_row: Vec<Vec<WeightedHit>> = vec![Vec::new(); rows.len()];
        let mut totals = vec![0u32; rows.len()];
        let answers = self.farm.run(&jobs, &|_| done(1))?;
        take(&jobs, answers, rows.start, &mut per_row, &mut totals)?;
        // the rows with more reports than one answer: the rest, a window per job
        let mut jobs = Vec::new();
        for (r, &t) in totals.iter().enumerate() {
            let mut skip = MAX_WEIGHTED as u32;
            while skip < t {
                let skip16 = u16::try_from(skip).context("too many hits in one row")?;
                jobs.push(Request::TraceRow {
                    row: row_id(rows.start + r as u32)?,
                    skip: skip16,
                });
                skip += MAX_WEIGHTED as u32;
            }
        }
        if !jobs.is_empty() {
            let answers = self.farm.run(&jobs, &|_| {})?;
            take(&jobs, answers, rows.start, &mut per_row, &mut totals)?;
        }
        per_row
            .iter()
            .enumerate()
            .map(|(r, hits)| {
                let y = rows.start + r as u32;
                anyhow::ensure!(
                    hits.len() == totals[r] as usize,
                    "row {y}: {} of {} reports",
                    hits.len(),
                    totals[r]
                );
                hits.iter()
                    .map(|hit| self.row_report(hit, y, w, spp))
                    .collect()
            })
            .collect()
    }

    /// One weighted report of image row `y` as (pixel, what it saw).
    fn row_report(&self, hit: &WeightedHit, y: u32, w: u32, spp: u32) -> Result<(u32, Seen)> {
        let x = u32::from(hit.ray) / spp;
        anyhow::ensure!(x < w, "a board answered a ray outside the row");
        let seen = Seen {
            side: BoardPatch(hit.patch).scene_patch(self.scene)?,
            u: hit.u,
            v: hit.v,
            weight: hit.weight,
            path: Path::Other,
        };
        Ok((y * w + x, seen))
    }
}

/// Appends the reports of `TraceRow` answers to their rows (indexed from image row `first`),
/// checking that each window follows the last.
fn take(
    jobs: &[Request],
    answers: Vec<Response>,
    first: u32,
    per_row: &mut [Vec<WeightedHit>],
    totals: &mut [u32],
) -> Result<()> {
    for (job, answer) in jobs.iter().zip(answers) {
        let (Request::TraceRow { row, skip }, Response::Weighted(got)) = (job, answer) else {
            bail!("a board answered a TraceRow job with something else");
        };
        let r = usize::from(*row) - first as usize;
        anyhow::ensure!(
            per_row[r].len() == usize::from(*skip),
            "row {row}: answers out of order"
        );
        totals[r] = got.total;
        per_row[r].extend(got.hits.iter().copied());
    }
    Ok(())
}
