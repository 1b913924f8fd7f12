//! Vectors for the compact datapath's coarse edge units (`hdl-model/rtl/coarse_edge.v`, the
//! set-up unit's edge words, and `coarse_test.v`, a lane's test on them): the model's functions
//! ([`narrow_patch`], edge by edge, and [`coarse_inside`]) on every edge and many pairs, for the
//! testbench to feed the RTL one a clock and compare in order. These units have no clock of
//! their own in the model (the set-up pass is charged a corner a clock, the lane a candidate a
//! clock), so the values are compared, not clocks.
//!
//! File lines (decimal): `E u0 u1 u2 v0 v1 v2 shift negate w0 w1 w2 kappa` (an edge from corner
//! u to corner v, a = v_k − O, and the words and κ the model forms), `C d0 d1 d2 quad kappa
//! e00 … e32 decided inside undecided` (a pair: the ray's d' = d >> 14, the patch's words and
//! κ, and the model's verdict).
//!
//! Workloads: the set-up passes of pass 1 on a scene (every slot's edges from K × K lattice
//! points of every slot, the pass's origin-wide truncation and side; pairs of rays through
//! points next to each edge and at random), and random edges of every size and distance with
//! their degenerate cases (edges seen end-on, whose cross product cancels; corners at the
//! origin; origin-wide truncations up to 4 bits).

use super::plane::lattice_origins;
use crate::rng::XorShift;
use hemi_hdl_model::format::PlaneDist;
use hemi_hdl_model::intersect::coarse::{
    coarse_inside, narrow_patch, Coarse, CoarseRay, Verdict, COARSE_DIR_SHIFT,
};
use hemi_hdl_model::intersect::patch_mem::{KIND_QUAD, KIND_TRIANGLE, PATCH_WORDS};
use hemi_hdl_model::intersect::{origin_shift, plane_distance};
use std::fmt::Write as _;

/// What a file holds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    /// `E` lines.
    pub edges: usize,
    /// `C` lines.
    pub pairs: usize,
    /// Pairs the model left (partly) to the exact unit.
    pub undecided: usize,
}

/// The vectors: the set-up passes over `slots` from K × K (`samples`) lattice points of each
/// slot, then `random` random patches (each its edges and eight pairs).
pub fn vectors(
    slots: &[[u32; PATCH_WORDS]],
    samples: u32,
    random: usize,
    seed: u64,
) -> (String, Counts) {
    let mut out = Vectors::default();
    let mut rng = XorShift::new(seed ^ 0x5851_f42d_4c95_7f2d);
    for o in lattice_origins(slots, samples) {
        for s in slots {
            out.scene_patch(s, o, &mut rng);
        }
    }
    for n in 0..random {
        let (corners, shift) = random_patch(&mut rng, n);
        out.patch(&corners, shift, n % 2 == 1, &mut rng);
    }
    (out.text, out.counts)
}

#[derive(Default)]
struct Vectors {
    text: String,
    counts: Counts,
}

impl Vectors {
    /// Slot `w` as the set-up pass sees it from origin `o` (Q8.24 words).
    fn scene_patch(&mut self, w: &[u32; PATCH_WORDS], o: [i32; 3], rng: &mut XorShift) {
        if let Some(v) = set_up_view(w, o) {
            self.patch(&v.corners, v.shift, v.negate, rng);
        }
    }

    /// A patch's edges, then pairs of it: rays through points next to each edge (inside and
    /// out by a few parts in 10⁶) and random rays.
    fn patch(&mut self, a: &[[i64; 3]], shift: u32, negate: bool, rng: &mut XorShift) {
        let (coarse, kappas) = narrow_patch(a, shift, negate);
        for k in 0..a.len() {
            let (u, v) = (a[k], a[(k + 1) % a.len()]);
            self.edge(&u, &v, shift, negate, &coarse.words[k], kappas[k]);
        }
        for d in rays_at(a, rng) {
            self.pair(&d.map(|c| c >> COARSE_DIR_SHIFT), &coarse, a.len());
        }
    }

    fn edge(&mut self, u: &[i64; 3], v: &[i64; 3], shift: u32, neg: bool, w: &[i32; 3], k: u8) {
        let _ = writeln!(
            self.text,
            "E {} {} {} {} {} {} {shift} {} {} {} {} {k}",
            u[0], u[1], u[2], v[0], v[1], v[2], neg as u8, w[0], w[1], w[2]
        );
        self.counts.edges += 1;
    }

    fn pair(&mut self, d: &[i32; 3], coarse: &Coarse, sides: usize) {
        let (decided, inside, undecided) = match coarse_inside(&CoarseRay::new(*d), coarse, sides) {
            Verdict::Decided(inside) => (1, inside as u8, 0),
            Verdict::Undecided(mask) => (0, 0, mask.count_ones() as u8),
        };
        let words: Vec<String> = coarse
            .words
            .iter()
            .flatten()
            .map(|w| w.to_string())
            .collect();
        let _ = writeln!(
            self.text,
            "C {} {} {} {} {} {} {decided} {inside} {undecided}",
            d[0],
            d[1],
            d[2],
            (sides == 4) as u8,
            coarse.kappa,
            words.join(" ")
        );
        self.counts.pairs += 1;
        self.counts.undecided += (decided == 0) as usize;
    }
}

/// Rays at a patch (corners `a` less the origin), as the rotator hands d (Q2.30): through a
/// point next to each edge, inside or out by a few parts in 10⁶ of the way to the centre, and
/// one random ray.
pub(super) fn rays_at(a: &[[i64; 3]], rng: &mut XorShift) -> Vec<[i32; 3]> {
    let mut out: Vec<[i32; 3]> = (0..a.len())
        .map(|k| {
            let (u, v) = (a[k], a[(k + 1) % a.len()]);
            let (t, off) = (rng.f64(), (rng.f64() - 0.5) * 1e-5);
            direction(core::array::from_fn(|c| {
                let centre = a.iter().map(|p| p[c] as f64).sum::<f64>() / a.len() as f64;
                let on = u[c] as f64 + t * (v[c] - u[c]) as f64;
                on + off * (on - centre)
            }))
        })
        .collect();
    out.push(direction([0; 3].map(|_| (rng.bits() as i64 >> 33) as f64)));
    out
}

/// The unit direction along `g` in Q2.30 words.
pub(super) fn direction(g: [f64; 3]) -> [i32; 3] {
    let l = g.iter().map(|c| c * c).sum::<f64>().sqrt().max(1e-300);
    g.map(|c| ((c / l) * (1u64 << 30) as f64).round() as i32)
}

/// Whether slot `w` is planar (a triangle or a quad), the slots the set-up unit sets up.
pub(super) fn is_planar(w: &[u32; PATCH_WORDS]) -> bool {
    matches!(w[0] & 0xF, KIND_TRIANGLE | KIND_QUAD)
}

/// A planar slot as the set-up pass sees it from an origin.
pub(super) struct SetUpView {
    /// The corners a = v − O (33-bit values).
    pub corners: Vec<[i64; 3]>,
    /// The origin-wide truncation of the edge products.
    pub shift: u32,
    /// The origin is on the back of the slot (h < 0): the edge words are negated.
    pub negate: bool,
    /// h = n · (v₀ − O), as the set-up pass forms it (Q.54).
    pub h: PlaneDist,
}

/// A slot's unit normal n, its Q2.30 words.
pub(super) fn normal_words(w: &[u32; PATCH_WORDS]) -> [i32; 3] {
    core::array::from_fn(|c| w[13 + c] as i32)
}

/// Slot `w` from origin `o` (Q8.24 words), or `None` if the set-up pass sets nothing up: a slot
/// that is not planar, or an origin on its plane.
pub(super) fn set_up_view(w: &[u32; PATCH_WORDS], o: [i32; 3]) -> Option<SetUpView> {
    let sides = match w[0] & 0xF {
        KIND_TRIANGLE => 3,
        KIND_QUAD => 4,
        _ => return None,
    };
    let corners: Vec<[i64; 3]> = (0..sides)
        .map(|k| core::array::from_fn(|c| w[1 + 3 * k + c] as i32 as i64 - o[c] as i64))
        .collect();
    // the set-up pass's rule: an origin on the patch's plane sets nothing up
    let h = plane_distance(normal_words(w), corners[0])?;
    Some(SetUpView {
        corners,
        shift: origin_shift(o.map(i64::from)),
        negate: h.is_negative(),
        h,
    })
}

/// A random patch's corners relative to its origin (33-bit values, as a − O of Q8.24 words)
/// and an origin-wide truncation: near and far, from 2^4 to 2^31, a fifth with an edge seen
/// end-on, an occasional corner at the origin.
pub(super) fn random_patch(rng: &mut XorShift, n: usize) -> (Vec<[i64; 3]>, u32) {
    let signed = |rng: &mut XorShift, bits: u32| (rng.bits() as i64) >> (64 - bits);
    let far = 8 + (n % 25) as u32;
    let size = 4 + ((n / 5) % 28) as u32;
    let c0 = [0; 3].map(|_| signed(rng, far + 1));
    let mut corners = vec![c0];
    for _ in 0..(2 + n % 2) {
        let last = corners[corners.len() - 1];
        corners.push(core::array::from_fn(|c| last[c] + signed(rng, size)));
    }
    if n.is_multiple_of(5) {
        // the second corner along the first, give or take a unit: an edge seen end-on
        let k = 2 + (rng.bits() % 3) as i64;
        corners[1] = core::array::from_fn(|c| c0[c] + c0[c] / k + signed(rng, 2));
    }
    if n.is_multiple_of(97) {
        corners[0] = [0; 3];
    }
    let corners = corners
        .into_iter()
        .map(|v| v.map(|c| c.clamp(-(1 << 32), (1 << 32) - 1)))
        .collect();
    (
        corners,
        if n.is_multiple_of(3) {
            (n % 5) as u32
        } else {
            0
        },
    )
}
