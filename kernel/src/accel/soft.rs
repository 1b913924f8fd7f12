//! The software accelerator: f32 arithmetic on whatever CPU runs the kernel.
//!
//! Hemisphere rays share their origin and come from a fixed direction table, and the engine
//! exploits both (the general-purpose casters it is compared with cannot):
//!
//! 1. Instead of turning 10⁴ rays onto the normal, it turns the few patch vertices the other way
//!    (`Rotation::invert`): the same rotation, applied where it is cheap.
//! 2. Seen from the shared origin a convex polygon is the pyramid spanned by its edges; a ray hits
//!    it iff `d · (a × b) ≥ 0` for every edge (a,b) of its vertices relative to the origin (signs
//!    flipped for a polygon seen from behind). No plane intersection is needed to decide a hit,
//!    and two patches sharing an edge use exactly negated edge normals, so a ray through the edge
//!    hits one of them: closed boxes do not leak.
//! 3. Each patch gets a bounding cone (axis c, half-angle α). Ring j only meets the cone over an
//!    azimuth interval, from `sinθ_j ρ_c cos(φ−φ_c) + cosθ_j c_z ≥ cos α`; only rays in that
//!    interval are tested against the patch. Work then grows with the solid angle the patches
//!    cover, not with rays × patches.

use super::{Accelerator, Hit, Ray};
use crate::geometry::{Polygon, Vec3};
use crate::hemisphere::{Hemisphere, Ring};
use crate::patch::Patch;
use crate::rotation::Rotation;
use core::ops::Range;

/// Per-patch data for one origin and frame, rebuilt for every hemisphere.
#[derive(Clone, Copy, Debug, Default)]
pub struct LocalPatch {
    edges: [Vec3; 4],
    sides: u8,
    normal: Vec3,
    /// n · (v0 − origin): the signed distance of the plane (its sign says which side we are on).
    h: f32,
    axis: Vec3,
    cos_alpha: f32,
    axis_rho: f32,
    axis_phi: f32,
    /// The cone is too wide to bound usefully: test every ray.
    full: bool,
    active: bool,
}

impl LocalPatch {
    /// Sets up `poly` as seen from `origin`, in the frame of `rot` (identity frame: pass a
    /// rotation onto +z).
    pub fn setup(poly: &Polygon, origin: Vec3, rot: &Rotation) -> LocalPatch {
        let mut lp = LocalPatch::default();
        let h = poly.normal.dot(poly.v[0] - origin);
        let sides = poly.sides as usize;
        let mut local = [Vec3::ZERO; 4];
        let mut scale = 0.0f32;
        for (l, v) in local.iter_mut().zip(poly.v.iter()).take(sides) {
            *l = rot.invert(*v - origin);
            scale = scale.max(l.length());
        }
        // An origin in the patch's plane (its own patch, coplanar neighbours) can only graze it.
        if !(h.abs() > 1e-6 * scale) {
            return lp;
        }
        let s = if h > 0.0 { 1.0 } else { -1.0 };
        for i in 0..sides {
            lp.edges[i] = local[i].cross(local[(i + 1) % sides]) * s;
        }
        lp.sides = poly.sides;
        lp.normal = rot.invert(poly.normal);
        lp.h = h;
        lp.active = true;
        // Bounding cone: a convex polygon lies in the cone of its vertex directions when α < 90°.
        let mut sum = Vec3::ZERO;
        for l in local.iter().take(sides) {
            sum += *l / l.length();
        }
        match sum.try_normalize() {
            Some(axis) => {
                let mut cos_alpha = 1.0f32;
                for l in local.iter().take(sides) {
                    cos_alpha = cos_alpha.min(axis.dot(*l / l.length()));
                }
                // widen a little so that rounding never culls a ray the exact test would accept
                cos_alpha -= 1e-4;
                lp.axis = axis;
                lp.cos_alpha = cos_alpha;
                lp.axis_rho = libm::sqrtf(axis.x * axis.x + axis.y * axis.y);
                lp.axis_phi = libm::atan2f(axis.y, axis.x);
                lp.full = cos_alpha < 0.05;
                if !lp.full && axis.z < 0.0 {
                    // entirely below the horizon: polar angle of the cone's top edge > 90°
                    let sin_alpha = libm::sqrtf((1.0 - cos_alpha * cos_alpha).max(0.0));
                    // max z over the cone = cos(θc − α) = cz cosα + ρ sinα
                    if axis.z * cos_alpha + lp.axis_rho * sin_alpha < -1e-4 {
                        lp.active = false;
                    }
                }
            }
            None => lp.full = true,
        }
        lp
    }

    /// Whether the patch can be hit at all from this origin.
    pub fn is_active(&self) -> bool {
        self.active
    }

    /// The distance to the patch along the local direction `d`, if the ray hits it.
    #[inline(always)]
    pub fn hit(&self, d: Vec3) -> Option<f32> {
        for e in &self.edges[..self.sides as usize] {
            if d.dot(*e) < 0.0 {
                return None;
            }
        }
        let t = self.h / self.normal.dot(d);
        if t > 0.0 && t < f32::INFINITY {
            Some(t)
        } else {
            None
        }
    }

    /// Which side the rays from this origin see.
    pub fn front(&self) -> bool {
        self.h < 0.0
    }

    /// The indices k of ring `ring` whose rays may hit the patch, as a (possibly wrapping) range
    /// `start..start+len` modulo N_j; `None` when the ring misses the cone.
    fn ring_interval(&self, ring: &Ring, j: usize) -> Option<(i64, i64)> {
        let n = ring.count as i64;
        if self.full || j == 0 {
            return Some((0, n));
        }
        let best = ring.sin_theta * self.axis_rho + ring.cos_theta * self.axis.z;
        if best < self.cos_alpha {
            return None;
        }
        if self.axis_rho < 1e-6 {
            return Some((0, n));
        }
        let q = (self.cos_alpha - ring.cos_theta * self.axis.z) / (ring.sin_theta * self.axis_rho);
        if q <= -1.0 {
            return Some((0, n));
        }
        let half = libm::acosf(q.min(1.0)) + 1e-4;
        let dphi = core::f32::consts::TAU / n as f32;
        let lo = libm::ceilf((self.axis_phi - half) / dphi - 0.5) as i64;
        let hi = libm::floorf((self.axis_phi + half) / dphi - 0.5) as i64;
        if hi < lo {
            return None;
        }
        let len = (hi - lo + 1).min(n);
        Some((lo.rem_euclid(n), len))
    }
}

/// Scratch memory the software accelerator works in; sized by the caller so that the kernel
/// never allocates (the firmware hands it static buffers, the host a `Vec` per thread).
pub struct SoftScratch<'s> {
    /// One entry per loaded patch.
    pub local: &'s mut [LocalPatch],
    /// At least the largest ring's ray count (4R).
    pub best_t: &'s mut [f32],
    /// Same length as `best_t`.
    pub best_id: &'s mut [u32],
}

/// The f32 ray engine over a slice of patches.
pub struct SoftAccelerator<'p, 's> {
    patches: &'p [Patch],
    scratch: SoftScratch<'s>,
}

const NO_HIT: u32 = u32::MAX;

/// Why a software accelerator could not be set up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SoftError {
    /// The scratch has fewer `local` entries than there are patches.
    ScratchTooSmall,
}

impl<'p, 's> SoftAccelerator<'p, 's> {
    /// An engine over `patches` (the patch memory) working in `scratch`.
    pub fn new(patches: &'p [Patch], scratch: SoftScratch<'s>) -> Result<Self, SoftError> {
        if scratch.local.len() < patches.len() || scratch.best_t.len() != scratch.best_id.len() {
            return Err(SoftError::ScratchTooSmall);
        }
        Ok(SoftAccelerator { patches, scratch })
    }

    /// The loaded patches.
    pub fn patches(&self) -> &'p [Patch] {
        self.patches
    }

    fn hit_with_uv(&self, id: u32, t: f32, origin: Vec3, dir: Vec3, want_uv: bool) -> Hit {
        let lp = &self.scratch.local[id as usize];
        let (u, v) = if want_uv {
            self.patches[id as usize]
                .as_polygon()
                .uv_of(origin + dir * t)
        } else {
            (0.0, 0.0)
        };
        Hit {
            patch: id,
            t,
            u,
            v,
            front: lp.front(),
        }
    }
}

impl Accelerator for SoftAccelerator<'_, '_> {
    fn rotate(&mut self, rot: &Rotation, d: Vec3) -> Vec3 {
        rot.apply(d)
    }

    fn nearest_hit(&mut self, ray: &Ray, t_max: f32) -> Option<Hit> {
        let frame = Rotation::onto(Vec3::Z);
        let mut best: Option<(u32, f32, bool)> = None;
        let mut best_t = t_max;
        for (i, p) in self.patches.iter().enumerate() {
            let lp = LocalPatch::setup(p.as_polygon(), ray.origin, &frame);
            if !lp.active {
                continue;
            }
            if let Some(t) = lp.hit(ray.dir) {
                if t < best_t {
                    best_t = t;
                    best = Some((i as u32, t, lp.front()));
                }
            }
        }
        best.map(|(id, t, front)| {
            let (u, v) = self.patches[id as usize]
                .as_polygon()
                .uv_of(ray.origin + ray.dir * t);
            Hit {
                patch: id,
                t,
                u,
                v,
                front,
            }
        })
    }

    fn cast_rings<F: FnMut(usize, u32, Option<Hit>)>(
        &mut self,
        origin: Vec3,
        rot: &Rotation,
        hemi: &Hemisphere<'_>,
        rings: Range<usize>,
        want_uv: bool,
        mut sink: F,
    ) {
        let n_patches = self.patches.len();
        for (lp, p) in self.scratch.local.iter_mut().zip(self.patches.iter()) {
            *lp = LocalPatch::setup(p.as_polygon(), origin, rot);
        }
        let max_ring = hemi
            .rings()
            .iter()
            .map(|r| r.count as usize)
            .max()
            .unwrap_or(0);
        if max_ring > self.scratch.best_t.len() {
            // Scratch too small for this table: fall back to the ray-by-ray path, which is
            // slower but needs no scratch (never a silent wrong answer).
            for j in rings {
                let ring = hemi.rings()[j];
                for k in 0..ring.count {
                    let dir = rot.apply(hemi.direction(j, k));
                    sink(j, k, self.nearest_hit(&Ray { origin, dir }, f32::INFINITY));
                }
            }
            return;
        }
        for j in rings {
            let ring = hemi.rings()[j];
            let n = ring.count as usize;
            let best_t = &mut self.scratch.best_t[..n];
            let best_id = &mut self.scratch.best_id[..n];
            best_t.fill(f32::INFINITY);
            best_id.fill(NO_HIT);
            let quarter_n = (ring.count / 4).max(1) as i64;
            for (id, lp) in self.scratch.local[..n_patches].iter().enumerate() {
                if !lp.active {
                    continue;
                }
                let Some((start, len)) = lp.ring_interval(&ring, j) else {
                    continue;
                };
                if j == 0 {
                    if let Some(t) = lp.hit(Vec3::Z) {
                        if t < best_t[0] {
                            best_t[0] = t;
                            best_id[0] = id as u32;
                        }
                    }
                    continue;
                }
                // walk k = start.. with the quarter index kept incrementally (no division per ray)
                let mut q = start / quarter_n;
                let mut r = start % quarter_n;
                let mut k = start as usize;
                for _ in 0..len {
                    let (c, s) = hemi.azimuth_in_quarter(&ring, q as u32, r as u32);
                    let d = Vec3::new(ring.sin_theta * c, ring.sin_theta * s, ring.cos_theta);
                    if let Some(t) = lp.hit(d) {
                        if t < best_t[k] {
                            best_t[k] = t;
                            best_id[k] = id as u32;
                        }
                    }
                    r += 1;
                    k += 1;
                    if r == quarter_n {
                        r = 0;
                        q += 1;
                        if q == 4 {
                            q = 0;
                            k = 0;
                        }
                    }
                }
            }
            for k in 0..n {
                let id = self.scratch.best_id[k];
                if id == NO_HIT {
                    sink(j, k as u32, None);
                } else {
                    let t = self.scratch.best_t[k];
                    let dir = if want_uv {
                        rot.apply(hemi.direction(j, k as u32))
                    } else {
                        Vec3::ZERO
                    };
                    sink(
                        j,
                        k as u32,
                        Some(self.hit_with_uv(id, t, origin, dir, want_uv)),
                    );
                }
            }
        }
    }
}
