//! The accelerator behind its register driver as an in-process engine, with the cycles and
//! rays of all its engines summed and the scene's load counted once: the cycle-level model in
//! this process ([`ModelSite`]), or any other implementation behind the same registers (the
//! RTL in a simulator, [`super::rtl`]).

use super::in_process::SHOT_BATCH;
use super::Engines;
use hemi_hdl_model::driver::{ClockedBus, ModelBus};
use hemi_hdl_model::{ModelConfig, ModelError, StreamingModel};
use hemi_kernel::accel::{Accelerator, HemiShot, Hit, Ray};
use hemi_kernel::geometry::Vec3;
use hemi_kernel::hemisphere::Hemisphere;
use hemi_kernel::patch::Patch;
use hemi_kernel::rotation::Rotation;
use std::ops::Range;
use std::sync::atomic::{AtomicU64, Ordering::Relaxed};

/// Where an engine's accelerator is (the model in this process, the RTL in a simulator): a bus
/// to it for each engine, and what it cannot take.
pub trait Site: Sync {
    /// The bus an engine drives it through.
    type Bus: ClockedBus;
    /// The backend's name in errors (`--backend model`).
    const NAME: &'static str;
    /// A bus to a freshly reset accelerator of `config`'s build.
    fn open(&self, config: &ModelConfig) -> anyhow::Result<Self::Bus>;
    /// Whether it can cast on `patches` (beyond the driver's own checks).
    fn supports(&self, _patches: &[Patch]) -> anyhow::Result<()> {
        Ok(())
    }
}

/// The cycle-level model in this process.
#[derive(Clone, Copy, Debug, Default)]
pub struct ModelSite;

impl Site for ModelSite {
    type Bus = ModelBus;
    const NAME: &'static str = "--backend model";
    fn open(&self, config: &ModelConfig) -> anyhow::Result<ModelBus> {
        anyhow::ensure!(
            config.params.is_valid(),
            "{}: {:?}",
            Self::NAME,
            ModelError::BadParams
        );
        Ok(ModelBus::with_params(config.params))
    }
}

/// The in-process engines of the model backend ([`super::InProcess`]`<Model>`): one
/// accelerator for each job rayon splits a pass into (the model's, or `S`'s), all adding to one
/// set of [`Counters`].
#[derive(Debug, Default)]
pub struct Model<S: Site = ModelSite> {
    /// The accelerator's configuration.
    pub config: ModelConfig,
    /// What its engines did, summed.
    pub counters: Counters,
    /// Batches numbered so far ([`Engines::number_batches`]).
    batches: AtomicU64,
    /// Where the accelerator is.
    site: S,
}

impl Model {
    /// Engines of `config`, with fresh counters.
    pub fn new(config: ModelConfig) -> Model {
        Model::on(ModelSite, config)
    }
}

impl<S: Site> Model<S> {
    /// Engines of `config` on `site`'s accelerators, with fresh counters.
    pub fn on(site: S, config: ModelConfig) -> Model<S> {
        Model {
            config,
            counters: Counters::default(),
            batches: AtomicU64::new(0),
            site,
        }
    }
}

impl<S: Site> Engines for Model<S> {
    const BATCHES: bool = true;

    type Engine<'p>
        = CountedModel<'p, S::Bus>
    where
        S: 'p;

    /// The site's own limits, then the model's: the same driver loads the same words on any
    /// site, so what the model can load the site can (without starting one just to see).
    fn check(&self, patches: &[Patch]) -> anyhow::Result<()> {
        self.site.supports(patches)?;
        engine_on(&ModelSite, patches, self.config).map(drop)
    }

    fn engine<'p>(&'p self, patches: &'p [Patch]) -> CountedModel<'p, S::Bus> {
        let inner =
            engine_on(&self.site, patches, self.config).expect("checked when the backend was made");
        CountedModel::new(inner, &self.counters)
    }

    /// A scene streamed in blocks reloads all but one of them for every batch: batches eight
    /// times the usual size make that cost an eighth (the cut 8 × 8 box in three blocks:
    /// 37 % of the clocks streaming at 8 shots, 7 % at 64; docs/PERFORMANCE.md).
    fn shot_batch(&self, patches: &[Patch]) -> usize {
        match StreamingModel::blocks_needed(patches, self.config.params) {
            1 => SHOT_BATCH,
            _ => 8 * SHOT_BATCH,
        }
    }

    fn number_batches(&self, count: usize) -> u64 {
        self.batches.fetch_add(count as u64, Relaxed)
    }

    fn begin_batch(engine: &mut CountedModel<'_, S::Bus>, number: u64) {
        engine.inner.align_to_batch(number);
    }
}

/// Cycles and rays summed over the model engines of a run (an engine for each job rayon splits
/// the shots into, so their number depends on the host's threads and its scheduling).
///
/// Every engine configures the accelerator and loads the scene before its first ray, which a
/// board does once: those clocks are counted once ([`Counters::load_cycles`]), so that the
/// count is that of one accelerator whatever the number of engines. Every batch of shots
/// starts and ends with the device idle, so for a scene that fits patch memory no other clock
/// depends on which engine casts it. A scene streamed in blocks reloads, in each batch, the
/// blocks other than the one in memory: an engine readied for a batch
/// ([`Engines::begin_batch`]) first loads the block one engine casting every batch in order
/// would hold, uncounted ([`StreamingModel::align_to_batch`]).
#[derive(Debug, Default)]
pub struct Counters {
    /// Accelerator clock cycles after each engine's load.
    pub cycles: AtomicU64,
    /// Clocks of one engine's configuration and first block's load.
    pub load_cycles: AtomicU64,
    /// Rays the accelerator cast.
    pub rays: AtomicU64,
    /// Of the cycles, those spent streaming blocks of a scene larger than patch memory.
    pub stream_cycles: AtomicU64,
    /// Blocks the scene was cut into (1: it fits the patch memory).
    pub blocks: AtomicU64,
}

impl Counters {
    /// (cycles, rays) so far, the scene's load counted once.
    pub fn get(&self) -> (u64, u64) {
        let cycles = self.cycles.load(Relaxed) + self.load_cycles.load(Relaxed);
        (cycles, self.rays.load(Relaxed))
    }

    /// (blocks, cycles spent streaming them) so far.
    pub fn stream(&self) -> (u64, u64) {
        (self.blocks.load(Relaxed), self.stream_cycles.load(Relaxed))
    }
}

/// A model engine that adds its cycles and rays to shared [`Counters`] when dropped. The model
/// (about 100 KB) lives on the heap: worker threads' stacks are rayon's 2 MiB by default.
pub struct CountedModel<'c, B: ClockedBus = ModelBus> {
    inner: Box<StreamingModel<'c, B>>,
    counters: &'c Counters,
}

impl<'c, B: ClockedBus> CountedModel<'c, B> {
    /// Wraps `inner`.
    pub fn new(inner: StreamingModel<'c, B>, counters: &'c Counters) -> Self {
        CountedModel {
            inner: Box::new(inner),
            counters,
        }
    }
}

impl<B: ClockedBus> Drop for CountedModel<'_, B> {
    fn drop(&mut self) {
        let load = self.inner.load_cycles();
        let uncounted = load + self.inner.aligning_cycles();
        self.counters
            .cycles
            .fetch_add(self.inner.cycles() - uncounted, Relaxed);
        self.counters.load_cycles.fetch_max(load, Relaxed);
        self.counters.rays.fetch_add(self.inner.rays(), Relaxed);
        let streamed = self.inner.stream_cycles();
        self.counters.stream_cycles.fetch_add(streamed, Relaxed);
        let blocks = self.inner.blocks() as u64;
        self.counters.blocks.fetch_max(blocks, Relaxed);
    }
}

impl<B: ClockedBus> Accelerator for CountedModel<'_, B> {
    fn rotate(&mut self, rot: &Rotation, d: Vec3) -> Vec3 {
        self.inner.rotate(rot, d)
    }
    fn set_origin_patch(&mut self, patch: Option<u32>) {
        self.inner.set_origin_patch(patch)
    }
    fn nearest_hit(&mut self, ray: &Ray, t_max: f32) -> Option<Hit> {
        self.inner.nearest_hit(ray, t_max)
    }
    fn cast_from<F: FnMut(usize, Option<Hit>)>(
        &mut self,
        origin: Vec3,
        dirs: &[Vec3],
        want_uv: bool,
        sink: F,
    ) {
        self.inner.cast_from(origin, dirs, want_uv, sink)
    }
    fn cast_rings<F: FnMut(usize, u32, Option<Hit>)>(
        &mut self,
        origin: Vec3,
        rot: &Rotation,
        hemi: &Hemisphere<'_>,
        rings: Range<usize>,
        want_uv: bool,
        sink: F,
    ) {
        self.inner
            .cast_rings(origin, rot, hemi, rings, want_uv, sink)
    }
    fn cast_hemispheres<F: FnMut(usize, usize, u32, Option<Hit>)>(
        &mut self,
        shots: &[HemiShot],
        hemi: &Hemisphere<'_>,
        rings: Range<usize>,
        want_uv: bool,
        sink: F,
    ) {
        self.inner
            .cast_hemispheres(shots, hemi, rings, want_uv, sink)
    }
}

/// An engine over `patches` on `site`'s accelerator, with an error that says what it cannot
/// load. A scene larger than the accelerator's patch memory is streamed through it in blocks.
fn engine_on<'p, S: Site>(
    site: &S,
    patches: &'p [Patch],
    config: ModelConfig,
) -> anyhow::Result<StreamingModel<'p, S::Bus>> {
    let bus = site.open(&config)?;
    StreamingModel::with_bus(patches, config, bus).map_err(|e| match e {
        ModelError::BadGeometry(i) => anyhow::anyhow!(
            "{}: patch {i} does not fit the accelerator's fixed-point formats (non-finite or out of range)",
            S::NAME
        ),
        other => anyhow::anyhow!("{}: {other:?}", S::NAME),
    })
}
