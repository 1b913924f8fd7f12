//! The backend of boards: the passes' requests cut into link jobs for a [`Farm`], and the
//! answers handed back as the in-process engines hand theirs (scene indices, tracer order), so
//! a board running the same kernel on the same accelerator gives the same bits as
//! `--backend model` (or `soft`): the passes themselves are the library's, written once.

mod field;
mod gather;
mod shoot;
mod trace;

use crate::farm::{Farm, Setup};
use crate::protocol::require;
use anyhow::{Context, Result};
use hemi::backend::{Backend, Gathered, Progress, Query, RowSink, Seen, Skip};
use hemi::grid::Grid;
use hemi::optics::SceneOptics;
use hemi::scene::Scene;
use hemi::settings::Pass1Settings;
use hemi::shots::{ElementRow, Shot};
use hemi::transport::{Accumulator, Layout, TransportRow};
use hemi_kernel::accel::{Hit, Ray};
use hemi_kernel::camera::Camera;
use hemi_kernel::hemisphere::OwnedHemisphere;
use hemi_kernel::link::Feature;
use hemi_kernel::link::{AccelKind, JobConfig, TraceSettings};
use hemi_kernel::optics::Surface;
use hemi_kernel::specular::SpecularStats;
use hemi_kernel::tracer::ShotStats;
use std::ops::Range;
use std::sync::atomic::{AtomicU64, Ordering};

/// The boards of a farm as a backend for one scene and settings.
pub struct Boards<'a> {
    farm: &'a Farm,
    scene: &'a Scene,
    settings: Pass1Settings,
    /// The engine each board is asked to use (`AccelKind::None`: its own).
    accel: AccelKind,
    /// The scene patch of each form-factor column (boards answer rows over diffuse columns,
    /// as the in-process tracer does).
    columns: Vec<usize>,
    /// The hemisphere the queries' ring weights come from.
    hemi: OwnedHemisphere,
    /// The farm's setup generation this backend uploaded last: another backend on the same
    /// farm may have uploaded its own scene since, and then this one uploads its again.
    uploaded: AtomicU64,
}

impl<'a> Boards<'a> {
    /// Gives the farm the scene and settings (uploaded to each board before its next job), with
    /// the optics table of a specular or translucent scene (protocol 4). `accel` asks the
    /// boards for an engine (`AccelKind::Soft`: their soft fallback, for measurements).
    pub fn new(
        farm: &'a Farm,
        scene: &'a Scene,
        settings: &Pass1Settings,
        accel: AccelKind,
    ) -> Result<Self> {
        hemi::optics::check(&settings.specular)?;
        anyhow::ensure!(
            settings.method == hemi::method::Method::Hemisphere,
            "boards shoot the hemisphere only (--method hemisphere)"
        );
        let hemi = OwnedHemisphere::new(settings.circles, settings.rule)
            .map_err(|e| anyhow::anyhow!("--circles: {e:?}"))?;
        let mut boards = Boards {
            farm,
            scene,
            settings: *settings,
            accel,
            columns: Vec::new(),
            hemi,
            uploaded: AtomicU64::new(0),
        };
        boards.columns = boards.set_up(None, 1)?;
        Ok(boards)
    }

    /// The farm.
    pub fn farm(&self) -> &Farm {
        self.farm
    }

    /// Uploads the scene with `camera` and `spp` (pass 2) and returns the column table.
    fn set_up(&self, camera: Option<Camera>, spp: u32) -> Result<Vec<usize>> {
        let (farm, scene) = (self.farm, self.scene);
        let optics = SceneOptics::new(scene, &self.hemi.view())?;
        let specular = optics.view().has_specular();
        // The optics table (specular surfaces, and the back sides of translucent sheets, which
        // are named past the patches and have columns of their own): say so before any upload,
        // rather than as a failed upload.
        if specular || scene.has_translucency() {
            require(
                farm,
                Feature::OpticsTable,
                "a specular or translucent scene on boards",
            )?;
        }
        let cap = farm.capacities().map_or(u16::MAX, |c| c.max_patches);
        anyhow::ensure!(
            optics.columns.len() <= usize::from(cap),
            "{} form-factor columns (diffuse patches and back sides): the boards hold {cap}",
            optics.columns.len()
        );
        let patches = scene
            .kernel_patches()
            .into_iter()
            .zip(scene.patches.iter().map(|p| p.area))
            .collect();
        let generation = farm.set_setup(Setup {
            patches,
            config: self.config(camera, spp)?,
            surfaces: special_surfaces(&optics)?,
            weights: optics.weights.clone(),
            tracing: self.tracing(specular),
        })?;
        self.uploaded.store(generation, Ordering::Release);
        Ok(optics.columns)
    }

    /// Uploads this backend's scene again if another backend on the farm replaced it.
    fn current(&self) -> Result<()> {
        if self.farm.generation() != self.uploaded.load(Ordering::Acquire) {
            self.set_up(None, 1)?;
        }
        Ok(())
    }

    fn config(&self, camera: Option<Camera>, spp: u32) -> Result<JobConfig> {
        let s = &self.settings;
        Ok(JobConfig {
            circles: u16::try_from(s.circles).context("--circles")?,
            rule: s.rule,
            samples: u16::try_from(s.samples).context("--samples")?,
            spp: u16::try_from(spp).context("--spp")?,
            camera,
            accel: self.accel,
        })
    }

    /// The board's stack: the host's --stack if it fits, else as many frames as the board holds
    /// (what a full stack cuts is counted on the board, `TraceStats::overflows`).
    fn tracing(&self, specular: bool) -> TraceSettings {
        let cap = self.farm.capacities().map_or(u16::MAX, |c| c.stack_depth);
        let s = &self.settings.specular;
        let stack = u16::try_from(s.stack).unwrap_or(u16::MAX);
        if specular && stack > cap {
            eprintln!(
                "boards: --stack {stack} > the board's {cap} frames: the boards use {cap} \
                 (frustums a full stack cuts are counted)"
            );
        }
        TraceSettings {
            threshold: s.threshold,
            max_bounces: s.max_bounces,
            stack: stack.min(cap),
        }
    }
}

/// The surfaces that are not plain diffuse with their own column, as the optics table sends
/// them.
fn special_surfaces(optics: &SceneOptics) -> Result<Vec<(u16, Surface)>> {
    optics
        .surfaces
        .iter()
        .enumerate()
        .filter(|(i, s)| **s != Surface::diffuse(*i as u32))
        .map(|(i, s)| Ok((u16::try_from(i).context("too many patches")?, *s)))
        .collect()
}

impl Backend for Boards<'_> {
    fn scene(&self) -> &Scene {
        self.scene
    }

    fn settings(&self) -> &Pass1Settings {
        &self.settings
    }

    fn shoot(&self, shots: &[Shot], done: &Progress<'_>) -> Result<(Vec<ElementRow>, ShotStats)> {
        self.current()?;
        self.shoot_rows(shots, done)
    }

    fn trace(
        &self,
        camera: &Camera,
        spp: u32,
        rows: Range<u32>,
        sink: &RowSink<'_>,
        done: &Progress<'_>,
    ) -> Result<SpecularStats> {
        self.trace_rows(camera, spp, rows, sink, done)
    }

    fn gather(&self, queries: &[Query]) -> Result<Vec<Vec<Seen>>> {
        self.current()?;
        queries.iter().map(|q| self.gather_one(q)).collect()
    }

    fn nearest(&self, rays: &[Ray]) -> Result<Vec<Option<Hit>>> {
        self.cast(rays)
    }

    fn casts_single_rays(&self) -> bool {
        crate::protocol::supports(self.farm, Feature::Cast)
    }

    fn gather_field(
        &self,
        shots: &[Shot],
        grids: &[Grid],
        skip: &Skip,
        done: &Progress<'_>,
    ) -> Result<Vec<Gathered>> {
        self.field_reports(shots, done)?
            .iter()
            .map(|(seen, blocked)| hemi::backend::gathered(grids, seen, skip, *blocked))
            .collect()
    }

    fn transport(
        &self,
        shots: &[Shot],
        layout: &Layout,
        skip: &Skip,
        done: &Progress<'_>,
    ) -> Result<Option<Vec<TransportRow>>> {
        let mut row = Accumulator::new(layout.len());
        let rows = self
            .field_reports(shots, done)?
            .iter()
            .map(|(seen, blocked)| {
                hemi::backend::transport_row(layout, &mut row, seen, skip, *blocked)
            })
            .collect::<Result<_>>()?;
        Ok(Some(rows))
    }
}
