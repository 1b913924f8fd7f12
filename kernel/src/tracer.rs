//! Pass 1's inner loop (paper §3.1, §3.3, §3.4): place the hemisphere on a sample point and add
//! each ray's delta form factor to the diffuse patch it reaches, directly or through specular
//! surfaces.
//!
//! A ray that reaches the front of a diffuse patch j adds δD of its ring to F_iq,j (the direct
//! form factor D_ij). A ray that reaches a reflecting (or transmitting) patch spawns frustums
//! whose rays add their weighted share of δD to the diffuse patches they reach (the indirect
//! form factor S_ij, per channel because k_r is). A ray that reaches a back side is blocked
//! (unless the patch transmits diffusely, k_y: then its back side has a column of its own), and
//! a ray that leaves the scene adds nothing, so a row sums to the fraction of the hemisphere
//! that sees diffuse sides, directly or in mirrors.

use crate::accel::{Accelerator, Hit, Ray};
use crate::geometry::Vec3;
use crate::hemisphere::Hemisphere;
use crate::optics::Optics;
use crate::rotation::Rotation;
use crate::skeleton::Skeleton;
use crate::specular::{spawns, Pending, SpecularStats, Walker};

/// What one or more hemisphere shots did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ShotStats {
    /// Hemisphere rays cast.
    pub rays: u32,
    /// Rays that hit a front side.
    pub front_hits: u32,
    /// Rays blocked by a back side.
    pub back_hits: u32,
    /// The frustums the specular hits spawned.
    pub specular: SpecularStats,
}

impl core::ops::AddAssign for ShotStats {
    fn add_assign(&mut self, o: ShotStats) {
        self.rays += o.rays;
        self.front_hits += o.front_hits;
        self.back_hits += o.back_hits;
        self.specular += o.specular;
    }
}

/// The tracer's working memory, in caller storage (static SRAM on the board).
pub struct TraceScratch<'s> {
    /// Specular hits of one batch of rings, parked until the batch is cast. A batch holds as many
    /// whole rings as fit; a ring larger than this is cast ray by ray.
    pub pending: &'s mut [Pending],
    /// Room for the specular hits of one frustum, turned into frames when it is shot.
    pub parked: &'s mut [Pending],
    /// The skeleton stack of frustums (§6.2); its capacity bounds the frustums waiting.
    pub skeleton: Skeleton<'s>,
    /// Δ of §6.5 (see [`crate::specular`]).
    pub threshold: f32,
    /// The most specular bounces a path may take.
    pub max_depth: u16,
}

impl<'s> TraceScratch<'s> {
    /// The pending buffer, and a specular walker over the rest of the scratch: what a pass that
    /// parks primary hits and then follows them needs (pass 1 and pass 2 alike).
    pub fn split<'w>(
        &'w mut self,
        optics: &'w Optics<'w>,
        hemi: &'w Hemisphere<'w>,
        want_uv: bool,
    ) -> (&'w mut [Pending], Walker<'w, 's>) {
        let walker = Walker {
            optics,
            hemi,
            threshold: self.threshold,
            max_depth: self.max_depth,
            skeleton: &mut self.skeleton,
            parked: self.parked,
            want_uv,
            stats: SpecularStats::default(),
        };
        (self.pending, walker)
    }
}

/// Shoots the hemisphere `hemi` from `origin` around `normal`, spun by `spin` about the normal
/// (see [`crate::rotation::spin_for_sample`]), and accumulates the element-to-patch form factors
/// F_iq,j per channel into `row` (one entry per diffuse column of `optics`; the caller zeroes
/// it). `origin_patch` is the patch the sample point lies on, which the hemisphere does not see
/// directly (F_ii = 0); it may see itself in a mirror.
#[allow(
    clippy::too_many_arguments,
    reason = "the inputs of one hemisphere shot, §3.4"
)]
pub fn shoot_hemisphere<A: Accelerator>(
    accel: &mut A,
    hemi: &Hemisphere<'_>,
    optics: &Optics<'_>,
    scratch: &mut TraceScratch<'_>,
    origin: Vec3,
    normal: Vec3,
    spin: f32,
    origin_patch: Option<u32>,
    row: &mut [[f32; 3]],
) -> ShotStats {
    let shot = Shot {
        origin,
        normal,
        spin,
        origin_patch,
        want_uv: false,
    };
    shoot(accel, hemi, optics, scratch, &shot, |hit, w| {
        if let Some(slot) = optics
            .surface(hit.patch)
            .column_for(hit.front)
            .and_then(|c| row.get_mut(c as usize))
        {
            for c in 0..3 {
                slot[c] += w[c];
            }
        }
    })
}

/// Where and how a hemisphere is placed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shot {
    /// The sample point.
    pub origin: Vec3,
    /// The surface normal there (the hemisphere's axis).
    pub normal: Vec3,
    /// Spin ψ about the normal.
    pub spin: f32,
    /// The patch the point lies on (not seen directly), if any.
    pub origin_patch: Option<u32>,
    /// Whether the sink needs (u,v) of direct hits.
    pub want_uv: bool,
}

/// The general hemisphere shot: calls `sink(hit, weight)` for every ray, direct or through
/// frustums, that reaches the front of a diffuse patch, `weight` per channel being the ray's δD
/// times what the specular path passed on. [`shoot_hemisphere`] sums these into a form-factor
/// row; irradiance queries weight them with the radiosity where they land.
pub fn shoot<A: Accelerator, S: FnMut(&Hit, [f32; 3])>(
    accel: &mut A,
    hemi: &Hemisphere<'_>,
    optics: &Optics<'_>,
    scratch: &mut TraceScratch<'_>,
    shot: &Shot,
    mut sink: S,
) -> ShotStats {
    let Shot {
        origin,
        normal,
        spin,
        origin_patch,
        want_uv,
    } = *shot;
    let rot = Rotation::onto_spun(normal, spin);
    let rings = hemi.rings();
    let mut stats = ShotStats::default();
    let diffuse = |hit: &Hit| optics.surface(hit.patch).column_for(hit.front).is_some();
    let count = |stats: &mut ShotStats, hit: &Option<Hit>| {
        stats.rays += 1;
        match hit {
            Some(h) if h.front => stats.front_hits += 1,
            Some(_) => stats.back_hits += 1,
            None => {}
        }
    };

    if !optics.has_specular() {
        accel.set_origin_patch(origin_patch);
        accel.cast_rings(origin, &rot, hemi, 0..rings.len(), want_uv, |j, _k, hit| {
            count(&mut stats, &hit);
            if let Some(h) = hit.filter(diffuse) {
                let d = rings[j].delta_ff;
                sink(&h, [d; 3]);
            }
        });
        accel.set_origin_patch(None);
        return stats;
    }

    let (pending, mut walker) = scratch.split(optics, hemi, want_uv);
    let mut start = 0;
    while start < rings.len() {
        // as many whole rings as the pending buffer holds
        let mut end = start;
        let mut fits = 0usize;
        while end < rings.len() && fits + rings[end].count as usize <= pending.len() {
            fits += rings[end].count as usize;
            end += 1;
        }
        accel.set_origin_patch(origin_patch);
        let mut parked = 0usize;
        if end == start {
            // a ring larger than the buffer: ray by ray, each followed at once
            end = start + 1;
            let delta = rings[start].delta_ff;
            for k in 0..rings[start].count {
                accel.set_origin_patch(origin_patch);
                let dir = accel.rotate(&rot, hemi.direction(start, k));
                let hit = accel.nearest_hit(&Ray { origin, dir }, f32::INFINITY);
                count(&mut stats, &hit);
                if let Some(h) = hit {
                    if diffuse(&h) {
                        sink(&h, [delta; 3]);
                    }
                    if spawns(optics, &h) {
                        walker.follow(accel, origin, dir, &h, delta, &mut |hh, w| {
                            sink(hh, w.map(|x| x * delta))
                        });
                    }
                }
            }
        } else {
            let uv = want_uv || optics.needs_uv();
            accel.cast_rings(origin, &rot, hemi, start..end, uv, |j, k, hit| {
                count(&mut stats, &hit);
                if let Some(h) = hit {
                    if diffuse(&h) {
                        let d = rings[j].delta_ff;
                        sink(&h, [d; 3]);
                    }
                    if spawns(optics, &h) {
                        if let Some(p) = pending.get_mut(parked) {
                            *p = Pending {
                                tag: j as u32,
                                k,
                                hit: h,
                            };
                            parked += 1;
                        }
                    }
                }
            });
        }
        accel.set_origin_patch(None);
        for p in pending.iter().take(parked) {
            let j = p.tag as usize;
            let delta = rings[j].delta_ff;
            let dir = accel.rotate(&rot, hemi.direction(j, p.k));
            walker.follow(accel, origin, dir, &p.hit, delta, &mut |hh, w| {
                sink(hh, w.map(|x| x * delta))
            });
        }
        start = end;
    }
    stats.specular = walker.stats;
    stats
}
