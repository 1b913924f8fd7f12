//! Irradiance at arbitrary points (the convention of Radiance's `rtrace -I`): the hemisphere is
//! placed at the point around the given direction and every ray gathers the radiosity where it
//! lands, directly or through specular surfaces, so `E = Σ δD_j · w · B(hit)` (with L = B/π for
//! diffuse surfaces, ∫L cos dω = Σ δD B; w is what mirrors on the way pass on).

use crate::backend::{Backend, Query, Seen};
use crate::radiosity::Grid;

/// Irradiance (W/m² per channel) at each query, emitters included, from the radiosity field
/// `grids` (per scene patch, the back sides of translucent sheets included).
pub fn irradiance(
    backend: &dyn Backend,
    grids: &[Grid],
    queries: &[Query],
) -> anyhow::Result<Vec<[f64; 3]>> {
    let mut out = Vec::with_capacity(queries.len());
    for chunk in queries.chunks(QUERIES_PER_REQUEST) {
        for seen in backend.gather(chunk)? {
            out.push(gathered(grids, &seen)?);
        }
    }
    Ok(out)
}

/// Queries one request to the backend carries: enough to keep every core busy, few enough that
/// their reports (about one per hemisphere ray) stay small.
const QUERIES_PER_REQUEST: usize = 64;

/// `E = Σ w · B(hit)` over one query's reports, in the order the tracer made them.
fn gathered(grids: &[Grid], seen: &[Seen]) -> anyhow::Result<[f64; 3]> {
    let mut e = [0.0f64; 3];
    for s in seen {
        let b = crate::radiosity::grid_of(grids, s.side)?.at(s.u, s.v);
        for c in 0..3 {
            e[c] += s.weight[c] as f64 * b[c];
        }
    }
    Ok(e)
}
