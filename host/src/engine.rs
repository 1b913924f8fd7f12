//! Ray engines as the host runs them: one per worker thread, each owning its working memory.
//!
//! Pass 1, pass 2 and the queries are generic over [`Accelerator`]; this module provides the
//! software engine in that form. Other backends (the HDL model, a board over the link) are
//! plugged in the same way: anything that implements `Accelerator` and can be made per thread.

use hemi_kernel::accel::soft::{LocalPatch, SoftAccelerator, SoftScratch};
use hemi_kernel::accel::{Accelerator, Hit, Ray};
use hemi_kernel::geometry::Vec3;
use hemi_kernel::hemisphere::{Hemisphere, MAX_CIRCLES};
use hemi_kernel::patch::Patch;
use hemi_kernel::rotation::Rotation;
use std::ops::Range;

/// The kernel's f32 engine with its scratch memory, sized for any hemisphere table.
pub struct SoftEngine<'p> {
    patches: &'p [Patch],
    local: Vec<LocalPatch>,
    best_t: Vec<f32>,
    best_id: Vec<u32>,
}

impl<'p> SoftEngine<'p> {
    /// An engine over `patches` (its patch memory).
    pub fn new(patches: &'p [Patch]) -> Self {
        let max_ring = 4 * MAX_CIRCLES;
        SoftEngine {
            patches,
            local: vec![LocalPatch::default(); patches.len()],
            best_t: vec![0.0; max_ring],
            best_id: vec![0; max_ring],
        }
    }

    fn accel(&mut self) -> SoftAccelerator<'p, '_> {
        SoftAccelerator::new(
            self.patches,
            SoftScratch {
                local: &mut self.local,
                best_t: &mut self.best_t,
                best_id: &mut self.best_id,
            },
        )
        .expect("scratch is sized for the patches and the largest ring")
    }
}

impl Accelerator for SoftEngine<'_> {
    fn rotate(&mut self, rot: &Rotation, d: Vec3) -> Vec3 {
        rot.apply(d)
    }
    fn nearest_hit(&mut self, ray: &Ray, t_max: f32) -> Option<Hit> {
        self.accel().nearest_hit(ray, t_max)
    }
    fn cast_from<F: FnMut(usize, Option<Hit>)>(
        &mut self,
        origin: Vec3,
        dirs: &[Vec3],
        want_uv: bool,
        sink: F,
    ) {
        self.accel().cast_from(origin, dirs, want_uv, sink)
    }
    fn cast_rings<F: FnMut(usize, u32, Option<Hit>)>(
        &mut self,
        origin: Vec3,
        rot: &Rotation,
        hemi: &Hemisphere<'_>,
        rings: Range<usize>,
        want_uv: bool,
        sink: F,
    ) {
        self.accel()
            .cast_rings(origin, rot, hemi, rings, want_uv, sink)
    }
}
