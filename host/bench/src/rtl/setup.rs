//! Vectors for the compact set-up unit (`hdl-model/rtl/setup_unit.v`): per origin, each planar
//! slot as the model's set-up pass sets it up — whether the origin is off its plane
//! ([`plane_distance`]), its edges' coarse words and κ ([`narrow_patch`]), its reach
//! ([`CullUnit::reach`]) — for the testbench to feed the RTL a corner a clock, pass after pass,
//! and compare in order, with the clocks the model charges: each patch's answer
//! [`CULL_SETUP_LATENCY`] after its last corner, its last edge's words and κ
//! [`EDGE_SETUP_LATENCY`] after it.
//!
//! File lines (decimal): `L latency edge_latency` first, then per patch `S pass n o0 o1 o2 shift
//! axes… n0 n1 n2 v… active κ words… kappas… kind lo len band_lo band_hi`: the pass's index (a
//! new origin and frame), the corner count, the origin (Q8.24 words), its origin-wide
//! truncation, the frame's axes (nine Q2.30 words), the slot's normal and n corners (its words),
//! then the model's set-up: whether the origin is off the plane, the patch's κ, each edge's words
//! and κ, and the reach (kind 0 below the horizon, 1 every sector, 2 sectors lo .. lo + len − 1).
//! A patch on whose plane the origin lies sets nothing up: its words and reach are 0.
//!
//! Workloads: the set-up passes of pass 1 on a scene (every slot from K × K lattice points of
//! every slot, in the sample point's frame as the model's rotator turns its axes), then random
//! passes of one to eight random patches each (corners near and far, normals of any direction,
//! origins on a patch's corner), each in a random frame.

use super::coarse::{is_planar, random_patch, set_up_view};
use super::reach::{random_axes, scene_frames, Axes};
use crate::rng::XorShift;
use hemi_hdl_model::format::Unit;
use hemi_hdl_model::intersect::coarse::{narrow_patch, Coarse};
use hemi_hdl_model::intersect::cull::{CullUnit, Reach, Wedge};
use hemi_hdl_model::intersect::patch_mem::{KIND_QUAD, KIND_TRIANGLE, PATCH_WORDS};
#[cfg(doc)]
use hemi_hdl_model::intersect::plane_distance;
use hemi_hdl_model::intersect::{origin_shift, CULL_SETUP_LATENCY, EDGE_SETUP_LATENCY};
use std::fmt::Write as _;

/// What a file's `S` lines hold.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    /// Passes (origins).
    pub passes: usize,
    /// Patches.
    pub patches: usize,
    /// Of them, with the origin on their plane.
    pub inactive: usize,
    /// Of them, below the horizon.
    pub below: usize,
    /// Of them, in a wedge of sectors.
    pub wedges: usize,
}

/// The vectors for a unit of `sectors` sectors: the set-up passes over `slots` from K × K
/// (`samples`) lattice points of each planar slot, then about `random` random patches.
pub fn vectors(
    sectors: u32,
    slots: &[[u32; PATCH_WORDS]],
    samples: u32,
    random: usize,
    seed: u64,
) -> (String, Counts) {
    let mut out = Vectors {
        unit: CullUnit::new(sectors),
        text: format!("L {CULL_SETUP_LATENCY} {EDGE_SETUP_LATENCY}\n"),
        counts: Counts::default(),
    };
    let planar: Vec<&[u32; PATCH_WORDS]> = slots.iter().filter(|s| is_planar(s)).collect();
    for (o, axes) in scene_frames(slots, samples) {
        out.pass(&planar, o, &axes);
    }
    let mut rng = XorShift::new(seed ^ 0xd1b5_4a32_d192_ed03);
    let mut n = 0;
    while n < random {
        let count = 1 + (rng.bits() % 8) as usize;
        let o = random_origin(&mut rng);
        let patches: Vec<[u32; PATCH_WORDS]> = (n..n + count)
            .map(|k| random_slot(&mut rng, o, k))
            .collect();
        let refs: Vec<&[u32; PATCH_WORDS]> = patches.iter().collect();
        out.pass(&refs, o, &random_axes(&mut rng));
        n += count;
    }
    (out.text, out.counts)
}

/// The file being written ([`super::UnitVectors`]).
type Vectors = super::UnitVectors<Counts>;

impl Vectors {
    /// One pass: every slot of `slots` from origin `o` (Q8.24 words) in the frame `axes`.
    fn pass(&mut self, slots: &[&[u32; PATCH_WORDS]], o: [i32; 3], axes: &Axes) {
        for w in slots {
            self.patch(w, o, axes);
        }
        self.counts.passes += 1;
    }

    /// A slot's line: its inputs, then the model's set-up of it.
    fn patch(&mut self, w: &[u32; PATCH_WORDS], o: [i32; 3], axes: &Axes) {
        let sides = if w[0] & 0xF == KIND_QUAD { 4 } else { 3 };
        let shift = origin_shift(o.map(i64::from));
        let t = &mut self.text;
        let _ = write!(
            t,
            "S {} {sides} {} {} {} {shift}",
            self.counts.passes, o[0], o[1], o[2]
        );
        let inputs = axes
            .iter()
            .flatten()
            .copied()
            .chain(w[13..16].iter().map(|&c| c as i32))
            .chain(w[1..1 + 3 * sides].iter().map(|&c| c as i32));
        for x in inputs {
            let _ = write!(t, " {x}");
        }
        self.counts.patches += 1;
        let answer = set_up(&self.unit, w, o, axes);
        match answer.as_ref().map(|(_, _, reach)| reach.wedge) {
            None => self.counts.inactive += 1,
            Some(Wedge::Below) => self.counts.below += 1,
            Some(Wedge::Sectors { .. }) => self.counts.wedges += 1,
            Some(Wedge::Full) => {}
        }
        write_answer(&mut self.text, sides, answer.as_ref());
        self.text.push('\n');
    }
}

/// A patch's set-up: its coarse words, each edge's κ, its reach.
pub(super) type SetUp = (Coarse, [u8; 4], Reach);

/// The model's set-up of planar slot `w` from origin `o` in the frame `axes` by `unit`'s
/// culling: its coarse words, each edge's κ and its reach, or `None` when the origin is on its
/// plane.
pub(super) fn set_up(
    unit: &CullUnit,
    w: &[u32; PATCH_WORDS],
    o: [i32; 3],
    axes: &Axes,
) -> Option<SetUp> {
    let v = set_up_view(w, o)?;
    let (coarse, kappas) = narrow_patch(&v.corners, v.shift, v.negate);
    let ax = axes.map(|a| a.map(Unit::from_bits));
    Some((coarse, kappas, unit.reach(&v.corners, &coarse, &ax)))
}

/// A `sides`-cornered patch's set-up as its line ends: 1 (off the plane), its κ, its edges'
/// words and κ, and its reach (kind 0 below the horizon, 1 every sector, 2 a wedge: lo, len; the
/// bands); for a patch on whose plane the origin lies, 0 and zeros in their place.
pub(super) fn write_answer(t: &mut String, sides: usize, answer: Option<&SetUp>) {
    let Some((coarse, kappas, reach)) = answer else {
        let _ = write!(t, " 0{}", " 0".repeat(1 + 4 * sides + 5));
        return;
    };
    let (kind, lo, len) = reach.wedge.words();
    let _ = write!(t, " 1 {}", coarse.kappa);
    for c in coarse.words[..sides].iter().flatten() {
        let _ = write!(t, " {c}");
    }
    for k in &kappas[..sides] {
        let _ = write!(t, " {k}");
    }
    let _ = write!(t, " {kind} {lo} {len} {} {}", reach.band_lo, reach.band_hi);
}

/// An origin anywhere in the Q8.24 cube, at any distance from the centre, and one pass in eight
/// with a component next to a step of the origin-wide truncation ([`origin_shift`]: |o| of
/// 2^30 − 2^25 and 2^31 − 2^25, give or take 4), where the unit's own test of the origin's bits
/// must agree with the model. (Until session 29 the origins stayed within 2^30: no pass had
/// the truncation's largest step.)
fn random_origin(rng: &mut XorShift) -> [i32; 3] {
    let bits = 8 + (rng.bits() % 25) as u32;
    let mut o = [0; 3].map(|_| ((rng.bits() as i64) >> (64 - bits)) as i32);
    if rng.bits().is_multiple_of(8) {
        let step: i64 = if rng.bits().is_multiple_of(2) {
            1 << 30
        } else {
            1 << 31
        };
        let v = step - (1 << 25) + (rng.bits() % 9) as i64 - 4;
        let v = if rng.bits().is_multiple_of(2) { v } else { -v };
        // within ±(2^31 − 2^25 + 4): an i32
        o[(rng.bits() % 3) as usize] = v as i32;
    }
    o
}

/// A random planar slot near origin `o`: corners as [`random_patch`] places them (clamped into
/// the Q8.24 words), a normal of any direction (the unit takes the slot's words as they are),
/// and now and then the origin on its first corner (then on its plane).
pub(super) fn random_slot(rng: &mut XorShift, o: [i32; 3], n: usize) -> [u32; PATCH_WORDS] {
    let (a, _) = random_patch(rng, n);
    let mut w = [0u32; PATCH_WORDS];
    w[0] = if a.len() == 4 {
        KIND_QUAD
    } else {
        KIND_TRIANGLE
    };
    for (k, corner) in a.iter().enumerate() {
        for c in 0..3 {
            let v = (o[c] as i64 + corner[c]).clamp(i32::MIN as i64, i32::MAX as i64);
            w[1 + 3 * k + c] = v as i32 as u32;
        }
    }
    if n.is_multiple_of(11) {
        w[1..4].copy_from_slice(&o.map(|c| c as u32));
    }
    let dir = super::plane::unit_vec(rng);
    for c in 0..3 {
        w[13 + c] = ((dir[c] * (1u64 << 30) as f64).round() as i64).clamp(-(1 << 31), (1 << 31) - 1)
            as i32 as u32;
    }
    w
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_workload_holds_every_kind_of_set_up() {
        let (text, c) = vectors(32, &[], 0, 600, 1);
        assert_eq!(text.lines().count(), c.patches + 1);
        assert!(c.inactive > 10 && c.below > 20 && c.wedges > 20, "{c:?}");
        assert!(c.passes > 50, "{c:?}");
        // every step of the origin-wide truncation: 0, 2 and 4 bits
        let shifts: std::collections::BTreeSet<&str> = text
            .lines()
            .filter_map(|l| l.strip_prefix("S ")?.split(' ').nth(5))
            .collect();
        assert_eq!(shifts.into_iter().collect::<Vec<_>>(), ["0", "2", "4"]);
    }
}
