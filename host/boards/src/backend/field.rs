//! The field on boards (protocol 5): every sample point's hemisphere as `Hemisphere` jobs, its
//! reports back with their paths a window at a time and folded by the library's own
//! [`hemi::backend::gathered`] and [`hemi::backend::transport_row`], as the in-process engines
//! fold theirs; and single rays as `Cast` jobs (the shadow rays of exact direct light and of
//! relighting, `hemi trace`).
//!
//! A window is a whole hemisphere shot again on the board (its walker cannot pause), so a
//! hemisphere of n reports costs n / [`MAX_PATHS`] shots: the price of a board's 64 KiB,
//! which cannot hold one hemisphere's reports.

use super::Boards;
use crate::index::BoardPatch;
use crate::protocol::require;
use anyhow::{bail, Context, Result};
use hemi::backend::{Path, Progress, Seen};
use hemi::shots::Shot;
use hemi_kernel::accel::{Hit, Ray};
use hemi_kernel::geometry::Vec3;
use hemi_kernel::link::{Feature, PathHit, PathHits, Request, Response, MAX_CAST, MAX_PATHS};
use hemi_kernel::rotation::spin_for_sample;
use std::sync::atomic::{AtomicUsize, Ordering};

/// What one shot's hemisphere reached, in tracer order, and the fraction of its rays that met
/// the back of an opaque patch first.
pub(super) type Reports = (Vec<Seen>, f32);

/// Where a hemisphere stands, as a `Hemisphere` job places it.
#[derive(Clone, Copy, Debug)]
pub(super) struct Placed {
    pub(super) origin: Vec3,
    pub(super) normal: Vec3,
    pub(super) spin: f32,
    pub(super) origin_patch: Option<u16>,
}

impl Boards<'_> {
    /// The reports of every shot's hemisphere, cast as pass 1 casts it (its spin, its origin
    /// patch); `done` gets shots as their last window arrives.
    pub(super) fn field_reports(
        &self,
        shots: &[Shot],
        done: &Progress<'_>,
    ) -> Result<Vec<Reports>> {
        let placed = shots
            .iter()
            .map(|s| {
                let patch = self.scene.kernel_id(s.patch);
                Ok(Placed {
                    origin: s.point.position,
                    normal: s.point.normal,
                    spin: spin_for_sample(s.cell.q()),
                    origin_patch: Some(u16::try_from(patch).context("too many patches")?),
                })
            })
            .collect::<Result<Vec<_>>>()?;
        self.hemispheres(&placed, done)
    }

    /// The reports of every hemisphere of `placed`: the first window of each, then the rest of
    /// every one's windows, each round spread over the farm; `done` gets hemispheres as their
    /// last window arrives.
    pub(super) fn hemispheres(
        &self,
        placed: &[Placed],
        done: &Progress<'_>,
    ) -> Result<Vec<Reports>> {
        require(self.farm, Feature::Paths, "the element field on boards")?;
        self.current()?;
        let first = placed
            .iter()
            .map(|p| hemisphere_job(p, 0))
            .collect::<Result<Vec<_>>>()?;
        let mut windows = Vec::with_capacity(placed.len());
        // the remaining windows' jobs, and the hemisphere each is of
        let (mut rest, mut owner) = (Vec::new(), Vec::new());
        for (i, answer) in self.farm.run(&first, &|_| {})?.into_iter().enumerate() {
            let w = paths(answer)?;
            for skip in (MAX_PATHS..w.total as usize).step_by(MAX_PATHS) {
                rest.push(hemisphere_job(&placed[i], skip)?);
                owner.push(i);
            }
            windows.push(Window {
                total: w.total,
                rays: w.rays,
                back_hits: w.back_hits,
                hits: w.hits.to_vec(),
            });
        }
        // windows still to come per hemisphere: one read whole counts now, the others as their
        // last window arrives
        let left: Vec<AtomicUsize> = (0..placed.len()).map(|_| AtomicUsize::new(0)).collect();
        owner
            .iter()
            .for_each(|&i| _ = left[i].fetch_add(1, Ordering::Relaxed));
        done(
            left.iter()
                .filter(|l| l.load(Ordering::Relaxed) == 0)
                .count() as u64,
        );
        let last = |j: usize| {
            if let Some(&i) = owner.get(j) {
                if left[i].fetch_sub(1, Ordering::Relaxed) == 1 {
                    done(1);
                }
            }
        };
        for (&i, answer) in owner.iter().zip(self.farm.run(&rest, &last)?) {
            let w = paths(answer)?;
            let whole = &mut windows[i];
            anyhow::ensure!(
                (w.total, w.rays, w.back_hits) == (whole.total, whole.rays, whole.back_hits),
                "a hemisphere's reports changed between jobs"
            );
            whole.hits.extend(w.hits);
        }
        windows.into_iter().map(|w| self.reports(w)).collect()
    }

    /// A hemisphere's windows, joined, as the library's reports.
    fn reports(&self, w: Window) -> Result<Reports> {
        anyhow::ensure!(
            w.hits.len() == w.total as usize,
            "{} of a hemisphere's {} reports",
            w.hits.len(),
            w.total
        );
        let seen = w
            .hits
            .iter()
            .map(|h| self.seen(h))
            .collect::<Result<Vec<_>>>()?;
        Ok((seen, w.back_hits as f32 / w.rays.max(1) as f32))
    }

    /// A board's report as the in-process tracer's sink makes it.
    fn seen(&self, h: &PathHit) -> Result<Seen> {
        Ok(Seen {
            side: BoardPatch(h.patch).scene_patch(self.scene)?,
            u: h.u,
            v: h.v,
            weight: h.weight,
            path: Path::of(h.via),
        })
    }

    /// The nearest hit of each ray, `MAX_CAST` rays a job.
    pub(super) fn cast(&self, rays: &[Ray]) -> Result<Vec<Option<Hit>>> {
        require(self.farm, Feature::Cast, "single rays on boards")?;
        self.current()?;
        let jobs: Vec<Request> = rays
            .chunks(MAX_CAST)
            .map(|chunk| Request::Cast {
                rays: chunk.iter().map(|r| (r.origin, r.dir)).collect(),
            })
            .collect();
        let fronts = self.scene.fronts();
        let mut hits = Vec::with_capacity(rays.len());
        for (job, answer) in jobs.iter().zip(self.farm.run(&jobs, &|_| {})?) {
            let (Request::Cast { rays }, Response::Nearest(got)) = (job, answer) else {
                bail!("a board answered a Cast job with something else");
            };
            anyhow::ensure!(got.len() == rays.len(), "short Cast answer");
            for h in got {
                anyhow::ensure!(
                    h.is_none_or(|h| usize::from(h.patch) < fronts),
                    "a board answered a hit on an unknown patch"
                );
                hits.push(h.map(|h| Hit {
                    patch: u32::from(h.patch),
                    t: h.t,
                    u: h.u,
                    v: h.v,
                    front: h.front,
                }));
            }
        }
        Ok(hits)
    }
}

/// The `Hemisphere` job of the hemisphere at `p` from report `skip` on.
fn hemisphere_job(p: &Placed, skip: usize) -> Result<Request> {
    let skip = u16::try_from(skip).map_err(|_| {
        anyhow::anyhow!(
            "a hemisphere with more than {} reports cannot be read from a board: lower --circles",
            u16::MAX
        )
    })?;
    Ok(Request::Hemisphere {
        origin: p.origin,
        normal: p.normal,
        spin: p.spin,
        origin_patch: p.origin_patch,
        skip,
    })
}

/// A hemisphere's reports, joined from its windows.
struct Window {
    total: u32,
    rays: u32,
    back_hits: u32,
    hits: Vec<PathHit>,
}

/// The window a `Hemisphere` job answered.
fn paths(answer: Response) -> Result<PathHits> {
    match answer {
        Response::Paths(w) => Ok(w),
        _ => bail!("a board answered a Hemisphere job with something else"),
    }
}
