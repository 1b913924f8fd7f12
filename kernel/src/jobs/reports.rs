//! How the tracer's hits become the wire's: a nearest hit as a [`RayHit`], and the window of
//! weighted reports a `TraceRow` answer carries, and the sides the windows of reports name.

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
    /// answer has room, naming its side as [`side_index`] does.
    pub(super) fn report(&mut self, ray: u16, h: &Hit, weight: [f32; 3]) {
        if self.out.total >= self.skip {
            let _ = self.out.hits.push(WeightedHit {
                ray,
                patch: side_index(h, self.patches),
                u: h.u,
                v: h.v,
                weight,
            });
        }
        self.out.total = self.out.total.saturating_add(1);
    }
}

/// The side a report names on the wire: its patch for a front, `patches` + its patch for the
/// back side of a translucent sheet (the only backs the tracer reports;
/// [`Feature::BackSides`](crate::link::Feature::BackSides)).
pub(super) fn side_index(h: &Hit, patches: usize) -> u16 {
    let side = if h.front {
        h.patch as usize
    } else {
        patches + h.patch as usize
    };
    side as u16
}
