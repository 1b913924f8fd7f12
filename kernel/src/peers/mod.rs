//! Peer methods for pass 1, in the same kernel and over the same [`Accelerator`], so that they
//! can be compared with the paper's hemisphere at equal rays (docs/ACCURACY.md):
//!
//! - [`hemicube`]: Cohen & Greenberg 1985, the baseline the paper replaces (§1, §9);
//! - [`monte_carlo`]: cosine-weighted random directions, stratified or not.
//!
//! Both produce the same per-channel element row F_iq,j as
//! [`crate::tracer::shoot_hemisphere`] (one entry per diffuse column of the optics). They follow
//! direct rays only: a scene with specular surfaces is refused ([`PeerError::Specular`]), since
//! the indirect form factors S_ij of §3.3 are the paper's own contribution and have no
//! counterpart in either peer as published.
//!
//! Rays leave through [`Accelerator::cast_from`] (many directions from one origin), in batches
//! of the caller's scratch size, so every engine runs them with its shared-origin path.

pub mod hemicube;
pub mod monte_carlo;

use crate::accel::{Accelerator, Hit};
use crate::form_row::FormRow;
use crate::geometry::Vec3;
use crate::optics::Optics;
use crate::tracer::ShotStats;

/// Why a peer method cannot shoot.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PeerError {
    /// The scene has specular surfaces; the peers compute direct form factors only.
    Specular,
    /// The direction scratch is empty.
    NoScratch,
    /// The method's parameters are out of range (a hemicube resolution that is odd or 0, zero
    /// Monte Carlo rays).
    BadParameters,
}

/// Where a peer shot is placed (the same inputs as the hemisphere shot, paper §3.4).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    /// The sample point.
    pub origin: Vec3,
    /// The surface normal there.
    pub normal: Vec3,
    /// Spin about the normal (the hemisphere's per-sample spin, so the peers' aliasing is
    /// decorrelated between sample points in the same way).
    pub spin: f32,
    /// The patch the sample lies on, never counted as hit.
    pub origin_patch: Option<u32>,
}

/// Casts `total` weighted directions from `at.origin` in batches of `batch.len()`: `dir(k)` is
/// direction k in scene space (unit), `weight(k)` its share of the form factor. Every ray that
/// reaches a diffuse side (see [`crate::optics::Surface::column_for`]) adds its weight to that
/// side's column of `row`.
#[expect(clippy::too_many_arguments, reason = "one batched shot")]
pub(crate) fn cast_weighted<A: Accelerator, R: FormRow + ?Sized>(
    accel: &mut A,
    optics: &Optics<'_>,
    at: &Placement,
    total: u32,
    batch: &mut [Vec3],
    mut dir: impl FnMut(u32) -> Vec3,
    weight: impl Fn(u32) -> f32,
    row: &mut R,
) -> Result<ShotStats, PeerError> {
    if optics.has_specular() {
        return Err(PeerError::Specular);
    }
    if batch.is_empty() {
        return Err(PeerError::NoScratch);
    }
    let mut stats = ShotStats::default();
    let origin_patch = at.origin_patch;
    let mut base = 0u32;
    accel.set_origin_patch(origin_patch);
    while base < total {
        let m = (total - base).min(batch.len() as u32) as usize;
        for (i, d) in batch[..m].iter_mut().enumerate() {
            *d = dir(base + i as u32);
        }
        accel.cast_from(at.origin, &batch[..m], false, |i, hit: Option<Hit>| {
            stats.rays += 1;
            // an engine that cannot skip the origin patch reports it: it is not "seen"
            let hit = hit.filter(|h| Some(h.patch) != origin_patch);
            if let Some(h) = hit {
                if h.front {
                    stats.front_hits += 1;
                } else {
                    stats.back_hits += 1;
                }
                if let Some(c) = optics.surface(h.patch).column_for(h.front) {
                    row.add(c as usize, [weight(base + i as u32); 3]);
                }
            }
        });
        base += m as u32;
    }
    accel.set_origin_patch(None);
    Ok(stats)
}
