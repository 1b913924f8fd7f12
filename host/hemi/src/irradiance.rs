//! Irradiance at arbitrary points (the convention of Radiance's `rtrace -I`): the hemisphere is
//! placed at the point around the given direction and every ray gathers the radiosity where it
//! lands, directly or through specular surfaces, so `E = Σ δD_j · w · B(hit)` (with L = B/π for
//! diffuse surfaces, ∫L cos dω = Σ δD B; w is what mirrors on the way pass on).
//!
//! With [`Direct::Exact`] (where [`crate::direct::applies`]) the emitting polygons seen directly are left out of that sum and their
//! light is taken from exact form factors with shadow rays instead ([`crate::direct`]): a
//! small lamp is then not quantised by the hemisphere's rays.

use crate::backend::{Backend, Query, Seen};
pub use crate::direct::Direct;
use crate::direct::{applies, Emitters};
use crate::radiosity::Grid;

/// Irradiance (W/m² per channel) at each query, emitters included, from the radiosity field
/// `grids` (per scene patch, the back sides of translucent sheets included), the emitters'
/// direct light as `direct` says where the scene and the backend allow it.
pub fn irradiance(
    backend: &dyn Backend,
    grids: &[Grid],
    queries: &[Query],
    direct: Direct,
) -> anyhow::Result<Vec<[f64; 3]>> {
    let emitters =
        (direct == Direct::Exact && applies(backend)).then(|| Emitters::of(backend.scene()));
    let mut out = Vec::with_capacity(queries.len());
    for chunk in queries.chunks(QUERIES_PER_REQUEST) {
        let seen = backend.gather(chunk)?;
        let direct = match &emitters {
            Some(em) => {
                let at: Vec<_> = chunk.iter().map(|q| (q.point, q.normal)).collect();
                em.irradiance(backend, grids, &at)?
            }
            None => vec![[0.0; 3]; chunk.len()],
        };
        for (seen, d) in seen.iter().zip(direct) {
            let e = gathered(grids, seen, emitters.as_ref())?;
            out.push([0, 1, 2].map(|c| e[c] + d[c]));
        }
    }
    Ok(out)
}

/// Queries one request to the backend carries: enough to keep every core busy, few enough that
/// their reports (about one per hemisphere ray) stay small.
const QUERIES_PER_REQUEST: usize = 64;

/// `E = Σ w · B(hit)` over one query's reports, in the order the tracer made them, leaving out
/// the emitters whose direct light `emitters` computes.
fn gathered(
    grids: &[Grid],
    seen: &[Seen],
    emitters: Option<&Emitters>,
) -> anyhow::Result<[f64; 3]> {
    let mut e = [0.0f64; 3];
    for s in seen {
        if emitters.is_some_and(|em| em.handles(s.side)) {
            continue;
        }
        let l = s.light(grids)?;
        for c in 0..3 {
            e[c] += l[c];
        }
    }
    Ok(e)
}
