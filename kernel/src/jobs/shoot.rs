//! Pass-1 jobs, `Shoot` and `ShootLevel`: form-factor rows of sample points of a patch, of the
//! configured uniform grid ([`crate::sampling::uniform_sample`]) or of any k×k lattice for
//! adaptive sampling. Both are one job here: the job runner is generic over its closure, and a
//! second copy of it does not fit a board's flash.

use super::capacity::{rows_per_job, ENGINE_MAX_PATCHES};
use super::engine::{Engine, Work};
use super::platform::Platform;
use super::provider::{AccelJob, AccelProvider};
use crate::accel::Accelerator;
use crate::geometry::Vec3;
use crate::hemisphere::Hemisphere;
use crate::link::message::{ErrorCode, Response, Rows};
use crate::optics::Optics;
use crate::rotation::spin_for_sample;
use crate::sampling::{lattice_sample, uniform_side};
use crate::tracer::{shoot_hemisphere, ShotStats, TraceScratch};

impl<P: AccelProvider, T: Platform> Engine<P, T> {
    /// Rows of sample points `first .. first + count` of `patch`: of the configured K×K grid
    /// (Bezier: the 4×4 of §7), or of the `level`×`level` lattice when given.
    pub(super) fn shoot(
        &mut self,
        patch: u16,
        level: Option<u16>,
        first: u16,
        count: u16,
    ) -> Result<(Response, Work), ErrorCode> {
        let cfg = self.ready()?;
        // Indices past the scene's patches name the back sides of translucent sheets
        // (`Feature::BackSides`): patch n + i is the back of patch i, shot from i's points facing
        // the other way.
        let (i, back) = match usize::from(patch).checked_sub(self.patches.len()) {
            Some(front) => (front, true),
            None => (usize::from(patch), false),
        };
        let (p, area) = match (self.patches.get(i), self.areas.get(i)) {
            (Some(p), Some(a)) => (*p, *a),
            _ => return Err(ErrorCode::OutOfRange),
        };
        if back && self.surfaces.get(i).and_then(|s| s.back_column).is_none() {
            return Err(ErrorCode::OutOfRange);
        }
        let cols = self.columns();
        // the lattice: the level's k, or the configured K×K grid (4×4 on a Bezier patch)
        let side = match level {
            Some(k) => u32::from(k),
            // Diffuse or not is the host's call (`uniform_count` gives a mirror no points): a
            // board places the lattice of whatever patch it is asked for, as it always has.
            None => uniform_side(&p.shape, true, u32::from(cfg.samples)),
        };
        let end = u32::from(first) + u32::from(count);
        if count == 0 || end > side * side {
            return Err(ErrorCode::OutOfRange);
        }
        if count > rows_per_job(cols) {
            return Err(ErrorCode::TooLong);
        }
        let mut rows = Rows::default();
        let mut work = Work::default();
        for q in u32::from(first)..end {
            let point = lattice_sample(&p.shape, area, side, q % side, q / side);
            let point = if back { point.flipped() } else { point };
            let shot =
                self.shoot_one(point.position, point.normal, spin_for_sample(q), i as u16)?;
            work.rays += shot.rays + shot.specular.rays;
            work.specular += shot.specular;
            let mut len = 0u16;
            for (j, f) in self.row.iter().take(cols).enumerate() {
                if *f != [0.0; 3] {
                    rows.entries
                        .push((j as u16, *f))
                        .map_err(|_| ErrorCode::TooLong)?;
                    len += 1;
                }
            }
            rows.lens.push(len).map_err(|_| ErrorCode::TooLong)?;
        }
        Ok((Response::Rows(rows), work))
    }

    /// Form-factor columns of the loaded scene: one per diffuse patch and one per back side of a
    /// translucent sheet (as many as the patches with the default all-diffuse optics).
    fn columns(&self) -> usize {
        self.surfaces
            .iter()
            .flat_map(|s| [s.column, s.back_column])
            .flatten()
            .map(|c| c as usize + 1)
            .max()
            .unwrap_or(0)
            .min(ENGINE_MAX_PATCHES)
    }

    /// One hemisphere into `self.row` (over diffuse columns): the one place the tracer is
    /// called for pass 1. `BadScene` if the optics table does not fit the scene and hemisphere.
    fn shoot_one(
        &mut self,
        origin: Vec3,
        normal: Vec3,
        spin: f32,
        patch: u16,
    ) -> Result<ShotStats, ErrorCode> {
        let cols = self.columns();
        let tracing = self.tracing();
        let row = &mut self.row[..cols];
        row.fill([0.0; 3]);
        let rule = self.config.rule;
        let hemi = Hemisphere::new(&self.rings, &self.quarter, rule);
        let optics = Optics::new(&self.patches, &self.surfaces, &self.weights, hemi.circles())
            .map_err(|_| ErrorCode::BadScene)?;
        let scratch = self.store.scratch(tracing);
        Ok(self.provider.run(
            &self.patches,
            ShootJob {
                hemi: &hemi,
                optics: &optics,
                scratch,
                origin,
                normal,
                spin,
                patch: u32::from(patch),
                row,
            },
        ))
    }
}

struct ShootJob<'a, 'h> {
    hemi: &'a Hemisphere<'h>,
    optics: &'a Optics<'a>,
    scratch: TraceScratch<'a>,
    origin: Vec3,
    normal: Vec3,
    spin: f32,
    patch: u32,
    row: &'a mut [[f32; 3]],
}

impl AccelJob for ShootJob<'_, '_> {
    type Out = ShotStats;
    fn run<A: Accelerator>(mut self, accel: &mut A) -> ShotStats {
        shoot_hemisphere(
            accel,
            self.hemi,
            self.optics,
            &mut self.scratch,
            self.origin,
            self.normal,
            self.spin,
            Some(self.patch),
            self.row,
        )
    }
}
