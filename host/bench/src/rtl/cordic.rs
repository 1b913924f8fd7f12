//! Co-simulation vectors of the CORDIC units' RTL (`hdl-model/rtl/`): the model's units are
//! driven clock by clock with a workload, and every input and every output is written with the
//! clock it happens on, for the Verilator testbench (`hdl-model/rtl/tb/cosim.cpp`) to drive the
//! RTL with the same inputs at the same clocks and compare its outputs bit for bit and clock for
//! clock.
//!
//! Two CORDIC units, each with its own stream in the file:
//! - the rotator (three rotation-mode CORDIC pipes, `rotator.v`): lines `R clk dx dy dz psi
//!   theta phi bypass` in, `r clk dx dy dz` out, 32-bit containers in hex;
//! - the angle unit's vectoring-mode pipe (`cordic_pipe.v`, MODE 1): `V clk x y z` in, `v clk x
//!   y z` out;
//! - the whole angle unit (`frame_unit.v`: the pipe and its sequencing, `frame.rs`): `F clk kind
//!   w1 … w6` a frame started (kind 0 from a normal and spin, 1 from three pairs), `a clk psi
//!   theta phi` the angles after a clock that changed them, `f clk` the clock a frame completed.
//!
//! The workload: pass 1's hemispheres on a scene (every sample point's frame through the
//! model's angle unit, then its rays through the rotator, as `ROTATE_TRACE` entries do), random
//! directions under random angles (the whole Q3.29 range, not only ±π), the edge cases
//! (extreme and zero words, angles at ±π/2 exactly, bypassed entries), and random vectors and
//! the degenerate ones for the vectoring pipe, with random gaps between entries so that the
//! pipes are seen both full and draining.

use crate::rng::XorShift;
use anyhow::Result;
use hemi::scene::Scene;
use hemi_hdl_model::cordic::{CordicConfig, CordicPipe, CordicSlot, Mode};
use hemi_hdl_model::format::{Angle, Unit};
use hemi_hdl_model::frame::{FrameRequest, FrameUnit};
use hemi_hdl_model::rotator::{RotIn, Rotator};
use hemi_kernel::hemisphere::{DeltaRule, OwnedHemisphere};
use hemi_kernel::rotation::{spin_for_sample, Rotation};
use std::fmt::Write as _;

/// One rotator entry: direction, (ψ, θ, φ), bypass.
#[derive(Clone, Copy, Debug)]
pub struct RotEntry {
    /// Direction words (Q2.30 containers).
    pub dir: [i32; 3],
    /// ψ, θ, φ (Q3.29 containers).
    pub angles: [i32; 3],
    /// Trace mode: the direction passes unrotated.
    pub bypass: bool,
}

/// What the file holds, counted.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    /// Rotator entries (rays).
    pub rays: u64,
    /// Vectoring-pipe entries.
    pub vectors: u64,
    /// Clocks simulated.
    pub clocks: u64,
}

/// A direction component as the driver writes it (`accel.rs`): saturated to Q2.30.
pub fn unit_word(x: f32) -> i32 {
    Unit::saturating_from_num(x).to_bits()
}

/// A frame's angles as the device computes them from the driver's (cos, sin) pairs.
pub fn frame_angles(rot: &Rotation, cfg: CordicConfig) -> [i32; 3] {
    let pair = |c: f32, s: f32| [c, s].map(|v| Unit::from_bits(unit_word(v)));
    let mut unit = FrameUnit::new(cfg);
    unit.start(FrameRequest::Pairs {
        phi: pair(rot.cos_phi, rot.sin_phi),
        theta: pair(rot.cos_theta, rot.sin_theta),
        psi: pair(rot.cos_psi, rot.sin_psi),
    });
    while !unit.tick() {}
    unit.angles().map(|a| a.to_bits())
}

/// Pass 1's rotator entries on `scene`: K × K sample points per patch, R circles, each sample
/// point's spin as pass 1 gives it.
pub fn hemisphere_entries(
    scene: &Scene,
    circles: u32,
    samples: u32,
    cfg: CordicConfig,
) -> Result<Vec<RotEntry>> {
    let hemi = OwnedHemisphere::new(circles, DeltaRule::Band)
        .map_err(|e| anyhow::anyhow!("hemisphere of {circles} circles: {e}"))?;
    let view = hemi.view();
    let mut out = Vec::new();
    let mut q = 0u32;
    for i in 0..scene.patches.len() {
        for p in hemi::shots::sample_points(scene, i, samples) {
            let rot = Rotation::onto_spun(p.normal, spin_for_sample(q));
            q += 1;
            let angles = frame_angles(&rot, cfg);
            for (j, ring) in view.rings().iter().enumerate() {
                for k in 0..ring.count {
                    let d = view.direction(j, k);
                    out.push(RotEntry {
                        dir: [d.x, d.y, d.z].map(unit_word),
                        angles,
                        bypass: false,
                    });
                }
            }
        }
    }
    Ok(out)
}

/// Words a random test favours: the extremes, zero, ±1 and ±π/2 in both formats, and their
/// neighbours (one LSB at the model's widest word and at the narrowest).
fn edge_word(rng: &mut XorShift) -> i32 {
    const EDGES: [i32; 12] = [
        i32::MIN,
        i32::MAX,
        0,
        1 << 30,
        -(1 << 30),
        0x3243_f6a8, // π/2 as Q3.29 (and its rounded neighbours below)
        -0x3243_f6a8,
        0x3244_0000,
        -0x3244_0000,
        1 << 29,
        -1,
        0x7fff_0000,
    ];
    let w = EDGES[(rng.bits() % EDGES.len() as u64) as usize];
    match rng.bits() % 4 {
        0 => w.wrapping_add(1 << 16),
        1 => w.wrapping_sub(1 << 16),
        _ => w,
    }
}

/// `n` random rotator entries, one in eight made of edge words, one in sixteen bypassed.
pub fn random_entries(rng: &mut XorShift, n: usize) -> Vec<RotEntry> {
    (0..n)
        .map(|_| {
            let edge = rng.bits().is_multiple_of(8);
            let word = |rng: &mut XorShift| {
                if edge {
                    edge_word(rng)
                } else {
                    rng.bits() as i32
                }
            };
            RotEntry {
                dir: [word(rng), word(rng), word(rng)],
                angles: [word(rng), word(rng), word(rng)],
                bypass: rng.bits().is_multiple_of(16),
            }
        })
        .collect()
}

/// `n` random vectors for the vectoring pipe: one in four made of edge words (zero vectors,
/// the axes, the extremes), the rest random.
pub fn random_vectors(rng: &mut XorShift, n: usize) -> Vec<[i32; 3]> {
    (0..n)
        .map(|_| {
            if rng.bits().is_multiple_of(4) {
                [edge_word(rng), edge_word(rng), edge_word(rng)]
            } else {
                [rng.bits() as i32, rng.bits() as i32, rng.bits() as i32]
            }
        })
        .collect()
}

/// The clock each of `n` entries enters on: back to back in bursts, with random gaps.
fn schedule(rng: &mut XorShift, n: usize) -> Vec<u64> {
    let mut clk = 2u64;
    (0..n)
        .map(|_| {
            let c = clk;
            clk += match rng.bits() % 8 {
                0 => 1 + rng.bits() % 40,
                _ => 1,
            };
            c
        })
        .collect()
}

fn hex(w: i32) -> String {
    format!("{:08x}", w as u32)
}

/// The rotator stream: entries in at their clocks, the model's outputs at theirs.
pub fn rotator_stream(
    cfg: CordicConfig,
    entries: &[RotEntry],
    rng: &mut XorShift,
    out: &mut String,
) -> u64 {
    let at = schedule(rng, entries.len());
    let mut rot: Rotator<()> = Rotator::new(cfg);
    let (mut next, mut clk) = (0usize, 0u64);
    let end = at.last().copied().unwrap_or(0) + rot.latency() as u64 + 2;
    while clk <= end {
        let input = (next < entries.len() && at[next] == clk).then(|| {
            let e = entries[next];
            next += 1;
            let _ = writeln!(
                out,
                "R {clk} {} {} {} {} {} {} {}",
                hex(e.dir[0]),
                hex(e.dir[1]),
                hex(e.dir[2]),
                hex(e.angles[0]),
                hex(e.angles[1]),
                hex(e.angles[2]),
                e.bypass as u8
            );
            RotIn {
                dir: e.dir.map(Unit::from_bits),
                angles: e.angles.map(Angle::from_bits),
                bypass: e.bypass,
                info: (),
            }
        });
        if let Some((d, ())) = rot.tick(input) {
            let w = d.map(|c| hex(c.to_bits()));
            let _ = writeln!(out, "r {clk} {} {} {}", w[0], w[1], w[2]);
        }
        clk += 1;
    }
    clk
}

/// The vectoring pipe's stream.
pub fn vector_stream(
    cfg: CordicConfig,
    vectors: &[[i32; 3]],
    rng: &mut XorShift,
    out: &mut String,
) -> u64 {
    let at = schedule(rng, vectors.len());
    let mut pipe: CordicPipe<()> = CordicPipe::new(Mode::Vector, cfg);
    let (mut next, mut clk) = (0usize, 0u64);
    let end = at.last().copied().unwrap_or(0) + cfg.latency() as u64 + 2;
    while clk <= end {
        let input = (next < vectors.len() && at[next] == clk).then(|| {
            let v = vectors[next];
            next += 1;
            let _ = writeln!(out, "V {clk} {} {} {}", hex(v[0]), hex(v[1]), hex(v[2]));
            CordicSlot {
                x: Unit::from_bits(v[0]),
                y: Unit::from_bits(v[1]),
                z: Angle::from_bits(v[2]),
                zero: false,
                payload: (),
            }
        });
        if let Some(s) = pipe.tick(input) {
            let (x, y, z) = (s.x.to_bits(), s.y.to_bits(), s.z.to_bits());
            let _ = writeln!(out, "v {clk} {} {} {}", hex(x), hex(y), hex(z));
        }
        clk += 1;
    }
    clk
}

/// `n` random frames: from a normal and a spin or from three (cos, sin) pairs, of random
/// angles (as the driver writes them) or, one in four, of edge words (zero and axis normals, the
/// extremes).
pub fn random_frames(rng: &mut XorShift, n: usize) -> Vec<FrameRequest> {
    let pair = |rng: &mut XorShift| -> [Unit; 2] {
        if rng.bits().is_multiple_of(4) {
            return [edge_word(rng), edge_word(rng)].map(Unit::from_bits);
        }
        let a = (rng.f64() * 2.0 - 1.0) * std::f64::consts::PI;
        [a.cos(), a.sin()].map(|v| Unit::from_bits(unit_word(v as f32)))
    };
    (0..n)
        .map(|_| match rng.bits() % 2 {
            0 => {
                let n = if rng.bits().is_multiple_of(4) {
                    [edge_word(rng), edge_word(rng), edge_word(rng)]
                } else {
                    let v = [rng.f64() - 0.5, rng.f64() - 0.5, rng.f64() - 0.5];
                    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt().max(1e-9);
                    v.map(|c| unit_word((c / l) as f32))
                };
                FrameRequest::Normal {
                    n: n.map(Unit::from_bits),
                    spin: pair(rng),
                }
            }
            _ => FrameRequest::Pairs {
                phi: pair(rng),
                theta: pair(rng),
                psi: pair(rng),
            },
        })
        .collect()
}

/// The angle unit's stream: each frame started on a clock its unit is idle (right after the
/// last one, or a few clocks later), every change of its angles and every completion.
pub fn frame_stream(
    cfg: CordicConfig,
    frames: &[FrameRequest],
    rng: &mut XorShift,
    out: &mut String,
) -> u64 {
    let mut unit = FrameUnit::new(cfg);
    let mut clk = 2u64;
    let mut angles = unit.angles();
    let bits = |u: Unit| u.to_bits();
    for f in frames {
        clk += rng.bits() % 3;
        let (kind, w) = match *f {
            FrameRequest::Normal { n, spin } => {
                (0, [n[0], n[1], n[2], spin[0], spin[1], Unit::ZERO])
            }
            FrameRequest::Pairs { phi, theta, psi } => {
                (1, [phi[0], phi[1], theta[0], theta[1], psi[0], psi[1]])
            }
        };
        let words: Vec<String> = w.iter().map(|u| hex(bits(*u))).collect();
        let _ = writeln!(out, "F {clk} {kind} {}", words.join(" "));
        unit.start(*f);
        loop {
            let done = unit.tick();
            if unit.angles() != angles {
                angles = unit.angles();
                let a = angles.map(|a| hex(a.to_bits()));
                let _ = writeln!(out, "a {clk} {} {} {}", a[0], a[1], a[2]);
            }
            if done {
                let _ = writeln!(out, "f {clk}");
            }
            clk += 1;
            if done {
                break;
            }
        }
    }
    clk
}

/// The whole file for one configuration: a header naming it, then the three streams.
pub fn vectors(
    cfg: CordicConfig,
    hemisphere: &[RotEntry],
    random_rays: usize,
    random_vecs: usize,
    seed: u64,
) -> (String, Counts) {
    let mut rng = XorShift::new(seed);
    let mut entries = hemisphere.to_vec();
    entries.extend(random_entries(&mut rng, random_rays));
    let vecs = random_vectors(&mut rng, random_vecs);
    let mut out = format!("# ITER={} W={}\n", cfg.iterations, cfg.width);
    let c1 = rotator_stream(cfg, &entries, &mut rng, &mut out);
    let c2 = vector_stream(cfg, &vecs, &mut rng, &mut out);
    let frames = random_frames(&mut rng, random_vecs / 4);
    let c3 = frame_stream(cfg, &frames, &mut rng, &mut out);
    let counts = Counts {
        rays: entries.len() as u64,
        vectors: (vecs.len() + frames.len()) as u64,
        clocks: c1 + c2 + c3,
    };
    (out, counts)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_entry_leaves_after_the_pipes_latency() {
        let cfg = CordicConfig {
            iterations: 12,
            width: 16,
        };
        let mut rng = XorShift::new(0x9e37_79b9_7f4a_7c15);
        let entries = random_entries(&mut rng, 50);
        let mut s = String::new();
        rotator_stream(cfg, &entries, &mut rng, &mut s);
        let clocks = |tag: &str| -> Vec<u64> {
            s.lines()
                .filter(|l| l.starts_with(tag))
                .map(|l| l.split(' ').nth(1).unwrap().parse().unwrap())
                .collect()
        };
        let (ins, outs) = (clocks("R "), clocks("r "));
        assert_eq!(ins.len(), 50);
        let lat = 3 * cfg.latency() as u64 + 2;
        assert!(ins.iter().zip(&outs).all(|(i, o)| o - i == lat));
    }
}
