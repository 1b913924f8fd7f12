//! The kernel's [`Accelerator`] on the accelerator's registers, through the driver:
//! [`RegisterAccelerator`] over any [`RegisterAccess`] (volatile MMIO on a board), and
//! [`ModelAccelerator`], the same code over the model's bus.
//!
//! This is the only place with floating point: the kernel's f32 values become register words on
//! the way in and come back on the way out.
//!
//! - Coordinates are normalised by a power of two (exact in f32) about the centre of the loaded
//!   patches' bounding box, so the scene fills [−1, 1] in Q8.24; origins may lie out to ±128
//!   half-sizes (cameras outside the scene); a ray from farther away is reported as a miss and
//!   counted in [`ModelAccelerator::out_of_range`].
//! - Directions and (cos, sin) pairs are Q2.30.
//! - `rotate` hands the rotator the frame as the three (cos, sin) pairs `Rotation` holds (vectored
//!   into angles on chip), so the model turns rays by the same three plane rotations, in the same
//!   order, as `Rotation::apply`.
//! - Bezier patches go to control-point memory, one row each, with the soft engine's accuracy
//!   criteria converted per patch: the flatness tolerance (`flatness` × the patch's box size,
//!   as `Bezier::intersect` computes it) and t_min (the soft engine's `CURVED_T_MIN` × size).
//! - `set_origin_patch` becomes the SKIP_PATCH register, latched with every ray, as the soft
//!   engine applies it to every cast.

use crate::cordic::CordicConfig;
use crate::driver::{ClockedBus, Driver, DriverError, ModelBus, RegisterAccess};
use crate::format::{Coord, Unit};
use crate::intersect::bezier::{BEZIER_ROWS, CP_WORDS};
use crate::intersect::patch_mem::{BezierSlot, PatchWords, KIND_QUAD, KIND_TRIANGLE, PATCH_WORDS};
use crate::params::Params;
use crate::regs::{mode, result};
use hemi_kernel::accel::{Accelerator, HemiShot, Hit, Ray};
use hemi_kernel::geometry::Vec3;
use hemi_kernel::hemisphere::Hemisphere;
use hemi_kernel::patch::{Patch, Shape};
use hemi_kernel::rotation::Rotation;

#[cfg(feature = "alloc")]
mod streaming;
#[cfg(feature = "alloc")]
pub use streaming::StreamingModel;

/// The accelerator's build parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModelConfig {
    /// CORDIC iterations (4..=30, at most width − 2).
    pub iterations: u32,
    /// CORDIC word width in bits (12..=32).
    pub width: u32,
    /// (u,v) bisection levels (1..=24).
    pub depth: u32,
    /// Bezier subdivision depth (1..=13 with the 40-entry stack).
    pub subdivision_depth: u32,
    /// Bezier control-point datapath width in bits (12..=26).
    pub coord_width: u32,
    /// Bezier flatness criterion as a fraction of each patch's size (0: always to the full
    /// depth), the kernel's `Subdivision::flatness`.
    pub flatness: f32,
    /// Intersection lanes, culling sectors and front-end width of the modelled build
    /// ([`Params`]; a board's accelerator reports its own in CAPS_LANES).
    pub params: Params,
}

impl Default for ModelConfig {
    /// The reset CORDIC configuration ([`CordicConfig::DEFAULT`]), 16 (u,v) levels; Bezier
    /// patches as the soft engine's default `Subdivision` (depth 10, flatness 1e-4) on 26-bit
    /// control points.
    fn default() -> Self {
        ModelConfig {
            iterations: CordicConfig::DEFAULT.iterations,
            width: CordicConfig::DEFAULT.width,
            depth: 16,
            subdivision_depth: 10,
            coord_width: 26,
            flatness: 1e-4,
            params: Params::DEFAULT,
        }
    }
}

/// The soft engine's `CURVED_T_MIN`: hits on a curved patch nearer than this fraction of its
/// size are the surface the ray starts on (a neighbour at a shared seam).
const CURVED_T_MIN: f32 = 1e-4;

/// Why the model accelerator could not be built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModelError {
    /// The driver failed (configuration refused, patch memory, ...).
    Driver(DriverError),
    /// More patches than the patch memory holds.
    TooManyPatches {
        /// Patches given.
        count: usize,
        /// Slots in the memory.
        capacity: u32,
    },
    /// More Bezier patches than control-point memory holds.
    TooManyBezierPatches {
        /// Bezier patches given.
        count: usize,
        /// Rows of control-point memory.
        capacity: usize,
    },
    /// A vertex or normal is not finite or out of the coordinate range.
    BadGeometry(usize),
    /// Build parameters the model cannot be built with (lanes, sectors, front-end width).
    BadParams,
}

impl From<DriverError> for ModelError {
    fn from(e: DriverError) -> Self {
        ModelError::Driver(e)
    }
}

/// The accelerator behind the kernel's trait, driven through its registers by the driver, over
/// any register access `B`: the model's bus on the host and under QEMU ([`ModelAccelerator`]),
/// volatile MMIO on a board. Everything it does goes through the driver.
pub struct RegisterAccelerator<B: RegisterAccess> {
    driver: Driver<B>,
    /// scene units to fixed point (centre, a power-of-two scale)
    norm: Normalise,
    frame: Option<Rotation>,
    origin: Option<[u32; 3]>,
    mode: Option<u32>,
    /// the patch hemisphere casts skip, and what SKIP_PATCH holds now
    origin_patch: Option<u32>,
    skip: Option<Option<u32>>,
    rays: u64,
    out_of_range: u64,
}

fn unit_word(x: f32) -> u32 {
    Unit::saturating_from_num(if x.is_nan() { 0.0 } else { x }).to_bits() as u32
}

fn unit_f32(w: u32) -> f32 {
    Unit::from_bits(w as i32).to_num()
}

/// The accelerator model behind the kernel's trait: [`RegisterAccelerator`] over the model's bus.
pub type ModelAccelerator = RegisterAccelerator<ModelBus>;

impl ModelAccelerator {
    /// Configures the model and loads `patches` into its patch memory through the driver.
    pub fn new(patches: &[Patch], config: ModelConfig) -> Result<Self, ModelError> {
        if !config.params.is_valid() {
            return Err(ModelError::BadParams);
        }
        // Built in place and then configured through `&mut self`: the model is about 100 KB,
        // and every by-value move of it is a copy on the stack in unoptimised builds (rayon's
        // worker threads, with 2 MiB stacks, nest several of these).
        // (So the fields are spelled out here rather than built by a helper taking the driver
        // by value.)
        let mut acc = RegisterAccelerator {
            driver: Driver::unattached(ModelBus::with_params(config.params)),
            norm: Normalise::IDENTITY,
            frame: None,
            origin: None,
            mode: None,
            origin_patch: None,
            skip: None,
            rays: 0,
            out_of_range: 0,
        };
        acc.load(patches, config)?;
        Ok(acc)
    }

    /// The Bezier unit's work counters: patch tests, subdivision steps, leaves, clocks.
    pub fn bezier_stats(&self) -> crate::intersect::bezier::BezierStats {
        self.driver.bus().device().bezier_stats()
    }

    /// The lanes' work counters: candidates tested, rays culled, set-up passes.
    pub fn lane_stats(&self) -> crate::intersect::LaneStats {
        self.driver.bus().device().lane_stats()
    }
}

impl<B: ClockedBus> RegisterAccelerator<B> {
    /// Clocks the accelerator has run (its CYCLE counter, read without spending bus cycles on
    /// it).
    pub fn cycles(&self) -> u64 {
        self.driver.bus().clocks()
    }
}

impl<B: RegisterAccess> RegisterAccelerator<B> {
    /// Attaches to the accelerator behind `bus` (ID and version check), configures it and loads
    /// `patches` into its patch memory.
    pub fn with_bus(bus: B, patches: &[Patch], config: ModelConfig) -> Result<Self, ModelError> {
        let mut acc = Self::unattached(bus);
        acc.load(patches, config)?;
        Ok(acc)
    }

    /// Over `bus`, not yet attached, configured or loaded. (Moves the bus: a board's is a
    /// pointer, a host's model keeps its memories on the heap; `ModelAccelerator::new` builds
    /// the firmware's model in place instead.)
    fn unattached(bus: B) -> Self {
        RegisterAccelerator {
            driver: Driver::unattached(bus),
            norm: Normalise::IDENTITY,
            frame: None,
            origin: None,
            mode: None,
            origin_patch: None,
            skip: None,
            rays: 0,
            out_of_range: 0,
        }
    }

    /// Loads a new scene into the accelerator it is attached to (configuring it again with
    /// `config`): what a board does for every scene, since its registers are taken only once.
    pub fn load_scene(&mut self, patches: &[Patch], config: ModelConfig) -> Result<(), ModelError> {
        self.frame = None;
        self.origin = None;
        self.mode = None;
        self.origin_patch = None;
        self.skip = None;
        self.load(patches, config)
    }

    /// Clocks the accelerator has run, read from its CYCLE registers (two bus accesses).
    pub fn device_cycles(&mut self) -> u64 {
        self.driver.cycles()
    }

    fn load(&mut self, patches: &[Patch], config: ModelConfig) -> Result<(), ModelError> {
        self.configure(config)?;
        let capacity = self.driver.patch_capacity();
        if patches.len() > capacity as usize {
            return Err(ModelError::TooManyPatches {
                count: patches.len(),
                capacity,
            });
        }
        let beziers = bezier_count(patches);
        if beziers > BEZIER_ROWS {
            return Err(ModelError::TooManyBezierPatches {
                count: beziers,
                capacity: BEZIER_ROWS,
            });
        }
        self.norm = Normalise::around(patches, config.flatness)?;
        self.load_block(patches)
    }

    /// Attaches and configures the accelerator (CORDIC, (u,v) depth, Bezier subdivision).
    fn configure(&mut self, config: ModelConfig) -> Result<(), ModelError> {
        let driver = &mut self.driver;
        driver.attach()?;
        driver.configure(config.iterations, config.width, config.depth)?;
        driver.configure_subdivision(config.subdivision_depth, config.coord_width)?;
        Ok(())
    }

    /// Writes `block` into patch memory from slot 0 (its Bezier patches into control-point
    /// rows from row 0) in the normalisation already chosen, whose range every patch of the
    /// block was checked against ([`Normalise::around`]).
    fn load_block(&mut self, block: &[Patch]) -> Result<(), ModelError> {
        let frame = self.norm;
        // PATCH_ADDR auto-increments: one run of PATCH_DATA writes fills every control-point
        // row, another every slot. Nothing patch-sized is kept on the stack (one model per
        // worker thread lives there, and rayon's workers nest jobs).
        self.driver
            .load_control_points(block.iter().filter_map(|p| match &p.shape {
                Shape::Bezier(b) => frame.encode_bezier(b, 0).map(|(_, words)| words),
                Shape::Polygon(_) => None,
            }))?;
        let mut row = 0u32;
        self.driver
            .load_patches(block.iter().map(|p| match &p.shape {
                Shape::Polygon(_) => frame.encode(p).unwrap_or_default(),
                Shape::Bezier(b) => {
                    let slot = frame.encode_bezier(b, row).map(|(s, _)| s);
                    row += 1;
                    slot.unwrap_or_default()
                }
            }))?;
        Ok(())
    }

    fn coord(&self, v: Vec3) -> Option<[u32; 3]> {
        self.norm.coord(v)
    }

    fn set_skip(&mut self, patch: Option<u32>) {
        if self.skip != Some(patch) {
            self.driver.set_skip(patch);
            self.skip = Some(patch);
        }
    }

    /// Rays traced (rotations alone not counted).
    pub fn rays(&self) -> u64 {
        self.rays
    }

    /// Rays reported as misses because their origin was outside the coordinate range.
    pub fn out_of_range(&self) -> u64 {
        self.out_of_range
    }

    /// The driver (for measurements).
    pub fn driver_mut(&mut self) -> &mut Driver<B> {
        &mut self.driver
    }

    fn set_mode(&mut self, m: u32) {
        if self.mode != Some(m) {
            self.driver.set_mode(m);
            self.mode = Some(m);
        }
    }

    fn set_frame(&mut self, rot: &Rotation) {
        if self.frame != Some(*rot) {
            self.driver.frame_from_pairs(
                [unit_word(rot.cos_phi), unit_word(rot.sin_phi)],
                [unit_word(rot.cos_theta), unit_word(rot.sin_theta)],
                [unit_word(rot.cos_psi), unit_word(rot.sin_psi)],
            );
            self.frame = Some(*rot);
        }
    }

    /// Sets the origin; false if it is out of range.
    fn set_origin(&mut self, origin: Vec3) -> bool {
        match self.coord(origin) {
            Some(o) => {
                if self.origin != Some(o) {
                    self.driver.set_origin(o);
                    self.origin = Some(o);
                }
                true
            }
            None => false,
        }
    }

    fn stream(
        &mut self,
        n: usize,
        dir: impl FnMut(usize) -> [u32; 3],
        sink: impl FnMut(usize, [u32; 4]),
    ) {
        device_ok(self.driver.stream(n, dir, sink));
    }
}

/// The driver's answer, unwrapped: every entry is set up so that the device cannot refuse it,
/// so an error here is a bug in the model or the driver, not in the caller's data.
fn device_ok<T>(r: Result<T, crate::driver::DriverError>) -> T {
    match r {
        Ok(t) => t,
        Err(e) => panic!("model accelerator: {e:?}"),
    }
}

/// The rays of rings `rings` of `hemi`.
fn rays_in(hemi: &Hemisphere<'_>, rings: core::ops::Range<usize>) -> usize {
    rings.map(|j| hemi.rings()[j].count as usize).sum()
}

impl<B: RegisterAccess> Accelerator for RegisterAccelerator<B> {
    fn rotate(&mut self, rot: &Rotation, d: Vec3) -> Vec3 {
        self.set_frame(rot);
        self.set_mode(mode::ROTATE);
        let mut out = Vec3::ZERO;
        let w = [d.x, d.y, d.z].map(unit_word);
        self.stream(
            1,
            |_| w,
            |_, r| {
                out = Vec3::new(unit_f32(r[1]), unit_f32(r[2]), unit_f32(r[3]));
            },
        );
        out
    }

    fn set_origin_patch(&mut self, patch: Option<u32>) {
        self.origin_patch = patch;
    }

    fn nearest_hit(&mut self, ray: &Ray, t_max: f32) -> Option<Hit> {
        let mut hit = None;
        self.cast_from(ray.origin, &[ray.dir], true, |_, h| hit = h);
        hit.filter(|h| h.t < t_max)
    }

    fn cast_from<F: FnMut(usize, Option<Hit>)>(
        &mut self,
        origin: Vec3,
        dirs: &[Vec3],
        want_uv: bool,
        mut sink: F,
    ) {
        let scale = self.norm.scale;
        self.cast_from_words(origin, dirs, want_uv, |i, r| sink(i, decode(scale, r)));
    }

    fn cast_rings<F: FnMut(usize, u32, Option<Hit>)>(
        &mut self,
        origin: Vec3,
        rot: &Rotation,
        hemi: &Hemisphere<'_>,
        rings: core::ops::Range<usize>,
        want_uv: bool,
        mut sink: F,
    ) {
        let scale = self.norm.scale;
        self.cast_rings_words(origin, rot, hemi, rings, want_uv, |j, k, r| {
            sink(j, k, decode(scale, r))
        });
    }

    fn cast_hemispheres<F: FnMut(usize, usize, u32, Option<Hit>)>(
        &mut self,
        shots: &[HemiShot],
        hemi: &Hemisphere<'_>,
        rings: core::ops::Range<usize>,
        want_uv: bool,
        mut sink: F,
    ) {
        let scale = self.norm.scale;
        self.cast_hemispheres_words(shots, hemi, rings, want_uv, |s, j, k, r| {
            sink(s, j, k, decode(scale, r))
        });
    }
}

/// The casts as the accelerator answers them: RESULT words (a miss, or an origin out of
/// range, is [`MISS`]), which [`decode`] turns into hits and the streaming accelerator compares
/// across blocks without rounding t to f32 first.
impl<B: RegisterAccess> RegisterAccelerator<B> {
    fn cast_from_words(
        &mut self,
        origin: Vec3,
        dirs: &[Vec3],
        want_uv: bool,
        mut sink: impl FnMut(usize, [u32; 4]),
    ) {
        if !self.set_origin(origin) {
            self.out_of_range += dirs.len() as u64;
            (0..dirs.len()).for_each(|i| sink(i, MISS));
            return;
        }
        self.set_mode(mode::TRACE | uv_flag(want_uv));
        self.set_skip(self.origin_patch);
        self.rays += dirs.len() as u64;
        let words = |i: usize| [dirs[i].x, dirs[i].y, dirs[i].z].map(unit_word);
        self.stream(dirs.len(), words, sink);
    }

    fn cast_rings_words(
        &mut self,
        origin: Vec3,
        rot: &Rotation,
        hemi: &Hemisphere<'_>,
        rings: core::ops::Range<usize>,
        want_uv: bool,
        mut sink: impl FnMut(usize, u32, [u32; 4]),
    ) {
        let all = hemi.rings();
        let n = rays_in(hemi, rings.clone());
        if !self.set_origin(origin) {
            self.out_of_range += n as u64;
            for j in rings {
                (0..all[j].count).for_each(|k| sink(j, k, MISS));
            }
            return;
        }
        self.set_frame(rot);
        self.set_mode(mode::ROTATE_TRACE | uv_flag(want_uv));
        self.set_skip(self.origin_patch);
        self.rays += n as u64;
        let mut push = RingCursor::new(hemi, rings.clone());
        let mut pop = RingCursor::new(hemi, rings);
        self.stream(
            n,
            |_| {
                let (j, k) = push.next_index();
                let d = hemi.direction(j, k);
                [d.x, d.y, d.z].map(unit_word)
            },
            |_, r| {
                let (j, k) = pop.next_index();
                sink(j, k, r);
            },
        );
    }

    /// Every shot's registers and rays follow the last shot's rays into the FIFO without
    /// waiting for their results (the registers are latched per entry), so the pipeline drains
    /// once per batch instead of once per hemisphere.
    fn cast_hemispheres_words(
        &mut self,
        shots: &[HemiShot],
        hemi: &Hemisphere<'_>,
        rings: core::ops::Range<usize>,
        want_uv: bool,
        mut sink: impl FnMut(usize, usize, u32, [u32; 4]),
    ) {
        let mut pop = BatchCursor {
            shots,
            hemi,
            rings: rings.clone(),
            frame: self.norm,
            s: 0,
            j: rings.start,
            k: 0,
            in_range: None,
            outstanding: 0,
        };
        let mode_word = mode::ROTATE_TRACE | uv_flag(want_uv);
        for (s, shot) in shots.iter().enumerate() {
            if !self.feed_shot(shot, hemi, rings.clone(), mode_word, &mut pop, &mut sink) {
                self.out_of_range += rays_in(hemi, rings.clone()) as u64;
                for j in rings.clone() {
                    (0..hemi.rings()[j].count).for_each(|k| sink(s, j, k, MISS));
                }
            }
        }
        let rest = pop.outstanding;
        device_ok(self.driver.collect(rest, |_, r| {
            let (s, j, k) = pop.next_index();
            sink(s, j, k, r);
        }));
        self.origin_patch = None;
    }

    /// One shot of a batch: its registers written (origin, frame, mode, skip) and its rays fed
    /// while earlier shots' results are handed to `sink` through `pop`; false if its origin is
    /// out of range (nothing fed).
    fn feed_shot(
        &mut self,
        shot: &HemiShot,
        hemi: &Hemisphere<'_>,
        rings: core::ops::Range<usize>,
        mode_word: u32,
        pop: &mut BatchCursor<'_, '_>,
        sink: &mut impl FnMut(usize, usize, u32, [u32; 4]),
    ) -> bool {
        if !self.set_origin(shot.origin) {
            return false;
        }
        if self.frame != Some(shot.rot) {
            // the frame command is an entry of the ray FIFO, which the last shot may have filled
            let made = self.driver.make_room(|_, r| {
                let (s, j, k) = pop.next_index();
                sink(s, j, k, r);
            });
            device_ok(made);
        }
        self.set_frame(&shot.rot);
        self.set_mode(mode_word);
        self.set_skip(shot.origin_patch);
        let n = rays_in(hemi, rings.clone());
        self.rays += n as u64;
        pop.outstanding += n;
        let mut push = RingCursor::new(hemi, rings);
        let fed = self.driver.feed(
            n,
            |_| {
                let (j, k) = push.next_index();
                let d = hemi.direction(j, k);
                [d.x, d.y, d.z].map(unit_word)
            },
            |_, r| {
                let (s, j, k) = pop.next_index();
                sink(s, j, k, r);
            },
        );
        device_ok(fed);
        true
    }
}

/// Walks (shot, ring, index) over a batch's shots in range, in the order their rays are
/// streamed, and counts the results still to come.
struct BatchCursor<'a, 'h> {
    shots: &'a [HemiShot],
    hemi: &'a Hemisphere<'h>,
    rings: core::ops::Range<usize>,
    frame: Normalise,
    /// shot, ring, index of the next result; whether shot `s` was found in range
    s: usize,
    j: usize,
    k: u32,
    in_range: Option<(usize, bool)>,
    outstanding: usize,
}

impl BatchCursor<'_, '_> {
    fn shot_in_range(&mut self, s: usize) -> bool {
        match self.in_range {
            Some((t, ok)) if t == s => ok,
            _ => {
                let ok = self.frame.coord(self.shots[s].origin).is_some();
                self.in_range = Some((s, ok));
                ok
            }
        }
    }

    fn next_index(&mut self) -> (usize, usize, u32) {
        self.outstanding = self.outstanding.saturating_sub(1);
        loop {
            let next_shot = !self.shot_in_range(self.s) || self.j >= self.rings.end;
            if next_shot {
                self.s += 1;
                (self.j, self.k) = (self.rings.start, 0);
            } else if self.k >= self.hemi.rings()[self.j].count {
                (self.j, self.k) = (self.j + 1, 0);
            } else {
                self.k += 1;
                return (self.s, self.j, self.k - 1);
            }
        }
    }
}

/// The scene-to-fixed-point normalisation: centre and power-of-two scale, and the Bezier
/// flatness fraction.
#[derive(Clone, Copy, Debug)]
struct Normalise {
    centre: [f64; 3],
    scale: f64,
    flatness: f32,
}

impl Normalise {
    /// No shift, no scaling: what an accelerator holds before its first scene.
    const IDENTITY: Normalise = Normalise {
        centre: [0.0; 3],
        scale: 1.0,
        flatness: 0.0,
    };

    /// The normalisation of `patches`: about the centre of their bounding box (of vertices and
    /// control points), scaled by a power of two (so the conversion is exact) to fill
    /// [−1, 1]; an error names the first patch that does not convert.
    fn around(patches: &[Patch], flatness: f32) -> Result<Normalise, ModelError> {
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for p in patches {
            for v in p.hull() {
                for (c, x) in [v.x, v.y, v.z].into_iter().enumerate() {
                    lo[c] = lo[c].min(x as f64);
                    hi[c] = hi[c].max(x as f64);
                }
            }
        }
        let (centre, half) = if patches.is_empty() {
            ([0.0; 3], 1.0)
        } else {
            let centre: [f64; 3] = core::array::from_fn(|c| (lo[c] + hi[c]) / 2.0);
            let half = (0..3).map(|c| (hi[c] - lo[c]) / 2.0).fold(0.0, f64::max);
            (centre, half)
        };
        let mut scale = 1.0f64;
        while half * scale > 1.0 {
            scale /= 2.0;
        }
        while half > 0.0 && half * scale * 2.0 <= 1.0 {
            scale *= 2.0;
        }
        let norm = Normalise {
            centre,
            scale,
            flatness,
        };
        for (index, p) in patches.iter().enumerate() {
            let ok = match &p.shape {
                Shape::Polygon(_) => norm.encode(p).is_some(),
                Shape::Bezier(b) => norm.encode_bezier(b, 0).is_some(),
            };
            if !ok {
                return Err(ModelError::BadGeometry(index));
            }
        }
        Ok(norm)
    }

    /// A scene point as Q8.24 words, if in range (f64 arithmetic: exact for f32 inputs).
    fn coord(&self, v: Vec3) -> Option<[u32; 3]> {
        let p = [v.x, v.y, v.z];
        let mut out = [0u32; 3];
        for c in 0..3 {
            let x = (p[c] as f64 - self.centre[c]) * self.scale;
            out[c] = Coord::checked_from_num(x)?.to_bits() as u32;
        }
        Some(out)
    }

    /// The slot of a Bezier patch using control-point row `row`, and that row's words; `None`
    /// if its geometry does not convert.
    fn encode_bezier(
        &self,
        b: &hemi_kernel::geometry::Bezier,
        row: u32,
    ) -> Option<([u32; PATCH_WORDS], [u32; CP_WORDS])> {
        let mut words = [0u32; CP_WORDS];
        for (i, p) in b.cp.iter().enumerate() {
            words[3 * i..3 * i + 3].copy_from_slice(&self.coord(*p)?);
        }
        // the criteria in scene units, computed in f32 as the soft engine does
        let size = b.bounds().size();
        let to_coord = |x: f32| Coord::checked_from_num(x as f64 * self.scale);
        let slot = BezierSlot {
            row,
            tol: to_coord(self.flatness * size)?,
            t_min: to_coord(CURVED_T_MIN * size)?,
        };
        Some((slot.encode(), words))
    }

    /// The slot words of a planar patch: `None` if its geometry does not convert.
    fn encode(&self, p: &Patch) -> Option<[u32; PATCH_WORDS]> {
        let poly = p.as_polygon()?;
        let mut w = PatchWords {
            kind: if poly.sides == 3 {
                KIND_TRIANGLE
            } else {
                KIND_QUAD
            },
            ..PatchWords::default()
        };
        for (slot, v) in w.v.iter_mut().zip(poly.v.iter()) {
            let c = self.coord(*v)?;
            *slot = c.map(|x| Coord::from_bits(x as i32));
        }
        let n = poly.normal;
        if !n.is_finite() {
            return None;
        }
        w.n = [n.x, n.y, n.z].map(|x| Unit::from_bits(unit_word(x) as i32));
        Some(w.encode())
    }
}

/// Bezier patches among `patches` (each takes a row of control-point memory).
fn bezier_count(patches: &[Patch]) -> usize {
    patches
        .iter()
        .filter(|p| matches!(p.shape, Shape::Bezier(_)))
        .count()
}

/// MODE.NO_UV unless the caller wants (u,v): short results cost two bus reads fewer per ray, and
/// the model skips the (u,v) unit's arithmetic for them.
fn uv_flag(want_uv: bool) -> u32 {
    if want_uv {
        0
    } else {
        mode::NO_UV
    }
}

/// RESULT words of no hit.
const MISS: [u32; 4] = [0; 4];

/// A hit from RESULT words, t back in scene units.
fn decode(scale: f64, r: [u32; 4]) -> Option<Hit> {
    if r[0] & result::HIT == 0 {
        return None;
    }
    let t = Coord::from_bits(r[1] as i32).to_num::<f64>() / scale;
    Some(Hit {
        patch: r[0] & result::PATCH_MASK,
        t: t as f32,
        u: unit_f32(r[2]),
        v: unit_f32(r[3]),
        front: r[0] & result::FRONT != 0,
    })
}

/// Walks (ring, index) over a range of rings in the order the rays are streamed.
struct RingCursor<'h> {
    hemi: &'h Hemisphere<'h>,
    j: usize,
    k: u32,
}

impl<'h> RingCursor<'h> {
    fn new(hemi: &'h Hemisphere<'h>, rings: core::ops::Range<usize>) -> Self {
        RingCursor {
            hemi,
            j: rings.start,
            k: 0,
        }
    }

    fn next_index(&mut self) -> (usize, u32) {
        while self.k >= self.hemi.rings()[self.j].count {
            self.j += 1;
            self.k = 0;
        }
        let out = (self.j, self.k);
        self.k += 1;
        out
    }
}
