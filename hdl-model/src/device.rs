//! The accelerator as a whole: register file, FIFOs and control around the angle unit, the
//! rotator and the intersection unit. [`Device::read`] and [`Device::write`] are the bus side;
//! [`Device::tick`] is one clock.
//!
//! ```text
//!  RAY_IN ─► ray FIFO ─┬─► rotator (3 CORDIC pipes) ─► ray queue ─► intersection unit ─► (u,v) ─► result FIFO ─► RESULT_OUT
//!                      └─► frame entries ─► angle unit (vectoring CORDIC) ─► ψ θ φ ─┘
//! ```
//!
//! Flow control is by credits, as in hardware: an entry leaves the ray FIFO only while fewer
//! than [`Params::ray_slots`] rays are between it and the result FIFO, so the ray queue and the
//! intersection unit's buffers always have room and no pipeline stalls mid-way; only the
//! intersection unit's retirement waits when the result FIFO is full.
//!
//! The front end is `rays_per_clock` wide ([`Params`]): that many entries leave the ray FIFO,
//! enter as many rotators, start in the intersection unit and retire into the result FIFO per
//! clock. Besides the register window, rays can enter and results leave through the stream port
//! ([`Device::stream_push`], [`Device::stream_pop`]): a DMA pair that moves `rays_per_clock`
//! entries each way per clock between the MCU's memory and the FIFOs.

use crate::cordic::CordicConfig;
use crate::fifo::Fifo;
use crate::format::{Angle, Coord, Unit};
use crate::frame::{FrameRequest, FrameUnit};
use crate::intersect::bezier::{
    BezierStats, SubdivConfig, BEZIER_ROWS, MAX_DEPTH, RECIP_LATENCY, STACK_ENTRIES,
};
use crate::intersect::patch_mem::{PatchMem, PATCH_WORDS};
use crate::intersect::{cull, IntersectUnit, LaneStats, RayIn, RayOut};
use crate::params::{Params, MAX_RAYS_PER_CLOCK};
use crate::regs::{self, bz_config, config, ctrl, error, irq, mode, result, skip, status};
use crate::rotator::{RotIn, Rotator};

/// Ray FIFO depth (entries).
pub const RAY_FIFO_DEPTH: usize = 32;
/// Result FIFO depth (results): what CAPS bits 15:8 can say. Until session 24 it was also every
/// build's credits (now [`Params::ray_slots`]).
pub const RESULT_FIFO_DEPTH: usize = 255;
/// Ray queue between the rotators and the intersection unit (covered by the credits).
const QUEUE_DEPTH: usize = crate::intersect::RAY_SLOTS;

/// The reset value of CONFIG: the reset CORDIC configuration ([`CordicConfig::DEFAULT`], 20
/// iterations on 24-bit words) and 16 (u,v) levels.
pub const CONFIG_RESET: u32 = CordicConfig::DEFAULT.iterations
    | (CordicConfig::DEFAULT.width << config::WIDTH_SHIFT)
    | (16 << config::DEPTH_SHIFT);
/// The reset value of BZ_CONFIG: depth 10, 26-bit control points.
pub const BZ_CONFIG_RESET: u32 = SubdivConfig::DEFAULT.depth << bz_config::DEPTH_SHIFT
    | SubdivConfig::DEFAULT.coord_width << bz_config::CWIDTH_SHIFT;

/// What a ray entry carries through the units.
#[derive(Clone, Copy, Debug, Default)]
pub struct Info {
    mode: u32,
    error: bool,
    origin: [Coord; 3],
    skip: Option<u32>,
    /// the frame a rotating entry was turned by, and its direction before the turn
    frame: Option<[Angle; 3]>,
    dir_ref: [Unit; 3],
}

/// What a ray carries past the rotator to its result: the rest of its [`Info`] is in the ray's
/// own fields by then, and a copy of it in each queue and buffer slot was time the model spent.
#[derive(Clone, Copy, Debug, Default)]
struct Tag {
    mode: u32,
    error: bool,
}

/// A ray FIFO entry: a ray (with its latched mode and origin) or a frame command, kept in order.
#[derive(Clone, Copy, Debug, Default)]
struct Entry {
    frame: Option<FrameRequest>,
    mode: u32,
    origin: [Coord; 3],
    skip: Option<u32>,
    dir: [Unit; 3],
}

/// Decoded CONFIG: CORDIC parameters and (u,v) depth, if valid.
pub fn decode_config(v: u32) -> Option<(CordicConfig, u32)> {
    let cfg = CordicConfig {
        iterations: (v >> config::ITER_SHIFT) & 0x1F,
        width: (v >> config::WIDTH_SHIFT) & 0x3F,
    };
    let depth = (v >> config::DEPTH_SHIFT) & 0x1F;
    (cfg.is_valid() && (config::MIN_DEPTH..=config::MAX_DEPTH).contains(&depth))
        .then_some((cfg, depth))
}

/// Decoded BZ_CONFIG, if valid for the unit's stack.
pub fn decode_bz_config(v: u32) -> Option<SubdivConfig> {
    let cfg = SubdivConfig {
        depth: (v >> bz_config::DEPTH_SHIFT) & 0x1F,
        coord_width: (v >> bz_config::CWIDTH_SHIFT) & 0x3F,
    };
    cfg.is_valid_for(STACK_ENTRIES).then_some(cfg)
}

/// The accelerator.
#[derive(Clone, Debug)]
pub struct Device {
    config_reg: u32,
    config_active: u32,
    bz_config_reg: u32,
    bz_config_active: u32,
    enable: bool,
    error: u32,
    irq_status: u32,
    irq_enable: u32,
    cycles: u64,
    busy_cycles: u64,
    cycle_hi: u32,
    busy_hi: u32,
    results_done: u32,
    mode: u32,
    origin: [Coord; 3],
    skip_reg: u32,
    normal: [Unit; 3],
    spin: [Unit; 2],
    phi: [Unit; 2],
    theta: [Unit; 2],
    staging: [Unit; 3],
    staged: usize,
    ray_fifo: Fifo<Entry, RAY_FIFO_DEPTH>,
    result_fifo: Fifo<[u32; 4], RESULT_FIFO_DEPTH>,
    result_word: usize,
    frame: FrameUnit,
    frame_valid: bool,
    params: Params,
    /// The CONFIG whose iterations, width and depth the units were synthesised with, the only
    /// one APPLY_CONFIG then takes (an RTL build's units are fixed); `None`: the model's units
    /// follow any valid CONFIG.
    built_for: Option<u32>,
    rotators: [Rotator<Info>; MAX_RAYS_PER_CLOCK as usize],
    queue: Fifo<RayIn<Tag>, QUEUE_DEPTH>,
    intersect: IntersectUnit<Tag>,
    mem: PatchMem,
    patch_addr: u32,
    patch_count: u32,
    was_busy: bool,
}

impl Default for Device {
    fn default() -> Self {
        Self::new()
    }
}

impl Device {
    /// The default build after power-on reset (patch memory zero, CONFIG at [`CONFIG_RESET`]).
    pub fn new() -> Self {
        Self::with_params(Params::DEFAULT)
    }

    /// A device built with `params` (which must be valid), after power-on reset.
    pub fn with_params(params: Params) -> Self {
        assert!(params.is_valid(), "invalid build parameters {params:?}");
        let (cfg, depth) = decode_config(CONFIG_RESET).expect("reset configuration is valid");
        let subdiv = decode_bz_config(BZ_CONFIG_RESET).expect("reset configuration is valid");
        Device {
            config_reg: CONFIG_RESET,
            config_active: CONFIG_RESET,
            bz_config_reg: BZ_CONFIG_RESET,
            bz_config_active: BZ_CONFIG_RESET,
            enable: false,
            error: 0,
            irq_status: 0,
            irq_enable: 0,
            cycles: 0,
            busy_cycles: 0,
            cycle_hi: 0,
            busy_hi: 0,
            results_done: 0,
            mode: mode::TRACE,
            origin: [Coord::ZERO; 3],
            skip_reg: 0,
            normal: [Unit::ZERO; 3],
            spin: [Unit::ONE.wrapping_sub(Unit::DELTA), Unit::ZERO],
            phi: [Unit::ZERO; 2],
            theta: [Unit::ZERO; 2],
            staging: [Unit::ZERO; 3],
            staged: 0,
            ray_fifo: Fifo::default(),
            result_fifo: Fifo::default(),
            result_word: 0,
            frame: FrameUnit::new(cfg),
            frame_valid: false,
            params,
            built_for: None,
            rotators: core::array::from_fn(|_| Rotator::new(cfg)),
            queue: Fifo::default(),
            intersect: IntersectUnit::new(params, depth, subdiv, cfg.width),
            mem: PatchMem::new(params.capacity() as usize),
            patch_addr: 0,
            patch_count: 0,
            was_busy: false,
        }
    }

    /// This device as an RTL build synthesised at CONFIG `config` (its units' iterations, width
    /// and depth fixed), after power-on reset: `config` in force, and APPLY_CONFIG of another
    /// CONFIG refused with ERROR.BAD_CONFIG, as `rtl/ahb_regs.v` has it when built for one (its
    /// BUILD_CONFIG). `config` must be a valid CONFIG (a build's, not an input).
    pub fn built_for(mut self, config: u32) -> Self {
        assert!(
            decode_config(config).is_some(),
            "CONFIG {config:#x} is not valid"
        );
        self.built_for = Some(config);
        self.config_reg = config;
        self.config_active = config;
        // the units rebuilt for it, as a soft reset rebuilds them for the configuration in force
        self.soft_reset();
        self
    }

    /// The interrupt line: any enabled interrupt flag.
    pub fn irq_line(&self) -> bool {
        self.irq_status & self.irq_enable != 0
    }

    /// Clocks since reset.
    pub fn cycles(&self) -> u64 {
        self.cycles
    }

    fn busy(&self) -> bool {
        !self.ray_fifo.is_empty()
            || self.frame.busy()
            || self.rotator_occupancy() > 0
            || !self.queue.is_empty()
            || self.intersect.in_flight() > 0
    }

    fn raise(&mut self, bits: u32) {
        self.error |= bits;
        self.irq_status |= irq::ERROR;
    }

    fn soft_reset(&mut self) {
        // patch memory and the configuration in force survive; everything else is reset
        let mem = core::mem::replace(&mut self.mem, PatchMem::new(0));
        let (config, bz, patch_count) =
            (self.config_active, self.bz_config_active, self.patch_count);
        let (cfg, depth) = decode_config(config).expect("active configuration is valid");
        let subdiv = decode_bz_config(bz).expect("active configuration is valid");
        *self = Device {
            built_for: self.built_for,
            ..Device::with_params(self.params)
        };
        self.mem = mem;
        self.config_reg = config;
        self.config_active = config;
        self.bz_config_reg = bz;
        self.bz_config_active = bz;
        self.patch_count = patch_count;
        self.rotators = core::array::from_fn(|_| Rotator::new(cfg));
        self.frame = FrameUnit::new(cfg);
        self.intersect = IntersectUnit::new(self.params, depth, subdiv, cfg.width);
    }

    fn apply_config(&mut self) {
        if self.busy() {
            self.raise(error::CONFIG_BUSY);
            return;
        }
        match (
            decode_config(self.config_reg),
            decode_bz_config(self.bz_config_reg),
        ) {
            (Some((cfg, depth)), Some(subdiv)) if self.takes(self.config_reg) => {
                self.config_active = self.config_reg;
                self.bz_config_active = self.bz_config_reg;
                self.rotators = core::array::from_fn(|_| Rotator::new(cfg));
                self.frame = FrameUnit::new(cfg);
                self.frame_valid = false;
                self.intersect.reconfigure(depth, subdiv, cfg.width);
            }
            _ => self.raise(error::BAD_CONFIG),
        }
    }

    /// Whether this build's units can take CONFIG `v` (a valid one): any, unless they were
    /// synthesised for one ([`Device::built_for`]).
    fn takes(&self, v: u32) -> bool {
        self.built_for
            .is_none_or(|b| decode_config(b) == decode_config(v))
    }

    fn push_entry(&mut self, e: Entry) {
        if self.ray_fifo.push(e).is_err() {
            self.raise(error::RAY_OVERFLOW);
        }
    }

    fn status(&self) -> u32 {
        let mut s = 0;
        if self.busy() {
            s |= status::BUSY;
        }
        if self.frame.busy() {
            s |= status::FRAME_BUSY;
        }
        if self.frame_valid {
            s |= status::FRAME_VALID;
        }
        if self.ray_fifo.is_full() {
            s |= status::RAY_FULL;
        }
        if !self.result_fifo.is_empty() {
            s |= status::RESULT_READY;
        }
        s | (self.ray_fifo.len() as u32) << status::RAY_LEVEL_SHIFT
            | (self.result_fifo.len() as u32) << status::RESULT_LEVEL_SHIFT
    }

    /// A bus read of the register at byte offset `offset` (reads of RESULT_OUT, CYCLE_LO and
    /// BUSY_LO have side effects). Unmapped offsets read 0.
    pub fn read(&mut self, offset: u32) -> u32 {
        let angle = |a: Angle| a.to_bits() as u32;
        match offset {
            regs::ID => regs::ID_VALUE,
            regs::VERSION => regs::VERSION_VALUE,
            regs::CAPS => {
                RAY_FIFO_DEPTH as u32
                    | (RESULT_FIFO_DEPTH as u32) << 8
                    | (self.mem.slots() as u32) << 16
            }
            regs::CTRL => self.enable as u32,
            regs::STATUS => self.status(),
            regs::ERROR => self.error,
            regs::IRQ_STATUS => self.irq_status,
            regs::IRQ_ENABLE => self.irq_enable,
            regs::CONFIG => self.config_reg,
            regs::CONFIG_ACTIVE => self.config_active,
            regs::CYCLE_LO => {
                self.cycle_hi = (self.cycles >> 32) as u32;
                self.cycles as u32
            }
            regs::CYCLE_HI => self.cycle_hi,
            regs::BUSY_LO => {
                self.busy_hi = (self.busy_cycles >> 32) as u32;
                self.busy_cycles as u32
            }
            regs::BUSY_HI => self.busy_hi,
            regs::RESULTS_DONE => self.results_done,
            regs::MODE => self.mode,
            regs::ORIGIN_X => self.origin[0].to_bits() as u32,
            regs::ORIGIN_Y => self.origin[1].to_bits() as u32,
            regs::ORIGIN_Z => self.origin[2].to_bits() as u32,
            regs::NORMAL_X => self.normal[0].to_bits() as u32,
            regs::NORMAL_Y => self.normal[1].to_bits() as u32,
            regs::NORMAL_Z => self.normal[2].to_bits() as u32,
            regs::SPIN_C => self.spin[0].to_bits() as u32,
            regs::SPIN_S => self.spin[1].to_bits() as u32,
            regs::PHI_C => self.phi[0].to_bits() as u32,
            regs::PHI_S => self.phi[1].to_bits() as u32,
            regs::THETA_C => self.theta[0].to_bits() as u32,
            regs::THETA_S => self.theta[1].to_bits() as u32,
            regs::FRAME_PSI => angle(self.frame.angles()[0]),
            regs::FRAME_THETA => angle(self.frame.angles()[1]),
            regs::FRAME_PHI => angle(self.frame.angles()[2]),
            regs::RESULT_OUT => match self.result_fifo.front() {
                Some(r) => {
                    let w = r[self.result_word];
                    let len = if r[0] & result::SHORT != 0 { 2 } else { 4 };
                    self.result_word += 1;
                    if self.result_word == len {
                        self.result_word = 0;
                        self.result_fifo.pop();
                    }
                    w
                }
                None => {
                    self.raise(error::RESULT_UNDERFLOW);
                    0
                }
            },
            regs::PATCH_ADDR => self.patch_addr,
            regs::PATCH_DATA => {
                let v = self.mem.read(self.patch_addr);
                if v.is_none() {
                    self.raise(error::PATCH_RANGE);
                }
                self.patch_addr = self.patch_addr.wrapping_add(1);
                v.unwrap_or(0)
            }
            regs::PATCH_COUNT => self.patch_count,
            regs::SKIP_PATCH => self.skip_reg,
            regs::BZ_CONFIG => self.bz_config_reg,
            regs::BZ_CONFIG_ACTIVE => self.bz_config_active,
            regs::CAPS_BEZIER => {
                BEZIER_ROWS as u32 | (STACK_ENTRIES as u32) << 16 | MAX_DEPTH << 24
            }
            regs::STACK_HIGH => self.intersect.stack_high_water() as u32,
            regs::CAPS_LANES => self.params.caps_word(),
            _ => 0,
        }
    }

    /// A bus write of `value` to the register at byte offset `offset`. Writes to read-only or
    /// unmapped offsets are ignored.
    pub fn write(&mut self, offset: u32, value: u32) {
        let unit = Unit::from_bits(value as i32);
        match offset {
            regs::CTRL => {
                if value & ctrl::SOFT_RESET != 0 {
                    self.soft_reset();
                    return;
                }
                self.enable = value & ctrl::ENABLE != 0;
                if value & ctrl::APPLY_CONFIG != 0 {
                    self.apply_config();
                }
                if value & ctrl::FRAME_NORMAL != 0 {
                    let req = FrameRequest::Normal {
                        n: self.normal,
                        spin: self.spin,
                    };
                    self.push_entry(Entry {
                        frame: Some(req),
                        ..Entry::default()
                    });
                }
                if value & ctrl::FRAME_PAIRS != 0 {
                    let req = FrameRequest::Pairs {
                        phi: self.phi,
                        theta: self.theta,
                        psi: self.spin,
                    };
                    self.push_entry(Entry {
                        frame: Some(req),
                        ..Entry::default()
                    });
                }
            }
            regs::ERROR => self.error &= !value,
            regs::IRQ_STATUS => self.irq_status &= !value,
            regs::IRQ_ENABLE => self.irq_enable = value & 0xF,
            regs::CONFIG => self.config_reg = value,
            regs::BZ_CONFIG => self.bz_config_reg = value,
            regs::SKIP_PATCH => self.skip_reg = value & (skip::ENABLE | result::PATCH_MASK),
            regs::MODE => {
                let known = mode::KIND_MASK | mode::NO_UV;
                if value & !known == 0 && value & mode::KIND_MASK <= mode::ROTATE_TRACE {
                    self.mode = value;
                } else {
                    self.raise(error::BAD_CONFIG);
                }
            }
            regs::ORIGIN_X => self.origin[0] = Coord::from_bits(value as i32),
            regs::ORIGIN_Y => self.origin[1] = Coord::from_bits(value as i32),
            regs::ORIGIN_Z => self.origin[2] = Coord::from_bits(value as i32),
            regs::NORMAL_X => self.normal[0] = unit,
            regs::NORMAL_Y => self.normal[1] = unit,
            regs::NORMAL_Z => self.normal[2] = unit,
            regs::SPIN_C => self.spin[0] = unit,
            regs::SPIN_S => self.spin[1] = unit,
            regs::PHI_C => self.phi[0] = unit,
            regs::PHI_S => self.phi[1] = unit,
            regs::THETA_C => self.theta[0] = unit,
            regs::THETA_S => self.theta[1] = unit,
            regs::RAY_IN => {
                self.staging[self.staged] = unit;
                self.staged += 1;
                if self.staged == 3 {
                    self.staged = 0;
                    let e = self.ray_entry(self.staging);
                    self.push_entry(e);
                }
            }
            regs::PATCH_ADDR => self.patch_addr = value,
            regs::PATCH_DATA => {
                if self.busy() {
                    self.raise(error::PATCH_BUSY);
                } else if self.mem.write(self.patch_addr, value) {
                    self.intersect.invalidate();
                } else {
                    self.raise(error::PATCH_RANGE);
                }
                self.patch_addr = self.patch_addr.wrapping_add(1);
            }
            regs::PATCH_COUNT => {
                if self.busy() {
                    self.raise(error::PATCH_BUSY);
                } else if value as usize > self.mem.slots() {
                    self.raise(error::PATCH_RANGE);
                } else {
                    self.patch_count = value;
                    self.intersect.invalidate();
                }
            }
            _ => {}
        }
    }

    fn result_words(r: &RayOut<Tag>) -> [u32; 4] {
        if r.info.error {
            return [result::ERROR, 0, 0, 0];
        }
        if r.info.mode & mode::KIND_MASK == mode::ROTATE {
            let d = r.dir.map(|c| c.to_bits() as u32);
            return [result::ROTATED, d[0], d[1], d[2]];
        }
        let short = if r.uv { 0 } else { result::SHORT };
        match r.hit {
            Some(h) => [
                result::HIT | if h.front { result::FRONT } else { 0 } | short | h.patch,
                h.t.to_bits() as u32,
                h.u.to_bits() as u32,
                h.v.to_bits() as u32,
            ],
            None => [short, 0, 0, 0],
        }
    }

    /// A ray entry from `dir` with the per-entry registers latched (what the third RAY_IN write
    /// and the stream port complete).
    fn ray_entry(&self, dir: [Unit; 3]) -> Entry {
        Entry {
            frame: None,
            mode: self.mode,
            origin: self.origin,
            skip: (self.skip_reg & skip::ENABLE != 0).then_some(self.skip_reg & result::PATCH_MASK),
            dir,
        }
    }

    /// The stream port's ray side: one entry (a direction, Q2.30 words) into the ray FIFO, as
    /// three RAY_IN writes would make it; false (and nothing queued) if the FIFO is full.
    pub fn stream_push(&mut self, dir: [u32; 3]) -> bool {
        if self.ray_fifo.is_full() {
            return false;
        }
        let e = self.ray_entry(dir.map(|w| Unit::from_bits(w as i32)));
        self.push_entry(e);
        true
    }

    /// Whether [`Device::stream_pop`] would give a result now.
    pub fn stream_ready(&self) -> bool {
        self.result_word == 0 && !self.result_fifo.is_empty()
    }

    /// The stream port's result side: the oldest whole result (four words; u, v are 0 in a
    /// SHORT one), unless none is ready or RESULT_OUT has been read part-way into it.
    pub fn stream_pop(&mut self) -> Option<[u32; 4]> {
        if self.result_word != 0 {
            return None;
        }
        self.result_fifo.pop()
    }

    /// Whether the ray FIFO is full.
    pub fn ray_full(&self) -> bool {
        self.ray_fifo.is_full()
    }

    /// The front end's width: rays per clock.
    pub fn rays_per_clock(&self) -> usize {
        self.params.rays_per_clock as usize
    }

    fn rotator_occupancy(&self) -> u32 {
        self.rotators.iter().map(|r| r.occupancy()).sum()
    }

    /// Up to `rays_per_clock` rays from the intersection unit into the result FIFO, while it has
    /// room (the rays behind wait in the unit's retirement buffer, which the credits size).
    fn retire(&mut self) {
        for _ in 0..self.rays_per_clock() {
            if self.result_fifo.is_full() {
                break;
            }
            let Some(r) = self.intersect.take_done(self.cycles) else {
                break;
            };
            let words = Self::result_words(&r);
            let pushed = self.result_fifo.push(words);
            debug_assert!(pushed.is_ok(), "room checked above");
            self.results_done = self.results_done.wrapping_add(1);
            self.irq_status |= irq::RESULT;
        }
        if core::mem::take(&mut self.intersect.unsupported) {
            self.raise(error::UNSUPPORTED_PATCH);
        }
        if core::mem::take(&mut self.intersect.overflow) {
            self.raise(error::STACK_OVERFLOW);
        }
    }

    /// Up to `rays_per_clock` rays from the queue into the intersection unit (each holds the
    /// result credit it took at the ray FIFO).
    fn start_rays(&mut self) {
        for _ in 0..self.rays_per_clock() {
            if !self.intersect.ready() {
                break;
            }
            let Some(r) = self.queue.pop() else {
                break;
            };
            let rotator = &self.rotators[0];
            self.intersect
                .start(&self.mem, self.patch_count, r, self.cycles, |angles| {
                    rotator.axes(angles)
                });
        }
    }

    /// The ray slots held: in the rotators, the queue, the intersection unit and the result
    /// FIFO (a ray enters a rotator only while one is free).
    fn held(&self) -> usize {
        self.rotator_occupancy() as usize
            + self.queue.len()
            + self.intersect.in_flight() as usize
            + self.result_fifo.len()
    }

    /// The ray FIFO's next entry for rotator `taken` of this clock, given `held` slots held
    /// before the clock: a frame goes to the angle unit (and the clock issues nothing more),
    /// a ray to the rotator. `None` ends the clock's issue. Up to `rays_per_clock` a clock,
    /// entry k of the clock to rotator k.
    fn issue(&mut self, taken: usize, held: usize) -> Option<RotIn<Info>> {
        if !self.enable || taken >= self.rays_per_clock() {
            return None;
        }
        let e = self.ray_fifo.front()?;
        if let Some(req) = e.frame {
            if !self.frame.busy() {
                self.ray_fifo.pop();
                self.frame.start(req);
            }
            return None;
        }
        let rotates = e.mode & mode::KIND_MASK != mode::TRACE;
        if held + taken >= self.params.ray_slots() || (rotates && self.frame.busy()) {
            return None;
        }
        let e = *e;
        self.ray_fifo.pop();
        let no_frame = rotates && !self.frame_valid;
        if no_frame {
            self.raise(error::NO_FRAME);
        }
        let angles = self.frame.angles();
        Some(RotIn {
            dir: e.dir,
            angles,
            bypass: !rotates || no_frame,
            info: Info {
                mode: e.mode,
                error: no_frame,
                origin: e.origin,
                skip: e.skip,
                frame: (rotates && !no_frame).then_some(angles),
                dir_ref: e.dir,
            },
        })
    }

    /// Shows the intersection unit the set-up key of the ray FIFO's head, if it is a ray that
    /// will be traced and its frame (if it rotates) is the angle unit's settled output, so
    /// that the set-up units can begin its origin's pass while earlier rays hold the credits.
    fn announce_head(&mut self) {
        let Some(e) = self.ray_fifo.front() else {
            return;
        };
        let kind = e.mode & mode::KIND_MASK;
        if e.frame.is_some() || kind == mode::ROTATE {
            return;
        }
        let frame = if kind == mode::TRACE {
            None
        } else if self.frame.busy() || !self.frame_valid {
            return;
        } else {
            Some(self.frame.angles())
        };
        self.intersect.announce(e.origin, frame, self.cycles);
    }

    /// One clock.
    pub fn tick(&mut self) {
        self.retire();
        self.start_rays();
        // each rotator's entry issued as it ticks (an array of them, built and moved each
        // clock, was a tenth of the simulation's time)
        let (held, mut issuing) = (self.held(), true);
        for k in 0..self.rotators.len() {
            let input = issuing.then(|| self.issue(k, held)).flatten();
            issuing = input.is_some();
            let rotator = &mut self.rotators[k];
            let turned = rotator.latency() as u64;
            let Some((dir, info)) = rotator.tick(input) else {
                continue;
            };
            // room was reserved when the entry left the FIFO
            // the wide datapath's reciprocal unit (1/d for the Bezier unit's slab tests) sits at
            // the queue's input: pipelined, its answer is ready RECIP_LATENCY clocks after the ray
            // enters (the compact datapath's serial one is in the intersection unit)
            let pushed = self.queue.push(RayIn {
                origin: info.origin,
                dir,
                bypass: info.mode & mode::KIND_MASK == mode::ROTATE || info.error,
                uv: info.mode & mode::NO_UV == 0,
                skip: info.skip,
                recip_at: self.cycles + RECIP_LATENCY,
                // the culling unit's ray side started with the rotator
                bin_at: self.cycles + (cull::RAY_LATENCY as u64).saturating_sub(turned),
                frame: info.frame,
                dir_ref: info.dir_ref,
                info: Tag {
                    mode: info.mode,
                    error: info.error,
                },
            });
            debug_assert!(pushed.is_ok(), "queue credit accounting");
        }
        self.announce_head();
        if self.frame.tick() {
            self.frame_valid = true;
            self.irq_status |= irq::FRAME;
        }
        let busy = self.busy();
        if busy {
            self.busy_cycles += 1;
        } else if self.was_busy {
            self.irq_status |= irq::IDLE;
        }
        self.was_busy = busy;
        self.cycles += 1;
    }

    /// Patch memory (for white-box tests of the units).
    pub fn patch_mem(&self) -> &PatchMem {
        &self.mem
    }

    /// The subdivision engine's work counters (for measurements).
    pub fn bezier_stats(&self) -> BezierStats {
        self.intersect.bezier_stats()
    }

    /// The lanes' work counters (for measurements).
    pub fn lane_stats(&self) -> LaneStats {
        self.intersect.lane_stats()
    }

    /// The build parameters.
    pub fn params(&self) -> Params {
        self.params
    }

    /// The ray FIFO's entries, oldest first, packed as the register file's RTL holds them
    /// (`hdl-model/rtl/ahb_regs.v`), for its co-simulation: word 0 the kind (bits 17:16: 0 a
    /// ray, 1 a frame from a normal, 2 a frame from pairs) and, for a ray, MODE (bits 8:0);
    /// then a ray's ORIGIN x, y, z, SKIP_PATCH (bit 31 set when it skips) and direction x, y,
    /// z; a frame's NORMAL x, y, z and SPIN c, s, or PHI c, s, THETA c, s and SPIN c, s; unused
    /// words 0.
    pub fn queued_entries(&self) -> impl Iterator<Item = [u32; ENTRY_WORDS]> + '_ {
        self.ray_fifo.iter().map(Entry::words)
    }
}

/// Words of a packed ray FIFO entry ([`Device::queued_entries`]).
pub const ENTRY_WORDS: usize = 8;

impl Entry {
    /// The entry packed as [`Device::queued_entries`] says.
    fn words(&self) -> [u32; ENTRY_WORDS] {
        let u = |v: Unit| v.to_bits() as u32;
        let mut w = [0; ENTRY_WORDS];
        match self.frame {
            Some(FrameRequest::Normal { n, spin }) => {
                w[0] = 1 << 16;
                for (o, v) in w[1..].iter_mut().zip(n.iter().chain(&spin)) {
                    *o = u(*v);
                }
            }
            Some(FrameRequest::Pairs { phi, theta, psi }) => {
                w[0] = 2 << 16;
                let all = phi.iter().chain(&theta).chain(&psi);
                for (o, v) in w[1..].iter_mut().zip(all) {
                    *o = u(*v);
                }
            }
            None => {
                w[0] = self.mode;
                for (o, c) in w[1..4].iter_mut().zip(&self.origin) {
                    *o = c.to_bits() as u32;
                }
                w[4] = self.skip.map_or(0, |p| skip::ENABLE | p);
                for (o, v) in w[5..].iter_mut().zip(&self.dir) {
                    *o = u(*v);
                }
            }
        }
        w
    }
}

const _: () = assert!(PATCH_WORDS == 16);
