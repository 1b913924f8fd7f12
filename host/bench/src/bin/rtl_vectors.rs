//! `rtl-vectors OUT [options]`: writes the co-simulation vectors of the accelerator's RTL
//! (`hemi_bench::rtl`) and prints what they hold, for `cargo xtask rtl` and the test suite's
//! `rtl-cosim` step.
//!
//! - CORDIC units (`--iterations N --width W`): pass 1's hemispheres on `--scene` (`--circles
//!   R`, `--samples K`) through the angle unit and the rotator, and `--random N` random rays and
//!   vectors;
//! - with `--plane OUT2 --depth D`: the planar intersection unit on the same scene's
//!   hemispheres (`--plane-samples K`) and on `--plane-random N` random rays against
//!   `--plane-patches P` random patches. The model's own speed on the same streams (without
//!   writing them) is printed as modelled clocks per host second;
//! - with `--regs OUT3`: the register file's bus accesses (`--regs-steps N` random steps after
//!   the directed ones);
//! - with `--coarse OUT4`: the compact datapath's coarse edge units on the scene's set-up
//!   passes (`--coarse-samples K` lattice points a slot) and `--coarse-random N` random patches;
//! - with `--cull OUT5`: the culling unit (the default build's sectors): its ray side on the
//!   reference directions of hemispheres of 8 to `--circles` circles and `--cull-random N`
//!   random directions, words and boundary cases; its patch side on the scene's set-up passes
//!   (`--coarse-samples K` lattice points a slot) and as many random patches, words and edge
//!   cases;
//! - with `--setup OUT6`: the compact set-up unit on the scene's set-up passes (`--coarse-samples
//!   K` lattice points a slot) and random passes of `--setup-random N` patches in all;
//! - with `--horizon OUT7`: the slot boxes' write path on the scene's slots written and
//!   `--horizon-random N` random writes, and the horizon filter on the scene's set-up passes
//!   (`--coarse-samples K` lattice points a slot) and as many random boxes;
//! - with `--bank OUT8`: a bank's set-up pass ahead of its set-up unit on the scene's bank 0
//!   (passes from `--coarse-samples K` lattice points a slot) and `--bank-random N` random
//!   banks;
//! - with `--writer OUT9`: a bank's bitmap writer on the set-up answers of the scene's bank 0
//!   (passes from `--coarse-samples K` lattice points a slot) and `--writer-random N` random
//!   passes;
//! - with `--walk OUT13`: a lane's bitmap walk on the bitmaps of the same passes (the scene's
//!   and `--walk-random N` random ones), rays of every sector and band of each.

use anyhow::{bail, Context, Result};
use hemi_bench::rng::XorShift;
use hemi_bench::rtl::{
    accel, bank, coarse, cordic, cull, exact, group_plane, horizon, plane, reach, regs, setup,
    walk, writer,
};
use hemi_hdl_model::cordic::CordicConfig;
use hemi_hdl_model::intersect::patch_mem::PATCH_WORDS;
use std::time::Instant;

struct Args {
    out: String,
    cfg: CordicConfig,
    scene: Option<String>,
    circles: u32,
    samples: u32,
    random: usize,
    plane: Option<String>,
    depth: u32,
    plane_samples: u32,
    plane_random: usize,
    plane_patches: usize,
    regs: Option<String>,
    regs_steps: usize,
    coarse: Option<String>,
    coarse_samples: u32,
    coarse_random: usize,
    cull: Option<String>,
    cull_random: usize,
    setup: Option<String>,
    setup_random: usize,
    horizon: Option<String>,
    horizon_random: usize,
    bank: Option<String>,
    bank_random: usize,
    writer: Option<String>,
    writer_random: usize,
    walk: Option<String>,
    walk_random: usize,
    exact: Option<String>,
    exact_random: usize,
    group_plane: Option<String>,
    group_plane_random: usize,
    accel: Option<String>,
    accel_samples: u32,
    accel_random: usize,
    seed: u64,
}

fn parse() -> Result<Args> {
    let mut a = Args {
        out: String::new(),
        cfg: CordicConfig::DEFAULT,
        scene: None,
        circles: 16,
        samples: 2,
        random: 10_000,
        plane: None,
        depth: 16,
        plane_samples: 1,
        plane_random: 10_000,
        plane_patches: 48,
        regs: None,
        regs_steps: 20_000,
        coarse: None,
        coarse_samples: 2,
        coarse_random: 20_000,
        cull: None,
        cull_random: 20_000,
        setup: None,
        setup_random: 20_000,
        horizon: None,
        horizon_random: 20_000,
        bank: None,
        bank_random: 100,
        writer: None,
        writer_random: 1_000,
        walk: None,
        walk_random: 200,
        exact: None,
        exact_random: 4_000,
        group_plane: None,
        group_plane_random: 4_000,
        accel: None,
        accel_samples: 1,
        accel_random: 500,
        seed: 0x2545_f491_4f6c_dd1d,
    };
    let mut it = std::env::args().skip(1);
    while let Some(arg) = it.next() {
        let mut value = || it.next().with_context(|| format!("{arg} needs a value"));
        match arg.as_str() {
            "--iterations" => a.cfg.iterations = value()?.parse()?,
            "--width" => a.cfg.width = value()?.parse()?,
            "--scene" => a.scene = Some(value()?),
            "--circles" => a.circles = value()?.parse()?,
            "--samples" => a.samples = value()?.parse()?,
            "--random" => a.random = value()?.parse()?,
            "--plane" => a.plane = Some(value()?),
            "--depth" => a.depth = value()?.parse()?,
            "--plane-samples" => a.plane_samples = value()?.parse()?,
            "--plane-random" => a.plane_random = value()?.parse()?,
            "--plane-patches" => a.plane_patches = value()?.parse::<usize>()?.clamp(1, 256),
            "--regs" => a.regs = Some(value()?),
            "--regs-steps" => a.regs_steps = value()?.parse()?,
            "--coarse" => a.coarse = Some(value()?),
            "--coarse-samples" => a.coarse_samples = value()?.parse()?,
            "--coarse-random" => a.coarse_random = value()?.parse()?,
            "--cull" => a.cull = Some(value()?),
            "--cull-random" => a.cull_random = value()?.parse()?,
            "--setup" => a.setup = Some(value()?),
            "--setup-random" => a.setup_random = value()?.parse()?,
            "--horizon" => a.horizon = Some(value()?),
            "--horizon-random" => a.horizon_random = value()?.parse()?,
            "--bank" => a.bank = Some(value()?),
            "--bank-random" => a.bank_random = value()?.parse()?,
            "--writer" => a.writer = Some(value()?),
            "--writer-random" => a.writer_random = value()?.parse()?,
            "--walk" => a.walk = Some(value()?),
            "--walk-random" => a.walk_random = value()?.parse()?,
            "--exact" => a.exact = Some(value()?),
            "--exact-random" => a.exact_random = value()?.parse()?,
            "--group-plane" => a.group_plane = Some(value()?),
            "--group-plane-random" => a.group_plane_random = value()?.parse()?,
            "--accel" => a.accel = Some(value()?),
            "--accel-samples" => a.accel_samples = value()?.parse()?,
            "--accel-random" => a.accel_random = value()?.parse()?,
            "--seed" => a.seed = value()?.parse()?,
            s if !s.starts_with('-') && a.out.is_empty() => a.out = s.to_string(),
            s => bail!("unknown argument `{s}`"),
        }
    }
    if a.out.is_empty() || !a.cfg.is_valid() || !(1..=24).contains(&a.depth) {
        bail!("usage: rtl-vectors OUT [--iterations N --width W (valid CORDIC)] [--scene PATH] [--circles R] [--samples K] [--random N] [--plane OUT2 --depth D (1..=24) --plane-samples K --plane-random N --plane-patches P] [--regs OUT3 --regs-steps N] [--coarse OUT4 --coarse-samples K --coarse-random N] [--cull OUT5 --cull-random N] [--setup OUT6 --setup-random N] [--horizon OUT7 --horizon-random N] [--bank OUT8 --bank-random N] [--writer OUT9 --writer-random N] [--walk OUT13 --walk-random N] [--exact OUT10 --exact-random N] [--group-plane OUT11 --group-plane-random N] [--accel OUT12 --accel-samples K --accel-random N] [--seed S]");
    }
    Ok(a)
}

fn main() -> Result<()> {
    let a = parse()?;
    let scene = match &a.scene {
        Some(path) => Some(
            hemi::scene::load(std::path::Path::new(path))
                .with_context(|| format!("loading {path}"))?,
        ),
        None => None,
    };
    let hemisphere = match &scene {
        Some(s) => cordic::hemisphere_entries(s, a.circles, a.samples, a.cfg)?,
        None => Vec::new(),
    };
    let t0 = Instant::now();
    let (text, counts) = cordic::vectors(a.cfg, &hemisphere, a.random, a.random, a.seed);
    let secs = t0.elapsed().as_secs_f64();
    std::fs::write(&a.out, text).with_context(|| format!("writing {}", a.out))?;
    println!(
        "rtl-vectors: ITER={} W={} hemisphere_rays={} rays={} vectors={} clocks={} model_seconds={secs:.3}",
        a.cfg.iterations,
        a.cfg.width,
        hemisphere.len(),
        counts.rays,
        counts.vectors,
        counts.clocks
    );
    // the scene's slots as the model's patch memory holds them, read once for every unit
    let wanted = [
        &a.plane,
        &a.coarse,
        &a.cull,
        &a.setup,
        &a.horizon,
        &a.bank,
        &a.writer,
        &a.walk,
        &a.exact,
        &a.group_plane,
    ];
    let slots = match &scene {
        Some(s) if wanted.iter().any(|o| o.is_some()) => plane::loaded_slots(&s.kernel_patches())?,
        _ => Vec::new(),
    };
    if let Some(out) = &a.plane {
        plane_vectors(&a, &slots, out)?;
    }
    if let Some(out) = &a.regs {
        let (text, c) = regs::vectors(a.regs_steps, a.seed);
        std::fs::write(out, text).with_context(|| format!("writing {out}"))?;
        println!(
            "rtl-vectors: registers accesses={} clocks={} fifo_entries={}",
            c.accesses, c.clocks, c.entries
        );
    }
    if let Some(out) = &a.coarse {
        let (text, c) = coarse::vectors(&slots, a.coarse_samples, a.coarse_random, a.seed);
        std::fs::write(out, text).with_context(|| format!("writing {out}"))?;
        println!(
            "rtl-vectors: coarse edges={} pairs={} undecided={}",
            c.edges, c.pairs, c.undecided
        );
    }
    if let Some(out) = &a.cull {
        cull_vectors(&a, &slots, out)?;
    }
    if let Some(out) = &a.setup {
        let sectors = hemi_hdl_model::params::Params::DEFAULT.sectors;
        let (text, c) = setup::vectors(sectors, &slots, a.coarse_samples, a.setup_random, a.seed);
        std::fs::write(out, text).with_context(|| format!("writing {out}"))?;
        println!(
            "rtl-vectors: setup passes={} patches={} inactive={} below={} wedges={}",
            c.passes, c.patches, c.inactive, c.below, c.wedges
        );
    }
    if let Some(out) = &a.horizon {
        let (text, c) = horizon::vectors(&slots, a.coarse_samples, a.horizon_random, a.seed);
        std::fs::write(out, text).with_context(|| format!("writing {out}"))?;
        println!(
            "rtl-vectors: horizon writes={} boxes={} below={}",
            c.writes, c.boxes, c.below
        );
    }
    if let Some(out) = &a.bank {
        let (text, c) = bank::vectors(&slots, a.coarse_samples, a.bank_random, a.seed);
        std::fs::write(out, text).with_context(|| format!("writing {out}"))?;
        println!(
            "rtl-vectors: bank passes={} slots={} corners={} set_up={} stalls={}",
            c.passes, c.slots, c.corners, c.set_up, c.stalls
        );
    }
    if let Some(out) = &a.writer {
        let (text, c) = writer::vectors(&slots, a.coarse_samples, a.writer_random, a.seed);
        std::fs::write(out, text).with_context(|| format!("writing {out}"))?;
        println!(
            "rtl-vectors: writer passes={} answers={} copies={} empty={}",
            c.passes, c.answers, c.copies, c.empty
        );
    }
    if let Some(out) = &a.walk {
        let (text, c) = walk::vectors(&slots, a.coarse_samples, a.walk_random, a.seed);
        std::fs::write(out, text).with_context(|| format!("writing {out}"))?;
        println!(
            "rtl-vectors: walk passes={} rays={} candidates={}",
            c.passes, c.rays, c.candidates
        );
    }
    if let Some(out) = &a.exact {
        let (text, c) = exact::vectors(&slots, a.coarse_samples, a.exact_random, a.seed);
        std::fs::write(out, text).with_context(|| format!("writing {out}"))?;
        println!(
            "rtl-vectors: exact pairs={} edges={} inside={} undecided={}",
            c.pairs, c.edges, c.inside, c.undecided
        );
    }
    if let (Some(out), Some(s)) = (&a.accel, &scene) {
        let (samples, random) = (a.accel_samples, a.accel_random);
        let patches = s.kernel_patches();
        let (text, c, t) = accel::vectors(&patches, a.circles, samples, random, a.seed)?;
        std::fs::write(out, text).with_context(|| format!("writing {out}"))?;
        println!(
            "rtl-vectors: accel accesses={} clocks={} rays={} hits={}",
            c.accesses, c.clocks, t.rays, t.hits
        );
    }
    if let Some(out) = &a.group_plane {
        let random = a.group_plane_random;
        let (text, c) = group_plane::vectors(&slots, a.coarse_samples, random, a.seed);
        std::fs::write(out, text).with_context(|| format!("writing {out}"))?;
        println!(
            "rtl-vectors: group plane rays={} pairs={} hits={} no_t={}",
            c.rays, c.pairs, c.hits, c.no_t
        );
    }
    Ok(())
}

/// The culling unit's file, both sides, at the default build's sectors (`cull_ray.v`'s and
/// `cull_reach.v`'s default SECTORS).
fn cull_vectors(a: &Args, slots: &[[u32; PATCH_WORDS]], out: &str) -> Result<()> {
    let sectors = hemi_hdl_model::params::Params::DEFAULT.sectors;
    let circles: Vec<u32> = [8, 16, 32, 64]
        .into_iter()
        .filter(|&r| r <= a.circles.max(8))
        .collect();
    let (mut text, c) = cull::vectors(sectors, &circles, a.cull_random, a.seed);
    let (patches, p) = reach::vectors(sectors, slots, a.coarse_samples, a.cull_random, a.seed);
    text.push_str(&patches);
    std::fs::write(out, text).with_context(|| format!("writing {out}"))?;
    println!(
        "rtl-vectors: cull rays={} culled={} patches={} below={} wedges={}",
        c.rays, c.culled, p.patches, p.below, p.wedges
    );
    Ok(())
}

/// The planar unit's file: the scene's hemispheres (on its `slots`, if any), then random
/// patches and rays, one stream after the other (the second reloads patch memory).
fn plane_vectors(a: &Args, slots: &[[u32; PATCH_WORDS]], out: &str) -> Result<()> {
    let mut rng = XorShift::new(a.seed ^ 0x9e37_79b9_7f4a_7c15);
    let mut works = Vec::new();
    if !slots.is_empty() {
        let rays = plane::hemispheres(slots, a.circles, a.plane_samples)?;
        works.push(plane::Workload {
            slots: slots.to_vec(),
            rays,
        });
    }
    if a.plane_random > 0 {
        works.push(plane::random(&mut rng, a.plane_patches, a.plane_random));
    }
    let mut text = String::new();
    let (mut rays, mut clocks) = (0, 0);
    for w in &works {
        let (t, c) = plane::stream(w, a.depth, &mut rng.clone(), true);
        rays += w.rays.len();
        clocks += c;
        text.push_str(&t);
        text.push_str("E\n");
    }
    std::fs::write(out, text).with_context(|| format!("writing {out}"))?;
    // the same streams again, timed, without the text
    let t0 = Instant::now();
    for w in &works {
        plane::stream(w, a.depth, &mut rng.clone(), false);
    }
    let secs = t0.elapsed().as_secs_f64();
    println!(
        "rtl-vectors: plane DEPTH={} rays={rays} clocks={clocks} model_seconds={secs:.3} \
         model_clocks_per_second={:.0}",
        a.depth,
        clocks as f64 / secs
    );
    Ok(())
}
