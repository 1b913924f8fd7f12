//! Irradiance at arbitrary points (the convention of Radiance's `rtrace -I`): the hemisphere is
//! placed at the point around the given direction and every ray gathers the radiosity where it
//! lands, directly or through specular surfaces, so `E = Σ δD_j · w · B(hit)` (with L = B/π for
//! diffuse surfaces, ∫L cos dω = Σ δD B; w is what mirrors on the way pass on).
//!
//! With [`Direct::Exact`] (where [`crate::direct::applies`]) the emitting polygons seen directly
//! are left out of that sum and their light is taken from exact form factors with shadow rays
//! instead ([`crate::direct`]): a small lamp is then not quantised by the hemisphere's rays.
//! The surfaces right next to the point are not read off the grids but evaluated afresh
//! ([`near`]), so corners and contact shadows are as sharp as the light in them.

pub mod near;

use crate::backend::{Backend, Query, Seen};
pub use crate::direct::Direct;
use crate::direct::{applies, Emitters};
use crate::radiosity::{combine, Grid};
use near::{surface_at, NearField};

/// How point queries gather.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QuerySettings {
    /// Where the emitters' direct light comes from.
    pub direct: Direct,
    /// How many levels of near-field evaluation ([`near`]): 0 reads every hit off the grids.
    pub near_levels: u32,
    /// How close a hit must be to be evaluated afresh, in cell sizes of its grid.
    pub near_cells: f32,
}

impl Default for QuerySettings {
    fn default() -> Self {
        QuerySettings {
            direct: Direct::Exact,
            near_levels: 1,
            near_cells: near::NEAR,
        }
    }
}

/// Irradiance (W/m² per channel) at each query, emitters included, from the radiosity field
/// `grids` (per scene patch, the back sides of translucent sheets included), the emitters'
/// direct light and the near field as `settings` say, where the scene and the backend allow.
pub fn irradiance(
    backend: &dyn Backend,
    grids: &[Grid],
    queries: &[Query],
    settings: &QuerySettings,
) -> anyhow::Result<Vec<[f64; 3]>> {
    let emitters = (settings.direct == Direct::Exact && applies(backend))
        .then(|| Emitters::of(backend.scene()));
    let gather = Gather {
        backend,
        grids,
        emitters: emitters.as_ref(),
        near_cells: settings.near_cells,
    };
    gather.at(queries, settings.near_levels)
}

/// Queries one request to the backend carries: enough to keep every core busy, few enough that
/// their reports (about one per hemisphere ray) stay small.
const QUERIES_PER_REQUEST: usize = 64;

/// What every level of a query's gather shares.
struct Gather<'a> {
    backend: &'a dyn Backend,
    grids: &'a [Grid],
    emitters: Option<&'a Emitters>,
    near_cells: f32,
}

impl Gather<'_> {
    /// Irradiance at `queries`, with `levels` of near field.
    fn at(&self, queries: &[Query], levels: u32) -> anyhow::Result<Vec<[f64; 3]>> {
        let mut out = Vec::with_capacity(queries.len());
        for chunk in queries.chunks(QUERIES_PER_REQUEST) {
            out.extend(self.request(chunk, levels)?);
        }
        Ok(out)
    }

    /// One request's queries: their hemispheres, their direct light and their near fields.
    fn request(&self, chunk: &[Query], levels: u32) -> anyhow::Result<Vec<[f64; 3]>> {
        let seen = self.backend.gather(chunk)?;
        let direct = match self.emitters {
            Some(em) => {
                let at: Vec<_> = chunk.iter().map(|q| (q.point, q.normal)).collect();
                em.irradiance(self.backend, self.grids, &at)?
            }
            None => vec![[0.0; 3]; chunk.len()],
        };
        let handled = |side| self.emitters.is_some_and(|em| em.handles(side));
        let scene = self.backend.scene();
        let near = match levels {
            0 => NearField::default(),
            _ => NearField::of(scene, self.grids, chunk, &seen, self.near_cells, handled),
        };
        let values = self.radiosity(&near.points, levels.saturating_sub(1))?;
        let mut out = Vec::with_capacity(chunk.len());
        for (k, (seen, d)) in seen.iter().zip(direct).enumerate() {
            let mut fresh = vec![None; seen.len()];
            for &(r, n) in near.hits.get(k).map_or(&[][..], |h| &h[..]) {
                fresh[r] = Some(values[n]);
            }
            let e = self.sum(seen, &fresh)?;
            out.push([0, 1, 2].map(|c| e[c] + d[c]));
        }
        Ok(out)
    }

    /// `E = Σ w · B(hit)` over one query's reports, in the order the tracer made them, leaving
    /// out the emitters whose direct light is computed exactly; B is `fresh` where the near
    /// field evaluated it, else read off the grids.
    fn sum(&self, seen: &[Seen], fresh: &[Option<[f64; 3]>]) -> anyhow::Result<[f64; 3]> {
        let mut e = [0.0f64; 3];
        for (s, f) in seen.iter().zip(fresh) {
            if self.emitters.is_some_and(|em| em.handles(s.side)) {
                continue;
            }
            let l = match f {
                Some(b) => [0, 1, 2].map(|c| s.weight[c] as f64 * b[c]),
                None => s.light(self.grids)?,
            };
            for c in 0..3 {
                e[c] += l[c];
            }
        }
        Ok(e)
    }

    /// The radiosity at each (side, u, v), evaluated as `E + ρH [+ τH_twin]` from queries at
    /// the point (both faces of a translucent sheet) with `levels` of near field below.
    fn radiosity(
        &self,
        points: &[(usize, f32, f32)],
        levels: u32,
    ) -> anyhow::Result<Vec<[f64; 3]>> {
        if points.is_empty() {
            return Ok(Vec::new());
        }
        let scene = self.backend.scene();
        let lift = scene.ray_offset();
        let mut queries = Vec::with_capacity(points.len());
        for &(side, u, v) in points {
            let (p, n) = surface_at(scene, side, u, v);
            queries.push(Query {
                point: p + n * lift,
                normal: n,
            });
            if scene.twin(side).is_some() {
                queries.push(Query {
                    point: p - n * lift,
                    normal: -n,
                });
            }
        }
        let h = self.at(&queries, levels)?;
        let mut h = h.into_iter();
        let mut out = Vec::with_capacity(points.len());
        for &(side, _, _) in points {
            let own = h.next().unwrap_or_default();
            let through = scene.twin(side).map(|_| h.next().unwrap_or_default());
            out.push(combine(scene.material_of(side), own, through));
        }
        Ok(out)
    }
}
