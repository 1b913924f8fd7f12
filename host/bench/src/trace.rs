//! `hemi bench trace`: single rays (the `trace` command, eye and frustum rays) through the soft
//! engine with and without its BVH, on one scene and one ray set in one run, with the hits
//! checked equal. The ratio is what the tree buys; the absolute rates are what a ray-casting
//! comparison (Embree) sees.

use anyhow::{ensure, Result};
use hemi::scene::Scene;
use hemi_kernel::accel::bvh::{self, Bvh, Node};
use hemi_kernel::accel::soft::{LocalPatch, SoftAccelerator, SoftScratch};
use hemi_kernel::accel::wide_bvh::{self, WideNode};
use hemi_kernel::accel::{Accelerator, Hit, Ray};
use hemi_kernel::geometry::{Aabb, Vec3};
use std::io::Write;
use std::time::Instant;

/// `rays` rays from random points in the scene's bounding box in random directions (a fixed
/// seed), cast one by one with the linear scan and with the tree; prints a markdown table.
pub fn single_rays(scene: &Scene, rays: usize, out: &mut impl Write) -> Result<()> {
    let patches = scene.kernel_patches();
    let n = patches.len();
    ensure!(n > 0 && rays > 0, "nothing to trace");
    let bounds = patches.iter().map(|p| p.bounds()).fold(
        Aabb {
            min: Vec3::new(f32::MAX, f32::MAX, f32::MAX),
            max: Vec3::new(f32::MIN, f32::MIN, f32::MIN),
        },
        |a, b| Aabb {
            min: a.min.min(b.min),
            max: a.max.max(b.max),
        },
    );
    let mut rng = super::rng::XorShift::new(0x9e37_79b9_7f4a_7c15);
    let mut next = move || rng.f32();
    let size = bounds.max - bounds.min;
    let ray_set: Vec<Ray> = std::iter::repeat_with(|| {
        let origin = Vec3::new(
            bounds.min.x + size.x * next(),
            bounds.min.y + size.y * next(),
            bounds.min.z + size.z * next(),
        );
        let dir = Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5).try_normalize();
        dir.map(|dir| Ray { origin, dir })
    })
    .flatten()
    .take(rays)
    .collect();

    let t0 = Instant::now();
    let mut nodes = vec![Node::default(); bvh::nodes_for(n)];
    let mut order = vec![0u32; n];
    let mut boxes: Vec<Aabb> = patches.iter().map(|p| p.bounds()).collect();
    bvh::build(&patches, &mut nodes, &mut order, &mut boxes)
        .map_err(|e| anyhow::anyhow!("BVH: {e:?}"))?;
    let build_s = t0.elapsed().as_secs_f64();

    let mut local = vec![LocalPatch::default(); n];
    let (mut best_t, mut best_id) = (vec![0.0f32; 4], vec![0u32; 4]);
    let mut run = |tree: Option<Bvh<'_>>| -> Result<(f64, f64, Vec<Option<Hit>>)> {
        let mut accel = SoftAccelerator::new(
            &patches,
            SoftScratch {
                local: &mut local,
                best_t: &mut best_t,
                best_id: &mut best_id,
            },
        )
        .map_err(|e| anyhow::anyhow!("{e:?}"))?;
        if let Some(t) = tree {
            accel = accel.with_bvh(t);
        }
        let t0 = Instant::now();
        let mut hits: Vec<Option<Hit>> = ray_set
            .iter()
            .map(|r| accel.nearest_hit(r, f32::INFINITY))
            .collect();
        let single = t0.elapsed().as_secs_f64();
        // the same directions as one bundle from the first ray's origin (as eye rays are cast)
        let t0 = Instant::now();
        let dirs: Vec<Vec3> = ray_set.iter().map(|r| r.dir).collect();
        accel.cast_from(ray_set[0].origin, &dirs, true, |_, h| hits.push(h));
        Ok((single, t0.elapsed().as_secs_f64(), hits))
    };
    let (linear_s, linear_b, linear) = run(None)?;
    let tree = Bvh::from_parts(&nodes, &order);
    let (tree_s, tree_b, treed) = run(Some(tree))?;
    let mut wide = vec![WideNode::default(); wide_bvh::nodes_for(n)];
    let used = wide_bvh::widen(&tree, &mut wide).map_err(|e| anyhow::anyhow!("wide BVH: {e:?}"))?;
    let (wide_s, wide_b, widened) = run(Some(tree.with_wide(&wide[..used])))?;
    let same = linear.iter().zip(&treed).filter(|(a, b)| a == b).count();
    let same_wide = linear.iter().zip(&widened).filter(|(a, b)| a == b).count();
    let linear = &linear[..ray_set.len()];
    let hit = linear.iter().filter(|h| h.is_some()).count();
    writeln!(
        out,
        "{n} patches, {} rays ({hit} hit), one thread; BVH of {} nodes built in {:.1} ms",
        ray_set.len(),
        bvh::nodes_for(n),
        build_s * 1e3
    )?;
    writeln!(out)?;
    writeln!(
        out,
        "| engine | single rays/s | µs per ray | bundle rays/s (shared origin) |"
    )?;
    writeln!(out, "|---|---|---|---|")?;
    let m = ray_set.len() as f64;
    for (label, s, b) in [
        ("linear scan", linear_s, linear_b),
        ("BVH", tree_s, tree_b),
        ("BVH, four children a node", wide_s, wide_b),
    ] {
        writeln!(
            out,
            "| {label} | {:.3} M | {:.2} | {:.3} M |",
            m / s / 1e6,
            s / m * 1e6,
            m / b / 1e6
        )?;
    }
    writeln!(out)?;
    writeln!(
        out,
        "BVH / linear speed: {:.1}x single rays, {:.1}x bundles; identical hits: {same} of {}",
        linear_s / tree_s,
        linear_b / tree_b,
        2 * ray_set.len()
    )?;
    writeln!(
        out,
        "four children / two: {:.2}x single rays, {:.2}x bundles; identical hits: {same_wide} of {}",
        tree_s / wide_s,
        tree_b / wide_b,
        2 * ray_set.len()
    )?;
    ensure!(
        same == 2 * ray_set.len() && same_wide == same,
        "the trees and the linear scan disagree on {} and {} rays",
        2 * ray_set.len() - same,
        2 * ray_set.len() - same_wide
    );
    Ok(())
}
