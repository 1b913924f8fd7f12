//! Vectors for the culling unit's patch side (`hdl-model/rtl/cull_reach.v`): the model's
//! [`CullUnit::reach`] (where a planar patch can be met by a hemisphere ray: below the horizon,
//! every sector or a wedge of them, and its polar bands) on the inputs the set-up pass gives it,
//! for the testbench to feed the RTL a corner a clock and compare in order. The model gives the
//! unit no clocks of its own (the set-up pipe's latency is charged once, after its last patch),
//! so the answers are compared, not clocks.
//!
//! File lines (decimal): `P n κ u0 u1 u2 v0 v1 v2 w0 w1 w2 a… e… kind lo len band_lo band_hi`:
//! the corner count, the coarse words' κ, the frame's axes (Q2.30 words), the n corners a = v −
//! O (three words each), the n edges' coarse words, then the reach (kind 0 below the horizon, 1
//! every sector, 2 sectors lo .. lo + len − 1; lo and len 0 unless 2).
//!
//! Workloads: the set-up passes of pass 1 on a scene (every slot from K × K lattice points of
//! every slot, in that sample point's frame as the model's rotator turns its axes), random
//! patches of every size and distance in random frames, random words (none of them need be a
//! patch or a frame), and the edges of what the unit decides: corners on the axis and at the
//! origin, patches straddling the horizon, the wrap of φ at ±π, and κ that bounds nothing.

use super::coarse::{is_planar, random_patch, set_up_view};
use super::plane::{lattice_point, slot_normal, turned, unit_vec};
use crate::rng::XorShift;
use crate::rtl::cordic::frame_angles;
use hemi_hdl_model::cordic::CordicConfig;
use hemi_hdl_model::format::Unit;
use hemi_hdl_model::intersect::coarse::{narrow_patch, Coarse, KAPPA_DECLINE};
use hemi_hdl_model::intersect::cull::CullUnit;
use hemi_hdl_model::intersect::patch_mem::PATCH_WORDS;
use hemi_kernel::geometry::Vec3;
use hemi_kernel::rotation::{spin_for_sample, Rotation};
use std::fmt::Write as _;

/// What a file's `P` lines hold.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    /// Patches.
    pub patches: usize,
    /// Of them, below the horizon.
    pub below: usize,
    /// Of them, in a wedge of sectors.
    pub wedges: usize,
}

/// The frame's axes u, v, w as Q2.30 words.
pub(super) type Axes = [[i32; 3]; 3];

/// The vectors for a unit of `sectors` sectors: the set-up passes over `slots` from K × K
/// (`samples`) lattice points of each slot, then `random` random patches, words and edge cases.
pub fn vectors(
    sectors: u32,
    slots: &[[u32; PATCH_WORDS]],
    samples: u32,
    random: usize,
    seed: u64,
) -> (String, Counts) {
    let mut out = Vectors {
        unit: CullUnit::new(sectors),
        text: String::new(),
        counts: Counts::default(),
    };
    for (o, axes) in scene_frames(slots, samples) {
        for s in slots {
            out.scene_patch(s, o, &axes);
        }
    }
    let mut rng = XorShift::new(seed ^ 0x9e37_79b9_7f4a_7c15);
    for n in 0..random {
        match n % 4 {
            0 | 1 => {
                let (a, shift) = random_patch(&mut rng, n);
                out.patch(&a, shift, n % 8 < 4, &random_axes(&mut rng));
            }
            2 => out.random_words(&mut rng, n),
            _ => out.edge_case(&mut rng, n),
        }
    }
    (out.text, out.counts)
}

/// The file being written ([`super::UnitVectors`]).
type Vectors = super::UnitVectors<Counts>;

impl Vectors {
    /// Slot `w` as the set-up pass sees it from origin `o` (Q8.24 words) in the frame `axes`.
    fn scene_patch(&mut self, w: &[u32; PATCH_WORDS], o: [i32; 3], axes: &Axes) {
        if let Some(v) = set_up_view(w, o) {
            self.patch(&v.corners, v.shift, v.negate, axes);
        }
    }

    /// A patch with the coarse words the set-up unit forms for it.
    fn patch(&mut self, a: &[[i64; 3]], shift: u32, negate: bool, axes: &Axes) {
        self.line(a, &narrow_patch(a, shift, negate).0, axes);
    }

    /// Words of any size: corners of 1 to 33 bits, coarse words of 1 to 18, any κ, axes of
    /// any length (the unit's answer is a function of its words, frame or not).
    fn random_words(&mut self, rng: &mut XorShift, n: usize) {
        // a signed word of 1 to `most` bits
        let signed = |rng: &mut XorShift, most: u64| {
            let bits = 1 + rng.bits() % most;
            (rng.bits() as i64) >> (64 - bits)
        };
        let sides = 3 + n % 2;
        let a: Vec<[i64; 3]> = (0..sides)
            .map(|_| [0; 3].map(|_| signed(rng, 33)))
            .collect();
        let mut coarse = Coarse {
            kappa: (rng.bits() % (KAPPA_DECLINE as u64 + 1)) as u8,
            ..Coarse::default()
        };
        for w in &mut coarse.words[..sides] {
            *w = [0; 3].map(|_| signed(rng, 18) as i32);
        }
        let axes = [0; 3].map(|_| [0; 3].map(|_| signed(rng, 32) as i32));
        self.line(&a, &coarse, &axes);
    }

    /// A patch at an edge of what the unit decides, in the identity frame or a random one.
    fn edge_case(&mut self, rng: &mut XorShift, n: usize) {
        let (mut a, shift) = random_patch(rng, n);
        let big = 1i64 << (8 + rng.bits() % 24);
        match (n / 4) % 6 {
            // a corner on the axis (its (x, y) zero in the identity frame)
            0 => a[0] = [0, 0, if rng.chance(0.5) { big } else { -big }],
            // a corner at the origin
            1 => a[1] = [0; 3],
            // every corner at z = ±1 of the horizon
            2 => a
                .iter_mut()
                .for_each(|v| v[2] = (rng.bits() % 3) as i64 - 1),
            // corners around φ = ±π: x < 0, y of either sign and small
            3 => a.iter_mut().for_each(|v| {
                v[0] = -big;
                v[1] = (rng.bits() % 64) as i64 - 32;
            }),
            // a corner straight up
            4 => a[2] = [(rng.bits() % 3) as i64 - 1, 0, big],
            _ => {}
        }
        let axes = if rng.chance(0.5) {
            [0, 1, 2].map(|k| core::array::from_fn(|c| if c == k { 1 << 30 } else { 0 }))
        } else {
            random_axes(rng)
        };
        if n.is_multiple_of(13) {
            // κ that bounds nothing
            let mut c = Coarse {
                kappa: KAPPA_DECLINE,
                ..Coarse::default()
            };
            c.words[..a.len()].iter_mut().for_each(|w| *w = [1, -1, 1]);
            self.line(&a, &c, &axes);
        } else {
            self.patch(&a, shift, rng.chance(0.5), &axes);
        }
    }

    /// The line of one patch, with the model's reach.
    fn line(&mut self, a: &[[i64; 3]], coarse: &Coarse, axes: &Axes) {
        let reach = self
            .unit
            .reach(a, coarse, &axes.map(|v| v.map(Unit::from_bits)));
        let (kind, lo, len) = reach.wedge.words();
        self.counts.patches += 1;
        self.counts.below += (kind == 0) as usize;
        self.counts.wedges += (kind == 2) as usize;
        let t = &mut self.text;
        let _ = write!(t, "P {} {}", a.len(), coarse.kappa);
        let words = axes
            .iter()
            .flatten()
            .map(|&c| c as i64)
            .chain(a.iter().flatten().copied())
            .chain(coarse.words[..a.len()].iter().flatten().map(|&c| c as i64));
        for w in words {
            let _ = write!(t, " {w}");
        }
        let _ = writeln!(t, " {kind} {lo} {len} {} {}", reach.band_lo, reach.band_hi);
    }
}

/// Pass 1's set-up passes on a scene: K × K (`samples`) lattice points of each planar slot,
/// each with its frame's axes (the slot's normal, the sample's golden-ratio spin) as the model's
/// rotator turns them.
pub(super) fn scene_frames(slots: &[[u32; PATCH_WORDS]], samples: u32) -> Vec<([i32; 3], Axes)> {
    let points = slots
        .iter()
        .filter(|s| is_planar(s))
        .flat_map(|slot| (0..samples * samples).map(move |k| (slot, k / samples, k % samples)));
    points
        .enumerate()
        .map(|(q, (slot, a, b))| {
            let rot = Rotation::onto_spun(slot_normal(slot), spin_for_sample(q as u32));
            let axes = rotated_axes(frame_angles(&rot, CordicConfig::DEFAULT));
            (lattice_point(slot, a, b, samples), axes)
        })
        .collect()
}

/// The frame's axes as the culling unit gets them: x̂, ŷ, ẑ turned by the model's rotator.
pub(super) fn rotated_axes(angles: [i32; 3]) -> Axes {
    let unit = [0, 1, 2].map(|k| core::array::from_fn(|c| if c == k { 1 << 30 } else { 0 }));
    let t = turned(&unit, angles, CordicConfig::DEFAULT);
    [t[0], t[1], t[2]]
}

/// The axes of a random frame, as pass 1 would build one for a random normal and spin and the
/// model's rotator turn them.
pub(super) fn random_axes(rng: &mut XorShift) -> Axes {
    let n = unit_vec(rng).map(|c| c as f32);
    let spin = (rng.f64() * std::f64::consts::TAU) as f32;
    let rot = Rotation::onto_spun(Vec3::new(n[0], n[1], n[2]), spin);
    rotated_axes(frame_angles(&rot, CordicConfig::DEFAULT))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_workload_holds_every_kind_of_reach() {
        let (text, c) = vectors(32, &[], 0, 400, 1);
        assert_eq!(text.lines().count(), c.patches);
        assert!(c.below > 20 && c.wedges > 20, "{c:?}");
        assert!(c.below + c.wedges < c.patches, "{c:?}");
    }
}
