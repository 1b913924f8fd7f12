//! Vectors for the whole accelerator of the one-lane build (`hdl-model/rtl/accel_single.v`,
//! [`Params::SINGLE`]): the model's [`Device`] behind the register driver the firmware uses
//! (`RegisterAccelerator`), every bus access and stream port clock written down in
//! [`super::regs`]' lines, for the testbench to make the same accesses on the RTL's AHB-Lite
//! port and the same clocks on its stream port, and compare every read, the interrupt line and
//! every result the port gives. Nothing of the datapath is driven from outside: the rays go in
//! through RAY_IN or the port, the results come out through RESULT_OUT or the port, and CYCLE
//! and BUSY are read, so the RTL's answers and its clocks are both compared.
//!
//! The workload: the scene loaded by the driver; pass 1's hemispheres at K × K sample points of
//! every planar slot (results without (u,v)) through RAY_IN and RESULT_OUT; a second round of
//! hemispheres with (u,v) through the stream port (the driver's way when the build has one); random
//! rays traced from points inside the scene's box, with (u,v), and directions rotated alone,
//! through the port; then, register by register, the cases the driver does not make: a ray that
//! rotates before any frame (NO_FRAME, an ERROR result), frames from pairs, a skipped slot beyond
//! the build's slots, PATCH_COUNT lowered and restored with rays, rays without a candidate
//! (PATCH_COUNT 0, a single slot skipped), the port asked for a result while RESULT_OUT is part-way
//! into it, APPLY_CONFIG with a frame in the same write and of a CONFIG the build was not
//! synthesised with, and soft resets with rays in the rotator,
//! the queue, the set-up pass, the divider and the (u,v) levels.

use super::regs::{Bench, Counts};
use crate::rng::XorShift;
use hemi_hdl_model::accel::RegisterAccelerator;
use hemi_hdl_model::device::{Device, CONFIG_RESET};
use hemi_hdl_model::driver::StreamPort;
use hemi_hdl_model::regs::{self, ctrl, mode, skip, status};
use hemi_hdl_model::{ModelConfig, Params};
use hemi_kernel::accel::{Accelerator, HemiShot, Ray};
use hemi_kernel::geometry::Vec3;
use hemi_kernel::hemisphere::{DeltaRule, OwnedHemisphere};
use hemi_kernel::patch::Patch;
use hemi_kernel::rotation::{spin_for_sample, Rotation};

/// What the file holds, beyond its accesses.
#[derive(Clone, Copy, Debug, Default)]
pub struct Traced {
    /// Rays traced or rotated through the driver.
    pub rays: u64,
    /// Of them, hits.
    pub hits: u64,
}

/// The workload on `patches` (planar, at most the build's 256 slots): hemispheres of `circles`
/// circles at `samples` × `samples` points a slot, `random` random rays, from `seed`.
pub fn vectors(
    patches: &[Patch],
    circles: u32,
    samples: u32,
    random: usize,
    seed: u64,
) -> anyhow::Result<(String, Counts, Traced)> {
    let config = ModelConfig {
        params: Params::SINGLE,
        ..ModelConfig::default()
    };
    let bench = Bench::new(Device::with_params(Params::SINGLE).built_for(CONFIG_RESET));
    let mut acc = RegisterAccelerator::with_bus(bench, patches, config)
        .map_err(|e| anyhow::anyhow!("the model refused the scene: {e:?}"))?;
    let hemi = OwnedHemisphere::new(circles, DeltaRule::Band)
        .map_err(|e| anyhow::anyhow!("hemisphere of {circles} circles: {e:?}"))?;
    let mut traced = Traced::default();
    let shots = shots(patches, samples);
    for want_uv in [false, true] {
        acc.driver_mut().bus_mut().port = want_uv;
        let rings = 0..hemi.view().rings().len();
        acc.cast_hemispheres(&shots, &hemi.view(), rings, want_uv, |_, _, _, hit| {
            traced.rays += 1;
            traced.hits += hit.is_some() as u64;
        });
    }
    let mut rng = XorShift::new(seed);
    random_rays(&mut acc, patches, random, &mut rng, &mut traced);
    let bench = acc.driver_mut().bus_mut();
    bench.port = false;
    directed(bench, patches.len() as u32);
    let text = core::mem::take(&mut bench.text);
    Ok((text, bench.counts, traced))
}

/// Pass 1's sample points: K × K on every planar patch, each with its frame turned onto the
/// patch's normal and spun as pass 1 spins it.
fn shots(patches: &[Patch], samples: u32) -> Vec<HemiShot> {
    let mut shots = Vec::new();
    for (i, p) in patches.iter().enumerate() {
        let Some(poly) = p.as_polygon() else {
            continue;
        };
        for a in 0..samples {
            for b in 0..samples {
                let (u, v) = (
                    (a as f32 + 0.5) / samples as f32,
                    (b as f32 + 0.5) / samples as f32,
                );
                let q = shots.len() as u32;
                shots.push(HemiShot {
                    origin: poly.point(u, v),
                    rot: Rotation::onto_spun(p.normal_at(u, v), spin_for_sample(q)),
                    origin_patch: Some(i as u32),
                });
            }
        }
    }
    shots
}

/// `n` rays from random points of the scene's box in random directions, traced with (u,v),
/// and every eighth direction rotated alone by a random frame.
fn random_rays(
    acc: &mut RegisterAccelerator<Bench>,
    patches: &[Patch],
    n: usize,
    rng: &mut XorShift,
    traced: &mut Traced,
) {
    let (lo, hi) = patches.iter().fold(
        (
            Vec3::new(f32::MAX, f32::MAX, f32::MAX),
            Vec3::new(f32::MIN, f32::MIN, f32::MIN),
        ),
        |(lo, hi), p| {
            let b = p.bounds();
            (lo.min(b.min), hi.max(b.max))
        },
    );
    let unit = |rng: &mut XorShift| loop {
        let v = Vec3::new(sym(rng), sym(rng), sym(rng));
        if (0.1..=1.0).contains(&v.length()) {
            if let Some(u) = v.try_normalize() {
                return u;
            }
        }
    };
    acc.set_origin_patch(None);
    for k in 0..n {
        let t = Vec3::new(rng.f64() as f32, rng.f64() as f32, rng.f64() as f32);
        let origin = Vec3::new(
            lo.x + (hi.x - lo.x) * t.x,
            lo.y + (hi.y - lo.y) * t.y,
            lo.z + (hi.z - lo.z) * t.z,
        );
        let dir = unit(rng);
        if k % 8 == 7 {
            let rot = Rotation::onto_spun(unit(rng), rng.f64() as f32);
            acc.rotate(&rot, dir);
        } else if acc.nearest_hit(&Ray { origin, dir }, f32::MAX).is_some() {
            traced.hits += 1;
        }
        traced.rays += 1;
    }
}

/// A number in [−1, 1).
fn sym(rng: &mut XorShift) -> f32 {
    (rng.f64() * 2.0 - 1.0) as f32
}

/// Q2.30 words of a direction.
fn dir_words(d: [f64; 3]) -> [u32; 3] {
    d.map(|c| (c * (1u64 << 30) as f64).round() as i32 as u32)
}

/// Pushes one ray through RAY_IN.
fn push(b: &mut Bench, d: [f64; 3]) {
    for w in dir_words(d) {
        b.write(regs::RAY_IN, w);
    }
}

/// The clock and busy counters, each low word latching its high one.
fn counters(b: &mut Bench) {
    for reg in [regs::CYCLE_LO, regs::CYCLE_HI, regs::BUSY_LO, regs::BUSY_HI] {
        b.read(reg);
    }
}

/// Reads STATUS until the accelerator is idle (at most `limit` reads), then every result and
/// the counters.
fn drain(b: &mut Bench, limit: u32) {
    drain_busy(b, limit);
    for _ in 0..300 {
        if b.read(regs::STATUS) & status::RESULT_READY == 0 {
            break;
        }
        b.read(regs::RESULT_OUT);
    }
    counters(b);
}

/// The cases the driver does not make, register by register, on a scene of `count` slots.
fn directed(b: &mut Bench, count: u32) {
    let origin = [0x0080_0000u32, 0x0100_0000, 0x0080_0000];
    let dirs = [
        [0.0, 0.0, 1.0],
        [0.6, 0.0, 0.8],
        [0.0, -1.0, 0.0],
        [-0.48, 0.6, 0.64],
    ];
    // the driver's casts, counted
    counters(b);
    b.write(regs::CTRL, ctrl::SOFT_RESET);
    b.write(regs::IRQ_ENABLE, 0xF);
    b.write(regs::CTRL, ctrl::ENABLE);
    for (k, w) in origin.iter().enumerate() {
        b.write(regs::ORIGIN_X + 4 * k as u32, *w);
    }
    // a ray that rotates before any frame: NO_FRAME, and an ERROR result
    b.write(regs::MODE, mode::ROTATE_TRACE);
    push(b, dirs[1]);
    drain(b, 200);
    b.read(regs::ERROR);
    b.write(regs::ERROR, 0xFFFF_FFFF);
    // frames from pairs (φ = 90°, θ = 45°, ψ = 0), then rays rotated and traced, and rotated
    // alone, one of them right behind the frame
    let h = 0x2D41_3CCD; // cos 45° in Q2.30
    for (reg, w) in [
        (regs::PHI_C, 0),
        (regs::PHI_S, 0x4000_0000),
        (regs::THETA_C, h),
        (regs::THETA_S, h),
        (regs::SPIN_C, 0x4000_0000),
        (regs::SPIN_S, 0),
    ] {
        b.write(reg, w);
    }
    b.write(regs::CTRL, ctrl::ENABLE | ctrl::FRAME_PAIRS);
    for d in dirs {
        push(b, d);
    }
    b.write(regs::MODE, mode::ROTATE);
    push(b, dirs[3]);
    drain(b, 400);
    b.read(regs::FRAME_PSI);
    b.read(regs::FRAME_THETA);
    b.read(regs::FRAME_PHI);
    // traced as given, skipping a slot beyond the build's slots (it skips nothing) and then
    // slot 0, with (u,v) and without
    b.write(regs::MODE, mode::TRACE);
    b.write(regs::SKIP_PATCH, skip::ENABLE | 0x100);
    for d in dirs {
        push(b, d);
    }
    b.write(regs::SKIP_PATCH, skip::ENABLE);
    b.write(regs::MODE, mode::TRACE | mode::NO_UV);
    for d in dirs {
        push(b, d);
    }
    drain(b, 400);
    // PATCH_COUNT lowered (the set-up forgotten), rays, then restored
    b.write(regs::PATCH_COUNT, count / 2);
    for d in dirs {
        push(b, d);
    }
    drain(b, 400);
    b.write(regs::PATCH_COUNT, count);
    for d in dirs {
        push(b, d);
    }
    drain(b, 400);
    without_candidates(b, dirs);
    b.write(regs::PATCH_COUNT, count);
    part_way(b, dirs);
    applied(b, dirs);
    // soft resets with rays in every stage: the rotator (86 clocks), the queue, the set-up
    // pass, the scan, the divider (32) and the (u,v) levels; then rays again, the counters and
    // a result read from nothing
    for delay in [30, 90, 110, 125, 140, 160, 190, 230] {
        b.write(regs::CTRL, ctrl::ENABLE);
        b.write(regs::MODE, mode::TRACE);
        for d in dirs.iter().cycle().take(6) {
            push(b, *d);
        }
        b.idle(delay);
        b.read(regs::STATUS);
        b.write(regs::CTRL, ctrl::SOFT_RESET);
        b.write(regs::CTRL, ctrl::ENABLE);
        b.read(regs::STATUS);
        for d in dirs {
            push(b, d);
        }
        drain(b, 400);
    }
    for reg in [
        regs::STATUS,
        regs::ERROR,
        regs::RESULT_OUT,
        regs::ERROR,
        regs::RESULTS_DONE,
        regs::IRQ_STATUS,
    ] {
        b.read(reg);
    }
    counters(b);
}

/// Rays without a candidate, each set of them right after its origin's set-up pass: with
/// PATCH_COUNT 0, then with one slot that every ray skips; then that slot not skipped.
fn without_candidates(b: &mut Bench, dirs: [[f64; 3]; 4]) {
    b.write(regs::MODE, mode::TRACE);
    for (count, skipped) in [(0, 0), (1, skip::ENABLE), (1, 0)] {
        b.write(regs::PATCH_COUNT, count);
        b.write(regs::SKIP_PATCH, skipped);
        for d in dirs {
            push(b, d);
        }
        drain(b, 400);
    }
}

/// The stream port asked for results while RESULT_OUT is part-way into one (it gives none),
/// then the rest read through RESULT_OUT, and a ray pushed through the port.
fn part_way(b: &mut Bench, dirs: [[f64; 3]; 4]) {
    b.write(regs::MODE, mode::TRACE);
    for d in dirs {
        push(b, d);
    }
    drain_busy(b, 400);
    b.read(regs::RESULT_OUT);
    for k in 0..3 {
        let got = StreamPort::pop(b);
        debug_assert!(got.is_none(), "the port gave a result read part-way");
        if k == 1 {
            StreamPort::push(b, dir_words(dirs[0]));
        }
        StreamPort::clock(b);
    }
    drain(b, 400);
}

/// APPLY_CONFIG (of the configuration in force): the set-up forgotten, so rays from the same
/// origin set up again; then with a frame command in the same write, the angles read while the
/// new frame is computed (reset to zero by the apply) and after; then APPLY_CONFIG of a CONFIG
/// the build was not synthesised with (20 iterations), refused, and rays after it.
fn applied(b: &mut Bench, dirs: [[f64; 3]; 4]) {
    b.write(regs::MODE, mode::TRACE);
    for d in dirs {
        push(b, d);
    }
    drain(b, 400);
    b.write(regs::CTRL, ctrl::ENABLE | ctrl::APPLY_CONFIG);
    for d in dirs {
        push(b, d);
    }
    drain(b, 400);
    b.write(
        regs::CTRL,
        ctrl::ENABLE | ctrl::APPLY_CONFIG | ctrl::FRAME_PAIRS,
    );
    for _ in 0..4 {
        b.read(regs::FRAME_PSI);
        b.read(regs::FRAME_PHI);
        b.idle(8);
    }
    drain(b, 200);
    b.read(regs::FRAME_PSI);
    // a CONFIG the build's units were not synthesised with (20 iterations), refused
    b.write(regs::CONFIG, CONFIG_RESET - 4);
    b.write(regs::CTRL, ctrl::ENABLE | ctrl::APPLY_CONFIG);
    for reg in [regs::ERROR, regs::CONFIG, regs::CONFIG_ACTIVE, regs::STATUS] {
        b.read(reg);
    }
    b.write(regs::ERROR, 0xFFFF_FFFF);
    for d in dirs {
        push(b, d);
    }
    drain(b, 400);
    b.write(regs::CONFIG, CONFIG_RESET);
}

/// Reads STATUS until the accelerator is idle (at most `limit` reads).
fn drain_busy(b: &mut Bench, limit: u32) {
    for _ in 0..limit {
        if b.read(regs::STATUS) & status::BUSY == 0 {
            break;
        }
    }
}
