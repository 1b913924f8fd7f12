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
//! such cells cost shadow rays, one evaluation per [`SPLIT`]² part of a cell; the rest of the
//! image is the paper's pass 2.

use crate::backend::{Backend, Seen};
use crate::direct::Emitters;
use crate::field::Reflected;
use crate::grid::{grid_of, Grid};
use crate::irradiance::near::surface_at;
use crate::irradiance::relight::miss_at;
use anyhow::Result;
use std::collections::BTreeMap;

/// A pixel is relit where the grid misses its samples by more than this fraction of the
/// cell's radiosity ([`crate::irradiance::relight::MISS`] is a tenth of it): the eye sees
/// errors of a few per cent nowhere but on a shadow's edge. On the Cornell box at the defaults
/// it relights 6,426 pixels of 262,144 (1 % would relight 24,645, for no difference an eye can
/// see).
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

/// Relit hits are grouped by [`SPLIT`] × [`SPLIT`] parts of a grid cell, each part evaluated
/// once at its centre: a pixel's several rays and its neighbours' share an evaluation, so the
/// work is bounded by the shadows' edges' area, not by the pixels times `spp`.
pub const SPLIT: u32 = 16;

/// What each hit adds to its pixel's radiosity, `max(B̃ + ρD(c) − ρD̃(c), 0) − B̃` per channel
/// (c the centre of its part of the cell), in the order of `hits`, the shadow rays of every
/// part in one request per chunk.
pub fn corrections(
    backend: &dyn Backend,
    emitters: &Emitters,
    grids: &[Grid],
    direct: &Reflected,
    hits: &[Hit],
) -> Result<Vec<[f64; 3]>> {
    let mut parts: BTreeMap<(usize, u32), usize> = BTreeMap::new();
    let mut part_of = Vec::with_capacity(hits.len());
    for (_, _, s) in hits {
        let k = grid_of(grids, s.side)?.k();
        let next = parts.len();
        part_of.push(*parts.entry((s.side, part(k, s.u, s.v))).or_insert(next));
    }
    let mut centres = vec![(0, 0.0, 0.0); parts.len()];
    for (&(side, index), &n) in &parts {
        let (u, v) = centre(grid_of(grids, side)?.k(), index);
        centres[n] = (side, u, v);
    }
    let add = part_corrections(backend, emitters, direct, grids, &centres)?;
    hits.iter()
        .zip(part_of)
        .map(|((_, _, s), n)| {
            let b = grid_of(grids, s.side)?.at(s.u, s.v);
            Ok([0, 1, 2].map(|c| (b[c] + add[n][c]).max(0.0) - b[c]))
        })
        .collect()
}

/// `ρD − ρD̃` at each (side, u, v), every point's shadow rays in one request per chunk.
fn part_corrections(
    backend: &dyn Backend,
    emitters: &Emitters,
    direct: &Reflected,
    grids: &[Grid],
    points: &[(usize, f32, f32)],
) -> Result<Vec<[f64; 3]>> {
    const CHUNK: usize = 4096;
    let scene = backend.scene();
    let lift = scene.ray_offset();
    let mut out = Vec::with_capacity(points.len());
    for chunk in points.chunks(CHUNK) {
        let at: Vec<_> = chunk
            .iter()
            .map(|&(side, u, v)| {
                let (p, n) = surface_at(scene, side, u, v);
                (p + n * lift, n)
            })
            .collect();
        let exact = emitters.irradiance(backend, grids, &at)?;
        for (&(side, u, v), d) in chunk.iter().zip(exact) {
            let rho = scene.material_of(side).diffuse;
            let lit = grid_of(&direct.grids, side)?.at(u, v);
            out.push([0, 1, 2].map(|c| rho[c] * d[c] - lit[c]));
        }
    }
    Ok(out)
}

/// The index of the part of a k×k grid's cell that (u, v) falls in ([`SPLIT`] per cell side).
fn part(k: usize, u: f32, v: f32) -> u32 {
    let n = k as u32 * SPLIT;
    let at = |t: f32| ((t.clamp(0.0, 1.0) * n as f32) as u32).min(n - 1);
    at(v) * n + at(u)
}

/// The (u, v) of the centre of part `index` of a k×k grid ([`part`]'s numbering).
fn centre(k: usize, index: u32) -> (f32, f32) {
    let n = k as u32 * SPLIT;
    let at = |i: u32| (i as f32 + 0.5) / n as f32;
    (at(index % n), at(index / n))
}
