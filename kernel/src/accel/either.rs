//! One of two engines behind one type: what lets a board that has two accelerators (the soft
//! engine as its fallback, and the hardware or its model) compile the tracer, the walker and the
//! pixel loop once instead of once per engine. On a 128 KiB flash that second copy is what does
//! not fit. The engine is chosen per job; the dispatch costs a branch per call into the engine,
//! and its calls are per ring or per bundle, not per ray.

use super::{Accelerator, HemiShot, Hit, Ray};
use crate::geometry::Vec3;
use crate::hemisphere::Hemisphere;
use crate::rotation::Rotation;
use core::ops::Range;

/// Either engine `A` or engine `B`, borrowed for one job.
pub enum Either<'e, A, B> {
    /// The first engine.
    Left(&'e mut A),
    /// The second engine.
    Right(&'e mut B),
}

impl<A: Accelerator, B: Accelerator> Accelerator for Either<'_, A, B> {
    fn rotate(&mut self, rot: &Rotation, d: Vec3) -> Vec3 {
        match self {
            Either::Left(a) => a.rotate(rot, d),
            Either::Right(b) => b.rotate(rot, d),
        }
    }
    fn set_origin_patch(&mut self, patch: Option<u32>) {
        match self {
            Either::Left(a) => a.set_origin_patch(patch),
            Either::Right(b) => b.set_origin_patch(patch),
        }
    }
    fn nearest_hit(&mut self, ray: &Ray, t_max: f32) -> Option<Hit> {
        match self {
            Either::Left(a) => a.nearest_hit(ray, t_max),
            Either::Right(b) => b.nearest_hit(ray, t_max),
        }
    }
    fn cast_from<F: FnMut(usize, Option<Hit>)>(
        &mut self,
        origin: Vec3,
        dirs: &[Vec3],
        want_uv: bool,
        sink: F,
    ) {
        match self {
            Either::Left(a) => a.cast_from(origin, dirs, want_uv, sink),
            Either::Right(b) => b.cast_from(origin, dirs, want_uv, sink),
        }
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
        match self {
            Either::Left(a) => a.cast_rings(origin, rot, hemi, rings, want_uv, sink),
            Either::Right(b) => b.cast_rings(origin, rot, hemi, rings, want_uv, sink),
        }
    }
    fn cast_hemispheres<F: FnMut(usize, usize, u32, Option<Hit>)>(
        &mut self,
        shots: &[HemiShot],
        hemi: &Hemisphere<'_>,
        rings: Range<usize>,
        want_uv: bool,
        sink: F,
    ) {
        match self {
            Either::Left(a) => a.cast_hemispheres(shots, hemi, rings, want_uv, sink),
            Either::Right(b) => b.cast_hemispheres(shots, hemi, rings, want_uv, sink),
        }
    }
}
