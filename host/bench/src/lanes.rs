//! The modelled accelerator's lanes and culling: cycles per ray against lanes and patch count
//! (a scene's quads subdivided n × n), the work the culling leaves the lanes, the simulation's
//! speed, and the area proxy of each build (docs/PERFORMANCE.md).

use crate::chart::{log_log, Series};
use anyhow::{Context, Result};
use hemi::scene::{Scene, Sides};
use hemi_hdl_model::area;
use hemi_hdl_model::cordic::CordicConfig;
use hemi_hdl_model::params::MAX_CAPACITY;
use hemi_hdl_model::{ModelConfig, Params, StreamingModel};
use hemi_kernel::accel::{Accelerator, HemiShot};
use hemi_kernel::geometry::Vec3;
use hemi_kernel::hemisphere::{DeltaRule, OwnedHemisphere};
use hemi_kernel::patch::Shape;
use hemi_kernel::rotation::{spin_for_sample, Rotation};
use std::fmt::Write as _;
use std::io::Write;
use std::path::Path;
use std::time::Instant;

/// The scene with every quad cut into n × n quads along its bilinear (u,v) map, as scene text
/// (materials as in `scene`; only diffuse and emissive materials and opaque quads and
/// triangles are written, which is what the Cornell box has).
pub fn subdivided(scene: &Scene, n: u32) -> Result<String> {
    let mut s = String::new();
    for m in &scene.materials {
        anyhow::ensure!(
            m.specular == [0.0; 3] && m.transmission == [0.0; 3],
            "material {}: only diffuse and emissive materials are subdivided",
            m.name
        );
        let _ = writeln!(
            s,
            "[[material]]\nname = \"{}\"\ndiffuse = {:?}\nemission = {:?}\n",
            m.name, m.diffuse, m.emission
        );
    }
    let at = |v: &[Vec3; 4], a: f64, b: f64| -> [f64; 3] {
        let w = [(1.0 - a) * (1.0 - b), a * (1.0 - b), a * b, (1.0 - a) * b];
        let c = |f: fn(&Vec3) -> f32| (0..4).map(|k| w[k] * f(&v[k]) as f64).sum::<f64>();
        [c(|p| p.x), c(|p| p.y), c(|p| p.z)]
    };
    for p in &scene.patches {
        anyhow::ensure!(p.sides == Sides::Opaque, "patch {}: not opaque", p.name);
        let Shape::Polygon(poly) = &p.shape else {
            anyhow::bail!("patch {}: only polygons are subdivided", p.name);
        };
        let material = &scene.materials[p.material].name;
        if poly.sides == 3 {
            let v = poly.v.map(|v| [v.x, v.y, v.z]);
            let _ = writeln!(
                s,
                "[[triangle]]\nname = \"{}\"\nmaterial = \"{material}\"\nvertices = {:?}\n",
                p.name,
                &v[..3]
            );
            continue;
        }
        for b in 0..n {
            for a in 0..n {
                let (a0, a1) = (a as f64 / n as f64, (a + 1) as f64 / n as f64);
                let (b0, b1) = (b as f64 / n as f64, (b + 1) as f64 / n as f64);
                let q = [
                    at(&poly.v, a0, b0),
                    at(&poly.v, a1, b0),
                    at(&poly.v, a1, b1),
                    at(&poly.v, a0, b1),
                ];
                let _ = writeln!(
                    s,
                    "[[quad]]\nname = \"{}_{a}_{b}\"\nmaterial = \"{material}\"\nvertices = {q:?}\n",
                    p.name
                );
            }
        }
    }
    Ok(s)
}

/// What one build did on one scene's pass 1.
struct Run {
    rays: u64,
    cycles: u64,
    candidates: u64,
    /// edges the coarse test left to the shared exact unit
    exact_edges: u64,
    /// lane clocks of the bitmap walks beyond the candidates
    walk_clocks: u64,
    /// of the patches set up for culling: the share in every sector, and bins covered each
    full: f64,
    bins: f64,
    /// of the planar patches out of the origin's plane, the share the horizon filter passed over
    passed_over: f64,
    /// clocks a set-up pass's buffer waited for its bitmap writers after its last answer
    write_wait: f64,
    seconds: f64,
    /// blocks the scene streamed through patch memory in (1: it fit)
    blocks: usize,
}

/// Pass 1's hemispheres of `scene` (K × K sample points per patch, R circles) on a model of
/// `params`.
fn run(scene: &Scene, params: Params, circles: u32, samples: u32) -> Result<Run> {
    let patches = scene.kernel_patches();
    let hemi = OwnedHemisphere::new(circles, DeltaRule::Band)
        .map_err(|e| anyhow::anyhow!("hemisphere of {circles} circles: {e}"))?;
    let view = hemi.view();
    let config = ModelConfig {
        params,
        ..ModelConfig::default()
    };
    let mut model = Box::new(
        StreamingModel::new(&patches, config).map_err(|e| anyhow::anyhow!("model: {e:?}"))?,
    );
    let (c0, t0) = (model.cycles(), Instant::now());
    let mut q = 0u32;
    // a row's hemispheres in one batch, as a shoot job casts them: the pipeline drains once a
    // row, not once a hemisphere
    for i in 0..patches.len() {
        let shots: Vec<HemiShot> = hemi::shots::sample_points(scene, i, samples)
            .into_iter()
            .map(|p| {
                q += 1;
                HemiShot {
                    origin: p.position,
                    rot: Rotation::onto_spun(p.normal, spin_for_sample(q - 1)),
                    origin_patch: Some(i as u32),
                }
            })
            .collect();
        model.cast_hemispheres(&shots, &view, 0..view.rings().len(), false, |_, _, _, _| {});
    }
    let st = model.lane_stats();
    Ok(Run {
        rays: model.rays(),
        cycles: model.cycles() - c0,
        candidates: st.candidates,
        exact_edges: st.exact_edges,
        walk_clocks: st.walk_clocks,
        full: st.full_patches as f64 / st.culled_patches.max(1) as f64,
        bins: st.bins as f64 / st.culled_patches.max(1) as f64,
        passed_over: st.passed_over as f64 / (st.passed_over + st.culled_patches).max(1) as f64,
        write_wait: st.write_wait as f64 / st.setups.max(1) as f64,
        seconds: t0.elapsed().as_secs_f64(),
        blocks: model.blocks(),
    })
}

/// The walk clocks a ray beyond the candidates, or "–" where the rays were not culled (no
/// bitmap walk).
fn walk_column(sectors: u32, clocks: u64, rays: u64) -> String {
    match sectors {
        0 => "–".into(),
        _ => format!("{:.3}", clocks as f64 / rays.max(1) as f64),
    }
}

/// A build of `lanes` lanes whose banks hold `patches` if the patch memory's window can
/// ([`MAX_CAPACITY`] slots; a larger scene streams through it in blocks): the default's
/// datapath and ray groups (fewer when there are fewer lanes).
fn build(lanes: u32, sectors: u32, rays_per_clock: u32, patches: usize) -> Params {
    let ray_groups = Params::DEFAULT.ray_groups.min(lanes);
    let banks = lanes / ray_groups;
    Params {
        lanes,
        sectors,
        rays_per_clock,
        bank_slots: (patches as u32)
            .div_ceil(banks)
            .max(Params::DEFAULT.bank_slots)
            .min(MAX_CAPACITY / banks),
        compact: Params::DEFAULT.compact,
        ray_groups,
    }
}

/// Prints the tables (cycles per ray against lanes and patch count, with culling and without;
/// simulation speed; area proxy) and, with `svg_dir`, writes `lanes-cycles.svg`.
pub fn bench(
    scene: &Scene,
    subdivisions: &[u32],
    lanes: &[u32],
    circles: u32,
    samples: u32,
    svg_dir: Option<&Path>,
    out: &mut impl Write,
) -> Result<()> {
    writeln!(out, "R = {circles}, K = {samples}; 2 rays per clock\n")?;
    writeln!(out, "| patches | lanes | culling | rays | cycles/ray | candidates/ray | exact edges/ray | walk clocks/ray | passed over by the horizon filter | patches in every sector | bins/patch | bitmap write wait/pass | model Mcycles/s | host M rays/s |")?;
    writeln!(
        out,
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
    )?;
    let mut series = Vec::new();
    for &n in subdivisions {
        let text = subdivided(scene, n)?;
        let sub = hemi::scene::parse(&text, "subdivided scene")?;
        let count = sub.patches.len();
        let mut points = Vec::new();
        for &l in lanes {
            // without culling a ray tests every patch: only measured on the smaller scenes
            let unculled: &[u32] = if count <= 400 { &[0] } else { &[] };
            for &sectors in [32].iter().chain(unculled) {
                let r = run(&sub, build(l, sectors, 2, count), circles, samples)?;
                let cpr = r.cycles as f64 / r.rays as f64;
                writeln!(
                    out,
                    "| {count}{} | {l} | {} | {} | {cpr:.2} | {:.2} | {:.3} | {} | {:.1} % | {:.1} % | {:.1} | {:.1} | {:.1} | {:.2} |",
                    match r.blocks {
                        1 => String::new(),
                        n => format!(" ({n} blocks)"),
                    },
                    if sectors > 0 { "32 sectors × 16 bands" } else { "none" },
                    r.rays,
                    r.candidates as f64 / r.rays as f64,
                    r.exact_edges as f64 / r.rays as f64,
                    walk_column(sectors, r.walk_clocks, r.rays),
                    r.passed_over * 100.0,
                    r.full * 100.0,
                    r.bins,
                    r.write_wait,
                    r.cycles as f64 / r.seconds / 1e6,
                    r.rays as f64 / r.seconds / 1e6
                )?;
                if sectors > 0 {
                    points.push((l as f64, cpr));
                }
            }
        }
        series.push(Series {
            name: format!("{count} patches"),
            points,
        });
    }
    area_table(lanes, out)?;
    default_parts(out)?;
    if let Some(dir) = svg_dir {
        let svg = log_log(
            "Modelled accelerator: cycles per ray against lanes",
            "lanes",
            "cycles per ray",
            &format!("Cornell box subdivided, R = {circles}, K = {samples}, 32 sectors × 16 bands, 2 rays/clock"),
            &series,
        );
        let path = dir.join("lanes-cycles.svg");
        std::fs::write(&path, svg).with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(())
}

/// The default build's area proxy unit by unit, on an ECP5-85k: what does not fit, named.
fn default_parts(out: &mut impl Write) -> Result<()> {
    let p = Params::DEFAULT;
    writeln!(out, "\nThe default build unit by unit ({p:?})\n")?;
    writeln!(out, "| unit | LUT4 | FF | DSP | EBR |")?;
    writeln!(out, "|---|---|---|---|---|")?;
    let mut row = |name: &str, f: area::Fpga| {
        writeln!(
            out,
            "| {name} | {} | {} | {} | {} |",
            f.luts, f.ffs, f.dsps, f.brams
        )
    };
    let mut total = area::Fpga::default();
    for (name, f) in area::compact_parts_on_ecp5(&p, CordicConfig::DEFAULT, 16) {
        total.luts += f.luts;
        total.ffs += f.ffs;
        total.dsps += f.dsps;
        total.brams += f.brams;
        row(name, f)?;
    }
    row(
        "total (each row with its own 10 % for control, the placed units as placed)",
        total,
    )?;
    row("ECP5-85k", area::ECP5_85K)?;
    Ok(())
}

/// The area proxy of the default build's neighbours, and what an ECP5-85k has.
fn area_table(lanes: &[u32], out: &mut impl Write) -> Result<()> {
    writeln!(
        out,
        "\nArea proxy (2 rays per clock, 512 slots per bank; ECP5-85k: {:?})\n",
        area::ECP5_85K
    )?;
    writeln!(out, "| lanes | culling | adders | multiplier bits | register bits | RAM bits | placed units LUT4 / FF | ray datapath LUT4 / FF / DSP / EBR | fixed units LUT4 / FF / DSP / EBR | fits |")?;
    writeln!(out, "|---|---|---|---|---|---|---|---|---|---|")?;
    for &l in lanes {
        for sectors in [32, 0] {
            let p = Params {
                lanes: l,
                sectors,
                rays_per_clock: 2,
                bank_slots: 512,
                compact: Params::DEFAULT.compact,
                ray_groups: Params::DEFAULT.ray_groups.min(l),
            };
            let proxy = area::ray_datapath(&p, CordicConfig::DEFAULT);
            let (ray, fixed) = area::on_ecp5(&p, CordicConfig::DEFAULT, 16);
            let total = area::Fpga {
                luts: ray.luts + fixed.luts,
                ffs: ray.ffs + fixed.ffs,
                dsps: ray.dsps + fixed.dsps,
                brams: ray.brams + fixed.brams,
            };
            writeln!(
                out,
                "| {l} | {} | {} | {} | {} | {} | {} / {} | {} / {} / {} / {} | {} / {} / {} / {} | {} |",
                if sectors > 0 { "32 sectors" } else { "none" },
                proxy.adders,
                proxy.multiplier_bits(),
                proxy.register_bits,
                proxy.ram_bits(),
                proxy.placed.luts,
                proxy.placed.ffs,
                ray.luts,
                ray.ffs,
                ray.dsps,
                ray.brams,
                fixed.luts,
                fixed.ffs,
                fixed.dsps,
                fixed.brams,
                if total.fits(&area::ECP5_85K) {
                    "yes"
                } else if ray.fits(&area::ECP5_85K) {
                    "ray datapath only"
                } else {
                    "no"
                }
            )?;
        }
    }
    Ok(())
}
