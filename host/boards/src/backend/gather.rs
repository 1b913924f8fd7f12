//! Irradiance queries on boards: `Gather` jobs over the rings of the hemisphere in a diffuse
//! scene; through specular surfaces, the whole hemisphere in one `tracer::shoot` call on the
//! board, as the in-process engines shoot it (so frustums are spun and parked alike), its
//! reports back a window at a time: `Hemisphere` jobs, which say how each report came (protocol
//! 5, so exact direct light can leave out the lamps' images in mirrors), or on older boards
//! `Query` jobs (protocol 4), which do not.

use super::field::Placed;
use super::Boards;
use crate::index::{seen_patch, BoardPatch};
use crate::protocol::{require, supports};
use anyhow::{bail, Context, Result};
use hemi::backend::{Path, Query, Seen};
use hemi_kernel::hemisphere::rays_on_ring;
use hemi_kernel::link::Feature;
use hemi_kernel::link::{Request, Response, WeightedHit, MAX_HITS, MAX_WEIGHTED};

impl Boards<'_> {
    /// What the hemisphere at `q` reached, in tracer order.
    pub(super) fn gather_one(&self, q: &Query) -> Result<Vec<Seen>> {
        if self.farm.specular() {
            if supports(self.farm, Feature::Paths) {
                let placed = Placed {
                    origin: q.point,
                    normal: q.normal,
                    spin: 0.0,
                    origin_patch: None,
                };
                let mut reports = self.hemispheres(&[placed], &|_| {})?;
                return Ok(reports.pop().map(|(seen, _)| seen).unwrap_or_default());
            }
            return self.query(q);
        }
        let circles = self.settings.circles;
        let mut jobs = Vec::new();
        for j in 0..circles {
            let on_ring = rays_on_ring(circles, j);
            let mut k = 0;
            while k < on_ring {
                let count = (MAX_HITS as u32).min(on_ring - k);
                jobs.push(Request::Gather {
                    point: q.point,
                    normal: q.normal,
                    ring: j as u16,
                    first: k as u16,
                    count: count as u16,
                });
                k += count;
            }
        }
        let view = self.hemi.view();
        let mut seen = Vec::new();
        for (job, answer) in jobs.iter().zip(self.farm.run(&jobs, &|_| {})?) {
            let (Request::Gather { ring, count, .. }, Response::Hits(hits)) = (job, answer) else {
                bail!("a board answered a Gather job with something else");
            };
            anyhow::ensure!(hits.len() == usize::from(*count), "short Gather answer");
            let weight = [view.rings()[usize::from(*ring)].delta_ff; 3];
            for hit in hits.iter().flatten() {
                if let Some(side) = seen_patch(self.scene, hit) {
                    seen.push(Seen {
                        side,
                        u: hit.u,
                        v: hit.v,
                        weight,
                        path: Path::Direct,
                    });
                }
            }
        }
        Ok(seen)
    }

    /// Through specular surfaces: `Query` jobs, a window of weighted reports each (each shoots
    /// the hemisphere again).
    fn query(&self, q: &Query) -> Result<Vec<Seen>> {
        require(
            self.farm,
            Feature::Query,
            "irradiance through specular surfaces on boards",
        )?;
        let job = |skip: u32| -> Result<Request> {
            Ok(Request::Query {
                point: q.point,
                normal: q.normal,
                skip: u16::try_from(skip).context("too many reports for one query")?,
            })
        };
        let first = self.farm.run(&[job(0)?], &|_| {})?;
        let Some(Response::Weighted(got)) = first.into_iter().next() else {
            bail!("a board answered a Query job with something else");
        };
        let total = got.total;
        let mut hits: Vec<WeightedHit> = got.hits.iter().copied().collect();
        let rest = (1..total.div_ceil(MAX_WEIGHTED as u32))
            .map(|w| job(w * MAX_WEIGHTED as u32))
            .collect::<Result<Vec<_>>>()?;
        for answer in self.farm.run(&rest, &|_| {})? {
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
        hits.iter()
            .map(|hit| {
                Ok(Seen {
                    side: BoardPatch(hit.patch).scene_patch(self.scene)?,
                    u: hit.u,
                    v: hit.v,
                    weight: hit.weight,
                    // a weighted report does not say whether it came through a mirror
                    path: Path::Other,
                })
            })
            .collect()
    }
}
