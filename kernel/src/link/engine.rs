//! The board's job engine: scene storage, hemisphere table and the three jobs of the link
//! (shoot, trace, gather), all in bounded memory, over any accelerator.
//!
//! It lives in the kernel (like [`LinkServer`](super::LinkServer)) so the exact code the firmware
//! runs is tested on the host too, and so a host can run an in-process board. The accelerator is
//! behind [`AccelProvider`]: the kernel's soft engine ([`SoftProvider`]) here, the HDL model or
//! the MMIO accelerator in the firmware.
//!
//! Every request is checked before any work: indices, counts and settings outside the board's
//! limits are refused with an error code, never indexed blindly. A job's result depends only on
//! the scene, the configuration and the job, so a job sent again (same id) is answered with the
//! same bits; the engine remembers the ids of recent jobs so a repeat is not counted twice.

use heapless::{Deque, Vec};

use super::message::{
    AccelKind, Capacities, EngineStats, ErrorCode, JobConfig, RayHit, Request, Response, Rows,
    TraceSettings, TraceStats, WeightedHit, WeightedHits, MAX_HITS, MAX_ROWS, MAX_ROW_ENTRIES,
};
use super::MAX_FRAME_LEN;
use crate::accel::soft::{LocalPatch, SoftAccelerator, SoftScratch};
use crate::accel::{Accelerator, Hit};
use crate::camera::Camera;
use crate::geometry::Vec3;
use crate::hemisphere::{build_into, Hemisphere, Ring};
use crate::optics::{Optics, Surface};
use crate::patch::{Patch, Shape};
use crate::pixels::trace_pixels;
use crate::rotation::{spin_for_sample, Rotation};
use crate::sampling::{lattice_sample, SamplePoint};
use crate::skeleton::{Frame, Skeleton};
use crate::specular::{Pending, SpecularStats, DEFAULT_THRESHOLD};
use crate::tracer::{shoot, shoot_hemisphere, Shot, ShotStats, TraceScratch};

/// Patches a board's engine stores (the Cornell box has 19, the teapot scene 34).
pub const ENGINE_MAX_PATCHES: usize = 48;
/// Largest hemisphere (circles R) a board's engine builds. R = 64 (the host's default) would need
/// 9 KiB more for the quarter table, which a 64 KiB part cannot spare next to the stack the
/// Bezier subdivision needs (docs/PERFORMANCE.md, firmware RAM); builds with RAM to spare
/// (feature `large-engine`: QEMU's model builds) take R ≤ 128.
#[cfg(not(feature = "large-engine"))]
pub const ENGINE_MAX_CIRCLES: usize = 48;
/// Largest hemisphere (circles R) a board's engine builds (feature `large-engine`).
#[cfg(feature = "large-engine")]
pub const ENGINE_MAX_CIRCLES: usize = 128;
/// Quarter-table entries of the largest hemisphere: `hemisphere::quarter_len(48)`.
#[cfg(not(feature = "large-engine"))]
pub const ENGINE_MAX_QUARTER: usize = 1442;
/// Quarter-table entries of the largest hemisphere: `hemisphere::quarter_len(128)`.
#[cfg(feature = "large-engine")]
pub const ENGINE_MAX_QUARTER: usize = 10372;
/// Rays on the largest ring of the largest hemisphere (4R): the soft engine's per-ring scratch.
pub const ENGINE_MAX_RING: usize = 4 * ENGINE_MAX_CIRCLES;
/// Jobs a host may keep in flight: their requests (≤ 16 bytes each) sit in the board's receive
/// ring while it works.
pub const ENGINE_MAX_IN_FLIGHT: usize = 8;
/// Recent job ids remembered to recognise repeats.
pub const RECENT_JOBS: usize = 64;
/// Frames of the skeleton stack (paper §6.2) the engine keeps in SRAM.
pub const ENGINE_STACK_DEPTH: usize = 16;
/// Primary specular hits the tracer parks per hemisphere cast; more make it cast the hemisphere
/// again for the next window of them (same rows, more rays; `TraceStats::recasts`).
pub const ENGINE_PENDING: usize = 32;
/// Specular hits one frustum may park (frustum rays reaching another specular patch); beyond,
/// they are cut and counted as overflows.
pub const ENGINE_PARKED: usize = 16;
/// Entries of the lobe-weight table: k + 1 per specular material, k < R (a few materials with
/// the widest lobes of the largest hemisphere).
pub const ENGINE_MAX_LOBES: usize = 2 * ENGINE_MAX_CIRCLES + 32;
/// The specular settings until the host sends its own: the host's defaults, with the board's
/// stack.
pub const ENGINE_DEFAULT_TRACING: TraceSettings = TraceSettings {
    threshold: DEFAULT_THRESHOLD,
    max_bounces: 24,
    stack: ENGINE_STACK_DEPTH as u16,
};

/// What a board's engine reports in the handshake.
pub const ENGINE_CAPACITIES: Capacities = Capacities {
    max_patches: ENGINE_MAX_PATCHES as u16,
    max_sample_rows: MAX_ROWS as u16,
    stack_depth: ENGINE_STACK_DEPTH as u16,
    max_frame_len: MAX_FRAME_LEN as u16,
    max_circles: ENGINE_MAX_CIRCLES as u16,
    max_in_flight: ENGINE_MAX_IN_FLIGHT as u16,
};

/// Sample points per side of a Bezier patch (paper §7: 4×4).
const BEZIER_SIDE: u32 = 4;

/// How many sample points of a scene with `patches` patches fit one [`Request::Shoot`] job
/// (every row can hold one entry per patch): what hosts ask for and boards accept.
pub fn rows_per_job(patches: usize) -> u16 {
    let per = MAX_ROW_ENTRIES / patches.max(1);
    per.clamp(1, MAX_ROWS) as u16
}

/// The side of the sample lattice of patch `patch` for K×K sampling: K for polygons, 4 for
/// Bezier patches (§7).
fn grid_side(patch: &Patch, k: u32) -> u32 {
    match patch.shape {
        Shape::Polygon(_) => k,
        Shape::Bezier(_) => BEZIER_SIDE,
    }
}

/// Samples on patch `patch` for K×K sampling: K² for polygons, 16 for Bezier patches.
pub fn sample_count(patch: &Patch, k: u32) -> u32 {
    let side = grid_side(patch, k);
    side.saturating_mul(side)
}

/// Sample point `q` of a patch (the host's `pass1::sample_points` order: v-major): cell q of
/// its lattice (`grid_sample` on a polygon, `bezier_sample` on a Bezier patch, both
/// [`lattice_sample`]).
pub fn sample_point(patch: &Patch, area: f32, k: u32, q: u32) -> SamplePoint {
    let side = grid_side(patch, k).max(1);
    lattice_sample(&patch.shape, area, side, q % side, q / side)
}

/// A piece of work that needs an accelerator, whichever one the board has.
pub trait AccelJob {
    /// What the job produces.
    type Out: Default;
    /// Runs the job.
    fn run<A: Accelerator>(self, accel: &mut A) -> Self::Out;
}

/// The accelerators of a board.
pub trait AccelProvider {
    /// The engine jobs run on now.
    fn kind(&self) -> AccelKind;
    /// Chooses the engine for the following jobs; `Unsupported` if the board has no such engine.
    fn select(&mut self, kind: AccelKind) -> Result<(), ErrorCode>;
    /// Loads a complete scene (patch memory of a hardware engine); `BadScene` if it cannot.
    fn load(&mut self, patches: &[Patch]) -> Result<(), ErrorCode>;
    /// Runs `job` on the selected engine over `patches` (the scene last loaded).
    fn run<J: AccelJob>(&mut self, patches: &[Patch], job: J) -> J::Out;
    /// Accelerator clock cycles so far (0 for engines without a clock of their own).
    fn cycles(&self) -> u64 {
        0
    }
    /// Sets the CORDIC of the accelerator (iterations, word width) for scenes loaded from now
    /// on; `Ok(true)` if that changed it (the engine then loads its scene again). Engines
    /// without a CORDIC compute in f32 and accept only the model's defaults (24, 32), which
    /// stand for "as exact as f32".
    fn set_cordic(&mut self, iterations: u8, width: u8) -> Result<bool, ErrorCode> {
        if (iterations, width) == (24, 32) {
            Ok(false)
        } else {
            Err(ErrorCode::Unsupported)
        }
    }
}

/// The kernel's f32 engine in fixed buffers: always there, the fallback of every board.
pub struct SoftProvider {
    local: Vec<LocalPatch, ENGINE_MAX_PATCHES>,
    best_t: [f32; ENGINE_MAX_RING],
    best_id: [u32; ENGINE_MAX_RING],
}

impl Default for SoftProvider {
    fn default() -> Self {
        Self::new()
    }
}

impl SoftProvider {
    /// Scratch for [`ENGINE_MAX_PATCHES`] patches and rings of up to [`ENGINE_MAX_RING`] rays.
    pub const fn new() -> Self {
        SoftProvider {
            local: Vec::new(),
            best_t: [0.0; ENGINE_MAX_RING],
            best_id: [0; ENGINE_MAX_RING],
        }
    }

    /// Runs `job` on the soft engine; `None` if the scratch cannot hold `patches`.
    pub fn run_soft<J: AccelJob>(&mut self, patches: &[Patch], job: J) -> Option<J::Out> {
        while self.local.len() < patches.len() {
            self.local.push(LocalPatch::default()).ok()?;
        }
        let scratch = SoftScratch {
            local: &mut self.local,
            best_t: &mut self.best_t,
            best_id: &mut self.best_id,
        };
        let mut accel = SoftAccelerator::new(patches, scratch).ok()?;
        Some(job.run(&mut accel))
    }
}

impl AccelProvider for SoftProvider {
    fn kind(&self) -> AccelKind {
        AccelKind::Soft
    }
    fn select(&mut self, kind: AccelKind) -> Result<(), ErrorCode> {
        match kind {
            AccelKind::Soft => Ok(()),
            _ => Err(ErrorCode::Unsupported),
        }
    }
    fn load(&mut self, patches: &[Patch]) -> Result<(), ErrorCode> {
        if patches.len() > ENGINE_MAX_PATCHES {
            return Err(ErrorCode::TooLong);
        }
        Ok(())
    }
    fn run<J: AccelJob>(&mut self, patches: &[Patch], job: J) -> J::Out {
        // `load` refused more patches than the scratch holds, and jobs only run on a loaded
        // scene, so `None` cannot happen; an empty result keeps it from being a panic path.
        self.run_soft(patches, job).unwrap_or_default()
    }
}

/// Hooks of the machine the engine runs on: a clock for CPU time and the stack's high-water mark.
pub trait Platform {
    /// A monotonic tick count (SysTick on a Cortex-M); 0 if there is none.
    fn ticks(&self) -> u64 {
        0
    }
    /// (deepest stack use, stack size) in bytes; zeros if not measured.
    fn stack(&self) -> (u32, u32) {
        (0, 0)
    }
}

/// A platform without a clock or stack measurement (host tests).
pub struct NoPlatform;
impl Platform for NoPlatform {}

/// Where the scene upload stands.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum SceneState {
    Empty,
    Loading { total: u16 },
    Ready,
}

/// The job engine of a board: scene, hemisphere, configuration, counters.
pub struct Engine<P: AccelProvider, T: Platform> {
    /// The accelerators.
    pub provider: P,
    /// The machine's clock and stack.
    pub platform: T,
    patches: Vec<Patch, ENGINE_MAX_PATCHES>,
    areas: Vec<f32, ENGINE_MAX_PATCHES>,
    /// Bit i: patch i of the upload has arrived.
    received: u64,
    scene: SceneState,
    /// The configuration; jobs are refused until one arrived (`configured`).
    config: JobConfig,
    configured: bool,
    rings: Vec<Ring, ENGINE_MAX_CIRCLES>,
    quarter: Vec<[f32; 2], ENGINE_MAX_QUARTER>,
    /// The form-factor row of one sample point (the tracer accumulates into it), per channel.
    row: [[f32; 3]; ENGINE_MAX_PATCHES],
    /// The surface of every patch: diffuse with column = patch index unless the host sent
    /// another (`SceneSurface`).
    surfaces: Vec<Surface, ENGINE_MAX_PATCHES>,
    /// The lobe-weight table the surfaces' lobes index (`SceneLobes`).
    weights: Vec<f32, ENGINE_MAX_LOBES>,
    /// Δ, bounces and stack frames the host sent; all zero (so a `const` engine stays in
    /// `.bss`) until then, meaning [`ENGINE_DEFAULT_TRACING`].
    tracing: TraceSettings,
    /// The tracer's scratch: parked specular hits and the skeleton stack's frames.
    store: TraceStore,
    /// What the frustums of distinct jobs did.
    specular: SpecularStats,
    dirs: [Vec3; MAX_HITS],
    recent: Deque<u32, RECENT_JOBS>,
    counts: Counters,
}

/// The engine's own counters. Plain integers, so that a `const` engine is all zero bytes and a
/// `static` one lands in `.bss` (no copy of it in flash).
#[derive(Clone, Copy, Debug, Default)]
struct Counters {
    jobs: u32,
    repeats: u32,
    refused: u32,
    rays: u64,
    accel_cycles: u64,
    cpu_ticks: u64,
}

/// What one job did, for the counters.
#[derive(Clone, Copy, Debug, Default)]
struct Work {
    rays: u64,
    specular: SpecularStats,
}

/// No specular settings received (all zero bytes).
const NO_TRACING: TraceSettings = TraceSettings {
    threshold: 0.0,
    max_bounces: 0,
    stack: 0,
};

/// No frustums yet (a `const` so the engine stays all zero bytes).
const NO_SPECULAR: SpecularStats = SpecularStats {
    frustums: 0,
    rays: 0,
    below_threshold: 0,
    cut_weight: 0.0,
    too_deep: 0,
    too_deep_weight: 0.0,
    overflows: 0,
    overflow_weight: 0.0,
    absorbed_weight: 0.0,
    escaped_weight: 0.0,
    high_water: 0,
    recasts: 0,
};

impl<P: AccelProvider, T: Platform> Engine<P, T> {
    /// An engine with no scene.
    pub const fn new(provider: P, platform: T) -> Self {
        Engine {
            provider,
            platform,
            patches: Vec::new(),
            areas: Vec::new(),
            received: 0,
            scene: SceneState::Empty,
            config: JobConfig {
                circles: 0,
                rule: crate::hemisphere::DeltaRule::Paper,
                samples: 0,
                spp: 0,
                camera: None,
                accel: AccelKind::None,
            },
            configured: false,
            rings: Vec::new(),
            quarter: Vec::new(),
            row: [[0.0; 3]; ENGINE_MAX_PATCHES],
            surfaces: Vec::new(),
            weights: Vec::new(),
            tracing: NO_TRACING,
            store: TraceStore {
                pending: Vec::new(),
                parked: Vec::new(),
                frames: Vec::new(),
            },
            specular: NO_SPECULAR,
            dirs: [Vec3::ZERO; MAX_HITS],
            recent: Deque::new(),
            counts: Counters {
                jobs: 0,
                repeats: 0,
                refused: 0,
                rays: 0,
                accel_cycles: 0,
                cpu_ticks: 0,
            },
        }
    }

    /// Drops scene, configuration, remembered jobs and counters.
    pub fn reset(&mut self) {
        self.patches.clear();
        self.areas.clear();
        self.received = 0;
        self.scene = SceneState::Empty;
        self.configured = false;
        self.rings.clear();
        self.quarter.clear();
        self.recent.clear();
        let _ = self.provider.select(self.provider.kind());
        self.counts = Counters::default();
        self.surfaces.clear();
        self.weights.clear();
        self.tracing = NO_TRACING;
        self.specular = NO_SPECULAR;
    }

    /// Δ, bounces and stack frames in use.
    fn tracing(&self) -> TraceSettings {
        if self.tracing.stack == 0 {
            ENGINE_DEFAULT_TRACING
        } else {
            self.tracing
        }
    }

    /// The specular counters and the buffers that bound them.
    pub fn trace_stats(&self) -> TraceStats {
        let s = &self.specular;
        TraceStats {
            frustums: s.frustums,
            frustum_rays: s.rays,
            below_threshold: s.below_threshold,
            too_deep: s.too_deep,
            overflows: s.overflows,
            cut_weight: (s.cut_weight + s.too_deep_weight + s.overflow_weight) as f32,
            recasts: s.recasts,
            stack_high_water: s.high_water as u16,
            stack_frames: self.tracing().stack,
            stack_capacity: ENGINE_STACK_DEPTH as u16,
            pending_capacity: ENGINE_PENDING as u16,
            parked_capacity: ENGINE_PARKED as u16,
            lobe_capacity: ENGINE_MAX_LOBES as u16,
        }
    }

    /// The counters, with the link's.
    pub fn stats(&self, link: super::message::LinkStats) -> EngineStats {
        let (high, size) = self.platform.stack();
        let c = self.counts;
        EngineStats {
            link,
            accel: Some(self.provider.kind()),
            patches: if self.scene == SceneState::Ready {
                self.patches.len() as u16
            } else {
                0
            },
            jobs: c.jobs,
            repeats: c.repeats,
            refused: c.refused,
            rays: c.rays,
            accel_cycles: c.accel_cycles,
            cpu_ticks: c.cpu_ticks,
            stack_high_water: high,
            stack_size: size,
        }
    }

    /// Serves an engine request (`None` for requests that are not the engine's).
    pub fn handle(&mut self, id: u32, req: &Request) -> Option<Response> {
        // Both pass-1 jobs go through one `job` call: the job runner is generic over its
        // closure, and a second copy of it with `shoot` inlined does not fit a board's flash.
        let shoot = match *req {
            Request::Shoot {
                patch,
                first,
                count,
            } => Some((patch, None, first, count)),
            Request::ShootLevel {
                patch,
                k,
                first,
                count,
            } => Some((patch, Some(k), first, count)),
            _ => None,
        };
        let result = if let Some((patch, level, first, count)) = shoot {
            self.job(id, |e| e.shoot(patch, level, first, count))
        } else {
            match req {
                Request::Configure(c) => self.configure(c).map(|()| Response::Configured),
                Request::SceneBegin { patches } => self.scene_begin(*patches),
                Request::ScenePatch { index, area, patch } => {
                    self.scene_patch(*index, *area, patch)
                }
                Request::Trace { first, count } => self.job(id, |e| e.trace(*first, *count)),
                Request::Gather {
                    point,
                    normal,
                    ring,
                    first,
                    count,
                } => self.job(id, |e| e.gather(*point, *normal, *ring, *first, *count)),
                Request::Tracing(t) => self.set_tracing(t).map(|()| Response::Configured),
                Request::SceneSurface { index, surface } => self.scene_surface(*index, surface),
                Request::SceneLobes { first, weights } => self.scene_lobes(*first, weights),
                Request::Cordic { iterations, width } => self.set_cordic(*iterations, *width),
                Request::TraceStats => Ok(Response::TraceStats(self.trace_stats())),
                Request::TraceRow { row, skip } => self.job(id, |e| e.trace_row(*row, *skip)),
                Request::Query {
                    point,
                    normal,
                    skip,
                } => self.job(id, |e| e.query(*point, *normal, *skip)),
                _ => return None,
            }
        };
        Some(result.unwrap_or_else(|code| {
            self.counts.refused = self.counts.refused.wrapping_add(1);
            Response::Error { code }
        }))
    }

    fn configure(&mut self, c: &JobConfig) -> Result<(), ErrorCode> {
        let circles = usize::from(c.circles);
        if !(2..=ENGINE_MAX_CIRCLES).contains(&circles) || c.samples == 0 || c.spp == 0 {
            return Err(ErrorCode::OutOfRange);
        }
        if usize::from(c.spp) > MAX_HITS || c.samples > 256 {
            return Err(ErrorCode::OutOfRange);
        }
        if let Some(cam) = &c.camera {
            let finite = [cam.eye, cam.forward, cam.right, cam.up]
                .iter()
                .all(|v| v.is_finite())
                && cam.tan_half_fov.is_finite();
            if !finite || cam.width == 0 || cam.height == 0 {
                return Err(ErrorCode::OutOfRange);
            }
        }
        self.provider.select(c.accel)?;
        let old = self.config;
        let same_table = self.configured
            && old.circles == c.circles
            && old.rule == c.rule
            && !self.rings.is_empty();
        if !same_table {
            self.rings.clear();
            self.quarter.clear();
            self.rings
                .resize_default(circles)
                .map_err(|_| ErrorCode::TooLong)?;
            let q = crate::hemisphere::quarter_len(u32::from(c.circles));
            self.quarter
                .resize(q, [0.0; 2])
                .map_err(|_| ErrorCode::TooLong)?;
            if build_into(
                u32::from(c.circles),
                c.rule,
                &mut self.rings,
                &mut self.quarter,
            )
            .is_err()
            {
                self.rings.clear();
                self.quarter.clear();
                self.configured = false;
                return Err(ErrorCode::OutOfRange);
            }
        }
        self.config = *c;
        self.configured = true;
        Ok(())
    }

    fn set_tracing(&mut self, t: &TraceSettings) -> Result<(), ErrorCode> {
        if !(t.threshold.is_finite() && t.threshold > 0.0 && t.threshold < 1.0) {
            return Err(ErrorCode::OutOfRange);
        }
        if t.stack == 0 || t.max_bounces == 0 {
            return Err(ErrorCode::OutOfRange);
        }
        if usize::from(t.stack) > ENGINE_STACK_DEPTH {
            return Err(ErrorCode::TooLong);
        }
        self.tracing = *t;
        Ok(())
    }

    fn set_cordic(&mut self, iterations: u8, width: u8) -> Result<Response, ErrorCode> {
        if self.provider.set_cordic(iterations, width)? && self.scene == SceneState::Ready {
            // the loaded scene goes into the accelerator again, under the new CORDIC
            self.provider.load(&self.patches).inspect_err(|_| {
                self.scene = SceneState::Empty;
            })?;
        }
        Ok(Response::Configured)
    }

    /// The scene being uploaded (or the loaded one): its patch count.
    fn scene_total(&self) -> Result<u16, ErrorCode> {
        match self.scene {
            SceneState::Loading { total } => Ok(total),
            SceneState::Ready => Ok(self.patches.len() as u16),
            SceneState::Empty => Err(ErrorCode::NoScene),
        }
    }

    fn scene_surface(&mut self, index: u16, surface: &Surface) -> Result<Response, ErrorCode> {
        let total = self.scene_total()?;
        if index >= total || surface.column.is_some_and(|c| c >= u32::from(total)) {
            return Err(ErrorCode::OutOfRange);
        }
        // Diffuse transmission: a back side's column lies past the patches' (protocol 4); it
        // must still fit the row.
        if surface
            .back_column
            .is_some_and(|c| c as usize >= ENGINE_MAX_PATCHES)
        {
            return Err(ErrorCode::TooLong);
        }
        let bad_k = [surface.reflect, surface.transmit]
            .into_iter()
            .flatten()
            .any(|s| s.k.iter().any(|k| !(k.is_finite() && *k >= 0.0)));
        if bad_k {
            return Err(ErrorCode::BadScene);
        }
        let slot = self
            .surfaces
            .get_mut(usize::from(index))
            .ok_or(ErrorCode::OutOfRange)?;
        *slot = *surface;
        Ok(self.scene_ack(total))
    }

    fn scene_lobes(&mut self, first: u16, weights: &[f32]) -> Result<Response, ErrorCode> {
        let total = self.scene_total()?;
        let start = usize::from(first);
        let end = start + weights.len();
        if end > ENGINE_MAX_LOBES {
            return Err(ErrorCode::TooLong);
        }
        if weights.iter().any(|w| !(w.is_finite() && *w >= 0.0)) {
            return Err(ErrorCode::BadScene);
        }
        if self.weights.len() < end {
            self.weights
                .resize(end, 0.0)
                .map_err(|_| ErrorCode::TooLong)?;
        }
        if let Some(dst) = self.weights.get_mut(start..end) {
            dst.copy_from_slice(weights);
        }
        Ok(self.scene_ack(total))
    }

    fn scene_ack(&self, total: u16) -> Response {
        let loaded = match self.scene {
            SceneState::Ready => total,
            _ => self.received.count_ones() as u16,
        };
        Response::SceneAck { loaded, total }
    }

    fn scene_begin(&mut self, patches: u16) -> Result<Response, ErrorCode> {
        if usize::from(patches) > ENGINE_MAX_PATCHES || patches == 0 {
            return Err(ErrorCode::TooLong);
        }
        // Every patch diffuse with its own column until the host says otherwise.
        self.surfaces.clear();
        for c in 0..u32::from(patches) {
            self.surfaces
                .push(Surface::diffuse(c))
                .map_err(|_| ErrorCode::TooLong)?;
        }
        self.weights.clear();
        self.patches.clear();
        self.areas.clear();
        self.received = 0;
        self.scene = SceneState::Loading { total: patches };
        Ok(Response::SceneAck {
            loaded: 0,
            total: patches,
        })
    }

    fn scene_patch(&mut self, index: u16, area: f32, patch: &Patch) -> Result<Response, ErrorCode> {
        let total = match self.scene {
            SceneState::Loading { total } => total,
            // A repeat of a patch that completed the scene: acknowledge it again.
            SceneState::Ready if usize::from(index) < self.patches.len() => {
                let n = self.patches.len() as u16;
                return Ok(Response::SceneAck {
                    loaded: n,
                    total: n,
                });
            }
            _ => return Err(ErrorCode::NoScene),
        };
        if index >= total {
            return Err(ErrorCode::OutOfRange);
        }
        let finite = patch.hull().iter().all(|v| v.is_finite()) && area.is_finite();
        if !finite {
            return Err(ErrorCode::BadScene);
        }
        let i = usize::from(index);
        // Slots fill in any order: grow with placeholders up to the index.
        while self.patches.len() <= i {
            self.patches.push(*patch).map_err(|_| ErrorCode::TooLong)?;
            self.areas.push(area).map_err(|_| ErrorCode::TooLong)?;
        }
        if let (Some(p), Some(a)) = (self.patches.get_mut(i), self.areas.get_mut(i)) {
            *p = *patch;
            *a = area;
        }
        self.received |= 1u64 << i;
        let loaded = self.received.count_ones() as u16;
        if loaded == total {
            self.provider.load(&self.patches).inspect_err(|_| {
                self.scene = SceneState::Empty;
            })?;
            self.scene = SceneState::Ready;
        }
        Ok(Response::SceneAck { loaded, total })
    }

    /// Runs a job, counting it once per id and timing it.
    fn job(
        &mut self,
        id: u32,
        f: impl FnOnce(&mut Self) -> Result<(Response, Work), ErrorCode>,
    ) -> Result<Response, ErrorCode> {
        let repeat = self.recent.iter().any(|&r| r == id);
        let t0 = self.platform.ticks();
        let c0 = self.provider.cycles();
        let (resp, work) = f(self)?;
        let ticks = self.platform.ticks().wrapping_sub(t0);
        let cycles = self.provider.cycles().wrapping_sub(c0);
        if repeat {
            self.counts.repeats = self.counts.repeats.wrapping_add(1);
        } else {
            if self.recent.is_full() {
                self.recent.pop_front();
            }
            let _ = self.recent.push_back(id);
            self.specular += work.specular;
            let s = &mut self.counts;
            s.jobs = s.jobs.wrapping_add(1);
            s.rays = s.rays.wrapping_add(work.rays);
            s.accel_cycles = s.accel_cycles.wrapping_add(cycles);
            s.cpu_ticks = s.cpu_ticks.wrapping_add(ticks);
        }
        Ok(resp)
    }

    fn ready(&self) -> Result<JobConfig, ErrorCode> {
        if self.scene == SceneState::Ready && self.configured && !self.rings.is_empty() {
            Ok(self.config)
        } else {
            Err(ErrorCode::NoScene)
        }
    }

    /// Rows of sample points `first .. first + count` of `patch`: of the configured K×K grid
    /// (Bezier: the 4×4 of §7), or of the `level`×`level` lattice when given.
    fn shoot(
        &mut self,
        patch: u16,
        level: Option<u16>,
        first: u16,
        count: u16,
    ) -> Result<(Response, Work), ErrorCode> {
        let cfg = self.ready()?;
        // Indices past the scene's patches name the back sides of translucent sheets (protocol
        // 4): patch n + i is the back of patch i, shot from i's points facing the other way.
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
            None => grid_side(&p, u32::from(cfg.samples)),
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
            let normal = if back { -point.normal } else { point.normal };
            let shot = self.shoot_one(point.position, normal, spin_for_sample(q), i as u16)?;
            work.rays += u64::from(shot.rays) + shot.specular.rays;
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

    fn trace(&mut self, first: u32, count: u16) -> Result<(Response, Work), ErrorCode> {
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

    fn trace_row(&mut self, row: u16, skip: u16) -> Result<(Response, Work), ErrorCode> {
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

    /// The weighted reports of an irradiance hemisphere at `point` around `normal`, from `skip`
    /// on. Not inlined into the request dispatch: its walker and scratch then only take stack
    /// while a query runs, not under every other job (a board's stack is tight with the teapot).
    #[inline(never)]
    fn query(
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
                rays: u64::from(shot.rays) + shot.specular.rays,
                specular: shot.specular,
            },
        ))
    }

    fn gather(
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

fn ray_hit(hit: Option<Hit>) -> Option<RayHit> {
    hit.map(|h| RayHit {
        patch: h.patch as u16,
        front: h.front,
        u: h.u,
        v: h.v,
    })
}

/// Fills a scratch Vec to its capacity (it starts empty so a static engine stays in `.bss`).
fn fill<T: Copy, const N: usize>(v: &mut Vec<T, N>, value: T) {
    while v.push(value).is_ok() {}
}

/// The storage of the tracer's scratch, in the engine's static SRAM.
struct TraceStore {
    pending: Vec<Pending, ENGINE_PENDING>,
    parked: Vec<Pending, ENGINE_PARKED>,
    frames: Vec<Frame, ENGINE_STACK_DEPTH>,
}

impl TraceStore {
    /// The scratch of one job, bounded by `tracing` (its stack at most the frames there are).
    fn scratch(&mut self, tracing: TraceSettings) -> TraceScratch<'_> {
        fill(&mut self.pending, Pending::EMPTY);
        fill(&mut self.parked, Pending::EMPTY);
        fill(&mut self.frames, Frame::EMPTY);
        let stack = usize::from(tracing.stack).min(self.frames.len());
        TraceScratch {
            pending: &mut self.pending,
            parked: &mut self.parked,
            skeleton: Skeleton::new(&mut self.frames[..stack]),
            threshold: tracing.threshold,
            max_depth: tracing.max_bounces,
        }
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

/// The window `skip ..` of a job's weighted reports, and their total.
struct Reports<'a> {
    out: &'a mut WeightedHits,
    skip: u32,
    /// The scene's patch count: a back side is reported as `patches` + its patch.
    patches: usize,
}

impl<'a> Reports<'a> {
    fn new(out: &'a mut WeightedHits, skip: u32, patches: usize) -> Self {
        out.total = 0;
        out.hits.clear();
        Reports { out, skip, patches }
    }

    /// Counts a report of ray `ray` reaching `h` with `weight`; kept from `skip` on while the
    /// answer has room. The patch it names is the patch for its front, `patches` + the patch
    /// for the back side of a translucent sheet (the only backs the tracer reports; protocol 4).
    fn report(&mut self, ray: u16, h: &Hit, weight: [f32; 3]) {
        if self.out.total >= self.skip {
            let patch = if h.front {
                h.patch as usize
            } else {
                self.patches + h.patch as usize
            };
            let _ = self.out.hits.push(WeightedHit {
                ray,
                patch: patch as u16,
                u: h.u,
                v: h.v,
                weight,
            });
        }
        self.out.total = self.out.total.saturating_add(1);
    }
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
            |h, weight| reports.report(0, h, weight),
        )
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
