//! Vectors for the register file and bus interface's RTL (`hdl-model/rtl/ahb_regs.v`): the
//! model's [`Device`] driven through its register bus, one access a clock as the driver drives
//! it, with every read's value and the interrupt line written down for the RTL to reproduce.
//!
//! The register file is co-simulated without the datapath behind it: the workload never lets
//! an entry leave the ray FIFO (ENABLE is set only while the FIFO is empty, and no entry is
//! queued while it is set), so nothing the model's units compute can show through the
//! registers, and the RTL's datapath ports stay idle. What it covers: every register's reads
//! and writes, the read-only and unmapped offsets, the write-one-to-clear flags and the
//! interrupt line, CONFIG and BZ_CONFIG validated by APPLY_CONFIG (applied, refused as invalid,
//! refused as busy), MODE's validation, the three-write RAY_IN entry and the frame commands
//! (two in one CTRL write) into the ray FIFO up to its overflow, the patch memory window
//! (auto-increment, the control-point region, out-of-range words, writes refused while busy),
//! PATCH_COUNT, the cycle and busy counters with their latched high words, RESULT_OUT's
//! underflow and soft reset.
//!
//! File lines (hex words but the clock): `I n` (n idle clocks), `W clk addr data irq` (a write
//! on model clock clk, the interrupt line before it), `R clk addr data irq` (a read and the
//! value the model gave), then `Q n` and n lines `F w0 … w7`: the ray FIFO's entries at the end,
//! oldest first, packed as [`Device::queued_entries`] packs them.

use crate::rng::XorShift;
use hemi_hdl_model::device::{Device, ENTRY_WORDS};
use hemi_hdl_model::driver::{RegisterAccess, StreamPort};
use hemi_hdl_model::intersect::bezier::{BEZIER_ROWS, CP_WORDS};
use hemi_hdl_model::intersect::patch_mem::CP_BASE;
use hemi_hdl_model::regs::{self, ctrl, status};
use std::fmt::Write as _;

/// What a workload held.
#[derive(Clone, Copy, Debug, Default)]
pub struct Counts {
    /// Bus accesses.
    pub accesses: u64,
    /// Clocks, idle ones included (the model's count restarts at each soft reset; this does
    /// not).
    pub clocks: u64,
    /// Entries left in the ray FIFO.
    pub entries: u64,
}

/// Words of control-point memory (from [`CP_BASE`]).
const CP_END: u32 = (BEZIER_ROWS * CP_WORDS) as u32;

/// Every offset of the map and a few unmapped ones.
const OFFSETS: [u32; 49] = [
    regs::ID,
    regs::VERSION,
    regs::CAPS,
    regs::CTRL,
    regs::STATUS,
    regs::ERROR,
    regs::IRQ_STATUS,
    regs::IRQ_ENABLE,
    regs::CONFIG,
    regs::CONFIG_ACTIVE,
    regs::CYCLE_LO,
    regs::CYCLE_HI,
    regs::BUSY_LO,
    regs::BUSY_HI,
    regs::RESULTS_DONE,
    regs::MODE,
    regs::ORIGIN_X,
    regs::ORIGIN_Y,
    regs::ORIGIN_Z,
    regs::NORMAL_X,
    regs::NORMAL_Y,
    regs::NORMAL_Z,
    regs::SPIN_C,
    regs::SPIN_S,
    regs::PHI_C,
    regs::PHI_S,
    regs::THETA_C,
    regs::THETA_S,
    regs::FRAME_PSI,
    regs::FRAME_THETA,
    regs::FRAME_PHI,
    regs::RAY_IN,
    regs::RESULT_OUT,
    regs::PATCH_ADDR,
    regs::PATCH_DATA,
    regs::PATCH_COUNT,
    regs::SKIP_PATCH,
    regs::BZ_CONFIG,
    regs::BZ_CONFIG_ACTIVE,
    regs::CAPS_BEZIER,
    regs::STACK_HIGH,
    regs::CAPS_LANES,
    0x03C,
    0x088,
    0x08C,
    0x0B4,
    0x100,
    0x3FC,
    0x0FFC,
];

/// The model and the file being written: a register bus that writes down every access it
/// makes, in this file's lines (the whole accelerator's vectors, [`super::accel`], drive the
/// register driver over it).
pub(super) struct Bench {
    pub(super) dev: Device,
    pub(super) text: String,
    pub(super) counts: Counts,
    /// Whether the driver sees the device's stream port (the whole accelerator's workload
    /// casts both ways; the register file alone has none)
    pub(super) port: bool,
    /// The stream port's clock being made: the port as it was before it, what moved
    pending: Option<PortClock>,
}

/// One stream port clock, written down when it ends (`S` lines).
#[derive(Clone, Copy, Debug, Default)]
struct PortClock {
    full: bool,
    ready: bool,
    push: Option<[u32; 3]>,
    pop: Option<[u32; 4]>,
}

impl Bench {
    /// A bench over `dev`, idle for the RTL's first clock (the first access's address phase:
    /// the model idles one clock to match).
    pub(super) fn new(dev: Device) -> Self {
        let mut b = Bench {
            dev,
            text: String::new(),
            counts: Counts::default(),
            port: false,
            pending: None,
        };
        b.idle(1);
        b
    }

    /// The model's clock (CYCLE: it restarts at each soft reset).
    fn model_clock(&self) -> u64 {
        self.dev.cycles()
    }

    pub(super) fn write(&mut self, addr: u32, data: u32) {
        self.end_port_clock();
        let (clk, irq) = (self.model_clock(), self.dev.irq_line() as u32);
        let _ = writeln!(self.text, "W {clk} {addr:x} {data:x} {irq}");
        self.dev.write(addr, data);
        self.dev.tick();
        self.counts.accesses += 1;
        self.counts.clocks += 1;
    }

    /// A read; a PATCH_DATA read's wait states first (clocks of counting: the testbench sees
    /// them as HREADYOUT low).
    pub(super) fn read(&mut self, addr: u32) -> u32 {
        self.end_port_clock();
        let waits = regs::read_waits(addr);
        for _ in 0..waits {
            self.dev.tick();
        }
        self.counts.clocks += waits;
        let (clk, irq) = (self.model_clock(), self.dev.irq_line() as u32);
        let data = self.dev.read(addr);
        self.dev.tick();
        let _ = writeln!(self.text, "R {clk} {addr:x} {data:x} {irq}");
        self.counts.accesses += 1;
        self.counts.clocks += 1;
        data
    }

    pub(super) fn idle(&mut self, n: u32) {
        for _ in 0..n {
            self.dev.tick();
        }
        let _ = writeln!(self.text, "I {n}");
        self.counts.clocks += n as u64;
    }

    /// Entries in the ray FIFO, peeked (STATUS has no read side effect, and no clock passes).
    fn queued(&mut self) -> u32 {
        self.dev.read(regs::STATUS) >> status::RAY_LEVEL_SHIFT & 0xFF
    }

    /// Whether an entry may be queued now: never while ENABLE is set (it would leave the FIFO
    /// for the datapath, which the RTL here does not have). CTRL is peeked as STATUS is.
    fn may_queue(&mut self) -> bool {
        self.dev.read(regs::CTRL) & ctrl::ENABLE == 0
    }
}

/// A value for a register: random, or one of the edge words.
fn value(rng: &mut XorShift) -> u32 {
    match rng.bits() % 8 {
        0 => 0,
        1 => u32::MAX,
        2 => 0x8000_0000,
        3 => 0x7FFF_FFFF,
        4 => rng.bits() as u32 & 0xFF,
        _ => rng.bits() as u32,
    }
}

/// A number in `lo..=hi`.
fn r(rng: &mut XorShift, lo: u64, hi: u64) -> u32 {
    (lo + rng.bits() % (hi - lo + 1)) as u32
}

/// A CONFIG word: usually valid (ITER ≤ WIDTH − 2, WIDTH 12..=32, DEPTH 1..=24), else random
/// fields near the bounds.
fn config_word(rng: &mut XorShift) -> u32 {
    if rng.bits().is_multiple_of(3) {
        return r(rng, 0, 31)
            | r(rng, 0, 63) << 8
            | r(rng, 0, 31) << 16
            | (value(rng) & 0xFF00_0000);
    }
    let width = r(rng, 12, 32);
    r(rng, 4, (width - 2).min(30) as u64) | width << 8 | r(rng, 1, 24) << 16
}

/// A BZ_CONFIG word: usually valid (DEPTH 1..=13, CWIDTH 12..=26), else random fields.
fn bz_config_word(rng: &mut XorShift) -> u32 {
    match rng.bits() % 3 {
        0 => r(rng, 0, 31) | r(rng, 0, 63) << 8 | (value(rng) & 0xFFFF_0000),
        _ => r(rng, 1, 13) | r(rng, 12, 26) << 8,
    }
}

/// A MODE word: usually a valid kind with or without NO_UV, sometimes kind 3 or stray bits.
fn mode_word(rng: &mut XorShift) -> u32 {
    match rng.bits() % 6 {
        0 => 3 | (rng.bits() as u32 & 0x100),
        1 => value(rng),
        _ => (rng.bits() % 3) as u32 | (rng.bits() as u32 & 0x100),
    }
}

/// A PATCH_ADDR: a slot word, a control-point word, or outside both; near the ends of each
/// range, so that a burst's auto-increment leaves it, or enters it (from below the control
/// points, and past 2^32 − 1 into the slots); and just below a multiple of 512 words inside
/// each, where a memory built of 512-word block RAMs moves to the next.
fn patch_addr(rng: &mut XorShift, slots: u32) -> u32 {
    let words = slots * 16;
    let below_512 = |n: u64, rng: &mut XorShift| {
        ((rng.bits() % n) as u32 + 1) * 512 - 1 - (rng.bits() % 8) as u32
    };
    match rng.bits() % 10 {
        6 => below_512(words as u64 / 512, rng),
        7 => CP_BASE + below_512(CP_END as u64 / 512, rng),
        0 => CP_BASE + (rng.bits() % CP_END as u64) as u32,
        1 => CP_BASE + CP_END - (rng.bits() % 8) as u32,
        2 => words - (rng.bits() % 8) as u32,
        3 => value(rng),
        4 => CP_BASE - 1 - (rng.bits() % 8) as u32,
        5 => u32::MAX - (rng.bits() % 8) as u32,
        _ => (rng.bits() % words as u64) as u32,
    }
}

/// One step of the random workload: an access, a short burst or a few idle clocks.
fn step(b: &mut Bench, rng: &mut XorShift, slots: u32) {
    match rng.bits() % 20 {
        0 | 1 => {
            let addr = OFFSETS[(rng.bits() % OFFSETS.len() as u64) as usize];
            b.read(addr);
        }
        2 => {
            let addr = OFFSETS[(rng.bits() % OFFSETS.len() as u64) as usize];
            // (RAY_IN and CTRL have their own steps, with the ENABLE rule)
            if addr != regs::RAY_IN && addr != regs::CTRL {
                b.write(addr, value(rng));
            }
        }
        3 | 4 if b.may_queue() => {
            for _ in 0..1 + rng.bits() % 6 {
                b.write(regs::RAY_IN, value(rng));
            }
        }
        5 => ctrl_step(b, rng),
        6 => {
            let addr = [regs::ERROR, regs::IRQ_STATUS][(rng.bits() % 2) as usize];
            b.read(addr);
            b.write(addr, value(rng));
        }
        7 => b.write(regs::IRQ_ENABLE, value(rng)),
        8 => patch_burst(b, rng, slots),
        9 => {
            let n = match rng.bits() % 3 {
                0 => value(rng),
                _ => (rng.bits() % (slots as u64 + 2)) as u32,
            };
            b.write(regs::PATCH_COUNT, n);
        }
        10 => {
            let lo = [regs::CYCLE_LO, regs::BUSY_LO][(rng.bits() % 2) as usize];
            b.read(lo);
            b.read(lo + 4);
        }
        11 => {
            b.read(regs::RESULT_OUT);
        }
        12 => b.idle(1 + (rng.bits() % 5) as u32),
        13 => b.write(regs::MODE, mode_word(rng)),
        14 => b.write(regs::CONFIG, config_word(rng)),
        15 => b.write(regs::BZ_CONFIG, bz_config_word(rng)),
        16 => {
            let reg = regs::ORIGIN_X + 4 * (rng.bits() % 12) as u32;
            b.write(reg, value(rng));
        }
        17 => b.write(regs::SKIP_PATCH, value(rng)),
        _ => {
            b.read(regs::STATUS);
        }
    }
}

/// A CTRL write: frame commands (one or both) and APPLY_CONFIG, ENABLE only while the ray FIFO
/// is empty and without frame commands, now and then a soft reset.
fn ctrl_step(b: &mut Bench, rng: &mut XorShift) {
    if rng.bits().is_multiple_of(12) {
        b.write(regs::CTRL, ctrl::SOFT_RESET | value(rng));
        return;
    }
    let mut v = rng.bits() as u32 & ctrl::APPLY_CONFIG;
    if b.may_queue() && rng.bits().is_multiple_of(2) {
        v |= rng.bits() as u32 & (ctrl::FRAME_NORMAL | ctrl::FRAME_PAIRS);
    } else if b.queued() == 0 && rng.bits().is_multiple_of(2) {
        v |= ctrl::ENABLE;
    }
    // stray bits other than SOFT_RESET are ignored
    v |= rng.bits() as u32 & 0x7FFF_FFF0;
    b.write(regs::CTRL, v);
}

/// PATCH_ADDR, then a run of PATCH_DATA writes or reads from it.
fn patch_burst(b: &mut Bench, rng: &mut XorShift, slots: u32) {
    b.write(regs::PATCH_ADDR, patch_addr(rng, slots));
    let write = rng.bits().is_multiple_of(2);
    for _ in 0..1 + rng.bits() % 20 {
        match write {
            true => b.write(regs::PATCH_DATA, value(rng)),
            false => {
                b.read(regs::PATCH_DATA);
            }
        }
    }
}

/// The directed start: every offset read at reset, the FIFO filled past its depth with rays
/// and frame pairs, refused and applied configurations, patch words written and read back.
fn directed(b: &mut Bench) {
    for &a in &OFFSETS {
        b.read(a);
    }
    b.write(regs::PATCH_ADDR, CP_BASE + CP_END - 2);
    for k in 0..6 {
        b.write(regs::PATCH_DATA, 0x1234_5670 + k);
    }
    b.write(regs::PATCH_ADDR, CP_BASE + CP_END - 2);
    for _ in 0..6 {
        b.read(regs::PATCH_DATA);
    }
    // a burst across every 512-word boundary of both memories (where one built of 512-word
    // block RAMs moves to the next), written, then read back
    let slot_words = b.dev.params().capacity() * 16;
    let bounds: Vec<u32> = (1..slot_words / 512)
        .map(|k| k * 512)
        .chain((1..CP_END / 512).map(|k| CP_BASE + k * 512))
        .collect();
    for (n, &at) in bounds.iter().enumerate() {
        b.write(regs::PATCH_ADDR, at - 2);
        for k in 0..4 {
            b.write(regs::PATCH_DATA, 0xB000_0000 | (n as u32) << 8 | k);
        }
    }
    for &at in &bounds {
        b.write(regs::PATCH_ADDR, at - 2);
        for _ in 0..4 {
            b.read(regs::PATCH_DATA);
        }
    }
    b.write(regs::MODE, 2 | 0x100);
    b.write(regs::SKIP_PATCH, 0x8000_0007);
    for k in 0..35 * 3 {
        b.write(regs::RAY_IN, 0x4000_0000 - k);
        if k.is_multiple_of(9) {
            b.read(regs::STATUS);
        }
    }
    b.write(
        regs::CTRL,
        ctrl::FRAME_NORMAL | ctrl::FRAME_PAIRS | ctrl::APPLY_CONFIG,
    );
    b.read(regs::ERROR);
    b.write(regs::PATCH_DATA, 5);
    b.write(regs::PATCH_COUNT, 3);
    b.read(regs::ERROR);
    b.write(regs::CTRL, ctrl::SOFT_RESET);
    b.write(regs::CONFIG, 0x0008_0C0A);
    b.write(regs::BZ_CONFIG, 0x0000_0E05);
    b.write(regs::CTRL, ctrl::APPLY_CONFIG | ctrl::ENABLE);
    b.read(regs::CONFIG_ACTIVE);
    b.read(regs::BZ_CONFIG_ACTIVE);
    b.write(regs::CONFIG, 0x0008_0C0B);
    b.write(regs::CTRL, ctrl::APPLY_CONFIG);
    b.read(regs::ERROR);
    b.write(regs::IRQ_ENABLE, 0xF);
    b.write(regs::ERROR, 0xFFFF_FFFF);
    b.write(regs::IRQ_STATUS, 0xF);
}

/// The driver's bus, written down access by access.
impl RegisterAccess for Bench {
    fn read(&mut self, offset: u32) -> u32 {
        Bench::read(self, offset)
    }
    fn write(&mut self, offset: u32, value: u32) {
        Bench::write(self, offset, value)
    }
    fn stream_port(&mut self) -> Option<&mut dyn StreamPort> {
        match self.port {
            true => Some(self),
            false => None,
        }
    }
}

impl Bench {
    /// A stream port clock begun and left for an access (the driver leaving its stream loop on
    /// an ERROR result) ends first, as a clock of its own, as `RtlBus` sends it.
    fn end_port_clock(&mut self) {
        if self.pending.is_some() {
            StreamPort::clock(self);
        }
    }

    /// The stream port's clock being made, begun with the port as it is now.
    fn port_clock(&mut self) -> &mut PortClock {
        let (full, ready) = (self.dev.ray_full(), self.dev.stream_ready());
        self.pending.get_or_insert(PortClock {
            full,
            ready,
            ..PortClock::default()
        })
    }
}

/// The device's stream port, clock by clock written down: `S clk push pop dx dy dz full ready
/// r0 r1 r2 r3` (the port's FULL and VALID before the clock, the result popped).
impl StreamPort for Bench {
    fn rays_per_clock(&self) -> usize {
        self.dev.rays_per_clock()
    }
    fn can_push(&self) -> bool {
        !self.dev.ray_full()
    }
    fn push(&mut self, dir: [u32; 3]) {
        self.port_clock().push = Some(dir);
        let pushed = self.dev.stream_push(dir);
        debug_assert!(pushed, "pushed without room");
    }
    fn pop(&mut self) -> Option<[u32; 4]> {
        self.port_clock();
        let r = self.dev.stream_pop();
        if let (Some(c), Some(r)) = (self.pending.as_mut(), r) {
            c.pop = Some(r);
        }
        r
    }
    fn clock(&mut self) {
        let c = *self.port_clock();
        self.pending = None;
        let d = c.push.unwrap_or_default();
        let r = c.pop.unwrap_or_default();
        let _ = writeln!(
            self.text,
            "S {} {} {} {:x} {:x} {:x} {} {} {:x} {:x} {:x} {:x}",
            self.model_clock(),
            c.push.is_some() as u8,
            c.pop.is_some() as u8,
            d[0],
            d[1],
            d[2],
            c.full as u8,
            c.ready as u8,
            r[0],
            r[1],
            r[2],
            r[3]
        );
        self.dev.tick();
        self.counts.clocks += 1;
    }
}

/// The register workload: the directed start, then `steps` random steps from `seed`.
pub fn vectors(steps: usize, seed: u64) -> (String, Counts) {
    let mut b = Bench::new(Device::new());
    let slots = b.dev.read(regs::CAPS) >> 16;
    directed(&mut b);
    let mut rng = XorShift::new(seed);
    for _ in 0..steps {
        step(&mut b, &mut rng, slots);
    }
    let entries: Vec<[u32; ENTRY_WORDS]> = b.dev.queued_entries().collect();
    let _ = writeln!(b.text, "Q {}", entries.len());
    for e in &entries {
        let words: Vec<String> = e.iter().map(|w| format!("{w:x}")).collect();
        let _ = writeln!(b.text, "F {}", words.join(" "));
    }
    b.counts.entries = entries.len() as u64;
    (b.text, b.counts)
}
