//! Hemispheres on boards: runs of consecutive cells of one patch's lattice as `Shoot` jobs
//! (uniform K×K points, placed by the board as the host places them) or `ShootLevel` jobs
//! (a k×k level of adaptive sampling, protocol 4).

use super::Boards;
use crate::index::BoardPatch;
use crate::protocol::require;
use anyhow::{bail, Context, Result};
use hemi::backend::Progress;
use hemi::shots::{Cell, ElementRow, Shot};
use hemi_kernel::hemisphere::ray_count;
use hemi_kernel::link::Feature;
use hemi_kernel::link::{Request, Response, Rows};
use hemi_kernel::tracer::ShotStats;

/// A form-factor row over scene patches: (j, F per channel) where non-zero.
type SparseRow = Vec<(u32, [f32; 3])>;

impl Boards<'_> {
    /// The rows of `shots`, as [`hemi::backend::Backend::shoot`].
    pub(super) fn shoot_rows(
        &self,
        shots: &[Shot],
        done: &Progress<'_>,
    ) -> Result<(Vec<ElementRow>, ShotStats)> {
        if shots.iter().any(|s| matches!(s.cell, Cell::Level { .. })) {
            require(self.farm, Feature::ShootLevel, "--adaptive on boards")?;
        }
        let spans = self.spans(shots);
        let jobs = spans
            .iter()
            .map(|&(s, count)| self.job(&shots[s], count))
            .collect::<Result<Vec<_>>>()?;
        let answers = self.farm.run(&jobs, &|j| {
            if let Some((_, c)) = spans.get(j) {
                done(u64::from(*c));
            }
        })?;
        let rays = ray_count(self.settings.circles);
        let mut elements = Vec::with_capacity(shots.len());
        let mut stats = ShotStats::default();
        for (&(s, count), answer) in spans.iter().zip(answers) {
            let Response::Rows(rows) = answer else {
                bail!("a board answered a Shoot job with something else");
            };
            for (shot, row) in shots[s..].iter().zip(self.scene_rows(&rows, count)?) {
                elements.push(ElementRow {
                    patch: shot.patch,
                    point: shot.point,
                    row,
                });
                stats.rays += u64::from(rays);
            }
        }
        Ok((elements, stats))
    }

    /// Runs (first shot, count) of consecutive cells of one patch's lattice, at most as many as
    /// one answer holds.
    fn spans(&self, shots: &[Shot]) -> Vec<(usize, u16)> {
        let per_job = usize::from(hemi_kernel::jobs::rows_per_job(self.scene.patches.len()));
        let follows = |a: &Shot, b: &Shot, c: u32| {
            a.patch == b.patch
                && match (a.cell, b.cell) {
                    (Cell::Uniform { q: qa }, Cell::Uniform { q: qb }) => qb == qa + c,
                    (Cell::Level { k: ka, q: qa }, Cell::Level { k: kb, q: qb }) => {
                        ka == kb && qb == qa + c
                    }
                    _ => false,
                }
        };
        let mut spans = Vec::new();
        let mut s = 0;
        while s < shots.len() {
            let mut c = 1;
            while s + c < shots.len() && c < per_job && follows(&shots[s], &shots[s + c], c as u32)
            {
                c += 1;
            }
            spans.push((s, c as u16));
            s += c;
        }
        spans
    }

    /// The job for `count` cells from `first`.
    fn job(&self, first: &Shot, count: u16) -> Result<Request> {
        let patch = BoardPatch::of(self.scene, first.patch)?.0;
        let cell = |q: u32| u16::try_from(q).context("lattice too fine for a board");
        Ok(match first.cell {
            Cell::Uniform { q } => Request::Shoot {
                patch,
                first: cell(q)?,
                count,
            },
            Cell::Level { k, q } => Request::ShootLevel {
                patch,
                k: cell(k)?,
                first: cell(q)?,
                count,
            },
        })
    }

    /// The `count` sparse rows of a `Rows` answer over scene patches: the board's columns
    /// mapped through the column table, as the in-process shot maps them.
    fn scene_rows(&self, rows: &Rows, count: u16) -> Result<Vec<SparseRow>> {
        let n = self.scene.patches.len();
        anyhow::ensure!(
            rows.lens.len() == usize::from(count),
            "a board answered {} rows for {count} sample points",
            rows.lens.len()
        );
        let mut entries = rows.entries.iter();
        rows.lens
            .iter()
            .map(|len| {
                let row: SparseRow = entries
                    .by_ref()
                    .take(usize::from(*len))
                    .filter_map(|&(c, f)| Some((*self.columns.get(usize::from(c))? as u32, f)))
                    .collect();
                anyhow::ensure!(
                    row.len() == usize::from(*len) && row.iter().all(|&(j, _)| (j as usize) < n),
                    "a board answered a malformed row"
                );
                Ok(row)
            })
            .collect()
    }
}
