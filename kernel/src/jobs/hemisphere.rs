//! The jobs that shoot one whole hemisphere through specular surfaces and send its reports a
//! window at a time: `Query` (irradiance at a point: no spin, no origin patch, the weights) and
//! `Hemisphere` (the field's element transport: a sample point as pass 1 casts it, and how each
//! report came). Both run one `tracer::shoot` call with one sink, so the firmware holds one
//! copy of the tracer for them.

use super::engine::{Engine, Work};
use super::platform::Platform;
use super::provider::{AccelJob, AccelProvider};
use super::reports::side_index;
use crate::accel::{Accelerator, Hit};
use crate::geometry::Vec3;
use crate::hemisphere::Hemisphere;
use crate::link::message::{
    ErrorCode, PathHit, PathHits, Response, WeightedHit, WeightedHits, MAX_PATHS, MAX_WEIGHTED,
};
use crate::optics::Optics;
use crate::specular::Via;
use crate::tracer::{shoot, Shot, ShotStats, TraceScratch};
use heapless::Vec;

/// Reports `skip .. skip + limit` of a hemisphere, and their total.
struct Window {
    skip: u32,
    limit: usize,
    total: u32,
    hits: Vec<PathHit, MAX_WEIGHTED>,
}

impl<P: AccelProvider, T: Platform> Engine<P, T> {
    /// The weighted reports of an irradiance hemisphere at `point` around `normal`, from `skip`
    /// on. Not inlined into the request dispatch, as none of these jobs is: their answers
    /// (about 1 KiB) then only take stack while they run, not under every other job (a 64 KiB
    /// board's stack is tight with the teapot).
    #[inline(never)]
    pub(super) fn query(
        &mut self,
        point: Vec3,
        normal: Vec3,
        skip: u16,
    ) -> Result<(Response, Work), ErrorCode> {
        let shot = Shot {
            origin: point,
            normal,
            spin: 0.0,
            origin_patch: None,
            want_uv: true,
        };
        let (window, _, work) = self.hemisphere_window(&shot, skip, MAX_WEIGHTED)?;
        let hits = window.hits.iter().map(|h| WeightedHit {
            ray: 0,
            patch: h.patch,
            u: h.u,
            v: h.v,
            weight: h.weight,
        });
        let out = WeightedHits {
            total: window.total,
            hits: hits.collect(),
        };
        Ok((Response::Weighted(out), work))
    }

    /// The reports, with their paths, of the hemisphere of a sample point (`shot`), from
    /// `skip` on.
    #[inline(never)]
    pub(super) fn hemisphere(
        &mut self,
        shot: &Shot,
        skip: u16,
    ) -> Result<(Response, Work), ErrorCode> {
        if let Some(p) = shot.origin_patch {
            if p as usize >= self.patches.len() {
                return Err(ErrorCode::OutOfRange);
            }
        }
        if !shot.spin.is_finite() {
            return Err(ErrorCode::OutOfRange);
        }
        let (window, stats, work) = self.hemisphere_window(shot, skip, MAX_PATHS)?;
        let narrow = |n: u64| u32::try_from(n).unwrap_or(u32::MAX);
        let out = PathHits {
            total: window.total,
            rays: narrow(stats.rays),
            back_hits: narrow(stats.back_hits),
            // at most MAX_PATHS were kept
            hits: window.hits.iter().copied().take(MAX_PATHS).collect(),
        };
        Ok((Response::Paths(out), work))
    }

    /// Shoots `shot`'s whole hemisphere and keeps its reports `skip .. skip + limit` (its own
    /// frame, under either job's, holds the walker and the scratch).
    #[inline(never)]
    fn hemisphere_window(
        &mut self,
        shot: &Shot,
        skip: u16,
        limit: usize,
    ) -> Result<(Window, ShotStats, Work), ErrorCode> {
        let cfg = self.ready()?;
        if !shot.origin.is_finite() || shot.normal.try_normalize().is_none() {
            return Err(ErrorCode::OutOfRange);
        }
        let hemi = Hemisphere::new(&self.rings, &self.quarter, cfg.rule);
        let optics = Optics::new(&self.patches, &self.surfaces, &self.weights, hemi.circles())
            .map_err(|_| ErrorCode::BadScene)?;
        let tracing = self.tracing();
        let scratch = self.store.scratch(tracing);
        let mut window = Window {
            skip: u32::from(skip),
            limit,
            total: 0,
            hits: Vec::new(),
        };
        let stats = self.provider.run(
            &self.patches,
            HemisphereJob {
                optics: &optics,
                hemi: &hemi,
                scratch,
                shot: *shot,
                window: &mut window,
            },
        );
        let work = Work {
            rays: stats.rays + stats.specular.rays,
            specular: stats.specular,
        };
        Ok((window, stats, work))
    }
}

struct HemisphereJob<'a> {
    optics: &'a Optics<'a>,
    hemi: &'a Hemisphere<'a>,
    scratch: TraceScratch<'a>,
    shot: Shot,
    window: &'a mut Window,
}

impl AccelJob for HemisphereJob<'_> {
    type Out = ShotStats;
    fn run<A: Accelerator>(mut self, accel: &mut A) -> ShotStats {
        let patches = self.optics.patches().len();
        let window = self.window;
        shoot(
            accel,
            self.hemi,
            self.optics,
            &mut self.scratch,
            &self.shot,
            |h: &Hit, weight, via: Via| {
                // kept from `skip` on while the window has room
                if window.total >= window.skip && window.hits.len() < window.limit {
                    let _ = window.hits.push(PathHit {
                        patch: side_index(h, patches),
                        u: h.u,
                        v: h.v,
                        weight,
                        via,
                    });
                }
                window.total = window.total.saturating_add(1);
            },
        )
    }
}
