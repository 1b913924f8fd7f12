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

use crate::accel::{Accelerator, HemiShot, Hit};
use crate::form_row::FormRow;
use crate::geometry::Vec3;
use crate::hemisphere::Hemisphere;
use crate::optics::Optics;
use crate::rotation::Rotation;
use crate::skeleton::Skeleton;
use crate::specular::{spawns, Pending, SpecularStats, Via, Walker};

/// What one or more hemisphere shots did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ShotStats {
    /// Hemisphere rays cast.
    pub rays: u64,
    /// Rays that hit a front side.
    pub front_hits: u64,
    /// Rays blocked by a back side.
    pub back_hits: u64,
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
    /// Specular hits of a hemisphere, parked until it is cast. If more arrive than fit, the
    /// hemisphere is cast again for each further window of them (same results, more rays cast):
    /// the host holds a whole hemisphere, a board a few dozen.
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
#[expect(
    clippy::too_many_arguments,
    reason = "the inputs of one hemisphere shot, §3.4"
)]
pub fn shoot_hemisphere<A: Accelerator, R: FormRow + ?Sized>(
    accel: &mut A,
    hemi: &Hemisphere<'_>,
    optics: &Optics<'_>,
    scratch: &mut TraceScratch<'_>,
    origin: Vec3,
    normal: Vec3,
    spin: f32,
    origin_patch: Option<u32>,
    row: &mut R,
) -> ShotStats {
    let shot = Shot {
        origin,
        normal,
        spin,
        origin_patch,
        want_uv: false,
    };
    shoot(accel, hemi, optics, scratch, &shot, |hit, w, _| {
        if let Some(c) = optics.surface(hit.patch).column_for(hit.front) {
            row.add(c as usize, w);
        }
    })
}

/// The form-factor rows of diffuse-only scenes, a batch of hemispheres at a time
/// ([`Accelerator::cast_hemispheres`], so a pipelined engine need not drain between them):
/// what [`shoot_hemisphere`] adds to each shot's row, into `rows[s]` for shot `s` in the order
/// it would, and each shot's stats in `stats[s]`. Optics with a mirror need the walker shot by
/// shot ([`shoot`]): this is for `!optics.has_specular()` only.
pub fn shoot_diffuse_batch<A: Accelerator, R: FormRow>(
    accel: &mut A,
    hemi: &Hemisphere<'_>,
    optics: &Optics<'_>,
    shots: &[HemiShot],
    stats: &mut [ShotStats],
    rows: &mut [R],
) {
    debug_assert!(!optics.has_specular());
    let rings = hemi.rings();
    accel.cast_hemispheres(shots, hemi, 0..rings.len(), false, |s, j, _k, hit| {
        let st = &mut stats[s];
        st.rays += 1;
        match hit {
            Some(h) if h.front => st.front_hits += 1,
            Some(_) => st.back_hits += 1,
            None => {}
        }
        let column = hit.and_then(|h| optics.surface(h.patch).column_for(h.front));
        if let Some(c) = column {
            rows[s].add(c as usize, [rings[j].delta_ff; 3]);
        }
    });
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

/// The general hemisphere shot: calls `sink(hit, weight, via)` for every ray, direct or through
/// frustums, that reaches the front of a diffuse patch, `weight` per channel being the ray's δD
/// times what the specular path passed on and `via` how it came ([`Via`]). [`shoot_hemisphere`]
/// sums these into a form-factor row; irradiance queries weight them with the radiosity where
/// they land, leaving out what the host's exact direct light covers.
pub fn shoot<A: Accelerator, S: FnMut(&Hit, [f32; 3], Via)>(
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
                sink(&h, [d; 3], Via::DIRECT);
            }
        });
        accel.set_origin_patch(None);
        return stats;
    }

    // The whole hemisphere is cast in one go, every diffuse hit sunk as it comes, and the
    // specular hits parked in the order the engine reports them; then each parked hit is
    // followed through the walker. When `pending` cannot hold every specular hit (a board's
    // small buffer), the hemisphere is cast again for the next window of them, in the same
    // order: the sink sees the same calls in the same order whatever the buffer's size, so a
    // board's rows equal the host's bit for bit (only the engine's work grows).
    let (pending, mut walker) = scratch.split(optics, hemi, want_uv);
    let uv = want_uv || optics.needs_uv();
    // specular hits followed so far (in report order), and rings before the window's first
    let mut done = 0usize;
    let mut from_ring = 0usize;
    let mut before = 0usize;
    let mut first_cast = true;
    loop {
        let mut parked = 0usize;
        // specular hits seen by this cast, in rings `from_ring..`
        let mut seen = before;
        // where the next window starts: its ring, and the specular hits before that ring
        let mut next: Option<(usize, usize)> = None;
        let mut ring_now = usize::MAX;
        let mut seen_at_ring = before;
        accel.set_origin_patch(origin_patch);
        accel.cast_rings(
            origin,
            &rot,
            hemi,
            from_ring..rings.len(),
            uv,
            |j, k, hit| {
                if j != ring_now {
                    ring_now = j;
                    seen_at_ring = seen;
                }
                if first_cast {
                    count(&mut stats, &hit);
                }
                let Some(h) = hit else { return };
                if first_cast && diffuse(&h) {
                    let d = rings[j].delta_ff;
                    sink(&h, [d; 3], Via::DIRECT);
                }
                if spawns(optics, &h) {
                    if seen >= done {
                        match pending.get_mut(parked) {
                            Some(p) => {
                                *p = Pending {
                                    tag: j as u32,
                                    k,
                                    hit: h,
                                };
                                parked += 1;
                            }
                            None => {
                                if next.is_none() {
                                    next = Some((j, seen_at_ring));
                                }
                            }
                        }
                    }
                    seen += 1;
                }
            },
        );
        accel.set_origin_patch(None);
        first_cast = false;
        for p in pending.iter().take(parked) {
            let j = p.tag as usize;
            let delta = rings[j].delta_ff;
            let dir = accel.rotate(&rot, hemi.direction(j, p.k));
            walker.follow(accel, origin, dir, &p.hit, delta, &mut |hh, w, via| {
                sink(hh, w.map(|x| x * delta), via)
            });
        }
        done += parked;
        match next {
            Some((ring, hits_before)) if parked > 0 => {
                walker.stats.recasts += 1;
                from_ring = ring;
                before = hits_before;
            }
            Some(_) => {
                // no room at all: the hits not followed are lost, and counted
                walker.stats.overflows += (seen - done) as u64;
                break;
            }
            None => break,
        }
    }
    stats.specular = walker.stats;
    stats
}
