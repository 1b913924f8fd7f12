//! The intersection unit of paper §6.1 and fig. 7: the nearest hit of a ray over patch memory.
//!
//! It keeps, per patch, the edge normals and plane distance seen from the current origin (its
//! "local memory", like the soft engine's `LocalPatch`): when a ray arrives from a new origin,
//! a set-up pass of one patch per clock fills it. Hemisphere rays share their origin, so the pass
//! is paid once per hemisphere. Then one patch is tested per clock, through a pipeline:
//!
//! 1. [`EdgeStage`]: the ray is inside the patch's pyramid iff d · e_i ≥ 0 for every edge
//!    normal e_i = a_i × a_{i+1} (a_i = v_i − O, sign flipped to the side the origin is on), and
//!    the denominator n · d is formed. Edge normals are exact integers, and neighbours that share
//!    an edge hold exactly opposite ones, so a ray through an edge hits one of them (no leaks).
//! 2. [`DivideStage`]: t = h / (n · d), a pipelined divider of [`DIV_LATENCY`] clocks (modelled
//!    as one exact integer quotient followed by a delay line; a restoring divider gives the same
//!    truncated quotient).
//! 3. [`SelectStage`]: keeps the nearest positive t of the ray and emits it after the ray's last
//!    patch.
//!
//! Then the (u,v) pipe ([`uv`]) locates the hit point on the hit patch. Widths: coordinates Q8.24
//! (32 bits), a_i 34 bits, e_i ≤ 62 bits (an origin-wide truncation keeps far origins in range),
//! d · e_i and h, n · d up to 98 bits (i128 containers), t Q8.24. h ([`PlaneDist`], Q.54), n · d
//! ([`PlaneDen`], Q.60) and t are `fixed` types, so the divider's alignment comes from their
//! formats; the edge normals stay integers (their scale follows the origin).
//!
//! A Bezier slot is not pipelined: its clock in the issue stage slab-tests the ray against the
//! patch's root box (computed in the set-up pass); a miss costs that one clock like a planar
//! patch, a hit hands the patch to the subdivision engine ([`bezier`], paper §6.1 and §7) and
//! the issue stage waits until the engine answers, then sends its t, (u,v) and side down the
//! same pipeline (through the divider's delay line, unchanged, so tokens stay in order); the
//! (u,v) pipe passes such a hit's (u,v) through instead of bisecting. The engine prunes with the
//! ray's nearest Bezier hit so far (planar hits are still in the divider at that point).
//! Slots of unknown kinds, and Bezier slots naming a row outside control-point memory, are
//! skipped and reported through the UNSUPPORTED_PATCH error.

pub mod bezier;
pub mod patch_mem;
pub mod uv;

use crate::format::{quotient, Coord, Coord64, PlaneDen, PlaneDist, Unit};
use crate::pipe::{Delay, Pipe};
use bezier::{BezierEngine, BezierStats, Box3, Job, RaySetup, SubdivConfig, BEZIER_ROWS};
use fixed::types::extra::U24;
use patch_mem::{
    BezierSlot, PatchMem, PatchWords, KIND_BEZIER, KIND_EMPTY, KIND_QUAD, KIND_TRIANGLE,
    PATCH_CAPACITY,
};
use uv::{Cell, UvStage};

/// Clocks of the pipelined divider (a quotient bit per clock for a 32-bit t plus two).
pub const DIV_LATENCY: usize = 34;

/// Plane distances at or below this count as "origin in the patch's plane": its own patch and
/// coplanar neighbours only graze. 2^-20 of the normalised scene half-size.
pub const PLANE_EPS: PlaneDist = PlaneDist::from_bits(1 << 34);

/// The per-patch set-up for one origin.
#[derive(Clone, Copy, Debug, Default)]
pub struct LocalPatch {
    /// Edge normals a_i × a_{i+1}: integers whose scale follows the origin (an origin-wide
    /// truncation, see `setup`), so they have no fixed binary point; only the signs of d · e_i
    /// are used.
    e: [[i64; 3]; 4],
    sides: u8,
    n: [Unit; 3],
    h: PlaneDist,
    active: bool,
    /// a Bezier slot with a valid row (its root box is in the unit's `bez_root`)
    bezier: bool,
}

/// A ray for the unit, with the info the device carries through.
#[derive(Clone, Copy, Debug, Default)]
pub struct RayIn<T: Copy + Default> {
    /// Origin, Q8.24.
    pub origin: [Coord; 3],
    /// Unit direction, Q2.30.
    pub dir: [Unit; 3],
    /// Skip the scan (rotate-only entries): one clock, no hit.
    pub bypass: bool,
    /// The caller wants the hit's (u,v). When clear the (u,v) stages are not enabled for the
    /// ray (it still takes its place in the pipe) and the hit's u and v are 0.
    pub uv: bool,
    /// A patch this ray never hits (the one its hemisphere stands on).
    pub skip: Option<u32>,
    /// The clock from which its reciprocals 1/d are ready (the reciprocal unit at the ray
    /// queue's input); Bezier slots wait for it.
    pub recip_at: u64,
    /// Carried to the result.
    pub info: T,
}

/// The nearest hit of a ray.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct HitOut {
    /// Patch index.
    pub patch: u32,
    /// Distance, Q8.24.
    pub t: Coord,
    /// u and v, Q2.30.
    pub u: Unit,
    /// v.
    pub v: Unit,
    /// The front side was hit.
    pub front: bool,
}

/// A finished ray.
#[derive(Clone, Copy, Debug, Default)]
pub struct RayOut<T: Copy + Default> {
    /// The ray as it came in.
    pub ray: RayIn<T>,
    /// Its nearest hit.
    pub hit: Option<HitOut>,
}

/// Ray slots: rays in flight are named by a slot index into the unit's ray table, which is what
/// the pipeline registers carry (a 6-bit tag) instead of the ray itself. The unit is in order,
/// so slots are handed out round-robin and one is free again once `in_flight` is below this.
pub const RAY_SLOTS: usize = 64;

/// A Bezier patch's answer, computed by the subdivision engine: t, u, v, side.
#[derive(Clone, Copy, Debug, Default)]
struct Direct {
    hit: bool,
    t: Coord64,
    u: Unit,
    v: Unit,
    front: bool,
}

/// The edge stage's output register.
#[derive(Clone, Copy, Debug, Default)]
struct Token {
    slot: u8,
    patch: u32,
    first: bool,
    last: bool,
    /// the ray is inside this patch's pyramid (edge stage result)
    inside: bool,
    h: PlaneDist,
    den: PlaneDen,
    front: bool,
    /// a Bezier slot's finished answer (bypasses the divider's arithmetic)
    direct: Option<Direct>,
}

/// What the divider hands on (its h and n · d inputs are consumed): a register of the delay
/// line that models the divider's latency.
#[derive(Clone, Copy, Debug, Default)]
struct Quotient {
    slot: u8,
    patch: u32,
    first: bool,
    last: bool,
    /// a positive, in-range t
    hit: bool,
    front: bool,
    t: Coord64,
    /// (u,v) already known (Bezier hits)
    uv: Option<(Unit, Unit)>,
}

/// A (u,v) pipeline register: the cell, whether the ray hit, and its slot.
#[derive(Clone, Copy, Debug, Default)]
struct UvReg {
    cell: Cell,
    hit: bool,
    slot: u8,
    /// (u,v) known on entry: the stages pass it through
    direct: Option<(Unit, Unit)>,
    /// the stages are enabled (the ray wants (u,v) and its hit is planar)
    bisect: bool,
}

/// Stage 1: edge tests and the denominator.
#[derive(Clone, Copy, Debug, Default)]
pub struct EdgeStage;

impl EdgeStage {
    fn eval<T: Copy + Default>(&self, mut tok: Token, ray: &RayIn<T>, lp: &LocalPatch) -> Token {
        if ray.bypass || !lp.active {
            tok.inside = false;
            return tok;
        }
        let d = ray.dir.map(|c| c.to_bits() as i128);
        let mut inside = true;
        for e in &lp.e[..lp.sides as usize] {
            let s = d[0] * e[0] as i128 + d[1] * e[1] as i128 + d[2] * e[2] as i128;
            inside &= s >= 0;
        }
        tok.inside = inside;
        tok.h = lp.h;
        // n · d matters only inside the pyramid (the divider ignores it otherwise)
        if inside {
            let n = lp.n.map(|c| c.to_bits() as i128);
            tok.den = PlaneDen::from_bits(d[0] * n[0] + d[1] * n[1] + d[2] * n[2]);
        }
        tok.front = lp.h.is_negative();
        tok
    }
}

/// Stage 2: t = h / (n · d) as Q8.24, or "no hit" (t ≤ 0, parallel, out of range).
#[derive(Clone, Copy, Debug, Default)]
pub struct DivideStage;

impl DivideStage {
    fn eval(&self, tok: Token) -> Quotient {
        let mut out = Quotient {
            slot: tok.slot,
            patch: tok.patch,
            first: tok.first,
            last: tok.last,
            hit: false,
            front: tok.front,
            t: Coord64::ZERO,
            uv: None,
        };
        if let Some(d) = tok.direct {
            out.hit = d.hit;
            out.t = d.t;
            out.front = d.front;
            out.uv = Some((d.u, d.v));
            return out;
        }
        if !tok.inside {
            return out;
        }
        // t in the Q8.24 of the result: positive and within its 32 bits
        match quotient::<U24, _, _>(tok.h, tok.den) {
            Some(q) if q.is_positive() && q.to_bits() <= i32::MAX as i128 => {
                out.hit = true;
                out.t = q.wrapping_to_num();
            }
            _ => {}
        }
        out
    }
}

/// The best candidate of a ray so far: patch, t, front, (u,v) if already known.
type Best = Option<(u32, Coord64, bool, Option<(Unit, Unit)>)>;

/// Stage 3: the running minimum of one ray.
#[derive(Clone, Copy, Debug, Default)]
pub struct SelectStage {
    best: Best,
}

impl SelectStage {
    /// The ray's slot and its nearest hit after its last patch.
    fn eval(&mut self, tok: Quotient) -> Option<(u8, Best)> {
        if tok.first {
            self.best = None;
        }
        if tok.hit && self.best.is_none_or(|(_, t, _, _)| tok.t < t) {
            self.best = Some((tok.patch, tok.t, tok.front, tok.uv));
        }
        tok.last.then(|| (tok.slot, self.best.take()))
    }
}

/// The unit.
#[derive(Clone, Debug)]
pub struct IntersectUnit<T: Copy + Default> {
    local: [LocalPatch; PATCH_CAPACITY],
    local_origin: Option<[Coord; 3]>,
    /// the rays in flight, by slot
    rays: [RayIn<T>; RAY_SLOTS],
    /// and their nearest hit, from the select stage on
    hits: [HitOut; RAY_SLOTS],
    next_slot: u8,
    /// slot of the ray being issued, the next patch to issue, and the set-up patch counter
    current: Option<u8>,
    next_patch: u32,
    setup_next: Option<u32>,
    /// The edge stage's output register, held as what the divider and the select stage make
    /// of it: the divider's arithmetic depends on this register alone, and the select stage
    /// sees the tokens in the same order whether it runs as they enter the divider's delay line
    /// or as they leave it (the line never stalls, and nothing else reads the select stage), so
    /// both are applied as the register is loaded. Only a ray's last token carries anything on:
    /// the ray's slot and nearest hit, which reach the (u,v) pipe after the divider's latency,
    /// on the clock they always did.
    edge_reg: Option<(u8, Best)>,
    divide: Delay<(u8, Best), DIV_LATENCY>,
    select: SelectStage,
    uv: Pipe<UvReg>,
    depth: u32,
    in_flight: u32,
    /// set when a slot of an unsupported kind was scanned
    pub unsupported: bool,
    /// set when the subdivision stack overflowed (a subtree was dropped)
    pub overflow: bool,
    /// the subdivision engine, and whether it is working on the slot at the issue stage
    engine: BezierEngine,
    engine_on: bool,
    /// root boxes of the control-point rows, from the set-up pass
    bez_root: [Box3; BEZIER_ROWS],
    /// the current ray with its reciprocals, and its nearest Bezier hit so far
    ray_setup: RaySetup,
    bez_best_t: Coord64,
}

/// Exclusive bound of a Bezier hit's t: the largest t of the result's Q8.24 plus one LSB.
const T_LIMIT: Coord64 = Coord64::from_bits(i32::MAX as i64 + 1);

impl<T: Copy + Default> IntersectUnit<T> {
    /// An idle unit whose (u,v) pipe has `depth` levels (1..=24) and whose subdivision engine
    /// runs `subdiv` (valid for [`bezier::STACK_ENTRIES`]).
    pub fn new(depth: u32, subdiv: SubdivConfig) -> Self {
        IntersectUnit {
            local: [LocalPatch::default(); PATCH_CAPACITY],
            local_origin: None,
            rays: [RayIn::default(); RAY_SLOTS],
            hits: [HitOut::default(); RAY_SLOTS],
            next_slot: 0,
            current: None,
            next_patch: 0,
            setup_next: None,
            edge_reg: None,
            divide: Delay::default(),
            select: SelectStage::default(),
            uv: Pipe::new(depth as usize + 1),
            depth,
            in_flight: 0,
            unsupported: false,
            overflow: false,
            engine: BezierEngine::new(subdiv, bezier::STACK_ENTRIES),
            engine_on: false,
            bez_root: [Box3::default(); BEZIER_ROWS],
            ray_setup: RaySetup::default(),
            bez_best_t: T_LIMIT,
        }
    }

    /// Rebuilt for a new configuration, in place: everything in flight and the set-up are
    /// dropped (the per-slot tables are large, so they are not rebuilt by value).
    pub fn reconfigure(&mut self, depth: u32, subdiv: SubdivConfig) {
        self.flush();
        self.depth = depth;
        self.uv = Pipe::new(depth as usize + 1);
        self.engine = BezierEngine::new(subdiv, bezier::STACK_ENTRIES);
        self.select = SelectStage::default();
        self.unsupported = false;
        self.overflow = false;
    }

    /// The subdivision engine's work counters.
    pub fn bezier_stats(&self) -> BezierStats {
        self.engine.stats()
    }

    /// Most subdivision stack entries in use at once.
    pub fn stack_high_water(&self) -> usize {
        self.engine.stack_high_water()
    }

    /// Whether a new ray can be started this clock.
    pub fn ready(&self) -> bool {
        self.current.is_none()
    }

    /// Rays started and not yet out of the (u,v) pipe.
    pub fn in_flight(&self) -> u32 {
        self.in_flight
    }

    /// Starts a ray (when [`IntersectUnit::ready`]).
    pub fn start(&mut self, ray: RayIn<T>) {
        debug_assert!(self.ready());
        // in order: the oldest ray in flight holds slot next_slot − in_flight
        assert!((self.in_flight as usize) < RAY_SLOTS, "ray slots exhausted");
        self.in_flight += 1;
        self.next_patch = 0;
        if !ray.bypass && self.local_origin != Some(ray.origin) {
            self.setup_next = Some(0);
        }
        let slot = self.next_slot;
        self.next_slot = (slot + 1) % RAY_SLOTS as u8;
        self.ray_setup = RaySetup::new(ray.origin, ray.dir);
        self.bez_best_t = T_LIMIT;
        self.rays[slot as usize] = ray;
        self.current = Some(slot);
    }

    /// Forgets the set-up (patch memory was written).
    pub fn invalidate(&mut self) {
        self.local_origin = None;
    }

    /// Drops everything in flight.
    pub fn flush(&mut self) {
        self.current = None;
        self.setup_next = None;
        self.edge_reg = None;
        self.divide.flush();
        self.select = SelectStage::default();
        self.uv.flush();
        self.engine.flush();
        self.engine_on = false;
        self.in_flight = 0;
        self.local_origin = None;
    }

    fn setup(&mut self, mem: &PatchMem, i: usize, origin: [Coord; 3]) {
        let mut lp = LocalPatch::default();
        if mem.kind(i) == KIND_BEZIER {
            // the root box of its control points (a wide row read and three min/max trees)
            let row = BezierSlot::decode(mem.slot(i)).row;
            match mem.cp_row(row) {
                Some(words) => {
                    self.bez_root[row as usize] = Box3::of(&self.engine.load(words));
                    lp.bezier = true;
                }
                None => self.unsupported = true,
            }
            self.local[i] = lp;
            return;
        }
        let p: PatchWords = mem.patch(i);
        if p.kind == KIND_EMPTY {
            self.local[i] = lp;
            return;
        }
        if p.kind != KIND_TRIANGLE && p.kind != KIND_QUAD {
            self.unsupported = true;
            self.local[i] = lp;
            return;
        }
        let o = origin.map(|c| c.to_bits() as i64);
        let sides = p.sides();
        let a: [[i64; 3]; 4] =
            core::array::from_fn(|k| core::array::from_fn(|c| p.v[k][c].to_bits() as i64 - o[c]));
        let n = p.n;
        let h = PlaneDist::from_bits(
            (0..3)
                .map(|c| n[c].to_bits() as i128 * a[0][c] as i128)
                .sum(),
        );
        if h.abs() <= PLANE_EPS {
            self.local[i] = lp;
            return;
        }
        // origin-wide truncation: a far origin (|a| up to 2^33) would need 67-bit edge normals;
        // shifting every patch's by the same amount, towards zero, keeps shared edges exactly
        // opposite.
        let amax = o.iter().map(|c| c.unsigned_abs()).max().unwrap_or(0) + (1 << 25);
        let bits = 64 - amax.leading_zeros();
        let shift = (2 * bits + 2).saturating_sub(62);
        let s: i128 = if h.is_positive() { 1 } else { -1 };
        for k in 0..sides {
            let (u, v) = (a[k], a[(k + 1) % sides]);
            let cross = [
                u[1] as i128 * v[2] as i128 - u[2] as i128 * v[1] as i128,
                u[2] as i128 * v[0] as i128 - u[0] as i128 * v[2] as i128,
                u[0] as i128 * v[1] as i128 - u[1] as i128 * v[0] as i128,
            ];
            // division by a power of two rounds towards zero: −x keeps giving −(x/2^k)
            lp.e[k] = cross.map(|c| ((c * s) / (1i128 << shift)) as i64);
        }
        lp.sides = sides as u8;
        lp.n = n;
        lp.h = h;
        lp.active = true;
        self.local[i] = lp;
    }

    /// One clock (the device's clock `now`) over the first `count` slots of `mem`; returns the
    /// ray leaving the (u,v) pipe.
    pub fn tick(&mut self, mem: &PatchMem, count: u32, now: u64) -> Option<RayOut<T>> {
        // (u,v) pipe, fed by the select stage
        let depth = self.depth;
        // its `depth` bisection levels are applied as the register leaves (`Pipe::shift`)
        if let Some(mut reg) = self.uv.shift(None) {
            if reg.hit && reg.direct.is_none() && reg.bisect {
                for _ in 0..depth {
                    UvStage.apply(&mut reg.cell);
                }
            }
            let ray = self.rays[reg.slot as usize];
            let hit = reg.hit.then(|| {
                let mut h = self.hits[reg.slot as usize];
                match reg.direct {
                    Some((u, v)) => {
                        h.u = u;
                        h.v = v;
                    }
                    None if reg.bisect => {
                        h.u = uv::centre(reg.cell.iu, depth);
                        h.v = uv::centre(reg.cell.iv, depth);
                    }
                    None => {}
                }
                h
            });
            self.in_flight -= 1;
            return self.finish_tick(mem, count, now, Some(RayOut { ray, hit }));
        }
        self.finish_tick(mem, count, now, None)
    }

    fn finish_tick(
        &mut self,
        mem: &PatchMem,
        count: u32,
        now: u64,
        out: Option<RayOut<T>>,
    ) -> Option<RayOut<T>> {
        // divider (and select) output → (u,v) pipe entry
        if let Some((slot, best)) = self.divide.tick(self.edge_reg.take()) {
            let mut entry = UvReg {
                cell: Cell::default(),
                hit: false,
                slot,
                direct: None,
                bisect: false,
            };
            if let Some((patch, t, front, direct)) = best {
                self.hits[slot as usize] = HitOut {
                    patch,
                    t: t.wrapping_to_num(),
                    u: Unit::ZERO,
                    v: Unit::ZERO,
                    front,
                };
                entry.hit = true;
                entry.direct = direct;
                // a planar hit whose ray wants (u,v): the bisection starts from the whole patch
                let ray = &self.rays[slot as usize];
                if direct.is_none() && ray.uv {
                    let p = mem.patch(patch as usize);
                    // P = O + t d, the product truncated to the origin's Q8.24 (t < 128, so it
                    // is the 32-bit Q8.24 it left the divider as)
                    let t: Coord = t.wrapping_to_num();
                    let hp: [i64; 3] = core::array::from_fn(|c| {
                        let td: Coord64 = t.wide_mul(ray.dir[c]).wrapping_to_num();
                        (Coord64::from(ray.origin[c]) + td).to_bits()
                    });
                    entry.cell = Cell::project(
                        p.v.map(|v| v.map(|c| c.to_bits() as i64)),
                        hp,
                        p.n.map(|c| c.to_bits() as i64),
                    );
                    entry.bisect = true;
                }
            }
            // the first (u,v) stage is this register; the pipe's other stages bisect
            self.uv.load_first(entry);
        }
        // set-up pass (one patch per clock) or issue (one patch per clock) into the edge stage
        if let Some(i) = self.setup_next {
            let origin = self
                .current
                .map(|s| self.rays[s as usize].origin)
                .unwrap_or_default();
            if i < count {
                self.setup(mem, i as usize, origin);
            }
            if i + 1 >= count {
                self.setup_next = None;
                self.local_origin = Some(origin);
            } else {
                self.setup_next = Some(i + 1);
            }
        } else if let Some(slot) = self.current {
            let ray = &self.rays[slot as usize];
            let p = self.next_patch;
            let pi = (p as usize).min(PATCH_CAPACITY - 1);
            let last = ray.bypass || count == 0 || p + 1 >= count;
            let mut tok = Token {
                slot,
                patch: p,
                first: p == 0,
                last,
                ..Token::default()
            };
            let skip = ray.skip == Some(p);
            if self.local[pi].bezier && !ray.bypass && count > 0 && !skip {
                let recip_at = ray.recip_at;
                match self.bezier_issue(mem, pi, recip_at, now) {
                    Some(d) => tok.direct = Some(d),
                    // waiting for the reciprocals or for the engine: the issue stage stalls
                    None => return out,
                }
            } else {
                tok = EdgeStage.eval(tok, ray, &self.local[pi]);
                if ray.bypass || count == 0 || skip {
                    tok.inside = false;
                }
            }
            self.edge_reg = self.select.eval(DivideStage.eval(tok));
            self.next_patch += 1;
            if last {
                self.current = None;
            }
        }
        out
    }

    /// The issue stage on Bezier slot `i`: the root slab test on its first clock, then one
    /// engine clock per clock until the engine answers. `None` while the stage must stall.
    fn bezier_issue(
        &mut self,
        mem: &PatchMem,
        i: usize,
        recip_at: u64,
        now: u64,
    ) -> Option<Direct> {
        if self.engine_on {
            let r = self.engine.tick()?;
            self.engine_on = false;
            self.overflow |= r.overflow;
            return Some(match r.hit {
                Some((t, u, v, front)) => {
                    self.bez_best_t = t;
                    Direct {
                        hit: true,
                        t,
                        u,
                        v,
                        front,
                    }
                }
                None => Direct::default(),
            });
        }
        if now < recip_at {
            return None;
        }
        let slot = BezierSlot::decode(mem.slot(i));
        let t_min = Coord64::from(slot.t_min);
        let root = self.bez_root[slot.row as usize];
        match root.slab(&self.ray_setup, t_min, self.bez_best_t) {
            None => Some(Direct::default()),
            Some(enter) => {
                let words = mem
                    .cp_row(slot.row)
                    .expect("row checked in the set-up pass");
                let cp = self.engine.load(words);
                self.engine.start(
                    cp,
                    enter,
                    Job {
                        ray: self.ray_setup,
                        t_min,
                        t_max: self.bez_best_t,
                        tol: Coord64::from(slot.tol),
                    },
                );
                self.engine_on = true;
                None
            }
        }
    }
}
