//! Pass 2's shadows' edges, relit: where the grid of a surface's reflected direct light misses
//! its own samples ([`crate::irradiance::relight`]), a pixel's ray does not read the lamps'
//! light off the grid but takes it exact at the point it sees,
//!
//! ```text
//!     B(x) = B̃(x) − ρD̃(x) + ρ D(x),
//! ```
//!
//! so a shadow is as sharp in the image as the lamps make it, not as the grid's cells (the
//! blocks' shadows on the Cornell box's floor, the teapot's on its table). Only the pixels on
//! such cells cost shadow rays; the rest of the image is the paper's pass 2.

use crate::backend::{Backend, Seen};
use crate::direct::Emitters;
use crate::field::Reflected;
use crate::grid::{grid_of, Grid};
use crate::irradiance::near::surface_at;
use crate::irradiance::relight::miss_at;
use anyhow::Result;

/// A pixel is relit where the grid misses its samples by more than this fraction of the
/// cell's radiosity ([`crate::irradiance::relight::MISS`] is a tenth of it): the eye sees
/// errors of a few per cent nowhere but on a shadow's edge. On the Cornell box at the defaults
/// it relights 6,426 pixels of 262,144 in 6 s of CPU (1 % would relight 24,645 in 13 s, for
/// no difference an eye can see).
pub const MISS: f64 = 0.1;

/// A pixel ray's hit whose direct light is relit: (pixel, its place among the pixel's rays in
/// tracer order, what it saw).
pub type Hit = (u32, u32, Seen);

/// Whether the hit `s` is on a cell where the reflected direct light's grid misses it.
pub fn wants(grids: &[Grid], direct: &Reflected, emitters: &Emitters, s: &Seen) -> bool {
    let Some(b) = grids.get(s.side) else {
        return false;
    };
    !emitters.handles(s.side) && miss_at(b, direct, s, MISS).is_some()
}

/// What each hit adds to its pixel's radiosity, `max(B̃ + ρD − ρD̃, 0) − B̃` per channel, in
/// the order of `hits`, every hit's shadow rays in one request per chunk.
pub fn corrections(
    backend: &dyn Backend,
    emitters: &Emitters,
    grids: &[Grid],
    direct: &Reflected,
    hits: &[Hit],
) -> Result<Vec<[f64; 3]>> {
    const CHUNK: usize = 4096;
    let scene = backend.scene();
    let lift = scene.ray_offset();
    let mut out = Vec::with_capacity(hits.len());
    for chunk in hits.chunks(CHUNK) {
        let at: Vec<_> = chunk
            .iter()
            .map(|(_, _, s)| {
                let (p, n) = surface_at(scene, s.side, s.u, s.v);
                (p + n * lift, n)
            })
            .collect();
        let exact = emitters.irradiance(backend, grids, &at)?;
        for ((_, _, s), d) in chunk.iter().zip(exact) {
            let rho = scene.material_of(s.side).diffuse;
            let b = grid_of(grids, s.side)?.at(s.u, s.v);
            let lit = grid_of(&direct.grids, s.side)?.at(s.u, s.v);
            out.push([0, 1, 2].map(|c| (b[c] - lit[c] + rho[c] * d[c]).max(0.0) - b[c]));
        }
    }
    Ok(out)
}
