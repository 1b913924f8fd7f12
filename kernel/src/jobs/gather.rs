//! The irradiance job of diffuse scenes, `Gather`: the nearest hits of a range of rays of one
//! ring of a hemisphere at a point.

use heapless::Vec;

use super::engine::{Engine, Work};
use super::platform::Platform;
use super::provider::{AccelJob, AccelProvider};
use super::reports::ray_hit;
use crate::accel::Accelerator;
use crate::geometry::Vec3;
use crate::hemisphere::Hemisphere;
use crate::link::message::{ErrorCode, RayHit, Response, MAX_HITS};
use crate::optics::Surface;
use crate::rotation::Rotation;

impl<P: AccelProvider, T: Platform> Engine<P, T> {
    pub(super) fn gather(
        &mut self,
        point: Vec3,
        normal: Vec3,
        ring: u16,
        first: u16,
        count: u16,
    ) -> Result<(Response, Work), ErrorCode> {
        let cfg = self.ready()?;
        let j = usize::from(ring);
        let on_ring = self
            .rings
            .get(j)
            .map(|r| r.count)
            .ok_or(ErrorCode::OutOfRange)?;
        let end = u32::from(first) + u32::from(count);
        if count == 0 || end > on_ring || !point.is_finite() || normal.try_normalize().is_none() {
            return Err(ErrorCode::OutOfRange);
        }
        if usize::from(count) > MAX_HITS {
            return Err(ErrorCode::TooLong);
        }
        let hemi = Hemisphere::new(&self.rings, &self.quarter, cfg.rule);
        if self.surfaces.iter().any(Surface::is_specular) {
            // Irradiance through mirrors needs the walker on the board: not yet.
            return Err(ErrorCode::Unsupported);
        }
        let mut hits = Vec::new();
        self.provider.run(
            &self.patches,
            GatherJob {
                hemi: &hemi,
                point,
                normal,
                ring: j,
                keep: u32::from(first)..end,
                hits: &mut hits,
            },
        );
        Ok((
            Response::Hits(hits),
            Work {
                rays: u64::from(on_ring),
                ..Work::default()
            },
        ))
    }
}

struct GatherJob<'a, 'h> {
    hemi: &'a Hemisphere<'h>,
    point: Vec3,
    normal: Vec3,
    ring: usize,
    keep: core::ops::Range<u32>,
    hits: &'a mut Vec<Option<RayHit>, MAX_HITS>,
}

impl AccelJob for GatherJob<'_, '_> {
    type Out = ();
    fn run<A: Accelerator>(self, accel: &mut A) {
        let rot = Rotation::onto(self.normal);
        let (keep, hits) = (self.keep, self.hits);
        // Filled by ray index, whatever order the engine reports the ring's rays in.
        hits.clear();
        let _ = hits.resize(keep.len(), None);
        accel.cast_rings(
            self.point,
            &rot,
            self.hemi,
            self.ring..self.ring + 1,
            true,
            |_, k, h| {
                if let Some(slot) = k
                    .checked_sub(keep.start)
                    .and_then(|i| hits.get_mut(i as usize))
                {
                    *slot = ray_hit(h);
                }
            },
        );
    }
}
