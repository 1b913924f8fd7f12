//! The intersection unit of paper §6.1 and fig. 7: the nearest hit of a ray over patch memory,
//! with several lanes working in parallel and the hemisphere culling of [`cull`].
//!
//! ```text
//!            ┌─ set-up unit b (one per bank): edge normals, plane, wedge ─► local memory b, sector bitmaps
//! ray ─► sector (vectoring CORDIC) ─► descriptor FIFO b ─► lane b: bitmap walk ─► edge stage ─► divider ─┐
//!      └──────────────────────────► Bezier lane: root slab test ─► subdivision engine ─────────────────────┴─► min tree ─► (u,v) ─► in order out
//! ```
//!
//! **Banks and lanes.** Patch memory and the per-origin "local memory" (like the soft engine's
//! `LocalPatch`) are banked by patch index modulo the lane count. When a ray arrives from a new
//! origin (or, with culling, in a new frame) the set-up units fill their banks in parallel, one
//! patch per clock each, so the pass costs ⌈P / lanes⌉ clocks plus the set-up pipe's latency;
//! hemisphere rays share their origin, so it is paid once per hemisphere. Each lane has a
//! descriptor FIFO of rays (a ray's sector and slot): it walks that sector's bitmap of its
//! bank word by word ([`bitmap_walk`]), handing one candidate patch per clock to its edge
//! stage, and a ray with no candidate in a bank costs that lane nothing. A ray is done when
//! every lane has passed its last candidate; its answers go through a min tree (nearest t,
//! ties to the lowest patch index, as the single scan kept them) and the (u,v) pipe, and rays
//! leave in the order they came.
//!
//! The stages of a lane:
//!
//! 1. [`EdgeStage`]: the ray is inside the patch's pyramid iff d · e_i ≥ 0 for every edge
//!    normal e_i = a_i × a_{i+1} (a_i = v_i − O, sign flipped to the side the origin is on), and
//!    the denominator n · d is formed. Edge normals are exact integers, and neighbours that share
//!    an edge hold exactly opposite ones, so a ray through an edge hits one of them (no leaks).
//! 2. [`DivideStage`]: t = h / (n · d), a pipelined divider of [`DIV_LATENCY`] clocks (modelled
//!    as one exact integer quotient; a restoring divider gives the same truncated quotient).
//! 3. the lane's running minimum, then the min tree over lanes (`merge_latency` clocks).
//!
//! On the compact datapath a lane has only the edge stage (a coarse test, the undecided pairs
//! to a shared exact unit): the pairs it finds inside go, with the h of the lane's word, to one
//! of its ray group's [`PLANE_UNITS`] plane units, which read the slot's n from the group's
//! normal memory and hold the n · d, the divider and each ray's running minimum by its tag
//! ([`group_plane`]); a lane whose pair finds them busy waits with it.
//!
//! Then the (u,v) pipe ([`uv`]) locates the hit point on the hit patch. Widths: coordinates Q8.24
//! (32 bits), a_i 34 bits, e_i ≤ 62 bits (an origin-wide truncation keeps far origins in range),
//! d · e_i and h, n · d up to 98 bits (i128 containers), t Q8.24. h ([`PlaneDist`], Q.54), n · d
//! ([`PlaneDen`], Q.60) and t are `fixed` types, so the divider's alignment comes from their
//! formats; the edge normals stay integers (their scale follows the origin).
//!
//! **How it is modelled.** The lanes are modelled at the level of their queues: when a ray
//! enters, its answer is computed by the stages above over exactly the candidates its lanes
//! would be handed, and the clock it leaves on follows from each lane's one-candidate-per-clock
//! occupancy (`bank_free`), the pipelines' fixed latencies and in-order retirement. Nothing
//! observable depends on a lane's registers between those clocks.
//!
//! **Bezier slots** are never culled and go to one Bezier lane, in index order: its first clock
//! slab-tests the ray against the patch's root box (computed in the set-up pass); a miss costs
//! that one clock, a hit runs the subdivision engine ([`bezier`], paper §6.1 and §7) to its
//! answer, one engine clock per clock. The engine prunes with the ray's nearest Bezier hit so far
//! (planar hits are in the other lanes at that point). A ray's Bezier lane starts once its
//! reciprocals 1/d are ready (the reciprocal unit at the ray queue's input).
//! Slots of unknown kinds, and Bezier slots naming a row outside control-point memory, are
//! skipped and reported through the UNSUPPORTED_PATCH error.

pub mod angle_memo;
pub mod bezier;
pub mod bitmap_walk;
pub mod bitmap_write;
pub mod coarse;
pub mod cull;
pub mod exact;
pub mod group_plane;
pub mod horizon;
pub mod patch_mem;
pub mod uv;

use crate::fifo::Fifo;
use crate::format::{quotient, Angle, Coord, Coord64, PlaneDen, PlaneDist, Unit};
use crate::params::{Params, MAX_LANES, MAX_SECTORS};
use crate::table::Table;
use angle_memo::AngleMemo;
use bezier::{BezierEngine, BezierStats, Box3, Job, RaySetup, SubdivConfig, BEZIER_ROWS};
use bitmap_walk::WordWalk;
use bitmap_write::{column, copy_clocks, row_writes, ColumnWriter};
use coarse::{
    coarse_edge, coarse_inside, narrow_patch, Coarse, CoarseRay, Verdict, COARSE_DIR_SHIFT,
};
use cull::{CullUnit, Reach, Wedge, BANDS};
use fixed::types::extra::U24;
use horizon::{PassTiming, HORIZON_LATENCY};
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

/// The set-up pass's origin-wide truncation of edge normals from origin `o` (Q8.24 words): a far
/// origin (|a| up to 2^33) would need 67-bit edge normals; shifting every patch's by the same
/// amount, towards zero, keeps shared edges exactly opposite.
pub fn origin_shift(o: [i64; 3]) -> u32 {
    let amax = o.iter().map(|c| c.unsigned_abs()).max().unwrap_or(0) + (1 << 25);
    let bits = 64 - amax.leading_zeros();
    (2 * bits + 2).saturating_sub(62)
}

/// x / 2^k rounded towards zero, as the set-up's truncation of edge normals is: −x gives
/// −(x / 2^k), so a shared edge's two normals stay exactly opposite. Shifts on the magnitude,
/// as the hardware does, rather than a 128-bit division (5 % of the model's time on a scene of a
/// thousand patches, where every origin sets up every patch).
pub fn shift_toward_zero(x: i128, k: u32) -> i128 {
    if x < 0 {
        -((-x) >> k)
    } else {
        x >> k
    }
}

/// h = n · a₀ (n a patch's Q2.30 normal words, a₀ = v₀ − O), or `None` when |h| ≤
/// [`PLANE_EPS`]: the origin is on the patch's plane and the set-up sets nothing up for it. Its
/// sign is the side the edge words are negated for. (The set-up pass's rule, which the RTL's
/// vectors take from here too.)
pub fn plane_distance(n: [i32; 3], a0: [i64; 3]) -> Option<PlaneDist> {
    let h = PlaneDist::from_bits((0..3).map(|c| n[c] as i128 * a0[c] as i128).sum());
    (h.abs() > PLANE_EPS).then_some(h)
}

/// The per-patch set-up for one origin.
#[derive(Clone, Copy, Debug, Default)]
pub struct LocalPatch {
    /// Edge normals a_i × a_{i+1}: integers whose scale follows the origin (an origin-wide
    /// truncation, see `setup`), so they have no fixed binary point; only the signs of d · e_i
    /// are used. The wide datapath's set-up forms them; the compact one's does not (its lanes
    /// test the coarse words), and its exact unit forms a pair's from the patch's corners
    /// ([`exact::verdict`]), so the model forms them only for those pairs (every patch's,
    /// every pass, were 7 % of its time on `scenes/cornell-8x8.toml`): they stay zero there.
    e: [[i64; 3]; 4],
    /// The edge normals as the coarse test's 18-bit words ([`coarse`]): truncated from `e`
    /// on the wide datapath, from the set-up's narrow products on the compact one.
    coarse: Coarse,
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
    /// The clock from which its sector and band are ready ([`cull::RAY_LATENCY`] after it
    /// entered the rotator); a culled ray's lanes wait for it.
    pub bin_at: u64,
    /// The frame a ROTATE_TRACE entry was turned by (ψ, θ, φ), and its direction before the
    /// turn (the culling unit's input); `None` for entries traced as given.
    pub frame: Option<[Angle; 3]>,
    /// The direction as written, before the rotator.
    pub dir_ref: [Unit; 3],
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

/// A finished ray: what the result FIFO's words are made of, not the whole [`RayIn`] (the
/// retirement buffer holds up to [`RAY_SLOTS`] of these and copies each in and out once; the
/// slimmer entry and the FIFO's wrap together took 3 % off the model's time).
#[derive(Clone, Copy, Debug, Default)]
pub struct RayOut<T: Copy + Default> {
    /// Its direction as it came in (a rotate-only entry's answer).
    pub dir: [Unit; 3],
    /// Whether the caller wanted the hit's (u,v).
    pub uv: bool,
    /// Carried from the ray.
    pub info: T,
    /// Its nearest hit.
    pub hit: Option<HitOut>,
}

/// Rays in the unit at once (entered and not yet retired) at most: the depth of each lane's
/// descriptor FIFO and of the retirement buffer. A build holds [`Params::ray_slots`] of them,
/// all on the compact datapath, 255 on the wide one (255 on both until session 24).
///
/// Why 1,023: they are also the device's credits, and so how far the set-up units look ahead.
/// An origin's set-up pass begins when its first ray reaches the ray FIFO's head, that is once
/// the last origin's rays are all in flight ([`IntersectUnit::announce`]). With 255 the next
/// pass overlapped only the last 255 rays of a hemisphere of 621, and the 1,216-patch Cornell
/// box cast at 3.93 cycles a ray; 511 gave 3.38, 1,023 2.62 and 2,047 2.60 (`hemi form-factors
/// scenes/cornell-8x8.toml --backend model --circles 16 --samples 2`).
pub const RAY_SLOTS: usize = 1023;

/// A Bezier patch's answer, computed by the subdivision engine: t, u, v, side.
#[derive(Clone, Copy, Debug, Default)]
struct Direct {
    hit: bool,
    t: Coord64,
    u: Unit,
    v: Unit,
    front: bool,
}

/// What the edge stage hands the divider for one (ray, patch).
#[derive(Clone, Copy, Debug, Default)]
struct Token {
    /// the ray is inside this patch's pyramid (edge stage result)
    inside: bool,
    h: PlaneDist,
    den: PlaneDen,
    front: bool,
}

/// Stage 1: edge tests and the denominator.
#[derive(Clone, Copy, Debug, Default)]
pub struct EdgeStage;

impl EdgeStage {
    fn eval(&self, dir: &[Unit; 3], lp: &LocalPatch) -> Token {
        if !lp.active {
            return Token::default();
        }
        let d = dir.map(|c| c.to_bits());
        let inside = lp.e[..lp.sides as usize]
            .iter()
            .all(|e| exact::inside_edge(&d, e));
        self.decided(dir, lp, inside)
    }

    /// The token of a pair whose side is known (`inside`): a compact lane's coarse test
    /// decided it, so its edges' exact products are not formed (a model of the lane need not
    /// form what the lane does not; a debug build checks them against the verdict).
    fn decided(&self, dir: &[Unit; 3], lp: &LocalPatch, inside: bool) -> Token {
        let mut tok = Token {
            inside,
            h: lp.h,
            front: lp.h.is_negative(),
            ..Token::default()
        };
        // n · d matters only inside the pyramid (the divider ignores it otherwise)
        if inside {
            let d = dir.map(|c| c.to_bits() as i128);
            let n = lp.n.map(|c| c.to_bits() as i128);
            tok.den = PlaneDen::from_bits(d[0] * n[0] + d[1] * n[1] + d[2] * n[2]);
        }
        tok
    }
}

/// Stage 2: t = h / (n · d) as Q8.24, or "no hit" (t ≤ 0, parallel, out of range).
#[derive(Clone, Copy, Debug, Default)]
pub struct DivideStage;

impl DivideStage {
    fn eval(&self, tok: Token) -> Option<Coord64> {
        if !tok.inside {
            return None;
        }
        // t in the Q8.24 of the result: positive and within its 32 bits
        match quotient::<U24, _, _>(tok.h, tok.den) {
            Some(q) if q.is_positive() && q.to_bits() <= i32::MAX as i128 => {
                Some(q.wrapping_to_num())
            }
            _ => None,
        }
    }
}

/// A candidate answer: patch, t, front, (u,v) if already known (Bezier).
#[derive(Clone, Copy, Debug)]
struct Best {
    patch: u32,
    t: Coord64,
    front: bool,
    uv: Option<(Unit, Unit)>,
}

/// The min tree's rule, as the single scan's running minimum kept it: the nearest t, and of
/// equal t the lowest patch index.
fn nearer(a: Option<Best>, b: Option<Best>) -> Option<Best> {
    match (a, b) {
        (Some(x), Some(y)) => Some(if (y.t, y.patch) < (x.t, x.patch) {
            y
        } else {
            x
        }),
        (x, None) => x,
        (None, y) => y,
    }
}

/// Clocks of the min tree over the lanes and the Bezier lane (one level per clock) and the
/// final select.
fn merge_latency(lanes: u32) -> u64 {
    (32 - lanes.leading_zeros()) as u64 + 1
}

/// Clocks from a planar patch's last corner to its last edge's coarse words and its κ, in the
/// compact set-up unit (`rtl/setup_unit.v`): the closing edge enters the edge unit two clocks
/// after the last corner (an edge is formed a clock after its second corner, the closing one a
/// clock after that), takes its 15, and the patch's κ is registered.
pub const EDGE_SETUP_LATENCY: u32 = 18;
/// Clocks a corner waits in the compact set-up unit before the culling unit's reach takes it
/// with its edge's words and the patch's κ (`rtl/setup_unit.v`): a quad's closing edge enters
/// the edge unit 5 clocks after its first corner and takes 15, and the patch's κ (the largest of
/// its edges') is registered a clock later, 21 clocks after the first corner; so every corner
/// waits 21.
pub const REACH_DELAY: u32 = 21;
/// Clocks from a planar patch's last corner to its reach in the compact set-up unit:
/// [`REACH_DELAY`] + [`cull::REACH_LATENCY`] = 84, as `rtl/setup_unit.v` takes them (until
/// session 28 the model charged the reach alone, as if the edge words were there at once).
pub const CULL_SETUP_LATENCY: u32 = REACH_DELAY + cull::REACH_LATENCY;

/// Clocks from a compact set-up unit taking a patch to the patch's first corner at its input:
/// the corner's read from patch memory, the block RAM's clock and a register after it, as
/// `rtl/bank_front.v` reads the box ([`horizon::BOX_READ`]; uncharged until session 32, when
/// the bank front's RTL showed it).
pub const CORNER_READ: u64 = horizon::BOX_READ;

/// Latency of the set-up pipe after its last patch: the wide datapath's edge normals' products
/// (`rtl/plane_setup.v`), or with culling the reach ([`cull::REACH_LATENCY`]); the compact
/// one's corner read ([`CORNER_READ`]), then its edge words ([`EDGE_SETUP_LATENCY`]; 2 until
/// session 28), or with culling the reach of the last patch ([`CULL_SETUP_LATENCY`]).
fn setup_latency(compact: bool, culling: bool) -> u64 {
    match (compact, culling) {
        (true, true) => CORNER_READ + CULL_SETUP_LATENCY as u64,
        (true, false) => CORNER_READ + EDGE_SETUP_LATENCY as u64,
        // the wide datapath's words are truncated from its exact edges, early enough to hide
        (false, true) => cull::REACH_LATENCY as u64,
        (false, false) => 2,
    }
}

/// The subdivision engine of a build: the compact datapath's tests a child box's axes one a
/// clock and forms a leaf's products two at a time.
fn engine(subdiv: SubdivConfig, compact: bool) -> BezierEngine {
    let e = BezierEngine::new(subdiv, bezier::STACK_ENTRIES);
    if compact {
        e.with_serial_slabs().with_serial_leaf()
    } else {
        e
    }
}

/// Iterative (u,v) units of the compact datapath, shared by all lanes: each runs one bisection
/// level a clock, so a hit whose (u,v) is wanted holds one for `depth` clocks (only hits on
/// planar patches of rays that want (u,v) use them).
pub const UV_UNITS: usize = 2;

/// Plane units of each ray group in a compact build: the lanes test edges only, and hand each
/// pair they find inside (with its slot's h from the lane's word) to one of their group's
/// plane units, which reads the slot's n from the group's normal memory ([`NORMAL_READ`]),
/// forms n · d, divides and keeps each ray's running minimum by its tag ([`group_plane`]). A
/// pair takes a plane unit one clock; a lane whose pair finds them busy holds it and stalls.
pub const PLANE_UNITS: usize = 1;

/// Clocks a compact build's plane unit spends reading a pair's unit normal n from its ray
/// group's normal memory (one read a clock, pipelined: latency only). Since issue 19's fourth
/// round n is not in the lanes' words (it does not depend on the origin, so one memory a group,
/// written with patch memory, holds it once instead of twice in every lane).
pub const NORMAL_READ: u64 = 1;

/// Most ray groups (CAPS_LANES holds groups − 1 in four bits).
const MAX_GROUPS: usize = 16;

/// A (ray, patch) pair found inside, for the plane units: its bank, its place among the bank's
/// candidates of the ray, and whether the shared exact unit decided it.
#[derive(Clone, Copy, Debug, Default)]
struct InsidePair {
    bank: u8,
    /// below the bank's slots (at most [`crate::params::MAX_CAPACITY`])
    at: u16,
    exact: bool,
}

/// Clocks a compact build's set-up unit spends on a slot: a corner a clock (one cross product,
/// the corner's dot products with the axes and its two vectorings: the multipliers and CORDIC
/// pipes `area` counts), so a quad costs four and any other slot (a Bezier root box, an empty
/// slot) one; the banks run in parallel ([`PassTiming`]).
pub fn corner_clocks(kind: u32) -> u64 {
    match kind {
        KIND_TRIANGLE => 3,
        KIND_QUAD => 4,
        _ => 1,
    }
}

/// A patch's corners relative to origin `o` (Q8.24 words): a_k = v_k − O, exact in 33 bits.
fn corner_vectors(p: &PatchWords, o: [i64; 3]) -> [[i64; 3]; 4] {
    core::array::from_fn(|k| core::array::from_fn(|c| p.v[k][c].to_bits() as i64 - o[c]))
}

/// A patch's exact edge normals from its corner vectors `a` (the first `sides`), each flipped to
/// the origin's side (`negate`) and truncated by the origin-wide `shift`.
fn exact_edges(a: &[[i64; 3]; 4], sides: usize, negate: bool, shift: u32) -> [[i64; 3]; 4] {
    let mut e = [[0; 3]; 4];
    for k in 0..sides {
        e[k] = exact::edge_normal(&a[k], &a[(k + 1) % sides], negate, shift);
    }
    e
}

/// Slot `i`'s corners less origin `o` (Q8.24 words), as the compact datapath's exact unit
/// reads them from patch memory, with the origin-wide shift of its edge normals.
fn exact_corners(mem: &PatchMem, i: usize, o: [Coord; 3]) -> ([[i64; 3]; 4], u32) {
    let o = o.map(|c| c.to_bits() as i64);
    (corner_vectors(&mem.patch(i), o), origin_shift(o))
}

/// A compact build's `lp` (slot `i`, set up from origin `o`) with the exact edge normals its
/// set-up did not form, for the debug build's checks of the lanes' verdicts.
fn with_exact_edges(mem: &PatchMem, i: usize, o: [Coord; 3], lp: &LocalPatch) -> LocalPatch {
    let (a, shift) = exact_corners(mem, i, o);
    let e = exact_edges(&a, lp.sides as usize, !lp.h.is_positive(), shift);
    LocalPatch { e, ..*lp }
}

/// One pair offered to a ray group's plane units (the clocks each is free) on clock `at`: the
/// clock the first free one takes it.
fn plane_take(units: &mut [u64; PLANE_UNITS], at: u64) -> u64 {
    let unit = (0..PLANE_UNITS).min_by_key(|&u| units[u]).unwrap_or(0);
    let taken = units[unit].max(at);
    units[unit] = taken + 1;
    taken
}

/// What the set-up pass was computed for: the origin, and the frame if it culled.
type SetupKey = ([Coord; 3], Option<[Angle; 3]>);

/// The candidates the lanes' bitmaps stand for, kept as bitmaps as the lanes keep them: per
/// sector and per polar band, a bit a slot (the planar patches that can be met there); every
/// active planar patch (unculled rays); every Bezier slot. A culled ray's candidates are its
/// sector's bits AND its band's, in slot order. (Until session 47 the model kept a list a
/// sector and tested each entry's bands: a culled ray of `scenes/cornell-8x8.toml` read 5.5
/// entries for each slot in its band, in the model's costliest loop.)
#[derive(Clone, Debug)]
struct Candidates {
    /// `words` words a sector, sector after sector
    sector: Table<u64, { (MAX_SECTORS as usize * PATCH_CAPACITY).div_ceil(64) }>,
    /// `words` words a band, band after band
    band: Table<u64, { (BANDS as usize * PATCH_CAPACITY).div_ceil(64) }>,
    /// words a row: the slots over 64, rounded up
    words: usize,
    active: Table<u16, PATCH_CAPACITY>,
    active_len: usize,
    bezier: Table<u16, PATCH_CAPACITY>,
    bezier_len: usize,
}

impl Candidates {
    /// Bitmaps and lists for `slots` patch slots in `sectors` sectors.
    fn new(slots: usize, sectors: u32) -> Self {
        let active = Table::new(0, slots);
        let (slots, words) = (active.len(), active.len().div_ceil(64));
        Candidates {
            sector: Table::new(0, sectors as usize * words),
            band: Table::new(0, BANDS as usize * words),
            words,
            active,
            active_len: 0,
            bezier: Table::new(0, slots),
            bezier_len: 0,
        }
    }

    fn clear(&mut self) {
        self.sector.fill(0);
        self.band.fill(0);
        self.active_len = 0;
        self.bezier_len = 0;
    }

    fn add(&mut self, i: u16, reach: Reach, sectors: u32) {
        self.active[self.active_len] = i;
        self.active_len += 1;
        let (word, bit) = (i as usize / 64, 1u64 << (i % 64));
        let words = self.words;
        for s in reach.wedge.sectors(sectors) {
            self.sector[s as usize * words + word] |= bit;
        }
        for b in reach.band_lo..=reach.band_hi {
            self.band[b as usize * words + word] |= bit;
        }
    }

    /// A ray's candidates into `out`, in slot order: those of sector and band `bin`, or every
    /// active planar patch. Returns how many.
    fn gather(&self, bin: Option<(u32, u32)>, out: &mut [u16]) -> usize {
        let Some((s, b)) = bin else {
            out[..self.active_len].copy_from_slice(&self.active[..self.active_len]);
            return self.active_len;
        };
        let words = self.words;
        let rows = self.sector[s as usize * words..][..words]
            .iter()
            .zip(&self.band[b as usize * words..][..words]);
        let mut n = 0;
        for (w, (sector, band)) in rows.enumerate() {
            let mut m = sector & band;
            while m != 0 {
                out[n] = (w * 64) as u16 + m.trailing_zeros() as u16;
                n += 1;
                m &= m - 1;
            }
        }
        n
    }
}

/// The unit.
#[derive(Clone, Debug)]
pub struct IntersectUnit<T: Copy + Default> {
    local: Table<LocalPatch, PATCH_CAPACITY>,
    key: Option<SetupKey>,
    candidates: Candidates,
    params: Params,
    cull: CullUnit,
    /// the corners' angles the culling set-up has vectored, and the hemisphere rays' (host
    /// speed only: [`angle_memo`])
    angles: AngleMemo,
    ray_angles: AngleMemo,
    /// the CORDIC words are wide enough to cull (see [`cull::MIN_CULL_WIDTH`])
    cull_ok: bool,
    /// the clock from which each lane, and the Bezier lane, can take its next candidate
    bank_free: [u64; MAX_LANES as usize],
    bezier_free: u64,
    /// rays in order with the clock they leave on
    retire: Fifo<(u64, RayOut<T>), RAY_SLOTS>,
    last_ready: u64,
    depth: u32,
    /// set when a slot of an unsupported kind was scanned
    pub unsupported: bool,
    /// set when the subdivision stack overflowed (a subtree was dropped)
    pub overflow: bool,
    engine: BezierEngine,
    /// root boxes of the control-point rows, from the set-up pass
    bez_root: [Box3; BEZIER_ROWS],
    /// work counters: (ray, patch) candidates handed to the lanes, rays, set-up passes
    stats: LaneStats,
    /// The compact datapath's clocks, cleared with the rest on a flush.
    clocks: CompactClocks,
    /// the current ray's pairs found inside (scratch of [`IntersectUnit::lanes`])
    inside: Table<InsidePair, PATCH_CAPACITY>,
    /// the current ray's candidates, in slot order (scratch of [`IntersectUnit::lanes`])
    listed: Table<u16, PATCH_CAPACITY>,
}

/// Where the compact datapath's shared resources stand.
#[derive(Clone, Copy, Debug, Default)]
struct CompactClocks {
    /// which of the two local-memory buffers the current set-up is in, the clock from which it
    /// is complete, the clock each buffer's last ray is done reading it, and the clock the
    /// set-up units take the next pass's first patch
    buffer: usize,
    ready_at: u64,
    release: [u64; 2],
    setup_free: u64,
    /// the ray group the next ray goes to; the shared exact edge unit's grid, and the clock
    /// the join lets it take its next pair
    next_group: u32,
    exact: exact::Schedule,
    exact_hold: u64,
    /// the clock each iterative (u,v) unit is free
    uv_free: [u64; UV_UNITS],
    /// the clock the reciprocal unit takes its next component
    recip_free: u64,
    /// the clock each ray group's plane units are free, and take their next readout
    plane_free: [[u64; PLANE_UNITS]; MAX_GROUPS],
    readout_free: [u64; MAX_GROUPS],
    /// the next set-up key seen at the ray FIFO's head ([`IntersectUnit::announce`]) and the
    /// clock it was first seen
    lookahead: Option<(SetupKey, u64)>,
    /// each bank's bitmap writer ([`bitmap_write`])
    writers: [ColumnWriter; MAX_LANES as usize],
}

/// What the lanes did (for measurements): candidates tested, rays, set-up passes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LaneStats {
    /// (ray, planar patch) pairs handed to a lane.
    pub candidates: u64,
    /// (ray, Bezier slot) pairs handed to the Bezier lane.
    pub bezier_candidates: u64,
    /// Rays traced (bypassing rotations not counted).
    pub rays: u64,
    /// Rays handed their sector's and band's candidates (the others got every active
    /// patch).
    pub culled_rays: u64,
    /// Set-up passes.
    pub setups: u64,
    /// Over the set-up passes that culled: active planar patches, those in every sector, and
    /// the (sector, band) bins their reaches cover.
    pub culled_patches: u64,
    /// Patches whose reach was every sector.
    pub full_patches: u64,
    /// Edges the coarse test could not decide, checked by the shared exact unit (compact
    /// builds).
    pub exact_edges: u64,
    /// Bins covered, summed.
    pub bins: u64,
    /// (ray, planar patch) pairs found inside the patch's pyramid, handed to a plane unit
    /// (compact builds).
    pub inside: u64,
    /// Clocks the culled rays' lanes spent on bitmap words beyond their candidates (a word
    /// whose only slot in band was the ray's own patch: [`bitmap_walk`]).
    pub walk_clocks: u64,
    /// Planar patches the horizon filter passed over, over the set-up passes ([`horizon`]).
    pub passed_over: u64,
    /// Clocks the set-up passes' buffers were ready after their last answer, waiting for the
    /// bitmap writers ([`bitmap_write`]), summed.
    pub write_wait: u64,
}

/// Exclusive bound of a Bezier hit's t: the largest t of the result's Q8.24 plus one LSB.
const T_LIMIT: Coord64 = Coord64::from_bits(i32::MAX as i64 + 1);

impl<T: Copy + Default> IntersectUnit<T> {
    /// An idle unit built with `params`, whose (u,v) pipe has `depth` levels (1..=24), whose
    /// subdivision engine runs `subdiv` (valid for [`bezier::STACK_ENTRIES`]), and which culls
    /// if the rotator's words are `width` ≥ [`cull::MIN_CULL_WIDTH`] bits.
    pub fn new(params: Params, depth: u32, subdiv: SubdivConfig, width: u32) -> Self {
        IntersectUnit {
            local: Table::new(LocalPatch::default(), params.capacity() as usize),
            key: None,
            candidates: Candidates::new(params.capacity() as usize, params.sectors),
            params,
            cull: CullUnit::new(params.sectors),
            angles: AngleMemo::new(),
            ray_angles: AngleMemo::for_rays(),
            cull_ok: width >= cull::MIN_CULL_WIDTH,
            bank_free: [0; MAX_LANES as usize],
            bezier_free: 0,
            retire: Fifo::default(),
            last_ready: 0,
            depth,
            unsupported: false,
            overflow: false,
            engine: engine(subdiv, params.compact),
            bez_root: [Box3::default(); BEZIER_ROWS],
            stats: LaneStats::default(),
            clocks: CompactClocks::default(),
            inside: Table::new(InsidePair::default(), params.capacity() as usize),
            listed: Table::new(0, params.capacity() as usize),
        }
    }

    /// Rebuilt for a new configuration, in place: everything in flight and the set-up are
    /// dropped (the per-slot tables are large, so they are not rebuilt by value).
    pub fn reconfigure(&mut self, depth: u32, subdiv: SubdivConfig, width: u32) {
        self.flush();
        self.depth = depth;
        self.cull_ok = width >= cull::MIN_CULL_WIDTH;
        self.engine = engine(subdiv, self.params.compact);
        self.unsupported = false;
        self.overflow = false;
    }

    /// The subdivision engine's work counters.
    pub fn bezier_stats(&self) -> BezierStats {
        self.engine.stats()
    }

    /// The lanes' work counters.
    pub fn lane_stats(&self) -> LaneStats {
        self.stats
    }

    /// Most subdivision stack entries in use at once.
    pub fn stack_high_water(&self) -> usize {
        self.engine.stack_high_water()
    }

    /// Whether a new ray can be started this clock.
    pub fn ready(&self) -> bool {
        self.retire.len() < self.params.ray_slots()
    }

    /// Rays started and not yet out.
    pub fn in_flight(&self) -> u32 {
        self.retire.len() as u32
    }

    /// Forgets the set-up (patch memory was written), and any pass begun ahead of its rays.
    pub fn invalidate(&mut self) {
        self.key = None;
        self.clocks.lookahead = None;
    }

    /// The entry at the ray FIFO's head on clock `now` traces from `origin`, in `frame` if it
    /// is turned by one: a compact build's set-up units may begin that origin's pass now, before
    /// its rays reach the unit (the credits hold at most [`RAY_SLOTS`] rays between the FIFO and
    /// the result FIFO, so without it a pass overlaps only those). The pass's values are those
    /// the unit computes when the first such ray starts (the same patch memory, origin and
    /// frame: a write to patch memory in between drops it); only its clock is taken from here.
    pub fn announce(&mut self, origin: [Coord; 3], frame: Option<[Angle; 3]>, now: u64) {
        if !self.params.compact || self.clocks.lookahead.is_some() {
            return;
        }
        let key = (origin, frame.filter(|_| self.culls()));
        if self.stale(&key) {
            self.clocks.lookahead = Some((key, now));
        }
    }

    /// Whether a ray of set-up key `key` needs a new pass: another origin, or another frame
    /// for a culled ray.
    fn stale(&self, key: &SetupKey) -> bool {
        match self.key {
            None => true,
            Some((o, f)) => o != key.0 || (key.1.is_some() && f != key.1),
        }
    }

    /// Drops everything in flight.
    pub fn flush(&mut self) {
        self.retire.clear();
        self.bank_free = [0; MAX_LANES as usize];
        self.bezier_free = 0;
        self.last_ready = 0;
        self.engine.flush();
        self.key = None;
        self.clocks = CompactClocks::default();
    }

    /// Whether rays in a frame are culled by this unit as configured.
    fn culls(&self) -> bool {
        self.cull_ok && self.cull.sectors() > 0
    }

    /// The set-up pass for `key` over the first `count` slots, starting once every lane is
    /// idle (one local memory per bank), ⌈count / lanes⌉ clocks and the set-up pipe's latency.
    fn setup_pass(
        &mut self,
        mem: &PatchMem,
        count: u32,
        key: SetupKey,
        axes: Option<[[Unit; 3]; 3]>,
        now: u64,
    ) {
        self.candidates.clear();
        // the horizon filter, ahead of a compact build's set-up units when the pass culls
        let horizon = axes.filter(|_| self.params.compact);
        let banks = self.params.banks() as usize;
        let filter = if horizon.is_some() {
            HORIZON_LATENCY
        } else {
            0
        };
        let latency = setup_latency(self.params.compact, axes.is_some()) + filter;
        // a compact build's pass starts once the set-up units and its buffer are free; its
        // answers leave the set-up pipe `latency` after their set-up, for the bitmap writers
        let start = self.pass_start(key, now);
        let copy = copy_clocks(self.cull.sectors());
        let mut timing = PassTiming::default();
        for i in 0..count as usize {
            let passed_over = horizon.is_some_and(|ax| self.passes_over(mem, i, key.0, &ax));
            let rows = if passed_over {
                self.local[i] = LocalPatch::default();
                self.stats.passed_over += 1;
                0
            } else {
                self.setup(mem, i, key.0, axes.as_ref())
            };
            let clocks = (!passed_over).then(|| corner_clocks(mem.kind(i)));
            let begins = timing.patch(i % banks, clocks);
            if let (Some(t), Some(c), true) = (begins, clocks, self.params.compact) {
                let at = start + t + c + latency;
                self.clocks.writers[i % banks].answer(column(i / banks), at, rows, copy);
            }
        }
        let lanes = self.params.lanes as usize;
        // one set-up unit a bank, writing every group's copy at once
        let pass = if self.params.compact {
            timing.clocks()
        } else {
            (count as u64).div_ceil(self.params.banks() as u64)
        };
        if self.params.compact {
            // the pass's end reaches the writers as its last answer would; a pass that does
            // not cull writes no bitmaps
            let answered = start + pass + latency;
            let written = match axes {
                Some(_) => self.clocks.writers[..banks]
                    .iter_mut()
                    .map(|w| w.close(answered, copy))
                    .max()
                    .unwrap_or(answered),
                None => answered,
            };
            self.double_buffered(start + pass, answered, written);
        } else {
            let busy = self.bank_free[..lanes]
                .iter()
                .copied()
                .fold(self.bezier_free, u64::max);
            let end = now.max(busy) + pass + latency;
            self.bank_free[..lanes].fill(end);
            self.bezier_free = end;
            self.clocks.ready_at = end;
        }
        self.key = Some(key);
        self.stats.setups += 1;
    }

    /// The clock a set-up pass for `key` seen on `now` starts: on a compact build, from the
    /// clock its key was first seen, once the set-up units are free and the buffer it fills (the
    /// one the current set-up is not in) has its last rays (two origins back) done reading it,
    /// while the lanes go on scanning the current buffer's rays.
    fn pass_start(&mut self, key: SetupKey, now: u64) -> u64 {
        if !self.params.compact {
            return now;
        }
        let begun = match self.clocks.lookahead.take() {
            Some((k, at)) if k == key => at,
            _ => now,
        };
        let next = 1 - self.clocks.buffer;
        begun
            .max(self.clocks.setup_free)
            .max(self.clocks.release[next])
    }

    /// A compact build's set-up pass ([`IntersectUnit::pass_start`]) that ends on `end`: the
    /// set-up units are free for the next pass then, and its buffer is ready once its last
    /// answer is out of the set-up pipe, on `answered`, and the bitmap writers have every answer
    /// in the block RAMs, on `written` ([`bitmap_write`]).
    fn double_buffered(&mut self, end: u64, answered: u64, written: u64) {
        self.clocks.setup_free = end;
        self.stats.write_wait += written.saturating_sub(answered);
        self.clocks.ready_at = answered.max(written);
        self.clocks.buffer = 1 - self.clocks.buffer;
    }

    /// The clock from which a ray started on `now` can take its first candidate, and the
    /// earliest it can be done: a compact build's ray waits for its set-up pass even without
    /// candidates (the wide datapath's lane takes such a ray for a clock: see `lanes`).
    fn first_clock(&self, now: u64) -> (u64, u64) {
        if self.params.compact {
            let t = (now + 1).max(self.clocks.ready_at);
            (t, t)
        } else {
            (now + 1, now + 1)
        }
    }

    /// A patch's coarse edge words: on the compact datapath from the set-up unit's narrow
    /// products of its corners `a` ([`narrow_edge`]), the patch's κ the largest of its edges';
    /// on the wide one truncated from the exact edges `e` (κ = 0).
    fn coarse_words(&self, a: &[[i64; 3]], e: &[[i64; 3]], shift: u32, negate: bool) -> Coarse {
        if self.params.compact {
            return narrow_patch(a, shift, negate).0;
        }
        let mut c = Coarse::default();
        for (w, e) in c.words.iter_mut().zip(e) {
            *w = coarse_edge(e);
        }
        c
    }

    /// Whether the horizon filter passes planar slot `i` over for a pass from `origin` in the
    /// frame of `axes`: its box is certainly below the horizon ([`horizon`]).
    fn passes_over(
        &self,
        mem: &PatchMem,
        i: usize,
        origin: [Coord; 3],
        axes: &[[Unit; 3]; 3],
    ) -> bool {
        let kind = mem.kind(i);
        if kind != KIND_QUAD && kind != KIND_TRIANGLE {
            return false;
        }
        let Some((lo, hi)) = mem.bounds(i) else {
            return false;
        };
        let o = origin.map(|c| c.to_bits() as i64);
        let below = horizon::below(lo, hi, o, axes[2].map(|c| c.to_bits()));
        debug_assert!(
            !below || self.sets_up_nothing(mem, i, o, axes),
            "the horizon filter passed over slot {i}, which the set-up would find"
        );
        below
    }

    /// Whether the set-up unit would find planar slot `i` in the origin's plane or below its
    /// horizon (what a slot the horizon filter passes over must be).
    fn sets_up_nothing(
        &self,
        mem: &PatchMem,
        i: usize,
        o: [i64; 3],
        axes: &[[Unit; 3]; 3],
    ) -> bool {
        let p = mem.patch(i);
        let sides = p.sides();
        let a = corner_vectors(&p, o);
        let Some(h) = plane_distance(p.n.map(|c| c.to_bits()), a[0]) else {
            return true;
        };
        let coarse = narrow_patch(&a[..sides], origin_shift(o), h.is_negative()).0;
        self.cull.reach(&a[..sides], &coarse, axes).wedge == Wedge::Below
    }

    fn setup(
        &mut self,
        mem: &PatchMem,
        i: usize,
        origin: [Coord; 3],
        axes: Option<&[[Unit; 3]; 3]>,
    ) -> u64 {
        let mut lp = LocalPatch::default();
        if mem.kind(i) == KIND_BEZIER {
            // the root box of its control points (a wide row read and three min/max trees)
            let row = BezierSlot::decode(mem.slot(i)).row;
            match mem.cp_row(row) {
                Some(words) => {
                    self.bez_root[row as usize] = Box3::of(&self.engine.load(words));
                    lp.bezier = true;
                    let c = &mut self.candidates;
                    c.bezier[c.bezier_len] = i as u16;
                    c.bezier_len += 1;
                }
                None => self.unsupported = true,
            }
            self.local[i] = lp;
            return 0;
        }
        let p: PatchWords = mem.patch(i);
        if p.kind == KIND_EMPTY {
            self.local[i] = lp;
            return 0;
        }
        if p.kind != KIND_TRIANGLE && p.kind != KIND_QUAD {
            self.unsupported = true;
            self.local[i] = lp;
            return 0;
        }
        let o = origin.map(|c| c.to_bits() as i64);
        let sides = p.sides();
        let a = corner_vectors(&p, o);
        let n = p.n;
        let Some(h) = plane_distance(n.map(|c| c.to_bits()), a[0]) else {
            self.local[i] = lp;
            return 0;
        };
        let shift = origin_shift(o);
        let negate = !h.is_positive();
        lp.sides = sides as u8;
        if !self.params.compact {
            lp.e = exact_edges(&a, sides, negate, shift);
        }
        lp.coarse = self.coarse_words(&a[..sides], &lp.e[..sides], shift, negate);
        lp.n = n;
        lp.h = h;
        lp.active = true;
        self.local[i] = lp;
        let reach = match axes {
            Some(ax) => {
                let r = self
                    .cull
                    .reach_remembering(&a[..sides], &lp.coarse, ax, &mut self.angles);
                let st = &mut self.stats;
                st.culled_patches += 1;
                let bands = (r.band_hi - r.band_lo) as u64 + 1;
                let sectors = match r.wedge {
                    Wedge::Below => 0,
                    Wedge::Full => {
                        st.full_patches += 1;
                        self.cull.sectors() as u64
                    }
                    Wedge::Sectors { len, .. } => len as u64,
                };
                st.bins += sectors * bands;
                r
            }
            None => Reach::ALL,
        };
        self.candidates.add(i as u16, reach, self.cull.sectors());
        // the bitmap writer's clocks for it, on a pass that culls
        axes.map_or(0, |_| row_writes(&reach, self.cull.sectors()))
    }

    /// Starts a ray (when [`IntersectUnit::ready`]) at clock `now`, over the first `count`
    /// slots of `mem`. `axes` turns a frame's x̂, ŷ, ẑ through the rotator, for the culling
    /// unit's set-up. Kept out of line: inlined into `Device::tick`, as the compiler chose once
    /// its body shrank in session 47, the model ran 3 % slower on `scenes/cornell-8x8.toml`.
    #[inline(never)]
    pub fn start(
        &mut self,
        mem: &PatchMem,
        count: u32,
        ray: RayIn<T>,
        now: u64,
        axes: impl FnOnce([Angle; 3]) -> [[Unit; 3]; 3],
    ) {
        debug_assert!(self.ready());
        let mut hit = None;
        let mut finish = now + 1;
        let mut wants_uv_unit = false;
        let mut group = None;
        if !ray.bypass {
            let key = (ray.origin, ray.frame.filter(|_| self.culls()));
            if self.stale(&key) {
                self.setup_pass(mem, count, key, key.1.map(axes), now);
            }
            let culled = self.key.is_some_and(|k| k.1.is_some()) && ray.frame.is_some();
            let bin = if culled {
                self.cull
                    .ray_bin_remembering(ray.dir_ref, &mut self.ray_angles)
            } else {
                None
            };
            self.stats.rays += 1;
            self.stats.culled_rays += bin.is_some() as u64;
            let at = if bin.is_some() {
                now.max(ray.bin_at)
            } else {
                now
            };
            let g = self.clocks.next_group as usize;
            self.clocks.next_group = (self.clocks.next_group + 1) % self.params.ray_groups.max(1);
            group = Some(g);
            let (planar, end) = self.lanes(mem, &ray, g, bin, at);
            let (curved, bez_end) = self.bezier_lane(mem, &ray, now);
            finish = end.max(bez_end);
            let used = &mut self.clocks.release[self.clocks.buffer];
            *used = (*used).max(finish);
            let best = nearer(planar, curved);
            wants_uv_unit = ray.uv && best.is_some_and(|b| b.uv.is_none());
            hit = best.map(|b| self.hit_out(mem, &ray, b));
        }
        let ready = self
            .retire_clock(finish, group, wants_uv_unit)
            .max(self.last_ready);
        self.last_ready = ready;
        let pushed = self.retire.push((
            ready,
            RayOut {
                dir: ray.dir,
                uv: ray.uv,
                info: ray.info,
                hit,
            },
        ));
        debug_assert!(pushed.is_ok(), "ray slots");
    }

    /// The clock a ray whose lanes (of ray group `group`, if it was cast) are done on `finish` can
    /// leave (before in-order retirement). The wide datapath: the min tree and the divider,
    /// then its unrolled (u,v) pipe for every ray. The compact one: the group's plane unit's
    /// answer ([`group_plane`]) against the Bezier lane's (a level of the min tree and the
    /// select), then the first free iterative (u,v) unit for a planar hit that wants (u,v)
    /// (the others pass it by).
    fn retire_clock(&mut self, finish: u64, group: Option<usize>, wants_uv_unit: bool) -> u64 {
        let depth = self.depth as u64;
        if !self.params.compact {
            let base = finish + merge_latency(self.params.banks()) + DIV_LATENCY as u64;
            return base + depth + 1;
        }
        let asked = match group {
            Some(g) => group_plane::readout(&mut self.clocks.readout_free[g], finish),
            None => finish,
        };
        let base = asked + group_plane::ANSWER_LATENCY + merge_latency(1);
        if !wants_uv_unit {
            return base + 1;
        }
        let unit = (0..UV_UNITS)
            .min_by_key(|&u| self.clocks.uv_free[u])
            .unwrap_or(0);
        let start = self.clocks.uv_free[unit].max(base);
        self.clocks.uv_free[unit] = start + depth;
        start + depth + 1
    }

    /// The planar lanes on one ray: its nearest planar hit and the clock its last lane is
    /// done. The ray goes to ray group `group`'s lanes (`start` deals them round robin); in a
    /// compact build each candidate's coarse test runs in its lane, the pairs it cannot decide
    /// queue for the shared exact unit after that lane's last candidate of the ray, and the
    /// pairs found inside go to the group's plane units (`compact_lanes`).
    fn lanes(
        &mut self,
        mem: &PatchMem,
        ray: &RayIn<T>,
        group: usize,
        bin: Option<(u32, u32)>,
        now: u64,
    ) -> (Option<Best>, u64) {
        let banks = self.params.banks() as usize;
        let mut counts = [0u64; MAX_LANES as usize];
        // edges the exact unit checks, per bank
        let mut exact = [0u64; MAX_LANES as usize];
        let mut best: Option<Best> = None;
        let compact = self.params.compact;
        let dc = CoarseRay::new(ray.dir.map(|c| c.to_bits() >> COARSE_DIR_SHIFT));
        let listed = self.candidates.gather(bin, &mut self.listed);
        let mut inside = 0;
        // a culled ray's lanes walk its sector's bitmaps word by word
        let mut walk = bin.map(|_| WordWalk::default());
        for &i in &self.listed[..listed] {
            let (bank, place) = (i as usize % banks, i as usize / banks);
            if let Some(walk) = walk.as_mut() {
                walk.see(bank, place);
            }
            if ray.skip == Some(i as u32) {
                continue;
            }
            counts[bank] += 1;
            let lp = &self.local[i as usize];
            let tok;
            if compact && lp.active {
                let verdict = coarse_inside(&dc, &lp.coarse, lp.sides as usize);
                tok = match verdict {
                    Verdict::Decided(inside) => {
                        debug_assert_eq!(
                            inside,
                            EdgeStage
                                .eval(&ray.dir, &with_exact_edges(mem, i as usize, ray.origin, lp))
                                .inside,
                            "coarse bound"
                        );
                        EdgeStage.decided(&ray.dir, lp, inside)
                    }
                    Verdict::Undecided(mask) => {
                        let edges = mask.count_ones() as u8;
                        exact[bank] += exact::pair_clocks(edges);
                        self.stats.exact_edges += edges as u64;
                        // the exact unit tests the masked edges alone: the others are positive
                        let d = ray.dir.map(|c| c.to_bits());
                        let (a, shift) = exact_corners(mem, i as usize, ray.origin);
                        let (sides, negate) = (lp.sides as usize, !lp.h.is_positive());
                        let inside = exact::verdict(&a[..sides], mask, negate, shift, &d);
                        debug_assert_eq!(
                            inside,
                            EdgeStage
                                .eval(&ray.dir, &with_exact_edges(mem, i as usize, ray.origin, lp))
                                .inside,
                            "the undecided edges decide"
                        );
                        EdgeStage.decided(&ray.dir, lp, inside)
                    }
                };
                if tok.inside {
                    self.inside[inside] = InsidePair {
                        bank: bank as u8,
                        at: (counts[bank] - 1) as u16,
                        exact: matches!(verdict, Verdict::Undecided(_)),
                    };
                    inside += 1;
                }
            } else {
                tok = EdgeStage.eval(&ray.dir, lp);
            }
            if let Some(t) = DivideStage.eval(tok) {
                if best.is_none_or(|b| t < b.t) {
                    best = Some(Best {
                        patch: i as u32,
                        t,
                        front: tok.front,
                        uv: None,
                    });
                }
            }
        }
        self.stats.candidates += counts.iter().sum::<u64>();
        self.stats.inside += inside as u64;
        // a lane's clocks: its candidates, or its walk's words read when they are more
        if let Some(walk) = walk {
            for (bank, n) in counts.iter_mut().enumerate() {
                let clocks = walk.clocks(bank, *n);
                // every word read holds a candidate, or only the ray's own patch
                debug_assert!(clocks <= *n + 1, "a bitmap walk read a word without a slot");
                self.stats.walk_clocks += clocks - *n;
                *n = clocks;
            }
        }
        let (first, mut end) = self.first_clock(now);
        if compact {
            let end = self
                .compact_lanes(group, &counts, &exact, inside, first)
                .max(end);
            return (best, end);
        }
        // a ray no lane has a candidate for still takes a clock of its group's first lane: the
        // lane carries its answer token in order, as `rtl/plane_unit.v`'s empty scan does, and
        // cannot know the ray has none before its origin's set-up pass has ended
        if counts[..banks].iter().all(|&n| n == 0) {
            counts[0] = 1;
        }
        let lanes = &mut self.bank_free[group * banks..(group + 1) * banks];
        for (b, free) in lanes.iter_mut().enumerate() {
            if counts[b] > 0 {
                let start = (*free).max(first);
                *free = start + counts[b];
                end = end.max(*free);
            }
        }
        (best, end)
    }

    /// A compact build's clocks for one ray in `group`, whose lanes have `counts` candidates
    /// and `exact` clocks of the shared exact unit, and whose first `inside` pairs of
    /// `self.inside` were found inside: the clock its last lane, exact check or plane unit is
    /// done. The lanes' pairs go to the group's plane units oldest first (a lane waits with its
    /// pair while they are busy, which delays its later candidates); the exact unit's pairs
    /// follow, as it decides them.
    fn compact_lanes(
        &mut self,
        group: usize,
        counts: &[u64; MAX_LANES as usize],
        exact: &[u64; MAX_LANES as usize],
        inside: usize,
        first: u64,
    ) -> u64 {
        let banks = self.params.banks() as usize;
        let lanes = group * banks..(group + 1) * banks;
        let mut start = [0u64; MAX_LANES as usize];
        for (b, free) in self.bank_free[lanes.clone()].iter().enumerate() {
            start[b] = (*free).max(first);
        }
        let pairs = &mut self.inside[..inside];
        pairs.sort_unstable_by_key(|p| (p.exact, p.bank, p.at));
        let lane_pairs = pairs.iter().filter(|p| !p.exact).count();
        let delay = self.plane_pairs(group, &start, lane_pairs);
        let mut end = first;
        let mut exact_end = [0u64; MAX_LANES as usize];
        for (b, free) in self.bank_free[lanes].iter_mut().enumerate() {
            if counts[b] > 0 {
                *free = start[b] + counts[b] + delay[b];
                end = end.max(*free);
            }
            if exact[b] > 0 {
                let unit = &mut self.clocks.exact;
                unit.advance(unit.begin(self.clocks.exact_hold.max(*free)), exact[b]);
                exact_end[b] = unit.verdict();
                end = end.max(exact_end[b]);
            }
        }
        for k in lane_pairs..inside {
            let p = self.inside[k];
            let taken = plane_take(
                &mut self.clocks.plane_free[group],
                exact_end[p.bank as usize],
            );
            self.clocks.exact_hold = self.clocks.exact_hold.max(taken + 1);
        }
        let plane = self.clocks.plane_free[group]
            .iter()
            .copied()
            .max()
            .unwrap_or(0);
        let exact = self.clocks.exact.free().max(self.clocks.exact_hold);
        end.max(exact).max(plane)
    }

    /// The first `n` pairs of `self.inside` (the lanes' own, sorted by bank and place) through
    /// `group`'s plane units, oldest first: each bank's stall, for lanes that started the ray
    /// on `start`.
    fn plane_pairs(
        &mut self,
        group: usize,
        start: &[u64; MAX_LANES as usize],
        n: usize,
    ) -> [u64; MAX_LANES as usize] {
        let pairs = &self.inside[..n];
        let units = &mut self.clocks.plane_free[group];
        let mut delay = [0u64; MAX_LANES as usize];
        // each bank's next pair: its index in `pairs`
        let mut next = [usize::MAX; MAX_LANES as usize];
        for (k, p) in pairs.iter().enumerate().rev() {
            next[p.bank as usize] = k;
        }
        let arrival = |k: usize, delay: &[u64; MAX_LANES as usize]| {
            let b = pairs[k].bank as usize;
            start[b] + delay[b] + pairs[k].at as u64 + 1
        };
        loop {
            let oldest = (0..MAX_LANES as usize)
                .filter(|&b| next[b] < n)
                .min_by_key(|&b| arrival(next[b], &delay));
            let Some(b) = oldest else {
                return delay;
            };
            let k = next[b];
            let at = arrival(k, &delay);
            delay[b] += plane_take(units, at) - at;
            next[b] = if pairs.get(k + 1).is_some_and(|p| p.bank as usize == b) {
                k + 1
            } else {
                usize::MAX
            };
        }
    }

    /// The Bezier lane on one ray: its nearest Bezier hit and the clock the lane is done.
    fn bezier_lane(&mut self, mem: &PatchMem, ray: &RayIn<T>, now: u64) -> (Option<Best>, u64) {
        let n = self.candidates.bezier_len;
        let (first, none) = self.first_clock(now);
        if n == 0 {
            return (None, none);
        }
        let setup = RaySetup::new(ray.origin, ray.dir);
        let mut best_t = T_LIMIT;
        let mut best = None;
        let mut clocks = 0u64;
        for k in 0..n {
            let i = self.candidates.bezier[k] as usize;
            if ray.skip == Some(i as u32) {
                continue;
            }
            self.stats.bezier_candidates += 1;
            let (d, c) = self.bezier_slot(mem, i, &setup, best_t);
            clocks += c;
            if d.hit {
                best_t = d.t;
                best = Some(Best {
                    patch: i as u32,
                    t: d.t,
                    front: d.front,
                    uv: Some((d.u, d.v)),
                });
            }
        }
        let recip = if self.params.compact {
            self.serial_recip(now)
        } else {
            ray.recip_at
        };
        let start = self.bezier_free.max(first).max(recip);
        self.bezier_free = start + clocks;
        (best, self.bezier_free)
    }

    /// A compact build's reciprocal unit for a ray started on `now` whose set-up has Bezier
    /// slots: one pipelined divider taking a component of d a clock (the wide datapath has
    /// three a front-end lane, at the ray queue's input, for every ray), so a ray holds it
    /// three clocks; the clock its three reciprocals are ready. Only the Bezier lane waits for
    /// them, and it spends at least a clock a Bezier slot on every ray.
    fn serial_recip(&mut self, now: u64) -> u64 {
        let start = self.clocks.recip_free.max(now + 1);
        self.clocks.recip_free = start + 3;
        start + 2 + bezier::RECIP_LATENCY
    }

    /// One Bezier slot: the root slab test, then the engine to its answer; the answer and
    /// the clocks it took.
    fn bezier_slot(
        &mut self,
        mem: &PatchMem,
        i: usize,
        ray: &RaySetup,
        t_max: Coord64,
    ) -> (Direct, u64) {
        let slot = BezierSlot::decode(mem.slot(i));
        let t_min = Coord64::from(slot.t_min);
        let root = self.bez_root[slot.row as usize];
        let Some(enter) = root.slab(ray, t_min, t_max) else {
            return (Direct::default(), 1);
        };
        let words = mem
            .cp_row(slot.row)
            .expect("row checked in the set-up pass");
        let cp = self.engine.load(words);
        let job = Job {
            ray: *ray,
            t_min,
            t_max,
            tol: Coord64::from(slot.tol),
        };
        self.engine.start(cp, enter, job);
        let mut clocks = 1;
        loop {
            clocks += 1;
            if let Some(r) = self.engine.tick() {
                self.overflow |= r.overflow;
                let d = match r.hit {
                    Some((t, u, v, front)) => Direct {
                        hit: true,
                        t,
                        u,
                        v,
                        front,
                    },
                    None => Direct::default(),
                };
                return (d, clocks);
            }
        }
    }

    /// The result of a ray's nearest candidate, with (u,v) by the bisection pipe if the ray
    /// wants it and the hit is planar.
    fn hit_out(&self, mem: &PatchMem, ray: &RayIn<T>, b: Best) -> HitOut {
        let t: Coord = b.t.wrapping_to_num();
        let mut out = HitOut {
            patch: b.patch,
            t,
            u: Unit::ZERO,
            v: Unit::ZERO,
            front: b.front,
        };
        match b.uv {
            Some((u, v)) => (out.u, out.v) = (u, v),
            None if ray.uv => {
                let p = mem.patch(b.patch as usize);
                // P = O + t d, the product truncated to the origin's Q8.24 (t < 128, so it is
                // the 32-bit Q8.24 it left the divider as)
                let hp: [i64; 3] = core::array::from_fn(|c| {
                    let td: Coord64 = t.wide_mul(ray.dir[c]).wrapping_to_num();
                    (Coord64::from(ray.origin[c]) + td).to_bits()
                });
                let mut cell = Cell::project(
                    p.v.map(|v| v.map(|c| c.to_bits() as i64)),
                    hp,
                    p.n.map(|c| c.to_bits() as i64),
                );
                for _ in 0..self.depth {
                    UvStage.apply(&mut cell);
                }
                out.u = uv::centre(cell.iu, self.depth);
                out.v = uv::centre(cell.iv, self.depth);
            }
            None => {}
        }
        out
    }

    /// The oldest ray, if it leaves on or before clock `now`.
    pub fn take_done(&mut self, now: u64) -> Option<RayOut<T>> {
        match self.retire.front() {
            Some((ready, _)) if *ready <= now => self.retire.pop().map(|(_, r)| r),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    /// A xorshift stream, for reproducible vectors and geometry (the culling unit's tests too).
    pub(super) struct Rng(pub(super) u64);
    impl Rng {
        pub(super) fn next(&mut self) -> u64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            self.0
        }
        /// A signed value of `bits` bits at most.
        pub(super) fn signed(&mut self, bits: u32) -> i64 {
            (self.next() as i64) >> (64 - bits)
        }
        /// Uniform in [0, 1).
        pub(super) fn unit(&mut self) -> f64 {
            (self.next() >> 11) as f64 / (1u64 << 53) as f64
        }
        /// Uniform in [−1, 1).
        pub(super) fn sym(&mut self) -> f64 {
            2.0 * self.unit() - 1.0
        }
    }

    #[test]
    fn the_shift_rounds_towards_zero_as_the_division_did() {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        for n in 0..20_000u32 {
            // edge normals' components: products of 33-bit words, either sign
            let x = rng.signed(60) as i128 * rng.signed(8) as i128;
            let k = n % 41;
            assert_eq!(
                super::shift_toward_zero(x, k),
                x / (1i128 << k),
                "{x} >> {k}"
            );
        }
        assert_eq!(super::shift_toward_zero(-1, 3), 0);
    }
}
