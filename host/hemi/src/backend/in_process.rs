//! In-process backends: the kernel's passes on all cores, one engine per worker thread, over
//! the soft engine or the accelerator model ([`Engines`]).

use super::TouchedRow;
use super::{Backend, Gathered, Path, Progress, Query, RowSink, Seen, Skip};
use crate::grid::Grid;
use crate::method::{Method, Shooter};
use crate::optics::{pending_for, SceneOptics, Scratch};
use crate::scene::Scene;
use crate::settings::Pass1Settings;
use crate::shots::{ElementRow, Shot};
use crate::transport::{Accumulator, Layout, TransportRow};
use anyhow::Result;
use hemi_kernel::accel::{Accelerator, HemiShot, Hit, Ray};
use hemi_kernel::camera::Camera;
use hemi_kernel::geometry::Vec3;
use hemi_kernel::hemisphere::OwnedHemisphere;
use hemi_kernel::optics::Optics;
use hemi_kernel::patch::Patch;
use hemi_kernel::pixels::trace_pixels;
use hemi_kernel::rotation::{spin_for_sample, Rotation};
use hemi_kernel::specular::{SpecularStats, Via};
use hemi_kernel::tracer::{self, ShotStats};
use rayon::prelude::*;
use std::ops::Range;

/// Shots a worker casts in one batch (diffuse-only hemisphere shots): enough for a pipelined
/// engine to drain seldom, few enough to keep the workers balanced.
pub const SHOT_BATCH: usize = 8;

/// A kind of in-process engine: how to make one per worker thread over the kernel's patches.
pub trait Engines: Sync {
    /// The engine, borrowing the patches and `self`.
    type Engine<'p>: Accelerator
    where
        Self: 'p;

    /// Whether hemisphere shots should reach an engine in batches: a pipelined engine (the
    /// model) drains once a batch instead of once a shot; the soft engine gains nothing, and a
    /// batch's rows cost O(columns) each to set up, which on 10⁵ patches is the pass.
    const BATCHES: bool = false;

    /// Whether engines can be made over `patches` (a clear error if not: the model's memories
    /// are bounded).
    fn check(&self, patches: &[Patch]) -> Result<()>;

    /// An engine over `patches`; [`Engines::check`] has passed for them.
    fn engine<'p>(&'p self, patches: &'p [Patch]) -> Self::Engine<'p>;

    /// Shots a batch holds for engines over `patches` (when [`Engines::BATCHES`]).
    fn shot_batch(&self, _patches: &[Patch]) -> usize {
        SHOT_BATCH
    }

    /// Numbers `count` batches about to be cast, in the order one engine would cast them: the
    /// first one's number (the numbers go on from call to call).
    fn number_batches(&self, _count: usize) -> u64 {
        0
    }

    /// Readies `engine` for batch `number` ([`Engines::number_batches`]), which it may cast
    /// after other batches or none: a modelled accelerator puts its memory where one engine
    /// casting every batch in order would have it, so that its clocks do not depend on how the
    /// host shares the batches among engines.
    fn begin_batch(_engine: &mut Self::Engine<'_>, _number: u64) {}
}

/// Eye rays one pixel-tracer call casts at a time.
const EYE_BATCH: usize = 4096;

/// The passes' requests answered in this process by engines `E`, for one scene and settings.
pub struct InProcess<'s, E> {
    scene: &'s Scene,
    settings: Pass1Settings,
    hemi: OwnedHemisphere,
    /// The optics table, which holds the kernel's patch memory too.
    optics: SceneOptics,
    engines: E,
}

impl<'s, E: Engines> InProcess<'s, E> {
    /// A backend for `scene` with `settings`: builds the hemisphere table and the optics once,
    /// and checks that `engines` can hold the scene.
    pub fn new(scene: &'s Scene, settings: &Pass1Settings, engines: E) -> Result<Self> {
        crate::optics::check(&settings.specular)?;
        let hemi = OwnedHemisphere::new(settings.circles, settings.rule)
            .map_err(|e| anyhow::anyhow!("--circles {}: {e}", settings.circles))?;
        let optics = SceneOptics::new(scene, &hemi.view())?;
        engines.check(&optics.patches)?;
        Ok(InProcess {
            scene,
            settings: *settings,
            hemi,
            optics,
            engines,
        })
    }

    /// The engines (the model's counters live there).
    pub fn engines(&self) -> &E {
        &self.engines
    }

    fn engine(&self) -> E::Engine<'_> {
        self.engines.engine(&self.optics.patches)
    }

    /// One shot's row over the form-factor columns, sparse and in scene indices.
    /// One shot's element row; `optics` is the view of `self.optics`, made once per request
    /// (making it checks every patch's surface, which per shot was O(P) per hemisphere).
    fn shoot_one(
        &self,
        state: &mut (E::Engine<'_>, Vec<TouchedRow>, Scratch, Shooter),
        optics: &Optics<'_>,
        shot: &Shot,
    ) -> Result<(ElementRow, ShotStats)> {
        let (engine, rows, scratch, shooter) = state;
        let row = &mut rows[0];
        let stats = shooter.shoot(
            engine,
            &self.hemi.view(),
            optics,
            &mut scratch.view(),
            &shot.point,
            shot.cell.q(),
            self.scene.kernel_id(shot.patch),
            row,
        )?;
        let sparse = row.take(|c| self.optics.columns[c] as u32);
        Ok((self.element(shot, sparse), stats))
    }

    /// A shot's element row from its non-zero columns (scene indices).
    fn element(&self, shot: &Shot, sparse: Vec<(u32, [f32; 3])>) -> ElementRow {
        ElementRow {
            patch: shot.patch,
            point: shot.point,
            row: sparse,
        }
    }

    /// Hemisphere shots of a diffuse-only scene in one batch (`tracer::shoot_diffuse_batch`):
    /// the rows and stats `shoot_one` gives each, bit for bit, with a pipelined engine (the
    /// model) draining once a batch instead of once a shot.
    fn shoot_batch(
        &self,
        engine: &mut E::Engine<'_>,
        rows: &mut [TouchedRow],
        optics: &Optics<'_>,
        chunk: &[Shot],
    ) -> Vec<(ElementRow, ShotStats)> {
        let at: Vec<HemiShot> = chunk
            .iter()
            .map(|shot| HemiShot {
                origin: shot.point.position,
                rot: Rotation::onto_spun(shot.point.normal, spin_for_sample(shot.cell.q())),
                origin_patch: Some(self.scene.kernel_id(shot.patch) as u32),
            })
            .collect();
        let rows = &mut rows[..chunk.len()];
        let mut stats = vec![ShotStats::default(); chunk.len()];
        let hemi = self.hemi.view();
        tracer::shoot_diffuse_batch(engine, &hemi, optics, &at, &mut stats, rows);
        let columns = |c: usize| self.optics.columns[c] as u32;
        chunk
            .iter()
            .zip(rows.iter_mut().zip(stats))
            .map(|(shot, (row, st))| (self.element(shot, row.take(columns)), st))
            .collect()
    }

    /// What the eye rays of image row `y` saw, in tracer order.
    fn trace_row(
        &self,
        (accel, dirs, scratch): &mut (E::Engine<'_>, Vec<Vec3>, Scratch),
        camera: &Camera,
        spp: u32,
        y: u32,
    ) -> (Vec<(u32, Seen)>, SpecularStats) {
        let w = camera.width;
        let mut seen = Vec::new();
        let stats = trace_pixels(
            accel,
            camera,
            &self.optics.view(),
            &self.hemi.view(),
            &mut scratch.view(),
            y * w..(y + 1) * w,
            spp,
            dirs,
            |p, _s, hit, weight| seen.push((p, self.seen(hit, weight, Path::Other))),
        );
        (seen, stats)
    }

    /// One shot's `Σ w · B(hit)` over `grids`, the reports `skip` leaves out left out.
    fn gather_field_at(
        &self,
        (state, seen): &mut ((E::Engine<'_>, Scratch), Vec<Seen>),
        s: &Shot,
        grids: &[Grid],
        skip: &Skip,
    ) -> Result<Gathered> {
        let blocked = self.field_reports(state, s, seen);
        super::gathered(grids, seen, skip, blocked)
    }

    /// One shot's row of the element transport over `layout`, the reports `skip` leaves out
    /// left out.
    fn transport_at(
        &self,
        (state, seen, row): &mut ((E::Engine<'_>, Scratch), Vec<Seen>, Accumulator),
        s: &Shot,
        layout: &Layout,
        skip: &Skip,
    ) -> Result<TransportRow> {
        let blocked = self.field_reports(state, s, seen);
        super::transport_row(layout, row, seen, skip, blocked)
    }

    /// Casts a shot's hemisphere as pass 1 does (its spin, its origin patch, through specular
    /// surfaces, with (u,v)) and puts what every ray saw into `seen`, in tracer order; returns
    /// the fraction of rays that met the back of an opaque patch ([`Gathered::blocked`]).
    fn field_reports(
        &self,
        (accel, scratch): &mut (E::Engine<'_>, Scratch),
        s: &Shot,
        seen: &mut Vec<Seen>,
    ) -> f32 {
        let shot = tracer::Shot {
            origin: s.point.position,
            normal: s.point.normal,
            spin: spin_for_sample(s.cell.q()),
            origin_patch: Some(self.scene.kernel_id(s.patch) as u32),
            want_uv: true,
        };
        let (hemi, optics) = (self.hemi.view(), self.optics.view());
        seen.clear();
        let stats = tracer::shoot(
            accel,
            &hemi,
            &optics,
            &mut scratch.view(),
            &shot,
            |hit, w, via| seen.push(self.seen(hit, w, Path::of(via))),
        );
        stats.back_hits as f32 / stats.rays.max(1) as f32
    }

    fn seen(&self, hit: &Hit, weight: [f32; 3], path: Path) -> Seen {
        Seen {
            side: self.scene.side_seen(hit.patch, hit.front),
            u: hit.u,
            v: hit.v,
            weight,
            path,
        }
    }
}

impl<E: Engines> Backend for InProcess<'_, E> {
    fn scene(&self) -> &Scene {
        self.scene
    }

    fn settings(&self) -> &Pass1Settings {
        &self.settings
    }

    fn shoot(&self, shots: &[Shot], done: &Progress<'_>) -> Result<(Vec<ElementRow>, ShotStats)> {
        let optics = self.optics.view();
        self.settings.method.check(&optics)?;
        let cols = self.optics.columns.len();
        let pending = if optics.has_specular() {
            pending_for(&self.hemi.view())
        } else {
            0
        };
        // diffuse-only hemisphere shots go in batches (the rows do not depend on it)
        let batch =
            E::BATCHES && self.settings.method == Method::Hemisphere && !optics.has_specular();
        // one row per shot of a batch, made once per worker and left zero by `take`
        let per_state = if batch {
            self.engines.shot_batch(&self.optics.patches)
        } else {
            1
        };
        let first = match batch {
            true => self.engines.number_batches(shots.len().div_ceil(per_state)),
            false => 0,
        };
        let results: Vec<Vec<(ElementRow, ShotStats)>> = shots
            .par_chunks(per_state)
            .enumerate()
            .map_init(
                || {
                    let scratch = Scratch::new(pending, &self.settings.specular);
                    let shooter = Shooter::new(self.settings.method, self.settings.circles);
                    let rows: Vec<TouchedRow> =
                        (0..per_state).map(|_| TouchedRow::new(cols)).collect();
                    (self.engine(), rows, scratch, shooter)
                },
                |state, (k, chunk)| {
                    let out = if batch {
                        E::begin_batch(&mut state.0, first + k as u64);
                        self.shoot_batch(&mut state.0, &mut state.1, &optics, chunk)
                    } else {
                        let one = |s| self.shoot_one(state, &optics, s);
                        chunk.iter().map(one).collect::<Result<_>>()?
                    };
                    done(chunk.len() as u64);
                    Ok(out)
                },
            )
            .collect::<Result<_>>()?;
        let mut stats = ShotStats::default();
        let mut elements = Vec::with_capacity(shots.len());
        for (e, s) in results.into_iter().flatten() {
            stats += s;
            elements.push(e);
        }
        Ok((elements, stats))
    }

    fn trace(
        &self,
        camera: &Camera,
        spp: u32,
        rows: Range<u32>,
        sink: &RowSink<'_>,
        done: &Progress<'_>,
    ) -> Result<SpecularStats> {
        let spp = spp.max(1);
        let per_row: Vec<SpecularStats> = rows
            .into_par_iter()
            .map_init(
                || {
                    let scratch = Scratch::new(EYE_BATCH, &self.settings.specular);
                    (self.engine(), vec![Vec3::ZERO; EYE_BATCH], scratch)
                },
                |state, y| {
                    let (seen, stats) = self.trace_row(state, camera, spp, y);
                    sink(y, &seen);
                    done(1);
                    stats
                },
            )
            .collect();
        let mut specular = SpecularStats::default();
        for s in per_row {
            specular += s;
        }
        Ok(specular)
    }

    fn gather(&self, queries: &[Query]) -> Result<Vec<Vec<Seen>>> {
        let pending = pending_for(&self.hemi.view());
        let answers = queries
            .par_iter()
            .map_init(
                || {
                    let scratch = Scratch::new(pending, &self.settings.specular);
                    (self.engine(), scratch)
                },
                |(accel, scratch), q| {
                    let shot = tracer::Shot {
                        origin: q.point,
                        normal: q.normal,
                        spin: 0.0,
                        origin_patch: None,
                        want_uv: true,
                    };
                    let mut seen = Vec::new();
                    let (hemi, optics) = (self.hemi.view(), self.optics.view());
                    let mut sink = |h: &Hit, w, via: Via| seen.push(self.seen(h, w, Path::of(via)));
                    tracer::shoot(accel, &hemi, &optics, &mut scratch.view(), &shot, &mut sink);
                    seen
                },
            )
            .collect();
        Ok(answers)
    }

    fn gather_field(
        &self,
        shots: &[Shot],
        grids: &[Grid],
        skip: &Skip,
        done: &Progress<'_>,
    ) -> Result<Vec<Gathered>> {
        let pending = pending_for(&self.hemi.view());
        shots
            .par_iter()
            .map_init(
                || {
                    let engine = (
                        self.engine(),
                        Scratch::new(pending, &self.settings.specular),
                    );
                    (engine, Vec::new())
                },
                |state, s| {
                    let h = self.gather_field_at(state, s, grids, skip);
                    done(1);
                    h
                },
            )
            .collect()
    }

    fn transport(
        &self,
        shots: &[Shot],
        layout: &Layout,
        skip: &Skip,
        done: &Progress<'_>,
    ) -> Result<Option<Vec<TransportRow>>> {
        let pending = pending_for(&self.hemi.view());
        let rows = shots
            .par_iter()
            .map_init(
                || {
                    let engine = (
                        self.engine(),
                        Scratch::new(pending, &self.settings.specular),
                    );
                    (engine, Vec::new(), Accumulator::new(layout.len()))
                },
                |state, s| {
                    let row = self.transport_at(state, s, layout, skip);
                    done(1);
                    row
                },
            )
            .collect::<Result<_>>()?;
        Ok(Some(rows))
    }

    fn nearest(&self, rays: &[Ray]) -> Result<Vec<Option<Hit>>> {
        Ok(rays
            .par_iter()
            .map_init(
                || self.engine(),
                |engine, ray| engine.nearest_hit(ray, f32::INFINITY),
            )
            .collect())
    }
}
