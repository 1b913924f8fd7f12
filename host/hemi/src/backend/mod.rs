//! The backend trait: what a ray engine does for the passes, whoever runs it.
//!
//! A backend is made for one scene and one [`Pass1Settings`] and answers four kinds of
//! requests: hemispheres from sample points ([`Backend::shoot`]: pass 1, adaptive levels,
//! progressive rows), eye rays through image rows ([`Backend::trace`]: pass 2), hemispheres
//! gathered at arbitrary points ([`Backend::gather`]: irradiance) and single rays
//! ([`Backend::nearest`]: `hemi trace`). Every pass is written once over these
//! ([`crate::pass1`], [`crate::adaptive`], [`crate::on_demand`], [`crate::render`],
//! [`crate::irradiance`]); the in-process engines ([`InProcess`] over [`Soft`] or [`Model`]) and
//! the boards (crate `hemi-boards`) implement them. A backend reports what its rays reached in
//! scene indices, in the order its tracer made the reports, so the pass's sums run in the same
//! order on every backend and a board gives the model's bits.

mod in_process;
mod model;
mod rtl;
mod soft;
mod touched_row;

pub use in_process::{Engines, InProcess};
pub use model::{CountedModel, Counters, Model, ModelSite, Site};
pub use rtl::{RtlBus, RtlSim, DEFAULT_SIM};
pub use soft::{Soft, SoftEngine, TREE_MIN_BUNDLE, TREE_MIN_SINGLE};
pub use touched_row::TouchedRow;

use crate::grid::Grid;
use crate::scene::Scene;
use crate::settings::Pass1Settings;
use crate::shots::{ElementRow, Shot};
use crate::transport::{Accumulator, Layout, TransportRow};
use anyhow::Result;
use hemi_kernel::accel::{Hit, Ray};
use hemi_kernel::camera::Camera;
use hemi_kernel::geometry::Vec3;
use hemi_kernel::specular::{SpecularStats, Via};
use hemi_kernel::tracer::ShotStats;
use std::ops::Range;

/// Progress of a request: called with how many units (rows, image rows) are done.
pub type Progress<'a> = dyn Fn(u64) + Sync + 'a;

/// What one ray reported on a diffuse surface: whose radiosity field it sees (the side of the
/// patch, a scene index), where, and the weight it carries there (δD of its ring for a
/// hemisphere ray, the product of the mirrors' k and lobe weights on the way for a frustum ray).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Seen {
    /// Scene patch whose grid the ray sees (`Scene::side_seen`).
    pub side: usize,
    /// Surface parameter u of the hit.
    pub u: f32,
    /// Surface parameter v of the hit.
    pub v: f32,
    /// Weight per channel.
    pub weight: [f32; 3],
    /// How the ray got there.
    pub path: Path,
}

/// How a reported ray reached the side it saw.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Path {
    /// Straight from the hemisphere's centre (or the eye).
    Direct,
    /// Through one perfect mirror, this scene patch, and nothing else.
    Mirror(usize),
    /// Through other specular surfaces, or more of them (or a backend that does not say).
    Other,
}

impl Path {
    /// The path of a kernel report ([`Via`]).
    pub fn of(via: Via) -> Path {
        match via.bounces {
            0 => Path::Direct,
            1 if via.mirror => Path::Mirror(via.last as usize),
            _ => Path::Other,
        }
    }
}

/// Which reports a gather leaves out: those that carry light computed by other means (the
/// lamps' exact direct light, [`crate::direct`]): hits on `sides` seen directly, or once
/// through a perfect mirror among `mirrors` (whose images of the lamps are computed too).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Skip {
    /// Per scene patch: its light seen directly is computed otherwise.
    pub sides: Vec<bool>,
    /// Per scene patch: a perfect mirror through which the light of `sides` is computed too.
    pub mirrors: Vec<bool>,
}

impl Skip {
    /// Leaves nothing out.
    pub fn none() -> Skip {
        Skip::default()
    }

    /// Whether the report `s` is left out.
    pub fn leaves_out(&self, s: &Seen) -> bool {
        let lit = self.sides.get(s.side).copied().unwrap_or(false);
        lit && match s.path {
            Path::Direct => true,
            Path::Mirror(m) => self.mirrors.get(m).copied().unwrap_or(false),
            Path::Other => false,
        }
    }
}

impl Seen {
    /// The light the ray carries back from the field `grids` (one per scene patch):
    /// `w · B_side(u, v)` per channel, the term every gather sums.
    pub fn light(&self, grids: &[Grid]) -> Result<[f64; 3]> {
        let b = crate::grid::grid_of(grids, self.side)?.at(self.u, self.v);
        Ok([0, 1, 2].map(|c| self.weight[c] as f64 * b[c]))
    }
}

/// Where [`Backend::trace`] hands each image row's reports: the row y and, in tracer order,
/// (pixel index, what its ray saw). Called once per row, from any thread, rows in any order.
pub type RowSink<'a> = dyn Fn(u32, &[(u32, Seen)]) + Sync + 'a;

/// What one shot of [`Backend::gather_field`] gathered.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Gathered {
    /// `Σ_k w_k · B(hit_k)` per channel.
    pub light: [f64; 3],
    /// The fraction of its rays that met the back of an opaque patch first: near 1 for a
    /// sample point buried in another body (a floor's point under a block), whose value is
    /// then not the surface's.
    pub blocked: f32,
}

/// What one shot of [`Backend::gather_field`] gathers from its reports `seen` (in tracer
/// order, `blocked` from its ray counts): the sum every backend makes the same way, so a board
/// gives the in-process engine's bits.
pub fn gathered(grids: &[Grid], seen: &[Seen], skip: &Skip, blocked: f32) -> Result<Gathered> {
    let mut light = [0.0f64; 3];
    for s in seen.iter().filter(|s| !skip.leaves_out(s)) {
        let l = s.light(grids)?;
        (0..3).for_each(|c| light[c] += l[c]);
    }
    Ok(Gathered { light, blocked })
}

/// One shot's row of [`Backend::transport`] from its reports `seen` (in tracer order), made in
/// `row` (left empty for the next shot): the record every backend makes the same way.
pub fn transport_row(
    layout: &Layout,
    row: &mut Accumulator,
    seen: &[Seen],
    skip: &Skip,
    blocked: f32,
) -> Result<TransportRow> {
    for s in seen.iter().filter(|s| !skip.leaves_out(s)) {
        layout.add(row, s.side, (s.u, s.v), s.weight)?;
    }
    Ok(row.take(blocked))
}

/// An irradiance query: a point and the normal of the surface it is on.
#[derive(Clone, Copy, Debug)]
pub struct Query {
    /// The point.
    pub point: Vec3,
    /// The surface normal (unit).
    pub normal: Vec3,
}

/// A ray engine as the passes see it (see the module notes).
pub trait Backend: Sync {
    /// The scene the backend was made for.
    fn scene(&self) -> &Scene;

    /// The settings the backend was made for.
    fn settings(&self) -> &Pass1Settings;

    /// Shoots the hemisphere of every shot and returns its element row, in the order of
    /// `shots`, with the tracer's counters; `done` gets rows as they finish.
    fn shoot(&self, shots: &[Shot], done: &Progress<'_>) -> Result<(Vec<ElementRow>, ShotStats)>;

    /// Traces the eye rays of image rows `rows` through `camera`, `spp` per pixel, each row as
    /// one run of the kernel's pixel tracer, and hands each row's reports to `sink` (so only the
    /// rows in flight are held); `done` gets image rows as they finish. Returns what the
    /// frustums did (in-process engines; boards count theirs on the board).
    fn trace(
        &self,
        camera: &Camera,
        spp: u32,
        rows: Range<u32>,
        sink: &RowSink<'_>,
        done: &Progress<'_>,
    ) -> Result<SpecularStats>;

    /// Shoots a hemisphere at each query (spin 0, no origin patch) and returns what each of its
    /// rays reached, directly or through specular surfaces, in tracer order (callers pass a few
    /// queries at a time: a hemisphere's reports number about as many as its rays).
    fn gather(&self, queries: &[Query]) -> Result<Vec<Vec<Seen>>>;

    /// The nearest hit of each ray, in scene patch indices (kernel patches: fronts).
    fn nearest(&self, rays: &[Ray]) -> Result<Vec<Option<Hit>>>;

    /// Whether [`Backend::nearest`] answers (boards have no job for single rays).
    fn casts_single_rays(&self) -> bool {
        true
    }

    /// Gathers the radiosity field `grids` (one per scene patch) over the hemisphere of every
    /// shot, cast as pass 1 casts it (its spin, its origin patch, through specular surfaces):
    /// per shot and channel `H = Σ_k w_k · B_side(k)(u_k, v_k)`, summed in tracer order. This is
    /// the element-to-element transport of [`crate::field`], from the same rays as pass 1's
    /// rows but with the light's variation across each patch; `done` gets shots as they finish.
    /// Reports `skip` leaves out are left out (the emitters whose direct light
    /// [`crate::direct`] computes exactly).
    fn gather_field(
        &self,
        shots: &[Shot],
        grids: &[Grid],
        skip: &Skip,
        done: &Progress<'_>,
    ) -> Result<Vec<Gathered>>;

    /// Records the element transport of every shot ([`crate::transport`]): the weight its
    /// hemisphere, cast as [`Backend::gather_field`] casts it, gives each vertex of `layout`,
    /// reports `skip` leaves out left out, so the field's sweeps need no rays. `None` if this
    /// backend does not record it (the sweeps then re-cast through `gather_field`).
    fn transport(
        &self,
        shots: &[Shot],
        layout: &Layout,
        skip: &Skip,
        done: &Progress<'_>,
    ) -> Result<Option<Vec<TransportRow>>> {
        let _ = (shots, layout, skip, done);
        Ok(None)
    }
}

/// [`Backend::shoot`], checked: one row per shot, for the shot's patch, in the order of
/// `shots` (a backend that answers otherwise is an error, not a panic further on).
pub fn shoot_checked(
    backend: &dyn Backend,
    shots: &[Shot],
    done: &Progress<'_>,
) -> Result<(Vec<ElementRow>, ShotStats)> {
    let (rows, stats) = backend.shoot(shots, done)?;
    anyhow::ensure!(
        rows.len() == shots.len() && rows.iter().zip(shots).all(|(r, s)| r.patch == s.patch),
        "the backend answered {} rows for {} shots, or rows of other patches",
        rows.len(),
        shots.len()
    );
    Ok((rows, stats))
}

/// The default backend, the soft engine in this process, for `scene` with `settings`.
pub fn soft<'s>(scene: &'s Scene, settings: &Pass1Settings) -> Result<InProcess<'s, Soft>> {
    InProcess::new(scene, settings, Soft::new())
}

/// The accelerator model of `config` in this process, for `scene` with `settings`.
pub fn model<'s>(
    scene: &'s Scene,
    settings: &Pass1Settings,
    config: hemi_hdl_model::ModelConfig,
) -> Result<InProcess<'s, Model>> {
    InProcess::new(scene, settings, Model::new(config))
}
