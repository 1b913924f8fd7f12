//! The job engine of a board: its state, and the dispatch of engine requests to the jobs
//! (one file each beside this one), the upload ([`super::upload`]) and the settings
//! ([`super::config`]).
//!
//! Every request is checked before any work: indices, counts and settings outside the board's
//! limits are refused with an error code, never indexed blindly. A job's result depends only on
//! the scene, the configuration and the job, so a job sent again (same id) is answered with the
//! same bits; the engine remembers the ids of recent jobs so a repeat is not counted twice.

use heapless::{Deque, Vec};

use super::capacity::{
    ENGINE_MAX_CIRCLES, ENGINE_MAX_LOBES, ENGINE_MAX_PATCHES, ENGINE_MAX_QUARTER, ENGINE_PARKED,
    ENGINE_PENDING, ENGINE_STACK_DEPTH, RECENT_JOBS,
};
use super::platform::Platform;
use super::provider::AccelProvider;
use super::store::TraceStore;
use super::upload::SceneState;
use crate::geometry::Vec3;
use crate::hemisphere::Ring;
use crate::link::message::{
    AccelKind, EngineStats, ErrorCode, JobConfig, LinkStats, Request, Response, TraceSettings,
    TraceStats, MAX_HITS,
};
use crate::link::JobHandler;
use crate::optics::Surface;
use crate::patch::Patch;
use crate::specular::SpecularStats;

/// The job engine of a board: scene, hemisphere, configuration, counters.
pub struct Engine<P: AccelProvider, T: Platform> {
    /// The accelerators.
    pub provider: P,
    /// The machine's clock and stack.
    pub platform: T,
    pub(super) patches: Vec<Patch, ENGINE_MAX_PATCHES>,
    pub(super) areas: Vec<f32, ENGINE_MAX_PATCHES>,
    /// Bit i: patch i of the upload has arrived.
    pub(super) received: u64,
    pub(super) scene: SceneState,
    /// The configuration; jobs are refused until one arrived (`configured`).
    pub(super) config: JobConfig,
    pub(super) configured: bool,
    pub(super) rings: Vec<Ring, ENGINE_MAX_CIRCLES>,
    pub(super) quarter: Vec<[f32; 2], ENGINE_MAX_QUARTER>,
    /// The form-factor row of one sample point (the tracer accumulates into it), per channel.
    pub(super) row: [[f32; 3]; ENGINE_MAX_PATCHES],
    /// The surface of every patch: diffuse with column = patch index unless the host sent
    /// another (`SceneSurface`).
    pub(super) surfaces: Vec<Surface, ENGINE_MAX_PATCHES>,
    /// The lobe-weight table the surfaces' lobes index (`SceneLobes`).
    pub(super) weights: Vec<f32, ENGINE_MAX_LOBES>,
    /// Δ, bounces and stack frames the host sent; all zero (so a `const` engine stays in
    /// `.bss`) until then, meaning [`super::ENGINE_DEFAULT_TRACING`].
    pub(super) tracing: TraceSettings,
    /// The tracer's scratch: parked specular hits and the skeleton stack's frames.
    pub(super) store: TraceStore,
    /// What the frustums of distinct jobs did.
    pub(super) specular: SpecularStats,
    pub(super) dirs: [Vec3; MAX_HITS],
    pub(super) recent: Deque<u32, RECENT_JOBS>,
    pub(super) counts: Counters,
}

/// The engine's own counters. Plain integers, so that a `const` engine is all zero bytes and a
/// `static` one lands in `.bss` (no copy of it in flash).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Counters {
    jobs: u32,
    repeats: u32,
    refused: u32,
    rays: u64,
    accel_cycles: u64,
    cpu_ticks: u64,
}

/// What one job did, for the counters.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Work {
    pub(super) rays: u64,
    pub(super) specular: SpecularStats,
}

/// No specular settings received (all zero bytes).
pub(super) const NO_TRACING: TraceSettings = TraceSettings {
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
    over_budget: 0,
    over_budget_weight: 0.0,
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
            store: TraceStore::new(),
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

    /// The specular counters and the buffers that bound them.
    pub fn trace_stats(&self) -> TraceStats {
        let s = &self.specular;
        TraceStats {
            frustums: s.frustums,
            frustum_rays: s.rays,
            below_threshold: s.below_threshold,
            too_deep: s.too_deep,
            overflows: s.overflows,
            cut_weight: (s.cut_weight
                + s.too_deep_weight
                + s.overflow_weight
                + s.over_budget_weight) as f32,
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
    pub fn stats(&self, link: LinkStats) -> EngineStats {
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
                Request::Hemisphere {
                    origin,
                    normal,
                    spin,
                    origin_patch,
                    skip,
                } => {
                    let shot = crate::tracer::Shot {
                        origin: *origin,
                        normal: *normal,
                        spin: *spin,
                        origin_patch: origin_patch.map(u32::from),
                        want_uv: true,
                    };
                    self.job(id, |e| e.hemisphere(&shot, *skip))
                }
                Request::Cast { rays } => self.job(id, |e| e.cast(rays)),
                _ => return None,
            }
        };
        Some(result.unwrap_or_else(|code| {
            self.counts.refused = self.counts.refused.wrapping_add(1);
            Response::Error { code }
        }))
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

    pub(super) fn ready(&self) -> Result<JobConfig, ErrorCode> {
        if self.scene == SceneState::Ready && self.configured && !self.rings.is_empty() {
            Ok(self.config)
        } else {
            Err(ErrorCode::NoScene)
        }
    }
}

/// The link's server hands the requests beyond its own to the engine through this (the link
/// knows nothing of jobs; the engine plugs in).
impl<P: AccelProvider, T: Platform> JobHandler for Engine<P, T> {
    fn handle(&mut self, id: u32, req: &Request) -> Option<Response> {
        Engine::handle(self, id, req)
    }
    fn reset(&mut self) {
        Engine::reset(self)
    }
    fn engine_stats(&self, link: LinkStats) -> Option<EngineStats> {
        Some(self.stats(link))
    }
}
