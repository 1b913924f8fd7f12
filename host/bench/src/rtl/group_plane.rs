//! Vectors for a compact build's plane unit (`hdl-model/rtl/group_plane.v`): the pairs a ray
//! group's lanes find inside, each on the clock the unit takes it, and each ray's readout with
//! the model's answer ([`group_plane`]).
//!
//! File lines (decimal): first `L t_latency answer_latency`, the unit's clocks; then `N slot n0
//! n1 n2`, the normal memory's words (Q2.30), written before clock 0; then, in clock order,
//! `P at slot tag h d0 d1 d2` (a pair taken on clock `at`: the slot, the ray's tag, the slot's
//! h (Q.54) from the ray's origin, the ray's direction, Q2.30) and `R at tag hit t slot front`
//! (ray `tag`'s answer asked for on clock `at`, and the model's answer: whether it hits, the
//! nearest t (Q8.24), its slot and side; the last three 0 for a miss).
//!
//! Workloads: rays of a scene's set-up passes (from K × K lattice points of every planar slot,
//! through points next to each edge of each slot and a random one) with every slot they are
//! inside, as the exact edge test decides; then random rays of zero to six random pairs: random
//! normals, a fifth of the directions at right angles to the normal (n · d = 0), h for a
//! random t in Q8.24's range or, one in four, of every size and both signs (t behind the
//! origin, out of Q8.24's range, truncated to 0), and a third with one more pair, of equal t on
//! the slot of the same normal (the lower slot wins). A ray's pairs come one a clock or after
//! gaps, interleaved with those of up to eight other rays; its readout comes once its last
//! pair is taken, in ray order, one a clock.

use super::coarse::{direction, normal_words, rays_at, set_up_view};
use super::plane::lattice_origins;
use crate::rng::XorShift;
use hemi_hdl_model::format::{PlaneDist, Unit};
use hemi_hdl_model::intersect::patch_mem::PATCH_WORDS;
use hemi_hdl_model::intersect::{exact, group_plane};
use std::collections::VecDeque;
use std::fmt::Write as _;

/// Slots of the testbench's normal memory (`group_plane.v`'s SLOT_BITS 10); the random rays'
/// slots are the upper half, in pairs of equal normals.
const SLOTS: usize = 1024;
const RANDOM_SLOTS: usize = SLOTS / 2;

/// Tags (`group_plane.v`'s TW 10): ray n is tag n mod this.
const TAGS: usize = 1024;

/// What a file holds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    /// Rays read out.
    pub rays: usize,
    /// Pairs taken.
    pub pairs: usize,
    /// Rays whose answer is a hit.
    pub hits: usize,
    /// Pairs whose t the divider does not give (behind, parallel, out of range).
    pub no_t: usize,
}

/// A pair as the unit is handed it.
#[derive(Clone, Copy, Debug)]
struct Pair {
    slot: usize,
    h: PlaneDist,
    d: [i32; 3],
}

/// The vectors: the rays of the set-up passes over `slots` from K × K (`samples`) lattice
/// points of each slot, then `random` random rays.
pub fn vectors(
    slots: &[[u32; PATCH_WORDS]],
    samples: u32,
    random: usize,
    seed: u64,
) -> (String, Counts) {
    let mut rng = XorShift::new(seed ^ 0x6a09_e667_f3bc_c908);
    let mut normals = vec![[0i32; 3]; SLOTS];
    for (s, w) in slots.iter().enumerate().take(RANDOM_SLOTS) {
        normals[s] = normal_words(w);
    }
    for s in (RANDOM_SLOTS..SLOTS).step_by(2) {
        let n = direction([0; 3].map(|_| (rng.bits() as i64 >> 33) as f64));
        normals[s] = n;
        normals[s + 1] = n;
    }
    let mut rays: Vec<Vec<Pair>> = Vec::new();
    for o in lattice_origins(slots, samples) {
        for w in slots {
            let Some(view) = set_up_view(w, o) else {
                continue;
            };
            for d in rays_at(&view.corners, &mut rng) {
                rays.push(scene_pairs(slots, o, d));
            }
        }
    }
    for _ in 0..random {
        rays.push(random_pairs(&normals, &mut rng));
    }
    schedule(&normals, &rays, &mut rng)
}

/// The pairs of ray `d` from `o`: every slot whose set-up pass sets it up and whose edges the
/// ray is inside of, exactly.
fn scene_pairs(slots: &[[u32; PATCH_WORDS]], o: [i32; 3], d: [i32; 3]) -> Vec<Pair> {
    let mut out = Vec::new();
    for (slot, w) in slots.iter().enumerate().take(RANDOM_SLOTS) {
        let Some(view) = set_up_view(w, o) else {
            continue;
        };
        let a = &view.corners;
        let all = (1u8 << a.len()) - 1;
        if exact::verdict(a, all, view.negate, view.shift, &d) {
            out.push(Pair { slot, h: view.h, d });
        }
    }
    out
}

/// Zero to six pairs on the random slots; a third of the rays with two of equal t.
fn random_pairs(normals: &[[i32; 3]], rng: &mut XorShift) -> Vec<Pair> {
    let count = (rng.bits() % 7) as usize;
    let d = direction([0; 3].map(|_| (rng.bits() as i64 >> 33) as f64));
    let mut out = Vec::new();
    for _ in 0..count {
        let slot = RANDOM_SLOTS + (rng.bits() as usize) % RANDOM_SLOTS;
        let d = if rng.bits().is_multiple_of(5) {
            at_right_angles(normals[slot])
        } else {
            d
        };
        let h = if rng.bits().is_multiple_of(4) {
            random_h(rng)
        } else {
            h_for_a_t(rng, normals[slot], d)
        };
        out.push(Pair { slot, h, d });
    }
    if count > 0 && rng.bits().is_multiple_of(3) {
        // the same h on the slot that shares this one's normal: the same t
        let twin = out[0].slot ^ 1;
        out.push(Pair {
            slot: twin,
            ..out[0]
        });
    }
    out
}

/// A direction (Q2.30) with n · d = 0 exactly.
fn at_right_angles(n: [i32; 3]) -> [i32; 3] {
    [-n[1], n[0], 0]
}

/// h (Q.54) for which the slot of normal `n` is met along `d` at a random t in Q8.24's range
/// (near the origin to far): t (n · d), so that a ray's pairs mostly hit and its minimum has
/// several to choose from.
fn h_for_a_t(rng: &mut XorShift, n: [i32; 3], d: [i32; 3]) -> PlaneDist {
    let den: i128 = (0..3).map(|c| n[c] as i128 * d[c] as i128).sum();
    let t = (rng.bits() >> (33 + rng.bits() % 12)) as i128;
    PlaneDist::from_bits((t * den) >> 30)
}

/// h (Q.54) of either sign, from a few units of 2^-54 to 2^66.
fn random_h(rng: &mut XorShift) -> PlaneDist {
    let bits = 4 + rng.bits() % 63;
    let wide = (rng.bits() as u128) << 64 | rng.bits() as u128;
    let h = (wide >> (128 - bits)) as i128;
    PlaneDist::from_bits(if rng.bits() & 1 == 1 { -h } else { h })
}

/// The rays' pairs and readouts on the unit's clocks, with the model's answers.
fn schedule(normals: &[[i32; 3]], rays: &[Vec<Pair>], rng: &mut XorShift) -> (String, Counts) {
    let mut text = format!(
        "L {} {}\n",
        group_plane::T_LATENCY,
        group_plane::ANSWER_LATENCY
    );
    for (s, n) in normals.iter().enumerate() {
        let _ = writeln!(text, "N {s} {} {} {}", n[0], n[1], n[2]);
    }
    let (mut pairs, mut readouts) = (String::new(), String::new());
    let mut counts = Counts::default();
    // the rays being handed over (index, pairs left); each ray's clock its lanes are done
    // and its readout's
    let mut open: Vec<(usize, VecDeque<Pair>)> = Vec::new();
    let mut finish: Vec<Option<u64>> = vec![None; rays.len()];
    let mut asked: Vec<u64> = Vec::new();
    let (mut readout_free, mut clock, mut opened) = (0u64, 0u64, 0usize);
    while asked.len() < rays.len() {
        let cap = 1 + (rng.bits() % 9) as usize;
        while open.len() < cap && opened < rays.len() && tag_free(&asked, opened, clock) {
            open.push((opened, rays[opened].iter().copied().collect()));
            opened += 1;
        }
        // a ray with no pair left is done: at once (the clock after its last pair, the
        // tightest readout) or after a gap
        while let Some(k) = open.iter().position(|(_, p)| p.is_empty()) {
            let (ray, _) = open.remove(k);
            finish[ray] = Some(clock + [0, 0, 1, 2, 5][(rng.bits() % 5) as usize]);
        }
        // readouts in ray order, one a clock, as the model asks them
        while let Some(Some(done)) = finish.get(asked.len()) {
            let at = group_plane::readout(&mut readout_free, *done);
            let ray = asked.len();
            readout_line(&mut readouts, &mut counts, normals, ray, &rays[ray], at);
            asked.push(at);
        }
        if !open.is_empty() && !rng.bits().is_multiple_of(4) {
            let k = (rng.bits() as usize) % open.len();
            if let Some(p) = open[k].1.pop_front() {
                counts.pairs += 1;
                let tag = open[k].0 % TAGS;
                let (h, d) = (p.h.to_bits(), p.d);
                let _ = writeln!(
                    pairs,
                    "P {clock} {} {tag} {h} {} {} {}",
                    p.slot, d[0], d[1], d[2]
                );
            }
        }
        clock += 1;
    }
    text.push_str(&pairs);
    text.push_str(&readouts);
    (text, counts)
}

/// Whether ray `n` may take its tag on `clock`: the ray that held it last has its
/// answer out.
fn tag_free(asked: &[u64], n: usize, clock: u64) -> bool {
    n < TAGS
        || asked
            .get(n - TAGS)
            .is_some_and(|at| at + group_plane::ANSWER_LATENCY < clock)
}

/// Ray `ray`'s readout on clock `at` and the model's answer: of the pairs whose t the divider
/// gives, the nearest t, of equal t the lowest slot.
fn readout_line(
    text: &mut String,
    counts: &mut Counts,
    normals: &[[i32; 3]],
    ray: usize,
    pairs: &[Pair],
    at: u64,
) {
    let unit = |w: [i32; 3]| w.map(Unit::from_bits);
    let mut best: Option<(i64, usize, bool)> = None;
    for p in pairs {
        let Some(t) = group_plane::pair_t(p.h, unit(normals[p.slot]), unit(p.d)) else {
            counts.no_t += 1;
            continue;
        };
        let key = (t.to_bits(), p.slot, p.h.is_negative());
        if best.is_none_or(|b| (key.0, key.1) < (b.0, b.1)) {
            best = Some(key);
        }
    }
    counts.rays += 1;
    counts.hits += best.is_some() as usize;
    let (t, slot, front) = best.unwrap_or((0, 0, false));
    let _ = writeln!(
        text,
        "R {at} {} {} {t} {slot} {}",
        ray % TAGS,
        best.is_some() as u8,
        front as u8
    );
}
