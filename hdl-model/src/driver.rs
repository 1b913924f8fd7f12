//! The driver: everything software does with the accelerator, written once against
//! [`RegisterAccess`]. On the board that trait is volatile MMIO at the accelerator's base address
//! (in `hemi-firmware`, the only `unsafe`); here [`ModelBus`] implements it over the model, one
//! clock per bus access, so host runs and QEMU runs drive the same code the board runs.

use crate::device::Device;
use crate::intersect::patch_mem::CP_BASE;
use crate::regs::{self, bz_config, config, ctrl, error, result, skip, status};

/// 32-bit register access at byte offsets from the accelerator's base.
pub trait RegisterAccess {
    /// Reads the register at `offset`.
    fn read(&mut self, offset: u32) -> u32;
    /// Writes `value` to the register at `offset`.
    fn write(&mut self, offset: u32, value: u32);
    /// The accelerator's stream port, if this bus reaches one (CAPS_LANES bit 24 says the
    /// accelerator has it; a bus must also have the DMA behind it). Without one the driver
    /// streams rays through RAY_IN and results through RESULT_OUT, which is what today's
    /// boards' MMIO does.
    fn stream_port(&mut self) -> Option<&mut dyn StreamPort> {
        None
    }
}

/// A bus that can tell its accelerator's clock without an access: the model's CYCLE counter,
/// or a simulator's. The host's engines count the clocks of a pass with it, where reading
/// CYCLE_LO and CYCLE_HI through the bus would spend two of them.
pub trait ClockedBus: RegisterAccess {
    /// Clocks the accelerator has run since its last reset, in the model's count: one for
    /// each access (a PATCH_DATA read's wait states too) and each clock without one, as the
    /// model's CYCLE reads after the last.
    fn clocks(&self) -> u64;
}

impl ClockedBus for ModelBus {
    fn clocks(&self) -> u64 {
        self.dev.cycles()
    }
}

/// The stream port: a DMA pair between the MCU's memory and the accelerator's FIFOs, moving up
/// to [`StreamPort::rays_per_clock`] ray entries in and as many results out per clock, beside the
/// register bus.
pub trait StreamPort {
    /// Entries each way per clock.
    fn rays_per_clock(&self) -> usize;
    /// Whether the ray FIFO has room for an entry.
    fn can_push(&self) -> bool;
    /// One ray entry into the ray FIFO this clock (latched with MODE, ORIGIN, SKIP_PATCH as
    /// RAY_IN latches them), if [`StreamPort::can_push`].
    fn push(&mut self, dir: [u32; 3]);
    /// One whole result out of the result FIFO this clock, if there is one.
    fn pop(&mut self) -> Option<[u32; 4]>;
    /// Ends the clock.
    fn clock(&mut self);
}

/// Register writes that start the stream port's two channels (addresses and counts).
const STREAM_DESCRIPTOR_WRITES: u64 = 4;

/// The model behind a bus: every access takes one clock (the device ticks after it), as a
/// single-cycle APB-style slave would.
#[derive(Clone, Debug, Default)]
pub struct ModelBus {
    dev: Device,
}

impl ModelBus {
    /// A bus to a freshly reset model of the default build.
    pub fn new() -> Self {
        ModelBus { dev: Device::new() }
    }

    /// A bus to a freshly reset model built with `params` (valid).
    pub fn with_params(params: crate::params::Params) -> Self {
        ModelBus {
            dev: Device::with_params(params),
        }
    }

    /// A bus to `dev` (e.g. a device modelled as an RTL build, [`Device::built_for`]).
    pub fn with_device(dev: Device) -> Self {
        ModelBus { dev }
    }

    /// The model (read-only: for its clock and for white-box tests).
    pub fn device(&self) -> &Device {
        &self.dev
    }

    /// Lets `n` clocks pass without a bus access.
    pub fn idle(&mut self, n: u64) {
        for _ in 0..n {
            self.dev.tick();
        }
    }
}

impl RegisterAccess for ModelBus {
    #[inline]
    fn read(&mut self, offset: u32) -> u32 {
        self.idle(crate::regs::read_waits(offset));
        let v = self.dev.read(offset);
        self.dev.tick();
        v
    }

    #[inline]
    fn write(&mut self, offset: u32, value: u32) {
        self.dev.write(offset, value);
        self.dev.tick();
    }

    fn stream_port(&mut self) -> Option<&mut dyn StreamPort> {
        Some(&mut self.dev)
    }
}

/// The model's stream port: the device's own FIFO ends, one device clock per port clock.
impl StreamPort for Device {
    fn rays_per_clock(&self) -> usize {
        Device::rays_per_clock(self)
    }
    fn can_push(&self) -> bool {
        !self.ray_full()
    }
    fn push(&mut self, dir: [u32; 3]) {
        let pushed = self.stream_push(dir);
        debug_assert!(pushed, "pushed without room");
    }
    fn pop(&mut self) -> Option<[u32; 4]> {
        self.stream_pop()
    }
    fn clock(&mut self) {
        self.tick();
    }
}

/// What went wrong talking to the accelerator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DriverError {
    /// ID or major version not what this driver speaks (the read values).
    WrongDevice {
        /// ID read.
        id: u32,
        /// VERSION read.
        version: u32,
    },
    /// The device refused the configuration (ERROR bits).
    BadConfig(u32),
    /// A patch memory write failed (ERROR bits).
    PatchMemory(u32),
    /// No progress for too long (STATUS at the time).
    Timeout(u32),
    /// An ERROR bit appeared while streaming (ERROR bits).
    Device(u32),
}

/// Polls without progress before a stream gives up: far above any latency the model has
/// (a set-up pass over a full patch memory plus a scan is about 2 × 256 clocks).
const STALL_LIMIT: u32 = 1 << 20;

/// The accelerator's driver over a register bus.
#[derive(Clone, Debug)]
pub struct Driver<B: RegisterAccess> {
    bus: B,
    ray_depth: u32,
    patch_capacity: u32,
    params: crate::params::Params,
    /// CAPS_LANES bit 24: the accelerator has the stream port
    stream_port: bool,
}

impl<B: RegisterAccess> Driver<B> {
    /// Checks the ID and version, learns the FIFO depth, and enables the device.
    pub fn new(bus: B) -> Result<Self, DriverError> {
        let mut d = Self::unattached(bus);
        d.attach()?;
        Ok(d)
    }

    /// A driver that has not talked to the device yet: [`Driver::attach`] before anything else.
    /// (For owners that build the driver in place, see `ModelAccelerator::new`.)
    pub fn unattached(bus: B) -> Self {
        Driver {
            bus,
            ray_depth: 0,
            patch_capacity: 0,
            params: crate::params::Params::SINGLE,
            stream_port: false,
        }
    }

    /// What [`Driver::new`] does on the bus: checks the ID and version, learns the FIFO depth,
    /// and enables the device.
    pub fn attach(&mut self) -> Result<(), DriverError> {
        let id = self.bus.read(regs::ID);
        let version = self.bus.read(regs::VERSION);
        if id != regs::ID_VALUE || version >> 16 != regs::VERSION_VALUE >> 16 {
            return Err(DriverError::WrongDevice { id, version });
        }
        let caps = self.bus.read(regs::CAPS);
        // 0 from a device before 1.3 (an unmapped offset): one lane, no culling
        let lanes = self.bus.read(regs::CAPS_LANES);
        self.bus.write(regs::CTRL, ctrl::ENABLE);
        self.ray_depth = caps & 0xFF;
        self.patch_capacity = caps >> 16;
        self.params = crate::params::Params::from_caps(lanes, self.patch_capacity);
        self.stream_port = lanes & (1 << 24) != 0;
        Ok(())
    }

    /// The accelerator's build parameters (CAPS_LANES, read at attach).
    pub fn params(&self) -> crate::params::Params {
        self.params
    }

    /// The bus.
    pub fn bus(&self) -> &B {
        &self.bus
    }

    /// The bus, mutably (for register-level tests).
    pub fn bus_mut(&mut self) -> &mut B {
        &mut self.bus
    }

    /// Patch slots the memory holds.
    pub fn patch_capacity(&self) -> u32 {
        self.patch_capacity
    }

    /// Soft reset: drops all work in flight, keeps patch memory and configuration.
    pub fn reset(&mut self) {
        self.bus.write(regs::CTRL, ctrl::SOFT_RESET);
        self.bus.write(regs::CTRL, ctrl::ENABLE);
    }

    /// Reads and clears the ERROR register.
    pub fn take_errors(&mut self) -> u32 {
        let e = self.bus.read(regs::ERROR);
        if e != 0 {
            self.bus.write(regs::ERROR, e);
        }
        e
    }

    /// Applies CORDIC iterations, word width and (u,v) depth; refused configurations leave the
    /// device as it was.
    pub fn configure(
        &mut self,
        iterations: u32,
        width: u32,
        depth: u32,
    ) -> Result<(), DriverError> {
        self.take_errors();
        let v = (iterations & 0x1F) << config::ITER_SHIFT
            | (width & 0x3F) << config::WIDTH_SHIFT
            | (depth & 0x1F) << config::DEPTH_SHIFT;
        self.bus.write(regs::CONFIG, v);
        self.bus
            .write(regs::CTRL, ctrl::ENABLE | ctrl::APPLY_CONFIG);
        let e = self.take_errors();
        if e & (error::BAD_CONFIG | error::CONFIG_BUSY) != 0
            || self.bus.read(regs::CONFIG_ACTIVE) != v
        {
            return Err(DriverError::BadConfig(e));
        }
        Ok(())
    }

    /// Applies the Bezier unit's subdivision depth and control-point width (with the CONFIG in
    /// force); refused configurations (a depth whose worst case exceeds the on-chip stack, a
    /// width outside 12..=26) leave the device as it was.
    pub fn configure_subdivision(
        &mut self,
        depth: u32,
        coord_width: u32,
    ) -> Result<(), DriverError> {
        self.take_errors();
        let v = (depth & 0x1F) << bz_config::DEPTH_SHIFT
            | (coord_width & 0x3F) << bz_config::CWIDTH_SHIFT;
        let config = self.bus.read(regs::CONFIG_ACTIVE);
        self.bus.write(regs::CONFIG, config);
        self.bus.write(regs::BZ_CONFIG, v);
        self.bus
            .write(regs::CTRL, ctrl::ENABLE | ctrl::APPLY_CONFIG);
        let e = self.take_errors();
        if e & (error::BAD_CONFIG | error::CONFIG_BUSY) != 0
            || self.bus.read(regs::BZ_CONFIG_ACTIVE) != v
        {
            // leave BZ_CONFIG as in force, so a later APPLY_CONFIG of CONFIG alone succeeds
            let active = self.bus.read(regs::BZ_CONFIG_ACTIVE);
            self.bus.write(regs::BZ_CONFIG, active);
            return Err(DriverError::BadConfig(e));
        }
        Ok(())
    }

    /// Writes control-point rows (48 words each: 16 points, x y z, Q8.24) from row 0.
    pub fn load_control_points<W: AsRef<[u32]>>(
        &mut self,
        rows: impl IntoIterator<Item = W>,
    ) -> Result<(), DriverError> {
        self.take_errors();
        self.bus.write(regs::PATCH_ADDR, CP_BASE);
        for row in rows {
            for &w in row.as_ref() {
                self.bus.write(regs::PATCH_DATA, w);
            }
        }
        match self.take_errors() {
            0 => Ok(()),
            e => Err(DriverError::PatchMemory(e)),
        }
    }

    /// Sets the patch the entries pushed from now on skip (`None`: none).
    pub fn set_skip(&mut self, patch: Option<u32>) {
        let v = patch.map_or(0, |p| skip::ENABLE | (p & result::PATCH_MASK));
        self.bus.write(regs::SKIP_PATCH, v);
    }

    /// Writes `slots` (each one patch slot's words) from slot 0 and sets PATCH_COUNT.
    pub fn load_patches<W: AsRef<[u32]>>(
        &mut self,
        slots: impl IntoIterator<Item = W>,
    ) -> Result<(), DriverError> {
        self.take_errors();
        self.bus.write(regs::PATCH_ADDR, 0);
        let mut count = 0;
        for slot in slots {
            for &w in slot.as_ref() {
                self.bus.write(regs::PATCH_DATA, w);
            }
            count += 1;
        }
        self.bus.write(regs::PATCH_COUNT, count);
        match self.take_errors() {
            0 => Ok(()),
            e => Err(DriverError::PatchMemory(e)),
        }
    }

    /// Sets the MODE of the entries pushed from now on.
    pub fn set_mode(&mut self, mode: u32) {
        self.bus.write(regs::MODE, mode);
    }

    /// Sets the origin (Q8.24 words) of the entries pushed from now on.
    pub fn set_origin(&mut self, origin: [u32; 3]) {
        self.bus.write(regs::ORIGIN_X, origin[0]);
        self.bus.write(regs::ORIGIN_Y, origin[1]);
        self.bus.write(regs::ORIGIN_Z, origin[2]);
    }

    /// Queues a frame from (cos, sin) pairs of φ, θ, ψ (Q2.30 words); later rotate entries use it.
    pub fn frame_from_pairs(&mut self, phi: [u32; 2], theta: [u32; 2], psi: [u32; 2]) {
        self.bus.write(regs::PHI_C, phi[0]);
        self.bus.write(regs::PHI_S, phi[1]);
        self.bus.write(regs::THETA_C, theta[0]);
        self.bus.write(regs::THETA_S, theta[1]);
        self.bus.write(regs::SPIN_C, psi[0]);
        self.bus.write(regs::SPIN_S, psi[1]);
        self.bus.write(regs::CTRL, ctrl::ENABLE | ctrl::FRAME_PAIRS);
    }

    /// Queues a frame from a normal and the spin (cos ψ, sin ψ) (Q2.30 words).
    pub fn frame_from_normal(&mut self, n: [u32; 3], psi: [u32; 2]) {
        self.bus.write(regs::NORMAL_X, n[0]);
        self.bus.write(regs::NORMAL_Y, n[1]);
        self.bus.write(regs::NORMAL_Z, n[2]);
        self.bus.write(regs::SPIN_C, psi[0]);
        self.bus.write(regs::SPIN_S, psi[1]);
        self.bus
            .write(regs::CTRL, ctrl::ENABLE | ctrl::FRAME_NORMAL);
    }

    /// Waits until the queued work (frames included) is done; returns the angles ψ, θ, φ.
    pub fn wait_idle(&mut self) -> Result<[u32; 3], DriverError> {
        let mut polls = 0;
        loop {
            let s = self.bus.read(regs::STATUS);
            if s & status::BUSY == 0 {
                break;
            }
            polls += 1;
            if polls > STALL_LIMIT {
                return Err(DriverError::Timeout(s));
            }
        }
        Ok([
            self.bus.read(regs::FRAME_PSI),
            self.bus.read(regs::FRAME_THETA),
            self.bus.read(regs::FRAME_PHI),
        ])
    }

    /// Pushes one direction (Q2.30 words) into the ray FIFO.
    pub fn push_ray(&mut self, dir: [u32; 3]) {
        self.bus.write(regs::RAY_IN, dir[0]);
        self.bus.write(regs::RAY_IN, dir[1]);
        self.bus.write(regs::RAY_IN, dir[2]);
    }

    /// Reads one result from the result FIFO: four words, or two for a SHORT one (its u and v
    /// are returned as 0).
    pub fn pop_result(&mut self) -> [u32; 4] {
        let w0 = self.bus.read(regs::RESULT_OUT);
        let w1 = self.bus.read(regs::RESULT_OUT);
        if w0 & result::SHORT != 0 {
            return [w0, w1, 0, 0];
        }
        [
            w0,
            w1,
            self.bus.read(regs::RESULT_OUT),
            self.bus.read(regs::RESULT_OUT),
        ]
    }

    /// Streams `n` rays: pushes `dir(i)` as the ray FIFO has room and hands each result to
    /// `sink(i, words)` in order. One STATUS read per round tells both how much room there is
    /// and how many results wait.
    /// Through the stream port when the bus has one and the accelerator reports it.
    pub fn stream(
        &mut self,
        n: usize,
        dir: impl FnMut(usize) -> [u32; 3],
        sink: impl FnMut(usize, [u32; 4]),
    ) -> Result<(), DriverError> {
        self.pump(n, n, dir, sink).map(|_| ())
    }

    /// Pushes `n` rays as [`Driver::stream`] does, handing `sink` every result that is ready
    /// meanwhile (results of rays pushed before, first), and returns once the last ray is in,
    /// with how many results it handed on. What lets the next origin's rays follow without the
    /// pipeline draining: the registers latched with each entry (MODE, ORIGIN, SKIP_PATCH, the
    /// frame) may be rewritten while earlier entries are in flight.
    pub fn feed(
        &mut self,
        n: usize,
        dir: impl FnMut(usize) -> [u32; 3],
        sink: impl FnMut(usize, [u32; 4]),
    ) -> Result<usize, DriverError> {
        self.pump(n, 0, dir, sink)
    }

    /// Hands `sink` the next `n` results, waiting for them (after [`Driver::feed`]).
    pub fn collect(
        &mut self,
        n: usize,
        sink: impl FnMut(usize, [u32; 4]),
    ) -> Result<(), DriverError> {
        self.pump(0, n, |_| [0; 3], sink).map(|_| ())
    }

    /// Hands `sink` ready results until the ray FIFO has room for an entry: what a frame
    /// command ([`Driver::frame_from_pairs`]) needs after [`Driver::feed`], since the FIFO drops
    /// an entry written into it when full (RAY_OVERFLOW). Returns the results handed on.
    pub fn make_room(
        &mut self,
        mut sink: impl FnMut(usize, [u32; 4]),
    ) -> Result<usize, DriverError> {
        let mut popped = 0;
        for _ in 0..STALL_LIMIT {
            let s = self.bus.read(regs::STATUS);
            if s & status::RAY_FULL == 0 {
                return Ok(popped);
            }
            let ready = ((s >> status::RESULT_LEVEL_SHIFT) & 0xFF) as usize;
            popped = self.pop_ready(ready, popped, &mut sink)?;
        }
        Err(DriverError::Timeout(self.bus.read(regs::STATUS)))
    }

    /// Pushes `n_push` rays and pops at least `min_pop` results (every ready one along the
    /// way), through the stream port when there is one; returns the results popped.
    fn pump(
        &mut self,
        n_push: usize,
        min_pop: usize,
        dir: impl FnMut(usize) -> [u32; 3],
        sink: impl FnMut(usize, [u32; 4]),
    ) -> Result<usize, DriverError> {
        let has_port = self.stream_port;
        match self.bus.stream_port() {
            Some(port) if has_port => match stream_through(port, n_push, min_pop, dir, sink) {
                Ok(popped) => Ok(popped),
                Err(StreamFault::Result) => Err(DriverError::Device(self.take_errors())),
                Err(StreamFault::Stall) => Err(DriverError::Timeout(self.bus.read(regs::STATUS))),
            },
            _ => self.stream_registers(n_push, min_pop, dir, sink),
        }
    }

    /// [`Driver::pump`] through RAY_IN and RESULT_OUT.
    fn stream_registers(
        &mut self,
        n_push: usize,
        min_pop: usize,
        mut dir: impl FnMut(usize) -> [u32; 3],
        mut sink: impl FnMut(usize, [u32; 4]),
    ) -> Result<usize, DriverError> {
        let (mut pushed, mut popped, mut stalls) = (0usize, 0usize, 0u32);
        while pushed < n_push || popped < min_pop {
            let s = self.bus.read(regs::STATUS);
            let ray_level = (s >> status::RAY_LEVEL_SHIFT) & 0xFF;
            let ready = ((s >> status::RESULT_LEVEL_SHIFT) & 0xFF) as usize;
            let room = (self.ray_depth - ray_level) as usize;
            let k = room.min(n_push - pushed);
            for _ in 0..k {
                self.push_ray(dir(pushed));
                pushed += 1;
            }
            popped = self.pop_ready(ready, popped, &mut sink)?;
            if k == 0 && ready == 0 {
                stalls += 1;
                if stalls > STALL_LIMIT {
                    return Err(DriverError::Timeout(s));
                }
            } else {
                stalls = 0;
            }
        }
        Ok(popped)
    }

    /// Pops `ready` results into `sink`, numbering them from `popped`; a result flagged ERROR
    /// stops with the device's errors. Returns the new count.
    fn pop_ready(
        &mut self,
        ready: usize,
        mut popped: usize,
        sink: &mut impl FnMut(usize, [u32; 4]),
    ) -> Result<usize, DriverError> {
        for _ in 0..ready {
            let r = self.pop_result();
            if r[0] & result::ERROR != 0 {
                return Err(DriverError::Device(self.take_errors()));
            }
            sink(popped, r);
            popped += 1;
        }
        Ok(popped)
    }

    /// Clocks since reset (CYCLE_LO latches CYCLE_HI).
    pub fn cycles(&mut self) -> u64 {
        let lo = self.bus.read(regs::CYCLE_LO) as u64;
        lo | (self.bus.read(regs::CYCLE_HI) as u64) << 32
    }

    /// Clocks with work in flight since reset.
    pub fn busy_cycles(&mut self) -> u64 {
        let lo = self.bus.read(regs::BUSY_LO) as u64;
        lo | (self.bus.read(regs::BUSY_HI) as u64) << 32
    }
}

/// Why a stream through the port stopped.
enum StreamFault {
    /// A result carried the ERROR flag.
    Result,
    /// No progress for [`STALL_LIMIT`] clocks.
    Stall,
}

/// Pushes `n_push` rays through the port and pops at least `min_pop` results (every ready one
/// along the way): the descriptor writes, then per clock up to its width of entries in and of
/// results out. Returns the results popped.
fn stream_through(
    port: &mut dyn StreamPort,
    n_push: usize,
    min_pop: usize,
    mut dir: impl FnMut(usize) -> [u32; 3],
    mut sink: impl FnMut(usize, [u32; 4]),
) -> Result<usize, StreamFault> {
    for _ in 0..STREAM_DESCRIPTOR_WRITES {
        port.clock();
    }
    let width = port.rays_per_clock();
    let (mut pushed, mut popped, mut stalls) = (0usize, 0usize, 0u32);
    while pushed < n_push || popped < min_pop {
        let before = (pushed, popped);
        for _ in 0..width {
            if pushed == n_push || !port.can_push() {
                break;
            }
            port.push(dir(pushed));
            pushed += 1;
        }
        for _ in 0..width {
            let Some(r) = port.pop() else {
                break;
            };
            if r[0] & result::ERROR != 0 {
                return Err(StreamFault::Result);
            }
            sink(popped, r);
            popped += 1;
        }
        port.clock();
        if (pushed, popped) == before {
            stalls += 1;
            if stalls > STALL_LIMIT {
                return Err(StreamFault::Stall);
            }
        } else {
            stalls = 0;
        }
    }
    Ok(popped)
}
