//! Vectors for the compact datapath's shared exact edge unit (`hdl-model/rtl/exact_edge.v`):
//! pairs a lane's coarse test left undecided, each with the clock it reaches the unit, and the
//! model's clock for its start, its verdict's clock and its verdict ([`exact`]).
//!
//! File lines (decimal): first `L window grid latency`, the unit's clocks; then one line a
//! pair, `X at slot quad mask negate shift o0 o1 o2 d0 d1 d2 v00 v01 v02 … v32 begin verdict
//! inside`: the clock it is offered, the patch slot its corners are read from, a quad or a
//! triangle, the undecided edges (bit k: corner k to the next), the side and the origin-wide
//! truncation, the origin (Q8.24), the ray's direction (Q2.30), the four corners (Q8.24; a
//! triangle's fourth repeats its third), the clock the model takes it, the clock its verdict is
//! out and the verdict. Pairs are offered in order; one waits until the unit takes it.
//!
//! Workloads: the set-up passes of a scene (from K × K lattice points of every planar slot,
//! every planar slot it sets up, rays through points next to each edge, inside and out by a
//! few parts in 10⁶, and a random ray), the pairs the coarse test leaves undecided with their
//! masks and one in four of the others with a random mask; and random patches of every size and
//! distance with their degenerate cases (an edge seen end-on, a corner at the origin), the side
//! and every truncation (half the pairs at another than their patch's, so that pairs back to
//! back differ in it), with random masks. Offered back to back, a few clocks after the unit
//! could take them (waiting for its grid) or about when it falls idle (an idle unit takes them
//! at once).

use super::coarse::{random_patch, rays_at, set_up_view};
use super::plane::lattice_origins;
use crate::rng::XorShift;
use hemi_hdl_model::intersect::coarse::{
    coarse_inside, narrow_patch, CoarseRay, Verdict, COARSE_DIR_SHIFT,
};
use hemi_hdl_model::intersect::exact;
use hemi_hdl_model::intersect::patch_mem::PATCH_WORDS;
use std::fmt::Write as _;

/// Slots the testbench's corner memory holds (`exact_edge.v`'s SLOT_BITS 10): pair n reads
/// slot n mod this, long free by then.
const SLOTS: usize = 1024;

/// What a file holds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    /// Pairs.
    pub pairs: usize,
    /// Edges tested (the masks' bits).
    pub edges: usize,
    /// Pairs found inside.
    pub inside: usize,
    /// Pairs the coarse test left undecided on the scene (with their own masks).
    pub undecided: usize,
}

/// A pair as the unit is handed it.
struct Pair {
    corners: Vec<[i32; 3]>,
    origin: [i32; 3],
    shift: u32,
    negate: bool,
    mask: u8,
    d: [i32; 3],
}

/// The vectors: the set-up passes over `slots` from K × K (`samples`) lattice points of each
/// slot, then `random` random patches (each with five pairs).
pub fn vectors(
    slots: &[[u32; PATCH_WORDS]],
    samples: u32,
    random: usize,
    seed: u64,
) -> (String, Counts) {
    let mut out = Vectors::new();
    let mut rng = XorShift::new(seed ^ 0x1405_7b7e_f767_814f);
    for o in lattice_origins(slots, samples) {
        for s in slots {
            out.scene_patch(s, o, &mut rng);
        }
    }
    for n in 0..random {
        let (a, shift) = random_patch(&mut rng, n);
        let origin = [0; 3].map(|_| (rng.bits() as i64 >> 34) as i32);
        let corners: Vec<[i32; 3]> = a
            .iter()
            .map(|v| {
                core::array::from_fn(|c| {
                    (origin[c] as i64 + v[c]).clamp(-(1 << 31), (1 << 31) - 1) as i32
                })
            })
            .collect();
        let negate = rng.bits() & 1 == 1;
        for d in rays_at(&relative(&corners, origin), &mut rng) {
            let mask = random_mask(&mut rng, corners.len());
            // half the pairs at another truncation than the patch's: the unit takes it with
            // each pair, and an edge's normal must be cut by its own pair's, not the next's
            // (the rays next to an edge are the ones whose verdict its rounding decides)
            let shift = match rng.bits() & 1 {
                0 => shift,
                _ => (rng.bits() % 5) as u32,
            };
            out.pair(
                &Pair {
                    corners: corners.clone(),
                    origin,
                    shift,
                    negate,
                    mask,
                    d,
                },
                &mut rng,
            );
        }
    }
    (out.text, out.counts)
}

struct Vectors {
    text: String,
    counts: Counts,
    /// The unit's grid and the clock the last pair was offered.
    unit: exact::Schedule,
    at: u64,
}

impl Vectors {
    fn new() -> Self {
        let text = format!(
            "L {} {} {}\n",
            exact::WINDOW,
            exact::GRID_START,
            exact::LATENCY
        );
        Vectors {
            text,
            counts: Counts::default(),
            unit: exact::Schedule::default(),
            at: 0,
        }
    }

    /// Slot `w` seen from origin `o`: the pairs of rays near its edges that the coarse test
    /// leaves undecided, and one in four of the others with a random mask.
    fn scene_patch(&mut self, w: &[u32; PATCH_WORDS], o: [i32; 3], rng: &mut XorShift) {
        let Some(view) = set_up_view(w, o) else {
            return;
        };
        let sides = view.corners.len();
        let (coarse, _) = narrow_patch(&view.corners, view.shift, view.negate);
        let corners = (0..sides)
            .map(|k| core::array::from_fn(|c| w[1 + 3 * k + c] as i32))
            .collect::<Vec<[i32; 3]>>();
        for d in rays_at(&view.corners, rng) {
            let coarse_d = CoarseRay::new(d.map(|c| c >> COARSE_DIR_SHIFT));
            let mask = match coarse_inside(&coarse_d, &coarse, sides) {
                Verdict::Undecided(mask) => {
                    self.counts.undecided += 1;
                    mask
                }
                Verdict::Decided(_) if rng.bits().is_multiple_of(4) => random_mask(rng, sides),
                Verdict::Decided(_) => continue,
            };
            let pair = Pair {
                corners: corners.clone(),
                origin: o,
                shift: view.shift,
                negate: view.negate,
                mask,
                d,
            };
            self.pair(&pair, rng);
        }
    }

    /// One pair, with the model's clocks and verdict: offered with the last (back to back), or
    /// a few clocks after the unit could take it (waiting for the grid), or once the unit is
    /// idle or about to be (an idle unit takes it at once).
    fn pair(&mut self, p: &Pair, rng: &mut XorShift) {
        let free = self.at.max(self.unit.free());
        self.at = match rng.bits() % 10 {
            0..=4 => self.at,
            5..=7 => free + 1 + rng.bits() % (exact::WINDOW - 1),
            _ => free + exact::IDLE_AFTER - 4 + rng.bits() % 30,
        };
        let edges = p.mask.count_ones() as u8;
        let begin = self.unit.take(self.at, edges);
        let verdict = self.unit.verdict();
        let a = relative(&p.corners, p.origin);
        let inside = exact::verdict(&a, p.mask, p.negate, p.shift, &p.d);
        let v: Vec<String> = (0..4)
            .flat_map(|k| p.corners[k.min(p.corners.len() - 1)])
            .map(|c| c.to_string())
            .collect();
        let (o, d) = (p.origin, p.d);
        let _ = writeln!(
            self.text,
            "X {} {} {} {} {} {} {} {} {} {} {} {} {} {begin} {verdict} {}",
            self.at,
            self.counts.pairs % SLOTS,
            (p.corners.len() == 4) as u8,
            p.mask,
            p.negate as u8,
            p.shift,
            o[0],
            o[1],
            o[2],
            d[0],
            d[1],
            d[2],
            v.join(" "),
            inside as u8
        );
        self.counts.pairs += 1;
        self.counts.edges += edges as usize;
        self.counts.inside += inside as usize;
    }
}

/// Corners less the origin (33-bit values).
fn relative(corners: &[[i32; 3]], o: [i32; 3]) -> Vec<[i64; 3]> {
    corners
        .iter()
        .map(|v| core::array::from_fn(|c| v[c] as i64 - o[c] as i64))
        .collect()
}

/// A mask of at least one of `sides` edges, each nonzero mask as likely.
fn random_mask(rng: &mut XorShift, sides: usize) -> u8 {
    (rng.bits() % ((1 << sides) - 1)) as u8 + 1
}
