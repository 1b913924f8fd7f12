//! The messages of the link. Host → board: [`Request`]; board → host: [`Response`].
//!
//! Compatibility rule (see docs/protocol.md): postcard encodes an enum as a varint variant index
//! followed by the variant's fields. New messages are therefore **appended** as new variants and
//! never inserted or reordered; an existing variant's fields never change without bumping
//! [`PROTOCOL_VERSION`]. A receiver that sees an index it does not know answers
//! [`ErrorCode::Unsupported`] (see `codec`), so a newer host talking to an older board gets a clear
//! refusal instead of garbage.

use heapless::{String, Vec};
use serde::{Deserialize, Serialize};

use crate::camera::Camera;
use crate::geometry::Vec3;
use crate::hemisphere::DeltaRule;
use crate::optics::Surface;
use crate::patch::Patch;
use crate::specular::Via;

/// Version of the wire protocol. Bumped on any incompatible change to an existing message, and
/// when messages are appended (so a host knows which a board understands).
///
/// - 2: scene upload, Shoot, Trace, Gather.
/// - 3: the optics table (`SceneSurface`, `SceneLobes`), the specular settings (`Tracing`), the
///   model's CORDIC settings (`Cordic`) and the specular counters (`TraceStats`); every message
///   of version 2 is unchanged.
/// - 4: `ShootLevel` (pass-1 jobs on a lattice of any k, for adaptive sampling) and `Query`
///   (irradiance through specular surfaces); every message of version 3 is unchanged. The
///   optics table is read as this build encodes it, with the back sides of translucent sheets.
/// - 5: `Hemisphere` (the field's element transport: a sample point's whole hemisphere, with
///   how each report came) and `Cast` (single rays with their distances: exact direct light's
///   shadow rays, `hemi trace`); every message of version 4 is unchanged.
///
/// [`Feature`] names each of these, and [`HelloInfo::supports`] says whether a link has it.
pub const PROTOCOL_VERSION: u16 = 5;
/// The oldest protocol this build still speaks: the handshake settles on the older of the two
/// sides' versions if it is at least this, and the host sends only that version's messages.
pub const MIN_PROTOCOL_VERSION: u16 = 2;
/// The accelerator's reset CORDIC configuration (iterations, word width): hdl-model's
/// `CordicConfig::DEFAULT`, which a test holds equal (the kernel cannot name it). It is what a
/// host asks when its user chose none, so an engine without a CORDIC (soft: f32) takes it as
/// "no particular setting" and refuses any other. 24 and 32 until session 44.
pub const RESET_CORDIC: (u8, u8) = (20, 24);
/// The CORDIC a board of protocol 2, which cannot take [`Request::Cordic`], computes with: the
/// reset configuration of its time.
pub const PROTOCOL_2_CORDIC: (u8, u8) = (24, 32);
/// Longest firmware build string in the handshake.
pub const BUILD_LEN: usize = 48;
/// Largest data block of the link-test messages ([`Request::Sink`], [`Response::Source`]).
pub const MAX_BULK: usize = 512;
/// Largest number of form-factor entries (over all rows) in one [`Response::Rows`]: each is at
/// most 14 bytes on the wire (patch index varint ≤ 2, three f32), so 64 of them and their row
/// lengths fit one frame.
pub const MAX_ROW_ENTRIES: usize = 64;
/// Largest number of rows (sample points) in one [`Request::Shoot`] job.
pub const MAX_ROWS: usize = 64;
/// Lobe weights in one [`Request::SceneLobes`] (4 + 5 bytes each on the wire at most).
pub const MAX_LOBE_CHUNK: usize = 16;
/// Largest number of ray hits in one [`Response::Hits`]: each is at most 12 bytes on the wire
/// (option tag, patch varint ≤ 2, front flag, u and v as f32), so 80 fit one frame.
pub const MAX_HITS: usize = 80;
/// Largest number of rays in one [`Request::Cast`]: each takes 24 bytes (origin and direction
/// as f32), so 20 keep the request no larger in memory than the link test's `Sink`, and the
/// slot a board decodes every request into does not grow (a 64 KiB board's stack has about
/// 1.6 KiB to spare with the teapot); each answer is at most 18 bytes on the wire.
pub const MAX_CAST: usize = 20;

/// Host → board. No heap on the board: a message is decoded once into one bounded stack slot,
/// as large as the largest variant (the link test's `Sink`, then a full `Cast`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Request {
    /// Handshake: the host's protocol version. Answered by [`Response::Hello`]. Idempotent, so the
    /// host may repeat it until it gets an answer (a pty drops bytes at start-up).
    Hello {
        /// The host's [`PROTOCOL_VERSION`].
        protocol: u16,
    },
    /// Liveness check, answered by [`Response::Pong`] with the same nonce.
    Ping {
        /// Echoed back unchanged.
        nonce: u32,
    },
    /// Asks for the link counters, answered by [`Response::LinkStats`].
    LinkStats,
    /// Drops all job state and zeroes the counters; answered by [`Response::ResetDone`] (the reply
    /// still reports the counters from before the reset).
    Reset,
    /// Link test, host → board direction: the board checksums `data` and answers
    /// [`Response::SinkAck`]. Measures upstream throughput.
    Sink {
        /// Arbitrary bytes.
        data: Vec<u8, MAX_BULK>,
    },
    /// Link test, board → host direction: asks for `len` bytes of a known pattern
    /// (`byte[i] = i as u8`), answered by [`Response::Source`]. Measures downstream throughput.
    Source {
        /// Number of bytes wanted; more than [`MAX_BULK`] is refused with
        /// [`ErrorCode::TooLong`].
        len: u16,
    },
    /// Sets how jobs are run: hemisphere, samples per patch, pass-2 camera, accelerator.
    /// Answered [`Response::Configured`]; idempotent. Refused [`ErrorCode::TooLong`] beyond the
    /// board's capacities, [`ErrorCode::Unsupported`] for an accelerator it does not have.
    Configure(JobConfig),
    /// Starts uploading a scene of `patches` patches; drops the previous scene. Answered
    /// [`Response::SceneAck`]. Idempotent (a repeat restarts the upload).
    SceneBegin {
        /// Number of patches that follow, at most `max_patches`.
        patches: u16,
    },
    /// One patch of the scene being uploaded, with the area the host's sampling uses (so the
    /// board's sample weights and Bezier sample points match the host's bit for bit). Answered
    /// [`Response::SceneAck`]; storing the same index twice is harmless. When the last missing
    /// patch arrives the board loads the scene into its accelerator.
    ScenePatch {
        /// Index of the patch, `< patches` of the `SceneBegin`.
        index: u16,
        /// The patch's area (the host's `ScenePatch::area`).
        area: f32,
        /// The geometry.
        patch: Patch,
    },
    /// Pass-1 job: shoot the hemisphere from sample points `first .. first + count` of patch
    /// `patch` (the board derives the points with `hemi_kernel::sampling`, K from
    /// [`JobConfig::samples`], spin from `spin_for_sample`). Since protocol 4, `patch` = n + i
    /// (n the scene's patches) names the back side of translucent patch i: i's points, facing
    /// the other way. Answered [`Response::Rows`]. The
    /// request id is the job id: a job sent again with the same id is answered again but counted
    /// once.
    Shoot {
        /// The patch the sample points lie on.
        patch: u16,
        /// First sample index (v-major: q = b·K + a).
        first: u16,
        /// Number of sample points; `count × patches ≤ MAX_ROW_ENTRIES`.
        count: u16,
    },
    /// Pass-2 job: eye rays through pixels `first .. first + count` (row-major), `spp` each, of
    /// the configured camera. Answered [`Response::Hits`] (pixel-major, sample-minor).
    Trace {
        /// First pixel index.
        first: u32,
        /// Number of pixels; `count × spp ≤ MAX_HITS`.
        count: u16,
    },
    /// Query job (irradiance): the hemisphere placed at `point` around `normal` (no spin), rays
    /// `first .. first + count` of ring `ring`. Answered [`Response::Hits`] in ray order.
    Gather {
        /// Where the hemisphere is placed.
        point: Vec3,
        /// The surface normal there.
        normal: Vec3,
        /// Ring j.
        ring: u16,
        /// First ray k on that ring.
        first: u16,
        /// Number of rays, at most `MAX_HITS`.
        count: u16,
    },
    /// Asks for the engine's counters, answered [`Response::EngineStats`].
    EngineStats,
    // ---- protocol 3 ----
    /// How specular surfaces are followed (paper §6.2, §6.5): Δ, bounces and the skeleton
    /// stack's frames. Answered [`Response::Configured`]; refused [`ErrorCode::TooLong`] for a
    /// stack deeper than the board's `stack_depth`, [`ErrorCode::OutOfRange`] for a bad Δ.
    Tracing(TraceSettings),
    /// The optics of patch `index` of the scene being uploaded (after `SceneBegin`; every patch
    /// not sent is diffuse with column = its index). Answered [`Response::SceneAck`].
    SceneSurface {
        /// Patch index, `< patches` of the `SceneBegin`.
        index: u16,
        /// Its column, reflection and transmission.
        surface: Surface,
    },
    /// Lobe weights `first .. first + weights.len()` of the scene's lobe-weight table (after
    /// `SceneBegin`, which empties it). Answered [`Response::SceneAck`]; refused
    /// [`ErrorCode::TooLong`] beyond the board's table.
    SceneLobes {
        /// Index of the first weight.
        first: u16,
        /// The weights ([`crate::frustum::lobe_weights`]).
        weights: Vec<f32, MAX_LOBE_CHUNK>,
    },
    /// The CORDIC of the board's accelerator model: iterations and word width, as the host's
    /// `--cordic-iterations` and `--cordic-width`. Answered [`Response::Configured`]; refused
    /// [`ErrorCode::Unsupported`] by an engine that cannot change them (soft: f32, so only
    /// [`RESET_CORDIC`] is accepted), [`ErrorCode::OutOfRange`] for values the model refuses.
    Cordic {
        /// CORDIC iterations.
        iterations: u8,
        /// Word width in bits.
        width: u8,
    },
    /// Asks for the specular counters, answered [`Response::TraceStats`].
    TraceStats,
    /// Pass-2 job through specular surfaces: the eye rays of image row `row` (`spp` per pixel),
    /// the whole row in one `trace_pixels` call as the host's pass 2 makes it (so the frustums
    /// are spun alike), every ray or frustum ray that reaches a diffuse side (a front, or the
    /// back of a translucent sheet) reported with its weight. Answered [`Response::Weighted`]
    /// with reports `skip ..` (at most [`MAX_WEIGHTED`]) and the row's total, so the host asks
    /// again with a larger `skip` for the rest (the row is traced again). Row and skip < 16384
    /// keep it ≤ 16 bytes.
    TraceRow {
        /// Image row.
        row: u16,
        /// Reports of the row already received.
        skip: u16,
    },
    /// Pass-1 job of adaptive sampling (protocol 4): as [`Request::Shoot`], but the sample
    /// points are cells `first .. first + count` (v-major: q = b·k + a) of the k×k lattice of
    /// the patch (`hemi_kernel::sampling::lattice_sample`, also on Bezier patches), whatever
    /// [`JobConfig::samples`] says. Answered [`Response::Rows`]. A frame of 16 bytes with a
    /// 3-byte job id and k ≤ 127.
    ShootLevel {
        /// The patch the sample points lie on (n + i: the back side of translucent patch i, as
        /// for [`Request::Shoot`]).
        patch: u16,
        /// The lattice's cells per side (≥ 1; cells past index 65 535 cannot be named).
        k: u16,
        /// First cell index.
        first: u16,
        /// Number of sample points; `count × patches ≤ MAX_ROW_ENTRIES`.
        count: u16,
    },
    /// Irradiance job through specular surfaces (protocol 4): the whole hemisphere placed at
    /// `point` around `normal` (no spin) in one `tracer::shoot` call, as the host's irradiance
    /// query makes it, every ray or frustum ray that reaches a diffuse side (a front, or the
    /// back of a translucent sheet) reported with its weight (δD times what the mirrors passed
    /// on). Answered [`Response::Weighted`] with reports `skip ..` (at most [`MAX_WEIGHTED`];
    /// `ray` is 0) and the total, so the host asks again with a larger `skip` for the rest (the
    /// hemisphere is shot again). A query with more than 65 535 reports cannot be read whole:
    /// the host says so.
    Query {
        /// Where the hemisphere is placed.
        point: Vec3,
        /// The surface normal there.
        normal: Vec3,
        /// Reports already received.
        skip: u16,
    },
    // ---- protocol 5 ----
    /// The field's hemisphere job (protocol 5): the whole hemisphere of a sample point as pass 1
    /// casts it (placed at `origin` around `normal`, turned by `spin`, leaving out
    /// `origin_patch`), in one `tracer::shoot` call, every ray or frustum ray that reaches a
    /// diffuse side reported with its weight and how it got there ([`PathHit`]). Answered
    /// [`Response::Paths`] with reports `skip ..` (at most [`MAX_PATHS`]), the total and the
    /// shot's ray counts, so the host asks again with a larger `skip` for the rest (the
    /// hemisphere is shot again). A frame of at most 40 bytes.
    Hemisphere {
        /// The sample point.
        origin: Vec3,
        /// The surface normal there.
        normal: Vec3,
        /// The hemisphere's turn about the normal (`rotation::spin_for_sample`), in radians.
        spin: f32,
        /// The patch the point lies on, which its rays do not see.
        origin_patch: Option<u16>,
        /// Reports already received.
        skip: u16,
    },
    /// Single rays (protocol 5): the nearest hit of each, with its distance. Answered
    /// [`Response::Nearest`] in ray order.
    Cast {
        /// (origin, direction) of each ray, at most [`MAX_CAST`].
        rays: Vec<(Vec3, Vec3), MAX_CAST>,
    },
}

impl Request {
    /// Number of variants: variant indices at or above it are unknown to this build.
    pub const VARIANTS: u32 = 23;
}

/// Board → host. Every response carries the id of the request it answers (see `codec`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Response {
    /// The handshake.
    Hello(HelloInfo),
    /// Answer to [`Request::Ping`].
    Pong {
        /// The request's nonce.
        nonce: u32,
    },
    /// Answer to [`Request::LinkStats`].
    LinkStats(LinkStats),
    /// Answer to [`Request::Reset`], with the counters as they were before it.
    ResetDone(LinkStats),
    /// Answer to [`Request::Sink`]: how many bytes arrived and their CRC-32.
    SinkAck {
        /// Number of data bytes received.
        len: u16,
        /// CRC-32 (IEEE) of those bytes, so the host can check them end to end.
        crc: u32,
    },
    /// Answer to [`Request::Source`].
    Source {
        /// `len` bytes, `byte[i] = i as u8`.
        data: Vec<u8, MAX_BULK>,
    },
    /// The request could not be served. The response's id is the request's when it could be read,
    /// else [`NO_ID`](super::codec::NO_ID).
    Error {
        /// Why.
        code: ErrorCode,
    },
    /// Answer to [`Request::Configure`].
    Configured,
    /// Answer to [`Request::SceneBegin`] and [`Request::ScenePatch`].
    SceneAck {
        /// Patches of the scene received so far.
        loaded: u16,
        /// Patches announced by `SceneBegin`.
        total: u16,
    },
    /// Answer to [`Request::Shoot`]: one sparse row per sample point.
    Rows(Rows),
    /// Answer to [`Request::Trace`] and [`Request::Gather`]: the nearest hit of every ray, in
    /// request order.
    Hits(Vec<Option<RayHit>, MAX_HITS>),
    /// Answer to [`Request::EngineStats`].
    EngineStats(EngineStats),
    // ---- protocol 3 ----
    /// Answer to [`Request::TraceStats`].
    TraceStats(TraceStats),
    /// Answer to [`Request::TraceRow`].
    Weighted(WeightedHits),
    // ---- protocol 5 ----
    /// Answer to [`Request::Hemisphere`].
    Paths(PathHits),
    /// Answer to [`Request::Cast`]: the nearest hit of every ray, in request order.
    Nearest(Vec<Option<CastHit>, MAX_CAST>),
}

impl Response {
    /// Number of variants: variant indices at or above it are unknown to this build.
    pub const VARIANTS: u32 = 16;
}

/// Largest number of reports in one [`Response::Paths`]: each is at most 32 bytes on the wire
/// (a [`WeightedHit`] without its ray, and the bounces, last patch and mirror flag of its
/// path), so 30 fit one frame with the counts.
pub const MAX_PATHS: usize = 30;

/// The reports of one [`Request::Hemisphere`] job, a window at a time.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PathHits {
    /// Reports of the whole hemisphere.
    pub total: u32,
    /// Rays of the hemisphere cast (its own, not the frustums').
    pub rays: u32,
    /// Of those, the rays whose nearest hit is the back of a patch.
    pub back_hits: u32,
    /// Reports `skip .. skip + hits.len()`, in the order the tracer made them.
    pub hits: Vec<PathHit, MAX_PATHS>,
}

/// A ray of a hemisphere (or a frustum ray it spawned) that reached a diffuse side, and how.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PathHit {
    /// Patch index; the board's patch count plus the index for the back side of a translucent
    /// sheet.
    pub patch: u16,
    /// Parametric u.
    pub u: f32,
    /// Parametric v.
    pub v: f32,
    /// Weight per channel (δD times what the specular surfaces on the way passed on).
    pub weight: [f32; 3],
    /// How it got there: the tracer's [`Via`].
    pub via: Via,
}

/// A single ray's nearest hit as the link carries it, with its distance.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CastHit {
    /// Patch index.
    pub patch: u16,
    /// Whether the front side was hit.
    pub front: bool,
    /// Distance along the ray (the direction as sent, not normalised).
    pub t: f32,
    /// Parametric u.
    pub u: f32,
    /// Parametric v.
    pub v: f32,
}

/// Largest number of reports in one [`Response::Weighted`]: each is at most 26 bytes on the wire
/// (ray and patch varints ≤ 3 each, u, v and three weights as f32), so 36 fit one frame.
pub const MAX_WEIGHTED: usize = 36;

/// Weighted hits of one image row (see [`Request::TraceRow`]).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct WeightedHits {
    /// Reports of the whole row.
    pub total: u32,
    /// Reports `skip .. skip + hits.len()`, in the order the tracer made them.
    pub hits: Vec<WeightedHit, MAX_WEIGHTED>,
}

/// A ray (eye or frustum) that reached the front of a diffuse patch in pass 2.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct WeightedHit {
    /// Eye ray of the row: pixel × spp + sample.
    pub ray: u16,
    /// Patch index; the board's patch count plus the index for the back side of a translucent
    /// sheet (protocol 4).
    pub patch: u16,
    /// Parametric u.
    pub u: f32,
    /// Parametric v.
    pub v: f32,
    /// Weight per channel relative to the eye ray (1 for a direct view).
    pub weight: [f32; 3],
}

/// How specular surfaces are followed (sent with [`Request::Tracing`]); the host's
/// `--specular-threshold`, `--max-bounces` and `--stack`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct TraceSettings {
    /// Δ of §6.5.
    pub threshold: f32,
    /// The most specular bounces a path may take.
    pub max_bounces: u16,
    /// Frames of the skeleton stack, at most the board's `stack_depth`.
    pub stack: u16,
}

/// What the specular transport of a board's distinct jobs did (protocol 3), with the buffers
/// that bound it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TraceStats {
    /// Frustums shot.
    pub frustums: u64,
    /// Frustum rays cast.
    pub frustum_rays: u64,
    /// Frustums cut below Δ.
    pub below_threshold: u64,
    /// Frustums cut at the bounce limit.
    pub too_deep: u64,
    /// Frustums (or parked hits) lost to a full stack or park.
    pub overflows: u64,
    /// Weight cut below Δ, at the bounce limit and by overflows, summed (form-factor units).
    pub cut_weight: f32,
    /// Extra hemisphere casts because the park of primary specular hits was full.
    pub recasts: u32,
    /// The deepest the skeleton stack has been, in frames.
    pub stack_high_water: u16,
    /// Frames of the stack in use (the configured `stack`).
    pub stack_frames: u16,
    /// The board's stack capacity, in frames.
    pub stack_capacity: u16,
    /// Primary specular hits parked per cast.
    pub pending_capacity: u16,
    /// Specular hits one frustum may park.
    pub parked_capacity: u16,
    /// Entries of the lobe-weight table.
    pub lobe_capacity: u16,
}

/// How the board runs jobs (sent with [`Request::Configure`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct JobConfig {
    /// Hemisphere circles R, at most `max_circles`.
    pub circles: u16,
    /// Delta form factor rule.
    pub rule: DeltaRule,
    /// K: K×K sample points per polygon patch (Bezier patches always have 4×4).
    pub samples: u16,
    /// Eye rays per pixel for [`Request::Trace`].
    pub spp: u16,
    /// The pass-2 camera, if pass 2 will run.
    pub camera: Option<Camera>,
    /// The engine wanted: the board's own kind, or [`AccelKind::Soft`] (always available).
    pub accel: AccelKind,
}

/// Sparse form-factor rows of one [`Request::Shoot`] job: row r holds the next `lens[r]`
/// entries of `entries`, ascending by patch, only non-zero F_iq,j.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Rows {
    /// Entries per row.
    pub lens: Vec<u16, MAX_ROWS>,
    /// (patch j, F_iq,j per channel) of all rows, concatenated.
    pub entries: Vec<(u16, [f32; 3]), MAX_ROW_ENTRIES>,
}

/// A ray's nearest hit as the link carries it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RayHit {
    /// Patch index.
    pub patch: u16,
    /// Whether the front side was hit.
    pub front: bool,
    /// Parametric u.
    pub u: f32,
    /// Parametric v.
    pub v: f32,
}

/// The engine's counters since boot or the last [`Request::Reset`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct EngineStats {
    /// The link counters (frame errors among them).
    pub link: LinkStats,
    /// The engine answering jobs now.
    pub accel: Option<AccelKind>,
    /// Patches of the loaded scene (0 while none is complete).
    pub patches: u16,
    /// Distinct jobs served (a job id seen again is not counted).
    pub jobs: u32,
    /// Jobs served again because their id came again (host retries).
    pub repeats: u32,
    /// Jobs refused with an error frame.
    pub refused: u32,
    /// Rays cast by distinct jobs.
    pub rays: u64,
    /// Accelerator clock cycles spent by distinct jobs (0 for the soft engine).
    pub accel_cycles: u64,
    /// CPU time spent in distinct jobs, in SysTick ticks (0 where the board has no tick source).
    pub cpu_ticks: u64,
    /// Deepest stack use since boot, in bytes (0 if the board does not measure it).
    pub stack_high_water: u32,
    /// Stack size, in bytes.
    pub stack_size: u32,
}

/// What kind of engine answers: decides what "shoot" and "trace" cost and how exact they are.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum AccelKind {
    /// No engine: the board answers link messages only.
    None,
    /// The kernel in software (f32) on the CPU.
    Soft,
    /// The bit-accurate cycle-level model of the accelerator.
    Model,
    /// The accelerator's registers (an FPGA on the memory bus).
    Mmio,
}

/// Fixed limits of a board, so the host can size jobs without trial and error.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Capacities {
    /// Patches of a loaded scene.
    pub max_patches: u16,
    /// Sample rows (hemisphere jobs) in flight.
    pub max_sample_rows: u16,
    /// Depth of the skeleton stack of specular frustums.
    pub stack_depth: u16,
    /// Largest frame the board accepts and sends, payload plus CRC, before stuffing.
    pub max_frame_len: u16,
    /// Largest hemisphere (circles R) the board can build.
    pub max_circles: u16,
    /// Jobs the host may keep in flight (the board's receive ring holds their requests).
    pub max_in_flight: u16,
}

/// The handshake.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct HelloInfo {
    /// The board's [`PROTOCOL_VERSION`].
    pub protocol: u16,
    /// Firmware name, version and git revision.
    pub build: String<BUILD_LEN>,
    /// The engine that will run jobs.
    pub accel: AccelKind,
    /// The board's limits.
    pub caps: Capacities,
}

impl HelloInfo {
    /// Whether the link can use `feature`: the handshake's version (the older of the two sides')
    /// is at least the one that added it. Hosts ask this instead of comparing versions, so
    /// what a version brought is written once, in [`Feature::since`].
    pub fn supports(&self, feature: Feature) -> bool {
        self.protocol >= feature.since()
    }
}

/// What each protocol version added, by name: a host asks [`HelloInfo::supports`] before it
/// sends the messages of a feature, and names the feature (its `Display`) when a board lacks
/// it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Feature {
    /// The job engine (v2): scene upload, `Configure`, `Shoot`, `Trace`, `Gather`,
    /// `EngineStats`. Every version this build speaks has it.
    Jobs,
    /// The specular settings, Δ, bounces and stack frames (`Tracing`, v3).
    Tracing,
    /// The accelerator's CORDIC iterations and word width (`Cordic`, v3).
    Cordic,
    /// The specular counters (`TraceStats`, v3).
    TraceStats,
    /// The lobe-weight table of specular materials (`SceneLobes`, v3).
    LobeTable,
    /// Pass 2 through specular surfaces, weighted reports per image row (`TraceRow`, v3).
    TraceRow,
    /// The optics table as this build encodes it (`SceneSurface` with the back sides'
    /// columns): `Surface` gained `back_column` after v3 was first built, so v3 builds do not
    /// agree on its encoding and only v4 boards can be sent one (specular and translucent
    /// scenes).
    OpticsTable,
    /// The back sides of translucent sheets named past the patches (patch n + i in `Shoot`,
    /// `ShootLevel` and the weighted reports, v4).
    BackSides,
    /// Pass-1 jobs on a k×k lattice of any k, for adaptive sampling (`ShootLevel`, v4).
    ShootLevel,
    /// Irradiance through specular surfaces (`Query`, v4).
    Query,
    /// The field's element transport, hemispheres with their paths (`Hemisphere`, v5).
    Paths,
    /// Single rays with their distances (`Cast`, v5).
    Cast,
}

impl Feature {
    /// Every feature, oldest first.
    pub const ALL: [Feature; 12] = [
        Feature::Jobs,
        Feature::Tracing,
        Feature::Cordic,
        Feature::TraceStats,
        Feature::LobeTable,
        Feature::TraceRow,
        Feature::OpticsTable,
        Feature::BackSides,
        Feature::ShootLevel,
        Feature::Query,
        Feature::Paths,
        Feature::Cast,
    ];

    /// The protocol version that added it (see [`PROTOCOL_VERSION`] for each version's list).
    pub const fn since(self) -> u16 {
        match self {
            Feature::Jobs => 2,
            Feature::Tracing
            | Feature::Cordic
            | Feature::TraceStats
            | Feature::LobeTable
            | Feature::TraceRow => 3,
            Feature::OpticsTable | Feature::BackSides | Feature::ShootLevel | Feature::Query => 4,
            Feature::Paths | Feature::Cast => 5,
        }
    }

    /// What it is, in words for a message ("the board lacks {name} (protocol {since})").
    pub const fn name(self) -> &'static str {
        match self {
            Feature::Jobs => "the job engine",
            Feature::Tracing => "specular settings (Tracing)",
            Feature::Cordic => "CORDIC settings (Cordic)",
            Feature::TraceStats => "specular counters (TraceStats)",
            Feature::LobeTable => "the lobe-weight table (SceneLobes)",
            Feature::TraceRow => "pass 2 through mirrors (TraceRow jobs)",
            Feature::OpticsTable => "the optics table with back sides (SceneSurface)",
            Feature::BackSides => "back sides of translucent sheets",
            Feature::ShootLevel => "adaptive sampling (ShootLevel jobs)",
            Feature::Query => "irradiance through mirrors (Query jobs)",
            Feature::Paths => "the field's hemispheres (Hemisphere jobs)",
            Feature::Cast => "single rays (Cast jobs)",
        }
    }
}

impl core::fmt::Display for Feature {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.name())
    }
}

/// Counters of the link since boot or the last [`Request::Reset`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct LinkStats {
    /// Frames that passed framing and CRC checks.
    pub frames_ok: u32,
    /// Frames dropped for a wrong CRC.
    pub bad_crc: u32,
    /// Frames dropped for invalid COBS or being shorter than a CRC.
    pub bad_framing: u32,
    /// Frames dropped for exceeding the receive buffer.
    pub too_long: u32,
    /// Good frames whose message did not decode.
    pub malformed: u32,
    /// Good frames with a message this build does not know.
    pub unsupported: u32,
    /// Bytes lost because the receive ring was full.
    pub rx_overruns: u32,
    /// Bytes received.
    pub bytes_rx: u32,
    /// Bytes sent.
    pub bytes_tx: u32,
}

/// Why a request was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum ErrorCode {
    /// The frame's CRC did not match.
    BadCrc,
    /// The frame was not valid COBS or too short.
    BadFraming,
    /// The frame, or what the request asked for, exceeds the board's limits.
    TooLong,
    /// The frame was intact but its message did not decode.
    Malformed,
    /// The message is unknown to this build (newer protocol), or asks for an engine the board
    /// does not have.
    Unsupported,
    /// A job arrived before a complete scene and a configuration.
    NoScene,
    /// An index or setting is out of range (patch, sample, pixel, ring, circles).
    OutOfRange,
    /// The accelerator cannot load the scene (e.g. a patch kind it cannot intersect).
    BadScene,
}
