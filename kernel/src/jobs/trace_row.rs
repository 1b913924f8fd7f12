//! The pass-2 job through specular surfaces, `TraceRow`: every diffuse side an eye ray or frustum
//! ray of an image row reaches, with its weight.

use super::engine::{Engine, Work};
use super::platform::Platform;
use super::provider::{AccelJob, AccelProvider};
use super::reports::Reports;
use crate::accel::Accelerator;
use crate::camera::Camera;
use crate::geometry::Vec3;
use crate::hemisphere::Hemisphere;
use crate::link::message::{ErrorCode, Response, WeightedHits};
use crate::optics::Optics;
use crate::pixels::trace_pixels;
use crate::specular::SpecularStats;
use crate::tracer::TraceScratch;

impl<P: AccelProvider, T: Platform> Engine<P, T> {
    pub(super) fn trace_row(&mut self, row: u16, skip: u16) -> Result<(Response, Work), ErrorCode> {
        let cfg = self.ready()?;
        let cam = cfg.camera.ok_or(ErrorCode::NoScene)?;
        if u32::from(row) >= cam.height {
            return Err(ErrorCode::OutOfRange);
        }
        let rays = u64::from(cam.width) * u64::from(cfg.spp);
        if rays > u64::from(u16::MAX) + 1 {
            return Err(ErrorCode::TooLong);
        }
        let hemi = Hemisphere::new(&self.rings, &self.quarter, cfg.rule);
        let optics = Optics::new(&self.patches, &self.surfaces, &self.weights, hemi.circles())
            .map_err(|_| ErrorCode::BadScene)?;
        let tracing = self.tracing();
        let scratch = self.store.scratch(tracing);
        let first = u32::from(row) * cam.width;
        let mut out = WeightedHits::default();
        let specular = self.provider.run(
            &self.patches,
            TraceRowJob {
                camera: &cam,
                optics: &optics,
                hemi: &hemi,
                scratch,
                pixels: first..first + cam.width,
                spp: u32::from(cfg.spp),
                dirs: &mut self.dirs,
                skip: u32::from(skip),
                out: &mut out,
            },
        );
        Ok((
            Response::Weighted(out),
            Work {
                rays: rays + specular.rays,
                specular,
            },
        ))
    }
}

struct TraceRowJob<'a> {
    camera: &'a Camera,
    optics: &'a Optics<'a>,
    hemi: &'a Hemisphere<'a>,
    scratch: TraceScratch<'a>,
    pixels: core::ops::Range<u32>,
    spp: u32,
    dirs: &'a mut [Vec3],
    skip: u32,
    out: &'a mut WeightedHits,
}

impl AccelJob for TraceRowJob<'_> {
    type Out = SpecularStats;
    fn run<A: Accelerator>(mut self, accel: &mut A) -> SpecularStats {
        let (first, spp) = (self.pixels.start, self.spp.max(1));
        let mut reports = Reports::new(self.out, self.skip, self.optics.patches().len());
        trace_pixels(
            accel,
            self.camera,
            self.optics,
            self.hemi,
            &mut self.scratch,
            self.pixels,
            self.spp,
            self.dirs,
            |p, s, h, weight| reports.report(((p - first) * spp + s) as u16, h, weight),
        )
    }
}
