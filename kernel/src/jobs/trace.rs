//! The pass-2 job of diffuse scenes, `Trace`: the nearest hit of each eye ray of a pixel range.

use heapless::Vec;

use super::capacity::ENGINE_STACK_DEPTH;
use super::engine::{Engine, Work};
use super::platform::Platform;
use super::provider::{AccelJob, AccelProvider};
use super::reports::ray_hit;
use crate::accel::Accelerator;
use crate::camera::Camera;
use crate::geometry::Vec3;
use crate::hemisphere::Hemisphere;
use crate::link::message::{ErrorCode, RayHit, Response, TraceSettings, MAX_HITS};
use crate::optics::Optics;
use crate::pixels::trace_pixels;
use crate::tracer::TraceScratch;

impl<P: AccelProvider, T: Platform> Engine<P, T> {
    pub(super) fn trace(&mut self, first: u32, count: u16) -> Result<(Response, Work), ErrorCode> {
        let cfg = self.ready()?;
        let cam = cfg.camera.ok_or(ErrorCode::NoScene)?;
        let pixels = u64::from(cam.width) * u64::from(cam.height);
        let end = u64::from(first) + u64::from(count);
        let rays = usize::from(count) * usize::from(cfg.spp);
        if count == 0 || end > pixels {
            return Err(ErrorCode::OutOfRange);
        }
        if rays > MAX_HITS {
            return Err(ErrorCode::TooLong);
        }
        let mut hits = Vec::new();
        let _ = hits.resize(rays, None);
        let hemi = Hemisphere::new(&self.rings, &self.quarter, cfg.rule);
        let optics = Optics::new(&self.patches, &self.surfaces, &self.weights, hemi.circles())
            .map_err(|_| ErrorCode::BadScene)?;
        if optics.has_specular() {
            // Pass 2 through mirrors reports several weighted hits per eye ray, which `Hits`
            // cannot carry: not on boards yet.
            return Err(ErrorCode::Unsupported);
        }
        // diffuse hits only: no frustum is ever pushed
        let scratch = self.store.scratch(TraceSettings {
            threshold: 0.01,
            max_bounces: 0,
            stack: ENGINE_STACK_DEPTH as u16,
        });
        self.provider.run(
            &self.patches,
            TraceJob {
                camera: &cam,
                optics: &optics,
                hemi: &hemi,
                scratch,
                pixels: first..first + u32::from(count),
                spp: u32::from(cfg.spp),
                dirs: &mut self.dirs,
                hits: &mut hits,
            },
        );
        Ok((
            Response::Hits(hits),
            Work {
                rays: rays as u64,
                ..Work::default()
            },
        ))
    }
}

struct TraceJob<'a> {
    camera: &'a Camera,
    optics: &'a Optics<'a>,
    hemi: &'a Hemisphere<'a>,
    scratch: TraceScratch<'a>,
    pixels: core::ops::Range<u32>,
    spp: u32,
    dirs: &'a mut [Vec3],
    hits: &'a mut Vec<Option<RayHit>, MAX_HITS>,
}

impl AccelJob for TraceJob<'_> {
    type Out = ();
    fn run<A: Accelerator>(mut self, accel: &mut A) {
        let hits = self.hits;
        let (first, spp) = (self.pixels.start, self.spp.max(1));
        // A diffuse scene: one report per eye ray that hits, weight 1 (no frustums).
        trace_pixels(
            accel,
            self.camera,
            self.optics,
            self.hemi,
            &mut self.scratch,
            self.pixels,
            self.spp,
            self.dirs,
            |p, s, h, _weight| {
                let i = (p - first) as usize * spp as usize + s as usize;
                if let Some(slot) = hits.get_mut(i) {
                    *slot = ray_hit(Some(*h));
                }
            },
        );
    }
}
