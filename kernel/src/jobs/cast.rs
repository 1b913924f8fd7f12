//! The single-ray job, `Cast`: the nearest hit of each ray, with its distance (the host's
//! shadow rays to the lamps and through mirrors, and `hemi trace`).

use heapless::Vec;

use super::engine::{Engine, Work};
use super::platform::Platform;
use super::provider::{AccelJob, AccelProvider};
use crate::accel::{Accelerator, Ray};
use crate::geometry::Vec3;
use crate::link::message::{CastHit, ErrorCode, Response, MAX_CAST};

impl<P: AccelProvider, T: Platform> Engine<P, T> {
    /// The nearest hit of each of `rays`. Not inlined into the request dispatch: its answer
    /// then only takes stack while it runs.
    #[inline(never)]
    pub(super) fn cast(&mut self, rays: &[(Vec3, Vec3)]) -> Result<(Response, Work), ErrorCode> {
        self.ready()?;
        if rays.is_empty() {
            return Err(ErrorCode::OutOfRange);
        }
        if rays.len() > MAX_CAST {
            return Err(ErrorCode::TooLong);
        }
        if rays
            .iter()
            .any(|(o, d)| !o.is_finite() || !d.is_finite() || d.try_normalize().is_none())
        {
            return Err(ErrorCode::OutOfRange);
        }
        let mut hits = Vec::new();
        self.provider.run(
            &self.patches,
            CastJob {
                rays,
                hits: &mut hits,
            },
        );
        let work = Work {
            rays: rays.len() as u64,
            ..Work::default()
        };
        Ok((Response::Nearest(hits), work))
    }
}

struct CastJob<'a> {
    rays: &'a [(Vec3, Vec3)],
    hits: &'a mut Vec<Option<CastHit>, MAX_CAST>,
}

impl AccelJob for CastJob<'_> {
    type Out = ();
    fn run<A: Accelerator>(self, accel: &mut A) {
        for &(origin, dir) in self.rays {
            let hit = accel.nearest_hit(&Ray { origin, dir }, f32::INFINITY);
            let _ = self.hits.push(hit.map(|h| CastHit {
                patch: h.patch as u16,
                front: h.front,
                t: h.t,
                u: h.u,
                v: h.v,
            }));
        }
    }
}
