//! How the tracer's hits become the wire's: a nearest hit as a [`RayHit`], and the window of
//! weighted reports a `TraceRow` or `Query` answer carries.

use crate::accel::Hit;
use crate::link::message::{RayHit, WeightedHit, WeightedHits};

/// A nearest hit as the wire carries it.
pub(super) fn ray_hit(hit: Option<Hit>) -> Option<RayHit> {
    hit.map(|h| RayHit {
        patch: h.patch as u16,
        front: h.front,
        u: h.u,
        v: h.v,
    })
}

/// The window `skip ..` of a job's weighted reports, and their total.
pub(super) struct Reports<'a> {
    out: &'a mut WeightedHits,
    skip: u32,
    /// The scene's patch count: a back side is reported as `patches` + its patch.
    patches: usize,
}

impl<'a> Reports<'a> {
    pub(super) fn new(out: &'a mut WeightedHits, skip: u32, patches: usize) -> Self {
        out.total = 0;
        out.hits.clear();
        Reports { out, skip, patches }
    }

    /// Counts a report of ray `ray` reaching `h` with `weight`; kept from `skip` on while the
    /// answer has room. The patch it names is the patch for its front, `patches` + the patch
    /// for the back side of a translucent sheet (the only backs the tracer reports;
    /// [`Feature::BackSides`](crate::link::Feature::BackSides)).
    pub(super) fn report(&mut self, ray: u16, h: &Hit, weight: [f32; 3]) {
        if self.out.total >= self.skip {
            let patch = if h.front {
                h.patch as usize
            } else {
                self.patches + h.patch as usize
            };
            let _ = self.out.hits.push(WeightedHit {
                ray,
                patch: patch as u16,
                u: h.u,
                v: h.v,
                weight,
            });
        }
        self.out.total = self.out.total.saturating_add(1);
    }
}
