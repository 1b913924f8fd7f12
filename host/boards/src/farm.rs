//! Spreading jobs over boards: one worker thread per link keeps several jobs in flight, and a
//! link that dies or stops answering has its outstanding jobs re-issued elsewhere or after it
//! reconnects (QEMU is rebooted, a serial port reopened; the scene is uploaded again).
//!
//! Rules that make the result exact whatever happens on the links:
//! - a job has one id for its whole life (retries resend the same id, so a board counts it once);
//! - the first answer to a job wins, later ones (a slow board, a retry) are dropped, so no row is
//!   ever counted twice, and the run ends only when every job has its answer;
//! - a board serves requests in order, so an answer to a job means every job sent before it on
//!   that link was lost (or its answer was): those are resent at once;
//! - a link quiet for longer than its timeout gets its jobs resent once, then is reconnected.

use std::collections::VecDeque;
use std::path::PathBuf;
use std::sync::atomic::{AtomicU32, AtomicU64, AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use anyhow::{anyhow, bail, Context, Result};
use hemi_kernel::link::{
    AccelKind, EngineStats, ErrorCode, Feature, HelloInfo, JobConfig, Request, Response,
    TraceSettings, TraceStats, MAX_LOBE_CHUNK, PROTOCOL_2_CORDIC,
};
use hemi_kernel::optics::Surface;
use hemi_kernel::patch::Patch;

use crate::error::describe;
use crate::error::is_refusal;
use crate::link::{Link, Retry};
use crate::qemu::{firmware_elf, Qemu, QemuOptions};

/// One board of a `--backend` list.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum BoardSpec {
    /// The firmware booted in QEMU (a new instance per connection).
    Qemu,
    /// A board (or anything speaking the protocol) on a serial device.
    Serial(String),
}

impl std::fmt::Display for BoardSpec {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BoardSpec::Qemu => write!(f, "qemu"),
            BoardSpec::Serial(p) => write!(f, "serial:{p}"),
        }
    }
}

/// Parses a comma-separated list of boards (`qemu`, `serial:PATH`); `None` if `list` names no
/// board at all (an in-process backend), an error if it mixes boards with other backends.
pub fn parse_boards(list: &str) -> Result<Option<Vec<BoardSpec>>> {
    let mut boards = Vec::new();
    let mut other = Vec::new();
    for item in list.split(',').map(str::trim) {
        match item {
            "qemu" => boards.push(BoardSpec::Qemu),
            s if s.starts_with("serial:") && s.len() > "serial:".len() => {
                boards.push(BoardSpec::Serial(s["serial:".len()..].to_string()))
            }
            s => other.push(s.to_string()),
        }
    }
    match (boards.is_empty(), other.is_empty()) {
        (true, _) => Ok(None),
        (false, true) => Ok(Some(boards)),
        (false, false) => bail!(
            "--backend {list}: `{}` cannot be mixed with boards (qemu, serial:PATH)",
            other.join(",")
        ),
    }
}

/// What every board must hold before it takes jobs: uploaded after each (re)connection.
#[derive(Clone, Debug)]
pub struct Setup {
    /// The scene's patches with the areas the host samples with.
    pub patches: Vec<(Patch, f32)>,
    /// Hemisphere, samples, camera, spp. `accel: AccelKind::None` means each board's own.
    pub config: JobConfig,
    /// The optics of the patches that are not plain diffuse with their own column (the optics
    /// table, `Feature::OpticsTable`; empty for a diffuse scene).
    pub surfaces: Vec<(u16, Surface)>,
    /// The lobe-weight table the surfaces index.
    pub weights: Vec<f32>,
    /// Δ, bounces and stack frames (protocol 3).
    pub tracing: TraceSettings,
}

impl Setup {
    /// Whether the boards must hold an optics table (protocol 3).
    pub fn specular(&self) -> bool {
        self.surfaces.iter().any(|(_, s)| s.is_specular())
    }
}

/// Job ids are 1..=JOB_IDS (the link's own requests use ids above, see `Link::send_as`).
pub const JOB_IDS: u32 = 1 << 21;
/// Reconnection attempts per board and run before it is given up.
const MAX_RECONNECTS: u32 = 4;
/// Timeout of set-up calls (scene upload, configuration).
const CALL_TIMEOUT: Duration = Duration::from_millis(1500);
/// Attempts of each set-up call (a damaged request or answer costs one).
const CALL_ATTEMPTS: u32 = 8;
/// Jobs in flight per link when the board allows more.
const WINDOW: usize = 4;
/// A quiet link's first timeout, before any job time is known.
const BASE_TIMEOUT: Duration = Duration::from_secs(4);

struct Conn {
    link: Link,
    hello: HelloInfo,
    /// Kept for its drop: stops QEMU (after the link, declared first, is closed).
    qemu: Option<Qemu>,
}

struct Slot {
    spec: BoardSpec,
    conn: Option<Conn>,
    /// Whether the current connection holds the current setup.
    set_up: bool,
    /// Whether only the configuration (not the scene) needs sending again.
    config_only: bool,
    dead: bool,
}

/// What happened on the links during the farm's life (for the fault tests and the log).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FarmEvents {
    /// Jobs answered (first answers only).
    pub answered: u64,
    /// Answers dropped because the job already had one.
    pub duplicates: u64,
    /// Jobs sent again (lost request or answer, timeout, dead link).
    pub resent: u64,
    /// Connections re-established.
    pub reconnects: u64,
}

/// A set of boards taking jobs.
pub struct Farm {
    slots: Vec<Mutex<Slot>>,
    firmware: Option<PathBuf>,
    qemu: QemuOptions,
    setup: Mutex<Option<Setup>>,
    next_job: AtomicU32,
    /// Bumped by every [`Farm::set_setup`], so a backend can tell that another replaced its scene.
    generation: AtomicU64,
    events: Mutex<FarmEvents>,
    quiet: bool,
    /// CORDIC iterations and word width for the boards' accelerator model (protocol 3).
    cordic: Mutex<Option<(u8, u8)>>,
}

/// How a farm boots and talks about its boards.
#[derive(Clone, Debug, Default)]
pub struct FarmOptions {
    /// The ELF QEMU boards boot (another build, e.g. the soft-only one, for measurements);
    /// `None`: this checkout's, built if missing ([`firmware_elf`]).
    pub firmware: Option<PathBuf>,
    /// Whether reconnections and re-issued jobs go unlogged.
    pub quiet: bool,
    /// How QEMU boards are started.
    pub qemu: QemuOptions,
}

impl Farm {
    /// Connects to every board (QEMU instances boot in parallel) and handshakes.
    pub fn connect(specs: &[BoardSpec], options: FarmOptions) -> Result<Farm> {
        anyhow::ensure!(!specs.is_empty(), "no boards given");
        let FarmOptions {
            firmware,
            quiet,
            qemu,
        } = options;
        let firmware = if specs.contains(&BoardSpec::Qemu) {
            Some(firmware_elf(firmware.as_deref())?)
        } else {
            firmware
        };
        let farm = Farm {
            slots: specs
                .iter()
                .map(|s| {
                    Mutex::new(Slot {
                        spec: s.clone(),
                        conn: None,
                        set_up: false,
                        config_only: false,
                        dead: false,
                    })
                })
                .collect(),
            firmware,
            qemu,
            setup: Mutex::new(None),
            next_job: AtomicU32::new(0),
            generation: AtomicU64::new(0),
            events: Mutex::new(FarmEvents::default()),
            quiet,
            cordic: Mutex::new(None),
        };
        let results: Vec<Result<()>> = std::thread::scope(|s| {
            let handles: Vec<_> = farm
                .slots
                .iter()
                .map(|slot| {
                    s.spawn(|| {
                        let mut slot = slot.lock().map_err(|_| anyhow!("poisoned"))?;
                        let conn = farm.open(&slot.spec)?;
                        slot.conn = Some(conn);
                        Ok(())
                    })
                })
                .collect();
            handles
                .into_iter()
                .map(|h| {
                    h.join()
                        .unwrap_or_else(|_| Err(anyhow!("connect panicked")))
                })
                .collect()
        });
        for (r, spec) in results.into_iter().zip(specs) {
            r.with_context(|| format!("connecting to board {spec}"))?;
        }
        Ok(farm)
    }

    fn open(&self, spec: &BoardSpec) -> Result<Conn> {
        match spec {
            BoardSpec::Qemu => {
                let elf = self
                    .firmware
                    .as_deref()
                    .context("no firmware ELF for QEMU")?;
                let qemu = Qemu::boot(elf, &self.qemu)?;
                let pty = qemu.pty().to_string_lossy().into_owned();
                let mut link = Link::open_serial(&pty)?;
                let hs = link.handshake(Retry::default()).with_context(|| {
                    format!("handshake with QEMU on {pty}: {}", qemu.stderr_text())
                })?;
                Ok(Conn {
                    link,
                    hello: hs.hello,
                    qemu: Some(qemu),
                })
            }
            BoardSpec::Serial(path) => {
                let mut link = Link::open_serial(path)?;
                let hs = link
                    .handshake(Retry::default())
                    .with_context(|| format!("handshake with the board on {path}"))?;
                Ok(Conn {
                    link,
                    hello: hs.hello,
                    qemu: None,
                })
            }
        }
    }

    /// The handshakes of the connected boards (in `--backend` order; `None` while reconnecting).
    pub fn hellos(&self) -> Vec<Option<HelloInfo>> {
        self.slots
            .iter()
            .map(|s| {
                s.lock()
                    .ok()
                    .and_then(|s| s.conn.as_ref().map(|c| c.hello.clone()))
            })
            .collect()
    }

    /// Process ids of the QEMU instances (fault tests kill them).
    pub fn qemu_pids(&self) -> Vec<Option<u32>> {
        self.slots
            .iter()
            .map(|s| {
                s.lock().ok().and_then(|s| {
                    s.conn
                        .as_ref()
                        .and_then(|c| c.qemu.as_ref().map(|q| q.pid()))
                })
            })
            .collect()
    }

    /// What happened on the links so far.
    pub fn events(&self) -> FarmEvents {
        self.events.lock().map(|e| *e).unwrap_or_default()
    }

    /// The smallest capacities over the connected boards.
    pub fn capacities(&self) -> Option<hemi_kernel::link::Capacities> {
        self.hellos()
            .into_iter()
            .flatten()
            .map(|h| h.caps)
            .reduce(|a, b| hemi_kernel::link::Capacities {
                max_patches: a.max_patches.min(b.max_patches),
                max_sample_rows: a.max_sample_rows.min(b.max_sample_rows),
                stack_depth: a.stack_depth.min(b.stack_depth),
                max_frame_len: a.max_frame_len.min(b.max_frame_len),
                max_circles: a.max_circles.min(b.max_circles),
                max_in_flight: a.max_in_flight.min(b.max_in_flight),
            })
    }

    /// The CORDIC settings (`--cordic-iterations`, `--cordic-width`) every board gets with its
    /// configuration; a board whose engine cannot apply them refuses (an error frame) and the
    /// run stops with that refusal.
    pub fn set_cordic(&self, iterations: u32, width: u32) -> Result<()> {
        let it = u8::try_from(iterations).context("--cordic-iterations")?;
        let w = u8::try_from(width).context("--cordic-width")?;
        *self.cordic.lock().map_err(|_| anyhow!("poisoned"))? = Some((it, w));
        for slot in &self.slots {
            if let Ok(mut s) = slot.lock() {
                s.config_only = s.set_up || s.config_only;
                s.set_up = false;
            }
        }
        Ok(())
    }

    /// Sets what the boards must hold; each board gets it before its next job (the scene is
    /// uploaded again only when the patches or their optics changed). Returns the new setup
    /// generation.
    pub fn set_setup(&self, setup: Setup) -> Result<u64> {
        if let Some(caps) = self.capacities() {
            anyhow::ensure!(
                setup.patches.len() <= usize::from(caps.max_patches),
                "the scene has {} patches; the board holds at most {}",
                setup.patches.len(),
                caps.max_patches
            );
            anyhow::ensure!(
                setup.config.circles <= caps.max_circles,
                "--circles {}: the board builds hemispheres of at most {} circles",
                setup.config.circles,
                caps.max_circles
            );
            anyhow::ensure!(
                setup.tracing.stack <= caps.stack_depth,
                "--stack {}: the board's skeleton stack holds {} frames",
                setup.tracing.stack,
                caps.stack_depth
            );
        }
        let mut cur = self.setup.lock().map_err(|_| anyhow!("poisoned"))?;
        let same_scene = cur.as_ref().is_some_and(|c| {
            c.patches.len() == setup.patches.len()
                && c.patches
                    .iter()
                    .zip(&setup.patches)
                    .all(|(a, b)| a.0 == b.0 && a.1.to_bits() == b.1.to_bits())
                && c.surfaces == setup.surfaces
                && c.weights.len() == setup.weights.len()
                && c.weights
                    .iter()
                    .zip(&setup.weights)
                    .all(|(a, b)| a.to_bits() == b.to_bits())
        });
        *cur = Some(setup);
        drop(cur);
        for slot in &self.slots {
            if let Ok(mut s) = slot.lock() {
                // Only the configuration changed: a board that holds the scene gets just that.
                s.config_only = same_scene && s.set_up;
                s.set_up = false;
            }
        }
        Ok(self.generation.fetch_add(1, Ordering::AcqRel) + 1)
    }

    /// Uploads the setup to a connected board (the configuration only, if `config_only`).
    fn upload(&self, conn: &mut Conn, config_only: bool) -> Result<()> {
        let setup = self
            .setup
            .lock()
            .map_err(|_| anyhow!("poisoned"))?
            .clone()
            .context("no scene set up for the boards")?;
        let link = &mut conn.link;
        let total = u16::try_from(setup.patches.len()).context("too many patches")?;
        let call = |link: &mut Link, req: &Request| -> Result<Response> {
            let mut last = anyhow!("not tried");
            for _ in 0..CALL_ATTEMPTS {
                match link.call(req, CALL_TIMEOUT) {
                    Ok(r) => return Ok(r),
                    // the board answered no: asking again would not change that
                    Err(e) if is_refusal(&e) => return Err(e),
                    Err(e) => last = e,
                }
            }
            Err(last)
        };
        let mut config = setup.config;
        if config.accel == AccelKind::None {
            config.accel = conn.hello.accel;
        }
        match call(link, &Request::Configure(config))? {
            Response::Configured => {}
            other => bail!("unexpected answer to Configure: {other:?}"),
        }
        let cordic = *self.cordic.lock().map_err(|_| anyhow!("poisoned"))?;
        if conn.hello.supports(Feature::Tracing) {
            let t = setup.tracing;
            match call(link, &Request::Tracing(t)).with_context(|| {
                format!(
                    "specular settings (--stack {}, Δ {}, {} bounces)",
                    t.stack, t.threshold, t.max_bounces
                )
            })? {
                Response::Configured => {}
                other => bail!("unexpected answer to Tracing: {other:?}"),
            }
        } else {
            anyhow::ensure!(
                !setup.specular(),
                "the board speaks protocol {}: it cannot hold specular surfaces (protocol 3)",
                conn.hello.protocol
            );
        }
        match cordic {
            Some((iterations, width)) if conn.hello.supports(Feature::Cordic) => {
                let req = Request::Cordic { iterations, width };
                match call(link, &req).with_context(|| {
                    format!(
                        "{:?} engine: --cordic-iterations {iterations} --cordic-width {width}",
                        config.accel
                    )
                })? {
                    Response::Configured => {}
                    other => bail!("unexpected answer to Cordic: {other:?}"),
                }
            }
            _ => {
                let (it, w) = PROTOCOL_2_CORDIC;
                anyhow::ensure!(
                    conn.hello.supports(Feature::Cordic) || cordic.is_none_or(|c| c == (it, w)),
                    "the board speaks protocol {}: it cannot take CORDIC settings (protocol 3) \
                     and computes with {it} iterations on {w}-bit words; pass \
                     --cordic-iterations {it} --cordic-width {w} to use it",
                    conn.hello.protocol
                )
            }
        }
        if config_only {
            return Ok(());
        }
        match call(link, &Request::SceneBegin { patches: total })? {
            Response::SceneAck { .. } => {}
            other => bail!("unexpected answer to SceneBegin: {other:?}"),
        }
        if conn.hello.supports(Feature::LobeTable) {
            for (c, chunk) in setup.weights.chunks(MAX_LOBE_CHUNK).enumerate() {
                let req = Request::SceneLobes {
                    first: u16::try_from(c * MAX_LOBE_CHUNK).context("lobe table too long")?,
                    weights: heapless::Vec::from_slice(chunk)
                        .map_err(|_| anyhow!("lobe chunk too long"))?,
                };
                match call(link, &req)
                    .with_context(|| format!("lobe table of {} weights", setup.weights.len()))?
                {
                    Response::SceneAck { .. } => {}
                    other => bail!("unexpected answer to SceneLobes: {other:?}"),
                }
            }
            // `Surface` gained `back_column` (translucent sheets) after protocol 3 was first
            // built, which changed SceneSurface's encoding: protocol 4 is the first whose boards
            // all read it.
            anyhow::ensure!(
                setup.surfaces.is_empty() || conn.hello.supports(Feature::OpticsTable),
                "the board speaks protocol {}: its optics table lacks the back sides' columns \
                 (protocol 4); flash a newer firmware for specular scenes",
                conn.hello.protocol
            );
            for &(index, surface) in &setup.surfaces {
                match call(link, &Request::SceneSurface { index, surface })
                    .with_context(|| format!("optics of patch {index}"))?
                {
                    Response::SceneAck { .. } => {}
                    other => bail!("unexpected answer to SceneSurface: {other:?}"),
                }
            }
        }
        for (i, (patch, area)) in setup.patches.iter().enumerate() {
            let req = Request::ScenePatch {
                index: i as u16,
                area: *area,
                patch: *patch,
            };
            match call(link, &req).with_context(|| format!("uploading patch {i}"))? {
                Response::SceneAck { .. } => {}
                other => bail!("unexpected answer to ScenePatch: {other:?}"),
            }
        }
        Ok(())
    }

    /// The generation of the current setup (see [`Farm::set_setup`]).
    pub fn generation(&self) -> u64 {
        self.generation.load(Ordering::Acquire)
    }

    /// Whether the current setup has specular surfaces.
    pub fn specular(&self) -> bool {
        self.setup
            .lock()
            .ok()
            .and_then(|s| s.as_ref().map(Setup::specular))
            .unwrap_or(false)
    }

    /// The specular counters of every connected board that speaks protocol 3.
    pub fn trace_stats(&self) -> Vec<Result<TraceStats>> {
        self.slots
            .iter()
            .map(|slot| {
                let mut s = slot.lock().map_err(|_| anyhow!("poisoned"))?;
                let conn = s.conn.as_mut().context("not connected")?;
                anyhow::ensure!(
                    conn.hello.supports(Feature::TraceStats),
                    "protocol {}",
                    conn.hello.protocol
                );
                match conn.link.call(&Request::TraceStats, CALL_TIMEOUT)? {
                    Response::TraceStats(st) => Ok(st),
                    other => bail!("unexpected answer to TraceStats: {other:?}"),
                }
            })
            .collect()
    }

    /// The engine counters of every connected board.
    pub fn engine_stats(&self) -> Vec<Result<EngineStats>> {
        self.slots
            .iter()
            .map(|slot| {
                let mut s = slot.lock().map_err(|_| anyhow!("poisoned"))?;
                let conn = s.conn.as_mut().context("not connected")?;
                match conn.link.call(&Request::EngineStats, CALL_TIMEOUT)? {
                    Response::EngineStats(st) => Ok(st),
                    other => bail!("unexpected answer to EngineStats: {other:?}"),
                }
            })
            .collect()
    }

    /// Runs `jobs` over all boards; returns their answers in job order. `progress` gets the
    /// index of each job as its (first) answer comes. Fails if a board refuses a job (a bug or a
    /// setting outside its limits) or if every board is lost.
    pub fn run(
        &self,
        jobs: &[Request],
        progress: &(dyn Fn(usize) + Sync),
    ) -> Result<Vec<Response>> {
        let n = jobs.len();
        let n32 = u32::try_from(n).context("too many jobs")?;
        // Job ids: 1..=JOB_IDS, so a request's id is a varint of at most 3 bytes (a Shoot
        // request stays within 15 bytes on the wire); unique over the last 2^21 jobs.
        let base = self.next_job.fetch_add(n32, Ordering::Relaxed);
        let id_of = |i: usize| (base.wrapping_add(i as u32) % JOB_IDS) + 1;
        let queue: Mutex<VecDeque<usize>> = Mutex::new((0..n).collect());
        let results: Mutex<Vec<Option<Response>>> = Mutex::new(vec![None; n]);
        let remaining = AtomicUsize::new(n);
        let fatal: Mutex<Option<anyhow::Error>> = Mutex::new(None);
        let shared = Shared {
            jobs,
            id_of: &id_of,
            queue: &queue,
            results: &results,
            remaining: &remaining,
            fatal: &fatal,
            progress,
        };
        std::thread::scope(|s| {
            for slot in &self.slots {
                let shared = &shared;
                s.spawn(move || {
                    if let Ok(mut slot) = slot.lock() {
                        self.work(&mut slot, shared);
                    }
                });
            }
        });
        if let Some(e) = fatal.into_inner().ok().flatten() {
            return Err(e);
        }
        let results = results.into_inner().map_err(|_| anyhow!("poisoned"))?;
        let missing = results.iter().filter(|r| r.is_none()).count();
        if missing > 0 {
            bail!("{missing} of {n} jobs unanswered: every board was lost");
        }
        Ok(results.into_iter().flatten().collect())
    }

    fn note(&self, f: impl FnOnce(&mut FarmEvents)) {
        if let Ok(mut e) = self.events.lock() {
            f(&mut e);
        }
    }

    fn log(&self, spec: &BoardSpec, msg: std::fmt::Arguments<'_>) {
        if !self.quiet {
            eprintln!("board {spec}: {msg}");
        }
    }

    /// One board's worker.
    fn work(&self, slot: &mut Slot, sh: &Shared<'_>) {
        Worker {
            farm: self,
            slot,
            sh,
            inflight: VecDeque::new(),
            reconnects: 0,
            slowest: Duration::ZERO,
            last_answer: Instant::now(),
            resent_on_timeout: false,
        }
        .run();
    }
}

/// What a worker does after a step.
enum Flow {
    /// Go on with this round.
    On,
    /// Start the next round.
    Next,
    /// Stop working.
    Stop,
}

/// One board's worker: keeps up to a window of jobs in flight on its link, re-sends what the
/// board's in-order answers show lost, and reconnects (at most [`MAX_RECONNECTS`] times) when
/// the link fails.
struct Worker<'a, 'b> {
    farm: &'a Farm,
    slot: &'a mut Slot,
    sh: &'a Shared<'b>,
    /// Jobs sent and not answered, oldest first, with when they were sent.
    inflight: VecDeque<(usize, Instant)>,
    reconnects: u32,
    /// The longest a job has taken (per place in the window), for the timeout.
    slowest: Duration,
    last_answer: Instant,
    resent_on_timeout: bool,
}

impl Worker<'_, '_> {
    fn run(mut self) {
        while self.sh.remaining.load(Ordering::Acquire) > 0 && !self.sh.failed() && !self.slot.dead
        {
            match self.ready() {
                Flow::On => {}
                Flow::Next => continue,
                Flow::Stop => break,
            }
            match self.round() {
                Flow::On | Flow::Next => {}
                Flow::Stop => break,
            }
        }
        self.requeue();
    }

    /// Hands the unanswered jobs back to the queue, oldest first.
    fn requeue(&mut self) {
        if let Ok(mut q) = self.sh.queue.lock() {
            for (i, _) in self.inflight.drain(..).rev() {
                q.push_front(i);
            }
        }
    }

    fn log(&self, msg: std::fmt::Arguments<'_>) {
        self.farm.log(&self.slot.spec, msg);
    }

    /// Drops the link: its jobs go back to the queue and the next round reconnects.
    fn drop_link(&mut self) {
        self.requeue();
        self.slot.conn = None;
    }

    /// A connected board that holds the setup, (re)connecting and uploading as needed.
    fn ready(&mut self) -> Flow {
        if self.slot.conn.is_some() && self.slot.set_up {
            return Flow::On;
        }
        if self.slot.conn.is_none() {
            if let flow @ (Flow::Next | Flow::Stop) = self.reconnect() {
                return flow;
            }
        }
        let Some(conn) = self.slot.conn.as_mut() else {
            return Flow::Next;
        };
        match self.farm.upload(conn, self.slot.config_only) {
            Ok(()) => {
                self.slot.set_up = true;
                self.slot.config_only = false;
                self.last_answer = Instant::now();
                Flow::On
            }
            Err(e) if is_refusal(&e) => {
                // The board answered and said no: reconnecting would not change that.
                let spec = self.slot.spec.clone();
                self.sh.fail(e.context(format!("setting up board {spec}")));
                Flow::Stop
            }
            Err(e) => {
                self.log(format_args!("set-up failed: {e:#}"));
                self.slot.conn = None;
                self.slot.config_only = false;
                Flow::Next
            }
        }
    }

    /// Opens the link again, or gives the board up after [`MAX_RECONNECTS`] tries.
    fn reconnect(&mut self) -> Flow {
        if self.reconnects >= MAX_RECONNECTS {
            let n = self.reconnects;
            self.log(format_args!("given up after {n} reconnections"));
            self.slot.dead = true;
            return Flow::Stop;
        }
        self.reconnects += 1;
        match self.farm.open(&self.slot.spec) {
            Ok(c) => {
                self.slot.conn = Some(c);
                self.slot.config_only = false;
                self.farm.note(|e| e.reconnects += 1);
                self.log(format_args!("reconnected"));
                Flow::On
            }
            Err(e) => {
                self.log(format_args!("reconnection failed: {e:#}"));
                std::thread::sleep(Duration::from_millis(200));
                Flow::Next
            }
        }
    }

    /// Fills the window, then waits a little for an answer.
    fn round(&mut self) -> Flow {
        let Some(conn) = self.slot.conn.as_ref() else {
            return Flow::Next;
        };
        let window = usize::from(conn.hello.caps.max_in_flight).clamp(1, WINDOW);
        if !self.fill(window) {
            self.drop_link();
            return Flow::Next;
        }
        if self.inflight.is_empty() {
            // Nothing left to take; other boards may still hand jobs back.
            std::thread::sleep(Duration::from_millis(5));
            self.last_answer = Instant::now();
            return Flow::Next;
        }
        let Some(conn) = self.slot.conn.as_mut() else {
            return Flow::Next;
        };
        match conn.link.recv_any(Duration::from_millis(50)) {
            Ok(Some((id, resp))) => self.answered(id, resp),
            Ok(None) => {
                self.quiet(window);
                Flow::On
            }
            Err(e) => {
                self.log(format_args!("link lost: {e:#}"));
                let n = self.inflight.len() as u64;
                self.farm.note(|e| e.resent += n);
                self.drop_link();
                Flow::On
            }
        }
    }

    /// Sends queued jobs until `window` are in flight; false if the link failed.
    fn fill(&mut self, window: usize) -> bool {
        while self.inflight.len() < window {
            let next = self.sh.queue.lock().ok().and_then(|mut q| q.pop_front());
            let Some(i) = next else { break };
            if self.sh.done(i) {
                continue;
            }
            self.inflight.push_back((i, Instant::now()));
            if let Err(e) = self.send(i) {
                self.log(format_args!("link lost while sending: {e:#}"));
                return false;
            }
        }
        true
    }

    fn send(&mut self, i: usize) -> Result<()> {
        let conn = self.slot.conn.as_mut().context("not connected")?;
        conn.link.send_as((self.sh.id_of)(i), &self.sh.jobs[i])
    }

    /// An answer with id `id`: stored, or the board's complaint acted on; what was sent before
    /// it and is still unanswered was lost (the board serves in order) and is sent again.
    fn answered(&mut self, id: u32, resp: Response) -> Flow {
        let sh = self.sh;
        let Some(pos) = self.inflight.iter().position(|(i, _)| (sh.id_of)(*i) == id) else {
            // A stale answer (a job resent and answered twice): already handled.
            return Flow::Next;
        };
        let (i, sent) = self.inflight.remove(pos).unwrap_or((0, Instant::now()));
        self.last_answer = Instant::now();
        self.resent_on_timeout = false;
        self.slowest = self.slowest.max(sent.elapsed() / (pos as u32 + 1));
        match resp {
            Response::Error {
                code: ErrorCode::NoScene,
            } => {
                // The board lost its scene (it was reset): set it up again.
                self.inflight.push_front((i, sent));
                self.requeue();
                self.slot.set_up = false;
                return Flow::Next;
            }
            Response::Error { code } => {
                let spec = &self.slot.spec;
                let job = &sh.jobs[i];
                sh.fail(anyhow!(
                    "board {spec} refused job {i} ({job:?}): {}",
                    describe(code)
                ));
                return Flow::Stop;
            }
            resp => match sh.store(i, resp) {
                true => self.farm.note(|e| e.answered += 1),
                false => self.farm.note(|e| e.duplicates += 1),
            },
        }
        self.resend_before(pos);
        Flow::On
    }

    /// Sends again, same id, the `pos` oldest jobs in flight that are still unanswered.
    fn resend_before(&mut self, pos: usize) {
        let lost: Vec<usize> = self.inflight.iter().take(pos).map(|(i, _)| *i).collect();
        for i in lost {
            self.inflight.retain(|(j, _)| *j != i);
            if self.sh.done(i) {
                continue;
            }
            self.farm.note(|e| e.resent += 1);
            // Moved to the back: it is now the newest request on the link.
            self.inflight.push_back((i, Instant::now()));
            if self.send(i).is_err() {
                self.drop_link();
                return;
            }
        }
    }

    /// No answer for a while: first send every job in flight again (maybe only the newest
    /// request, or its answer, was lost), then reconnect.
    fn quiet(&mut self, window: usize) {
        let timeout = BASE_TIMEOUT + self.slowest * (2 * window as u32 + 2);
        if self.last_answer.elapsed() <= timeout {
            return;
        }
        if !self.resent_on_timeout {
            self.resent_on_timeout = true;
            self.last_answer = Instant::now();
            let jobs: Vec<usize> = self.inflight.iter().map(|(i, _)| *i).collect();
            for i in jobs {
                self.farm.note(|e| e.resent += 1);
                if self.send(i).is_err() {
                    break;
                }
            }
        } else {
            self.log(format_args!("no answer for {timeout:?}: reconnecting"));
            let n = self.inflight.len() as u64;
            self.farm.note(|e| e.resent += n);
            self.drop_link();
            self.resent_on_timeout = false;
        }
    }
}

struct Shared<'a> {
    jobs: &'a [Request],
    id_of: &'a (dyn Fn(usize) -> u32 + Sync),
    queue: &'a Mutex<VecDeque<usize>>,
    results: &'a Mutex<Vec<Option<Response>>>,
    remaining: &'a AtomicUsize,
    fatal: &'a Mutex<Option<anyhow::Error>>,
    progress: &'a (dyn Fn(usize) + Sync),
}

impl Shared<'_> {
    fn done(&self, i: usize) -> bool {
        self.results
            .lock()
            .map(|r| r.get(i).is_some_and(Option::is_some))
            .unwrap_or(true)
    }
    /// Stores the first answer to job `i`; false if it had one.
    fn store(&self, i: usize, resp: Response) -> bool {
        let Ok(mut r) = self.results.lock() else {
            return false;
        };
        match r.get_mut(i) {
            Some(slot @ None) => {
                *slot = Some(resp);
                self.remaining.fetch_sub(1, Ordering::AcqRel);
                (self.progress)(i);
                true
            }
            _ => false,
        }
    }
    fn fail(&self, e: anyhow::Error) {
        if let Ok(mut f) = self.fatal.lock() {
            f.get_or_insert(e);
        }
    }
    fn failed(&self) -> bool {
        self.fatal.lock().map(|f| f.is_some()).unwrap_or(true)
    }
}
