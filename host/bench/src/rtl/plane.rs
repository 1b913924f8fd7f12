//! Vectors for the planar intersection unit's RTL (`hdl-model/rtl/plane_unit.v`): the model's
//! [`IntersectUnit`] built with one lane and no culling, driven clock by clock as the device
//! drives it (a finished ray taken, then a new one started if the unit is ready), every entry
//! and result written with its clock.
//!
//! File lines (hex words): `P slot w0 … w15` (patch memory, loaded before clock 0), `N count`,
//! `T clk ox oy oz dx dy dz uv skip_en skip bypass` (a ray started), `H clk hit patch t u v
//! front` (a result taken).
//!
//! Workloads: pass 1's hemispheres on a scene (sample points on each slot, the hemisphere
//! turned onto the slot's normal by the model's rotator, the slot itself skipped), and random
//! planar quads and triangles hit by random rays from shared, fresh and far origins (far ones
//! take the set-up's truncation of 2 and 4 bits), with the degenerate cases: origins on a
//! patch's plane, rays parallel to a patch, zero and non-unit directions, empty slots and slots
//! of an unknown kind, bypassed entries.

use super::cordic::{frame_angles, unit_word};
use crate::rng::XorShift;
use hemi_hdl_model::cordic::CordicConfig;
use hemi_hdl_model::driver::RegisterAccess;
use hemi_hdl_model::format::{Angle, Coord, Unit};
use hemi_hdl_model::intersect::bezier::SubdivConfig;
use hemi_hdl_model::intersect::patch_mem::{PatchMem, PATCH_WORDS};
use hemi_hdl_model::intersect::{IntersectUnit, RayIn};
use hemi_hdl_model::rotator::{RotIn, Rotator};
use hemi_hdl_model::{regs, ModelAccelerator, ModelConfig, Params};
use hemi_kernel::geometry::Vec3;
use hemi_kernel::hemisphere::{DeltaRule, OwnedHemisphere};
use hemi_kernel::patch::Patch;
use hemi_kernel::rotation::{spin_for_sample, Rotation};
use std::fmt::Write as _;

/// Patch slots of the RTL build the vectors are for (IW = 8).
pub const SLOTS: usize = 256;

/// A ray entry of the unit.
#[derive(Clone, Copy, Debug, Default)]
pub struct PlaneRay {
    /// Origin (Q8.24 words).
    pub origin: [i32; 3],
    /// Direction (Q2.30 words).
    pub dir: [i32; 3],
    /// The hit's (u,v) wanted.
    pub uv: bool,
    /// The slot this ray skips.
    pub skip: Option<u32>,
    /// A rotate-only entry: no scan.
    pub bypass: bool,
}

/// Patch memory and rays.
#[derive(Clone, Debug, Default)]
pub struct Workload {
    /// Slot words.
    pub slots: Vec<[u32; PATCH_WORDS]>,
    /// Rays in entry order.
    pub rays: Vec<PlaneRay>,
}

/// The slots the accelerator holds for `patches` (loaded by the driver, read back through
/// PATCH_ADDR/PATCH_DATA), so the vectors see the very words the hardware would.
pub fn loaded_slots(patches: &[Patch]) -> anyhow::Result<Vec<[u32; PATCH_WORDS]>> {
    let mut model = ModelAccelerator::new(patches, ModelConfig::default())
        .map_err(|e| anyhow::anyhow!("model: {e:?}"))?;
    let bus = model.driver_mut().bus_mut();
    Ok((0..patches.len())
        .map(|i| {
            bus.write(regs::PATCH_ADDR, (i * PATCH_WORDS) as u32);
            core::array::from_fn(|_| bus.read(regs::PATCH_DATA))
        })
        .collect())
}

/// The origins of a scene's set-up passes: K × K (`k`) lattice points of every slot, slot by
/// slot.
pub(super) fn lattice_origins(
    slots: &[[u32; PATCH_WORDS]],
    k: u32,
) -> impl Iterator<Item = [i32; 3]> + '_ {
    slots.iter().flat_map(move |slot| {
        (0..k).flat_map(move |a| (0..k).map(move |b| lattice_point(slot, a, b, k)))
    })
}

/// The point at lattice cell (a, b) of K × K on a slot's bilinear map, in Q8.24 words.
pub(super) fn lattice_point(w: &[u32; PATCH_WORDS], a: u32, b: u32, k: u32) -> [i32; 3] {
    let (s, t) = ((a as f64 + 0.5) / k as f64, (b as f64 + 0.5) / k as f64);
    bilinear_point(w, s, t).map(|x| x.round() as i32)
}

/// The point (s, t) of a slot's bilinear map (s from corner 0 to 1, t from 0 to 3), in units
/// of the Q8.24 words.
fn bilinear_point(w: &[u32; PATCH_WORDS], s: f64, t: f64) -> [f64; 3] {
    let v = |corner: usize, c: usize| w[1 + 3 * corner + c] as i32 as f64;
    core::array::from_fn(|c| {
        let bottom = v(0, c) * (1.0 - s) + v(1, c) * s;
        let top = v(3, c) * (1.0 - s) + v(2, c) * s;
        bottom * (1.0 - t) + top * t
    })
}

/// The slot's normal as the f32 vector the host's frame would be built from.
pub(super) fn slot_normal(w: &[u32; PATCH_WORDS]) -> Vec3 {
    let n = |c: usize| Unit::from_bits(w[13 + c] as i32).to_num::<f32>();
    Vec3::new(n(0), n(1), n(2))
}

/// Hemisphere directions turned by `angles` through the model's rotator.
pub(super) fn turned(dirs: &[[i32; 3]], angles: [i32; 3], cfg: CordicConfig) -> Vec<[i32; 3]> {
    let mut rot: Rotator<()> = Rotator::new(cfg);
    let mut out = Vec::with_capacity(dirs.len());
    let mut next = 0;
    while out.len() < dirs.len() {
        let input = dirs.get(next).map(|d| RotIn {
            dir: d.map(Unit::from_bits),
            angles: angles.map(Angle::from_bits),
            bypass: false,
            info: (),
        });
        next += 1;
        if let Some((d, ())) = rot.tick(input) {
            out.push(d.map(|c| c.to_bits()));
        }
    }
    out
}

/// Pass 1's hemispheres over `slots`: K × K sample points on every planar slot, R circles.
pub fn hemispheres(
    slots: &[[u32; PATCH_WORDS]],
    circles: u32,
    samples: u32,
) -> anyhow::Result<Vec<PlaneRay>> {
    let cfg = CordicConfig::DEFAULT;
    let hemi = OwnedHemisphere::new(circles, DeltaRule::Band)
        .map_err(|e| anyhow::anyhow!("hemisphere of {circles} circles: {e:?}"))?;
    let view = hemi.view();
    let mut reference = Vec::new();
    for (j, ring) in view.rings().iter().enumerate() {
        for k in 0..ring.count {
            let d = view.direction(j, k);
            reference.push([d.x, d.y, d.z].map(unit_word));
        }
    }
    let mut rays = Vec::new();
    let mut q = 0;
    for (i, w) in slots.iter().enumerate() {
        if !matches!(w[0] & 0xF, 1 | 2) {
            continue;
        }
        for a in 0..samples {
            for b in 0..samples {
                let rot = Rotation::onto_spun(slot_normal(w), spin_for_sample(q));
                q += 1;
                let origin = lattice_point(w, a, b, samples);
                for dir in turned(&reference, frame_angles(&rot, cfg), cfg) {
                    rays.push(PlaneRay {
                        origin,
                        dir,
                        uv: true,
                        skip: Some(i as u32),
                        bypass: false,
                    });
                }
            }
        }
    }
    Ok(rays)
}

/// A random unit vector (uniform over the sphere, by rejection).
pub(super) fn unit_vec(rng: &mut XorShift) -> [f64; 3] {
    loop {
        let v = [0; 3].map(|_| rng.f64() * 2.0 - 1.0);
        let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        if (0.1..=1.0).contains(&n) {
            return v.map(|c| c / n);
        }
    }
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn q824(x: f64) -> i32 {
    Coord::saturating_from_num(x).to_bits()
}

fn q230(x: f64) -> i32 {
    Unit::saturating_from_num(x).to_bits()
}

/// A random planar slot: a quad (two in three) or a triangle around a random centre, its
/// corners counter-clockwise about its normal; one in sixteen empty, one in thirty-two of an
/// unknown kind.
fn random_slot(rng: &mut XorShift) -> [u32; PATCH_WORDS] {
    let mut w = [0u32; PATCH_WORDS];
    let kind = match rng.bits() % 32 {
        0 => 5,
        1 | 2 => 0,
        r if r % 3 == 0 => 1,
        _ => 2,
    };
    let n = unit_vec(rng);
    let t1 = {
        let c = cross(n, unit_vec(rng));
        let l = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt().max(1e-9);
        c.map(|x| x / l)
    };
    let t2 = cross(n, t1);
    let centre = [0; 3].map(|_| rng.f64() * 1.6 - 0.8);
    let (s1, s2) = (0.02 + rng.f64() * 0.3, 0.02 + rng.f64() * 0.3);
    let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
    for (k, (a, b)) in corners.iter().enumerate() {
        let k = if kind == 1 && k == 3 { 2 } else { k };
        let (a, b) = if kind == 1 && k == 2 {
            (0.0, 1.0)
        } else {
            (*a, *b)
        };
        for c in 0..3 {
            let x = centre[c] + a * s1 * t1[c] + b * s2 * t2[c];
            w[1 + 3 * k + c] = q824(x) as u32;
        }
    }
    if kind == 1 {
        // the triangle's v3 is a copy of v2
        for c in 0..3 {
            w[10 + c] = w[7 + c];
        }
    }
    w[0] = kind;
    for c in 0..3 {
        w[13 + c] = q230(n[c]) as u32;
    }
    w
}

/// A random ray's origin: shared by runs of rays (so most rays reuse a set-up), sometimes far
/// out (|coordinate| ≥ 64, the set-up's truncation) or on a slot's plane.
fn random_origin(rng: &mut XorShift, slots: &[[u32; PATCH_WORDS]]) -> [i32; 3] {
    match rng.bits() % 16 {
        0 => [0; 3].map(|_| q824((rng.f64() * 2.0 - 1.0) * 127.0)),
        1 => {
            let w = &slots[(rng.bits() % slots.len() as u64) as usize];
            core::array::from_fn(|c| w[1 + c] as i32)
        }
        2 => {
            let w = &slots[(rng.bits() % slots.len() as u64) as usize];
            lattice_point(w, 0, 0, 2)
        }
        _ => [0; 3].map(|_| q824(rng.f64() * 2.0 - 1.0)),
    }
}

/// A random direction: unit mostly, sometimes zero, an extreme word, or along a slot's edge
/// (parallel to its plane).
fn random_dir(rng: &mut XorShift, slots: &[[u32; PATCH_WORDS]]) -> [i32; 3] {
    match rng.bits() % 32 {
        0 => [0; 3],
        1 => [i32::MIN, i32::MAX, (rng.bits() as i32) >> 1],
        2 => {
            let w = &slots[(rng.bits() % slots.len() as u64) as usize];
            let e = [0, 1, 2].map(|c| w[4 + c] as i32 as f64 - w[1 + c] as i32 as f64);
            let l = (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]).sqrt().max(1.0);
            e.map(|x| q230(x / l))
        }
        _ => unit_vec(rng).map(q230),
    }
}

/// A direction from `origin` at a point of a random slot on one of its (u,v) unit's segments:
/// u or v a multiple of 2^-k for a level k of the bisection, so that at level k the point is on
/// the segment the side test halves the cell by and the test's rounding decides its side
/// (`uv::SEG_BITS`; a direction that misses its slot is still a ray).
fn aimed_at_a_segment(
    rng: &mut XorShift,
    slots: &[[u32; PATCH_WORDS]],
    origin: [i32; 3],
) -> [i32; 3] {
    let w = &slots[(rng.bits() % slots.len() as u64) as usize];
    let level = 1 + rng.bits() % 12;
    let on_line = (2 * (rng.bits() % (1 << (level - 1))) + 1) as f64 / (1u64 << level) as f64;
    let across = rng.f64();
    let (s, t) = if rng.bits().is_multiple_of(2) {
        (on_line, across)
    } else {
        (across, on_line)
    };
    let on = bilinear_point(w, s, t);
    let p: [f64; 3] = core::array::from_fn(|c| on[c] - origin[c] as f64);
    let l = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt().max(1.0);
    p.map(|x| q230(x / l))
}

/// `patches` random slots (at least one) and `rays` random rays against them, one in four
/// aimed at a point on a segment of the (u,v) bisection (u or v a multiple of 2^-k), where the
/// side test's rounding decides.
pub fn random(rng: &mut XorShift, patches: usize, rays: usize) -> Workload {
    let slots: Vec<_> = (0..patches).map(|_| random_slot(rng)).collect();
    let mut origin = random_origin(rng, &slots);
    let rays = (0..rays)
        .map(|_| {
            if rng.bits().is_multiple_of(24) {
                origin = random_origin(rng, &slots);
            }
            let dir = if rng.bits().is_multiple_of(4) {
                aimed_at_a_segment(rng, &slots, origin)
            } else {
                random_dir(rng, &slots)
            };
            PlaneRay {
                origin,
                dir,
                uv: !rng.bits().is_multiple_of(4),
                skip: (rng.bits().is_multiple_of(3)).then(|| (rng.bits() % patches as u64) as u32),
                bypass: rng.bits().is_multiple_of(32),
            }
        })
        .collect();
    Workload { slots, rays }
}

/// The unit the RTL mirrors: one lane of [`SLOTS`] slots, no culling, (u,v) of `depth` levels.
fn unit(depth: u32) -> IntersectUnit<u32> {
    let params = Params {
        lanes: 1,
        sectors: 0,
        rays_per_clock: 1,
        bank_slots: SLOTS as u32,
        compact: false,
        ray_groups: 1,
    };
    IntersectUnit::new(params, depth, SubdivConfig::DEFAULT, 32)
}

fn ray_in(r: &PlaneRay, seq: u32) -> RayIn<u32> {
    let dir = r.dir.map(Unit::from_bits);
    RayIn {
        origin: r.origin.map(Coord::from_bits),
        dir,
        bypass: r.bypass,
        uv: r.uv,
        skip: r.skip,
        recip_at: 0,
        bin_at: 0,
        frame: None,
        dir_ref: dir,
        info: seq,
    }
}

/// Runs `work` through the model, rays arriving with random gaps; returns the file text (empty
/// unless `record`: the model's own speed is timed without it) and the clocks it took.
pub fn stream(work: &Workload, depth: u32, rng: &mut XorShift, record: bool) -> (String, u64) {
    let mut out = String::new();
    let mut mem = PatchMem::new(SLOTS);
    for (i, w) in work.slots.iter().enumerate() {
        let words: Vec<String> = w.iter().map(|x| format!("{x:08x}")).collect();
        let _ = writeln!(out, "P {i} {}", words.join(" "));
        for (k, x) in w.iter().enumerate() {
            mem.write((i * PATCH_WORDS + k) as u32, *x);
        }
    }
    let count = work.slots.len() as u32;
    let _ = writeln!(out, "N {count}");
    let mut u = unit(depth);
    let (mut next, mut arrive, mut now) = (0usize, 2u64, 0u64);
    while next < work.rays.len() || u.in_flight() > 0 {
        if let Some(r) = u.take_done(now).filter(|_| record) {
            let h = r.hit.unwrap_or_default();
            let _ = writeln!(
                out,
                "H {now} {} {:x} {:08x} {:08x} {:08x} {}",
                r.hit.is_some() as u8,
                h.patch,
                h.t.to_bits() as u32,
                h.u.to_bits() as u32,
                h.v.to_bits() as u32,
                h.front as u8
            );
        }
        if next < work.rays.len() && arrive <= now && u.ready() {
            let r = &work.rays[next];
            let (before, at) = (u.lane_stats(), out.len());
            let o = r.origin.map(|c| format!("{:08x}", c as u32));
            let d = r.dir.map(|c| format!("{:08x}", c as u32));
            let (skip_en, skip) = (r.skip.is_some() as u8, r.skip.unwrap_or(0));
            let _ = writeln!(
                out,
                "T {now} {} {} {} {} {} {} {} {skip_en} {skip:x} {}",
                o[0], o[1], o[2], d[0], d[1], d[2], r.uv as u8, r.bypass as u8
            );
            u.start(&mem, count, ray_in(r, next as u32), now, |_| {
                unreachable!("no culling: the unit never asks for a frame's axes")
            });
            let after = u.lane_stats();
            // for reading a mismatch: the candidates the lane was handed, the set-up passes
            let _ = writeln!(
                out,
                "# n={} setup={}",
                after.candidates - before.candidates,
                after.setups - before.setups
            );
            if !record {
                out.truncate(at);
            }
            next += 1;
            arrive = now
                + if rng.bits().is_multiple_of(8) {
                    rng.bits() % 300
                } else {
                    0
                };
        }
        now += 1;
    }
    (out, now)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_ray_gets_one_result() {
        let mut rng = XorShift::new(0x5851_f42d_4c95_7f2d);
        let work = random(&mut rng, 40, 300);
        let (text, _) = stream(&work, 8, &mut rng, true);
        let n = |tag: &str| text.lines().filter(|l| l.starts_with(tag)).count();
        assert_eq!((n("T "), n("H "), n("P ")), (300, 300, 40));
        let hits = text
            .lines()
            .filter(|l| l.starts_with("H ") && l.split(' ').nth(2) == Some("1"))
            .count();
        assert!(hits > 0, "some rays hit");
    }
}
