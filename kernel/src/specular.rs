//! Indirect transport through specular surfaces (paper §3.3, §5, §6.2): a ray that reaches a
//! reflecting or transmitting patch spawns a frustum; the frustum's rays that reach diffuse
//! patches hand their weight to a sink (an indirect form factor S_ij in pass 1, a specular
//! colour in pass 2), and those that reach specular patches spawn deeper frustums.
//!
//! The weight a frustum ray carries, relative to the primary ray, is the product along its path
//! of each surface's k and each frustum's per-ray weight W_jk, as in the paper's
//!
//! ```text
//! S¹_12 = K⁻¹ Σ_k cos φ_k { k_s3 K'⁻¹ Σ_l cos^{n_3} α_l }                          (§3.3)
//! ```
//!
//! where the outer factor (the primary ray's δD, or a pixel's share) is applied by the caller.
//!
//! **Where the tree stops (§6.5).** A frustum is shot only if the weight it would carry (its
//! largest channel, relative to the primary ray) is at least Δ. Since a frustum of n rays hands
//! each ray about 1/n of its weight, this is the paper's per-ray threshold scaled with the
//! frustum size: Δ/n per ray. Energy conservation bounds the work: the frustums of one
//! generation carry at most k_max^g in total, so at most 1/((1 − k_max) Δ) frustums are ever
//! shot per primary ray, however the mirrors are arranged. A depth limit bounds the bounces of
//! one path (§5), and the stack's capacity the frustums waiting; a frustum cut by either is
//! counted with the weight it carried, never a panic.
//!
//! **The work budget.** With lossless mirrors (k = 1) that bound is infinite, and only the depth
//! limit holds the tree to about max_bounces/Δ frustums: at Δ = 10⁻⁶ a box of glossy mirrors
//! runs for minutes. So one primary ray's tree shoots at most [`TREE_BUDGET`] frustums; what is
//! still waiting then is cut and counted (`over_budget`, with its weight) like any other cut.
//! At the default Δ the bound is 24/0.01 = 2400 frustums, below the budget, so default runs are
//! unchanged.

use crate::accel::{Accelerator, Hit, Ray};
use crate::geometry::Vec3;
use crate::hemisphere::Hemisphere;
use crate::optics::{Optics, Specular};
use crate::rotation::{spin_for_sample, Rotation};
use crate::skeleton::{Frame, Skeleton};

/// Δ of §6.5 when the caller has no better idea: frustums carrying less than 1 % of their
/// primary ray are not shot.
pub const DEFAULT_THRESHOLD: f32 = 0.01;

/// The most frustums one primary ray's tree may shoot (see the module's doc, "the work
/// budget").
pub const TREE_BUDGET: u32 = 4096;

/// What the specular transport of a run did. Weights are in the caller's units (form factor in
/// pass 1, pixel fraction in pass 2), summed over primary rays.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SpecularStats {
    /// Frustums shot.
    pub frustums: u64,
    /// Frustum rays cast.
    pub rays: u64,
    /// Frustums not shot because they would carry less than Δ.
    pub below_threshold: u64,
    /// Weight those frustums would have carried (the truncation error of §6.5).
    pub cut_weight: f64,
    /// Frustums not shot because their path already had the most bounces allowed.
    pub too_deep: u64,
    /// Weight those frustums would have carried.
    pub too_deep_weight: f64,
    /// Frustums (or parked hits) cut because the skeleton stack (or the park) was full.
    pub overflows: u64,
    /// Weight lost with them.
    pub overflow_weight: f64,
    /// Weight of lobe rays that would have gone through their own surface (absorbed).
    pub absorbed_weight: f64,
    /// Weight of frustum rays that left the scene or were blocked by a back side.
    pub escaped_weight: f64,
    /// Frustums cut because their primary ray's tree had shot [`TREE_BUDGET`] frustums.
    pub over_budget: u32,
    /// Weight lost with them.
    pub over_budget_weight: f64,
    /// The deepest the skeleton stack has been.
    pub high_water: u32,
    /// Extra hemisphere casts because the tracer's park of primary specular hits was full (the
    /// same results, more rays: a board's small buffer).
    pub recasts: u32,
}

impl core::ops::AddAssign for SpecularStats {
    fn add_assign(&mut self, o: SpecularStats) {
        self.frustums += o.frustums;
        self.rays += o.rays;
        self.below_threshold += o.below_threshold;
        self.cut_weight += o.cut_weight;
        self.too_deep += o.too_deep;
        self.too_deep_weight += o.too_deep_weight;
        self.overflows += o.overflows;
        self.overflow_weight += o.overflow_weight;
        self.absorbed_weight += o.absorbed_weight;
        self.escaped_weight += o.escaped_weight;
        self.over_budget += o.over_budget;
        self.over_budget_weight += o.over_budget_weight;
        self.high_water = self.high_water.max(o.high_water);
        self.recasts += o.recasts;
    }
}

/// One primary hit on a specular surface, parked until the primary batch is cast (an engine
/// casting a batch cannot shoot frustums in the middle of it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pending {
    /// The caller's tag (ring index in pass 1, ray index in pass 2).
    pub tag: u32,
    /// Second tag (ray index within the ring in pass 1).
    pub k: u32,
    /// The hit.
    pub hit: Hit,
}

impl Pending {
    /// Storage filler.
    pub const EMPTY: Pending = Pending {
        tag: 0,
        k: 0,
        hit: Hit {
            patch: u32::MAX,
            t: 0.0,
            u: 0.0,
            v: 0.0,
            front: false,
        },
    };
}

/// How a reported ray reached its patch: straight from the hemisphere (or the eye), or through
/// specular surfaces. A caller that computes some light by other means (the host's exact
/// direct light from the lamps and from their images in plane mirrors) leaves out the reports
/// that carry that light, and needs to know which came how (a board sends it with each report,
/// protocol 5).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Via {
    /// Specular bounces on the way (0: seen directly).
    pub bounces: u16,
    /// The patch of the last specular bounce (`u32::MAX` when seen directly).
    pub last: u32,
    /// Whether that bounce's frustum was a single ray (a perfect mirror: lobe size 0).
    pub mirror: bool,
}

impl Via {
    /// Seen directly.
    pub const DIRECT: Via = Via {
        bounces: 0,
        last: u32::MAX,
        mirror: false,
    };
}

/// Whether a ray's hit must be followed by frustums: a front hit on a reflector, or a hit on
/// either side of a transmitter.
pub fn spawns(optics: &Optics<'_>, hit: &Hit) -> bool {
    let s = optics.surface(hit.patch);
    (hit.front && s.reflect.is_some()) || s.transmit.is_some()
}

/// The specular walker: the optics, the hemisphere the frustums are cut from, Δ, and the stack.
pub struct Walker<'w, 's> {
    /// Surfaces and lobes.
    pub optics: &'w Optics<'w>,
    /// The hemisphere table (frustum size k = its first k + 1 rings).
    pub hemi: &'w Hemisphere<'w>,
    /// Δ: the smallest relative weight a frustum must carry to be shot.
    pub threshold: f32,
    /// The most specular bounces a path may take (§5: recursion bounded by depth).
    pub max_depth: u16,
    /// The skeleton stack.
    pub skeleton: &'w mut Skeleton<'s>,
    /// Room for one frustum's hits on specular surfaces, pushed as frames when it is done.
    pub parked: &'w mut [Pending],
    /// Whether the sink needs (u,v) of the hits it gets (pass 2 does, pass 1 does not).
    pub want_uv: bool,
    /// What happened so far.
    pub stats: SpecularStats,
}

impl Walker<'_, '_> {
    /// Follows everything a primary ray along `dir` does after `hit`: pushes the frustums the
    /// hit spawns and shoots the whole tree (§6.2), calling `sink(hit, weight, via)` for every
    /// frustum ray that reaches the front of a diffuse patch, `weight` per channel relative to
    /// the primary ray, `via` how it came ([`Via`]). `scale` converts relative weights to the
    /// caller's units for the stats.
    ///
    /// A frustum is shot whole, as rings 0..=k of the hemisphere turned onto its axis, through
    /// the engine's shared-origin ring path (the same one the hemisphere takes, so an engine
    /// culls and batches frustum rays as it does hemisphere rays). Its hits on specular
    /// surfaces are parked and pushed as new frames once the frustum is done; the newest frame
    /// is shot next, so the tree is walked depth first and the stack holds the frustums still
    /// to shoot, deepest on top.
    pub fn follow<A: Accelerator, S: FnMut(&Hit, [f32; 3], Via)>(
        &mut self,
        accel: &mut A,
        origin: Vec3,
        dir: Vec3,
        hit: &Hit,
        scale: f32,
        sink: &mut S,
    ) {
        self.spawn(origin + dir * hit.t, dir, hit, [1.0; 3], 0, scale);
        let mut shot = 0u32;
        while let Some(f) = self.skeleton.top_mut().copied() {
            self.skeleton.pop();
            if shot >= TREE_BUDGET {
                self.stats.over_budget += 1;
                self.stats.over_budget_weight += (max3(f.weight) * scale) as f64;
                continue;
            }
            shot += 1;
            let lobe = f.lobe;
            // the side the rays must leave towards, in the frustum's own frame: one test per ray
            // on the stored direction, no rotation
            let side = f.rot.invert(f.side);
            let mut parked = 0usize;
            let want_uv = self.want_uv || self.optics.needs_uv();
            let Walker {
                optics,
                hemi,
                stats,
                parked: park,
                ..
            } = self;
            let mut on_hit = |j: usize, k: u32, hit: Option<Hit>| {
                stats.rays += 1;
                let w = optics.weight(&lobe, j);
                let weight = f.weight.map(|c| c * w);
                if hemi.direction(j, k).dot(side) <= 0.0 {
                    stats.absorbed_weight += (max3(weight) * scale) as f64;
                    return;
                }
                let Some(hit) = hit else {
                    stats.escaped_weight += (max3(weight) * scale) as f64;
                    return;
                };
                if optics.surface(hit.patch).column_for(hit.front).is_some() {
                    let via = Via {
                        bounces: f.depth,
                        last: f.from,
                        mirror: lobe.size == 0,
                    };
                    sink(&hit, weight, via);
                }
                if spawns(optics, &hit) {
                    match park.get_mut(parked) {
                        Some(p) => {
                            *p = Pending {
                                tag: j as u32,
                                k,
                                hit,
                            };
                            parked += 1;
                        }
                        None => {
                            stats.overflows += 1;
                            stats.overflow_weight += (max3(weight) * scale) as f64;
                        }
                    }
                } else if !hit.front {
                    stats.escaped_weight += (max3(weight) * scale) as f64;
                }
            };
            accel.set_origin_patch(Some(f.from));
            if lobe.size == 0 {
                // a mirror: one ray, no ring set-up
                let d = accel.rotate(&f.rot, Vec3::Z);
                let hit = accel.nearest_hit(
                    &Ray {
                        origin: f.origin,
                        dir: d,
                    },
                    f32::INFINITY,
                );
                on_hit(0, 0, hit);
            } else {
                accel.cast_rings(
                    f.origin,
                    &f.rot,
                    hemi,
                    0..lobe.size as usize + 1,
                    want_uv,
                    &mut on_hit,
                );
            }
            accel.set_origin_patch(None);
            for i in 0..parked {
                let p = self.parked[i];
                let j = p.tag as usize;
                let w = self.optics.weight(&lobe, j);
                let d = accel.rotate(&f.rot, self.hemi.direction(j, p.k));
                self.spawn(
                    f.origin + d * p.hit.t,
                    d,
                    &p.hit,
                    f.weight.map(|c| c * w),
                    f.depth,
                    scale,
                );
            }
        }
        self.stats.high_water = self.stats.high_water.max(self.skeleton.high_water() as u32);
    }

    /// Pushes the frustums a ray along `dir` carrying `weight` spawns at `hit` (at `point`).
    fn spawn(
        &mut self,
        point: Vec3,
        dir: Vec3,
        hit: &Hit,
        weight: [f32; 3],
        depth: u16,
        scale: f32,
    ) {
        let surface = self.optics.surface(hit.patch);
        let Some(patch) = self.optics.patches().get(hit.patch as usize) else {
            return;
        };
        let n = patch.normal_at(hit.u, hit.v);
        if hit.front {
            if let Some(r) = surface.reflect {
                // mirror direction about the front normal: d − 2 (d·n) n
                let axis = dir - n * (2.0 * dir.dot(n));
                self.push(point, axis, n, hit.patch, &r, weight, depth, scale);
            }
        }
        if let Some(t) = surface.transmit {
            let side = if hit.front { -n } else { n };
            self.push(point, dir, side, hit.patch, &t, weight, depth, scale);
        }
    }

    #[expect(
        clippy::too_many_arguments,
        reason = "one frame's fields, named at the one call"
    )]
    fn push(
        &mut self,
        origin: Vec3,
        axis: Vec3,
        side: Vec3,
        from: u32,
        spec: &Specular,
        weight: [f32; 3],
        depth: u16,
        scale: f32,
    ) {
        let w = [0, 1, 2].map(|c| weight[c] * spec.k[c]);
        let carried = max3(w);
        if carried <= 0.0 {
            return;
        }
        if carried < self.threshold {
            self.stats.below_threshold += 1;
            self.stats.cut_weight += (carried * scale) as f64;
            return;
        }
        if depth >= self.max_depth {
            self.stats.too_deep += 1;
            self.stats.too_deep_weight += (carried * scale) as f64;
            return;
        }
        let Some(axis) = axis.try_normalize() else {
            return;
        };
        let frame = Frame {
            origin,
            // each frustum turned by its own golden-ratio spin, so frustums of neighbouring
            // primary rays do not line their rings up
            rot: Rotation::onto_spun(axis, spin_for_sample(self.stats.frustums as u32)),
            side,
            from,
            lobe: spec.lobe,
            weight: w,
            depth: depth.saturating_add(1),
        };
        match self.skeleton.push(frame) {
            Ok(()) => self.stats.frustums += 1,
            Err(_) => {
                self.stats.overflows += 1;
                self.stats.overflow_weight += (carried * scale) as f64;
            }
        }
    }
}

fn max3(w: [f32; 3]) -> f32 {
    w[0].max(w[1]).max(w[2])
}
