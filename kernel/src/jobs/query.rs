//! The irradiance job through specular surfaces, `Query`: every diffuse side a hemisphere at a
//! point reaches, directly or through mirrors, with its weight.

use super::engine::{Engine, Work};
use super::platform::Platform;
use super::provider::{AccelJob, AccelProvider};
use super::reports::Reports;
use crate::accel::Accelerator;
use crate::geometry::Vec3;
use crate::hemisphere::Hemisphere;
use crate::link::message::{ErrorCode, Response, WeightedHits};
use crate::optics::Optics;
use crate::tracer::{shoot, Shot, ShotStats, TraceScratch};

impl<P: AccelProvider, T: Platform> Engine<P, T> {
    /// The weighted reports of an irradiance hemisphere at `point` around `normal`, from `skip`
    /// on. Not inlined into the request dispatch: its walker and scratch then only take stack
    /// while a query runs, not under every other job (a board's stack is tight with the teapot).
    #[inline(never)]
    pub(super) fn query(
        &mut self,
        point: Vec3,
        normal: Vec3,
        skip: u16,
    ) -> Result<(Response, Work), ErrorCode> {
        let cfg = self.ready()?;
        if !point.is_finite() || normal.try_normalize().is_none() {
            return Err(ErrorCode::OutOfRange);
        }
        let hemi = Hemisphere::new(&self.rings, &self.quarter, cfg.rule);
        let optics = Optics::new(&self.patches, &self.surfaces, &self.weights, hemi.circles())
            .map_err(|_| ErrorCode::BadScene)?;
        let tracing = self.tracing();
        let scratch = self.store.scratch(tracing);
        let mut out = WeightedHits::default();
        let shot = self.provider.run(
            &self.patches,
            QueryJob {
                optics: &optics,
                hemi: &hemi,
                scratch,
                shot: Shot {
                    origin: point,
                    normal,
                    spin: 0.0,
                    origin_patch: None,
                    want_uv: true,
                },
                skip: u32::from(skip),
                out: &mut out,
            },
        );
        Ok((
            Response::Weighted(out),
            Work {
                rays: shot.rays + shot.specular.rays,
                specular: shot.specular,
            },
        ))
    }
}

struct QueryJob<'a> {
    optics: &'a Optics<'a>,
    hemi: &'a Hemisphere<'a>,
    scratch: TraceScratch<'a>,
    shot: Shot,
    skip: u32,
    out: &'a mut WeightedHits,
}

impl AccelJob for QueryJob<'_> {
    type Out = ShotStats;
    fn run<A: Accelerator>(mut self, accel: &mut A) -> ShotStats {
        let mut reports = Reports::new(self.out, self.skip, self.optics.patches().len());
        shoot(
            accel,
            self.hemi,
            self.optics,
            &mut self.scratch,
            &self.shot,
            |h, weight, _| reports.report(0, h, weight),
        )
    }
}
