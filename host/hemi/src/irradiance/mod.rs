//! Irradiance at arbitrary points (the convention of Radiance's `rtrace -I`): the hemisphere is
//! placed at the point around the given direction and every ray gathers the radiosity where it
//! lands, directly or through specular surfaces, so `E = Σ δD_j · w · B(hit)` (with L = B/π for
//! diffuse surfaces, ∫L cos dω = Σ δD B; w is what mirrors on the way pass on).
//!
//! With [`Direct::Exact`] (where [`crate::direct::applies`]) the emitting polygons seen directly
//! are left out of that sum and their light is taken from exact form factors with shadow rays
//! instead ([`crate::direct`]): a small lamp is then not quantised by the hemisphere's rays.
//! The surfaces right next to the point are not read off the grids but evaluated afresh
//! ([`near`]), so corners and contact shadows are as sharp as the light in them. Farther out,
//! the hits in a cell that holds a shadow's edge take the lamps' light exact at the hit and the
//! rest of their light off the grid ([`relight`]).

pub mod finer;
pub mod near;
pub mod relight;

use crate::backend::{Backend, Query, Seen};
pub use crate::direct::Direct;
use crate::direct::{applies, Emitters};
use crate::field::Reflected;
use crate::radiosity::{combine, Grid};
use finer::Finer;
use near::{surface_at, Grouping, NearField};
use relight::Relit;

/// How point queries gather.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QuerySettings {
    /// Where the emitters' direct light comes from.
    pub direct: Direct,
    /// How many levels of near-field evaluation ([`near`]): 0 reads every hit off the grids.
    pub near_levels: u32,
    /// How close a hit must be to a query asked to be evaluated afresh, in cell sizes of its
    /// grid (each level below reaches [`near::SHRINK`] times as far as the one above).
    pub near_cells: f32,
}

impl Default for QuerySettings {
    fn default() -> Self {
        QuerySettings {
            direct: Direct::Exact,
            near_levels: 4,
            near_cells: near::NEAR,
        }
    }
}

/// The solved light a query reads.
#[derive(Clone, Copy, Debug)]
pub struct Light<'a> {
    /// The radiosity grid of every scene patch (the back sides of translucent sheets included).
    pub grids: &'a [Grid],
    /// The field's reflected direct light ([`crate::field::Field::direct`]), where it has it:
    /// hits on a shadow's edge are then relit ([`relight`]).
    pub direct: Option<&'a Reflected>,
}

impl<'a> Light<'a> {
    /// The radiosity grids alone (no relighting).
    pub fn of(grids: &'a [Grid]) -> Light<'a> {
        Light {
            grids,
            direct: None,
        }
    }
}

/// Irradiance (W/m² per channel) at each query, emitters included, from the radiosity field
/// `light`, the emitters' direct light and the near field as `settings` say, where the scene
/// and the backend allow.
pub fn irradiance(
    backend: &dyn Backend,
    light: Light<'_>,
    queries: &[Query],
    settings: &QuerySettings,
) -> anyhow::Result<Vec<[f64; 3]>> {
    irradiance_with(backend, backend, light, queries, settings)
}

/// [`irradiance`], the queries' own hemispheres cast on `own` (a backend for the same scene
/// with a finer hemisphere than pass 1's), everything else (the near field's evaluations, the
/// shadow rays) on `backend`.
///
/// A query's answer is one hemisphere, which quantises what it sees: at a point lit from
/// close by (a block's face millimetres above the floor, whose near field fills half the
/// hemisphere at grazing angles) that is a per cent or more, which the field's refinement does
/// not move (docs/ACCURACY.md, "Held-out points"). A finer hemisphere for the query itself
/// costs rays once per query; its near field's evaluations keep pass 1's.
pub fn irradiance_with(
    backend: &dyn Backend,
    own: &dyn Backend,
    light: Light<'_>,
    queries: &[Query],
    settings: &QuerySettings,
) -> anyhow::Result<Vec<[f64; 3]>> {
    let emitters = (settings.direct == Direct::Exact && applies(backend))
        .then(|| Emitters::of(backend.scene()));
    let sharp = emitters.clone().map(Emitters::with_sharper_edges);
    let gather = Gather {
        backend,
        own,
        grids: light.grids,
        direct: light.direct.filter(|_| emitters.is_some()),
        emitters: emitters.as_ref(),
        sharp: sharp.as_ref(),
        near_cells: settings.near_cells,
        levels: settings.near_levels,
    };
    gather.at(queries, settings.near_levels)
}

/// Where the radiosity at one hit comes from.
#[derive(Clone, Copy, Debug)]
enum Fresh {
    /// Read off its grid.
    Grid,
    /// Read off its grid, plus a correction of its direct light ([`relight`]).
    Corrected([f64; 3]),
    /// Evaluated afresh by the near field.
    Value([f64; 3]),
}

/// What the near hits of a request read: per query, (index into its `seen` list, value).
struct NearValues {
    hits: Vec<Vec<(usize, usize)>>,
    values: Vec<[f64; 3]>,
}

/// Queries one request to the backend carries: enough to keep every core busy, few enough that
/// their reports (about one per hemisphere ray) stay small.
const QUERIES_PER_REQUEST: usize = 64;

/// What every level of a query's gather shares.
struct Gather<'a> {
    backend: &'a dyn Backend,
    /// Where the queries asked cast their own hemispheres.
    own: &'a dyn Backend,
    grids: &'a [Grid],
    direct: Option<&'a Reflected>,
    emitters: Option<&'a Emitters>,
    /// The same, with shadows' edges cut twice, for the direct light at the queries asked
    /// (their near fields' evaluations, whose light is a part of a part, keep one cut).
    sharp: Option<&'a Emitters>,
    near_cells: f32,
    /// The near field's levels of the queries asked (their own hemispheres are at this level).
    levels: u32,
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
        // the queries asked, not a near field's evaluations
        let top = levels == self.levels;
        let caster = match top {
            true => self.own,
            false => self.backend,
        };
        let seen = caster.gather(chunk)?;
        let emitters = match top {
            true => self.sharp,
            false => self.emitters,
        };
        let direct = match emitters {
            Some(em) => {
                let at: Vec<_> = chunk.iter().map(|q| (q.point, q.normal)).collect();
                em.irradiance(self.backend, self.grids, &at)?
            }
            None => vec![[0.0; 3]; chunk.len()],
        };
        let handled = |s: &Seen| self.emitters.is_some_and(|em| em.skip().leaves_out(s));
        let scene = self.backend.scene();
        let near = match levels {
            0 => NearField::default(),
            _ => {
                let grouping = match top {
                    true => Grouping::PerQuery,
                    false => Grouping::Shared,
                };
                NearField::of(
                    scene,
                    self.grids,
                    chunk,
                    &seen,
                    self.near_cells * near::SHRINK.powi((self.levels - levels) as i32),
                    grouping,
                    handled,
                )
            }
        };
        let values = self.per_owner(&near, levels.saturating_sub(1))?;
        let values = self.finer(chunk, &seen, &near, values, top)?;
        let (relit, corrections) = self.relight(&seen, &near, &direct, top)?;
        let mut out = Vec::with_capacity(chunk.len());
        for (k, (seen, d)) in seen.iter().zip(direct).enumerate() {
            let mut fresh = vec![Fresh::Grid; seen.len()];
            for &(r, n) in relit.hits.get(k).map_or(&[][..], |h| &h[..]) {
                if let Some(d) = corrections[n] {
                    fresh[r] = Fresh::Corrected(d);
                }
            }
            for &(r, n) in values.hits.get(k).map_or(&[][..], |h| &h[..]) {
                fresh[r] = Fresh::Value(values.values[n]);
            }
            let e = self.sum(seen, &fresh)?;
            out.push([0, 1, 2].map(|c| e[c] + d[c]));
        }
        Ok(out)
    }

    /// The near hits' values: their groups' evaluations, with the direct light of a finer
    /// group in the queries' own level ([`finer`]) where a shadow's edge may cross the cell
    /// (the field's grid of reflected direct light misses its own samples there, as
    /// [`relight`] asks; everywhere when the field keeps no such grid).
    fn finer(
        &self,
        chunk: &[Query],
        seen: &[Vec<Seen>],
        near: &NearField,
        values: Vec<[f64; 3]>,
        top: bool,
    ) -> anyhow::Result<NearValues> {
        let mut out = NearValues {
            hits: near.hits.clone(),
            values,
        };
        let Some(em) = self.emitters.filter(|_| top) else {
            return Ok(out);
        };
        let smooth = |s: &Seen| {
            self.direct.is_some_and(|direct| {
                let grid = self.grids.get(s.side);
                grid.is_none_or(|b| relight::miss_at(b, direct, s, relight::MISS).is_none())
            })
        };
        let finer = Finer::of(self.backend.scene(), self.grids, chunk, seen, near, smooth);
        let add = finer.corrections(self.backend, em, self.grids, near)?;
        // each finer group's value follows the evaluations', and its hits read it instead
        let first = out.values.len();
        for (hits, fine) in out.hits.iter_mut().zip(&finer.hits) {
            for ((_, n), f) in hits.iter_mut().zip(fine) {
                if let Some(f) = f {
                    *n = first + f;
                }
            }
        }
        for (&g, d) in finer.groups.iter().zip(add) {
            let coarse = out.values[g];
            out.values
                .push([0, 1, 2].map(|c| (coarse[c] + d[c]).max(0.0)));
        }
        Ok(out)
    }

    /// The hits of one request's queries on a shadow's edge beyond their near fields, and the
    /// correction each of their evaluations adds to the grid ([`relight`]).
    fn relight(
        &self,
        seen: &[Vec<Seen>],
        near: &NearField,
        direct_light: &[[f64; 3]],
        top: bool,
    ) -> anyhow::Result<(Relit, Vec<Option<[f64; 3]>>)> {
        let (Some(direct), Some(em)) = (self.direct, self.emitters) else {
            return Ok((Relit::default(), Vec::new()));
        };
        let in_near: Vec<std::collections::HashSet<usize>> = (0..seen.len())
            .map(|k| {
                near.hits
                    .get(k)
                    .map_or_else(Default::default, |h| h.iter().map(|&(r, _)| r).collect())
            })
            .collect();
        let mut scale = Vec::with_capacity(seen.len());
        for (s, d) in seen.iter().zip(direct_light) {
            let e = self.sum(s, &vec![Fresh::Grid; s.len()])?;
            scale.push([0, 1, 2].map(|c| e[c] + d[c]));
        }
        let scene = self.backend.scene();
        let budget = if top {
            relight::BUDGET
        } else {
            relight::NEAR_BUDGET
        };
        let relit = Relit::of(
            scene,
            self.grids,
            direct,
            seen,
            &scale,
            budget,
            |k, r, s| em.skip().leaves_out(s) || in_near[k].contains(&r),
        );
        let corrections = relit.corrections(self.backend, em, self.grids, direct)?;
        Ok((relit, corrections))
    }

    /// `E = Σ w · B(hit)` over one query's reports, in the order the tracer made them, leaving
    /// out the emitters whose direct light is computed exactly; B is as `fresh` says.
    fn sum(&self, seen: &[Seen], fresh: &[Fresh]) -> anyhow::Result<[f64; 3]> {
        let mut e = [0.0f64; 3];
        for (s, f) in seen.iter().zip(fresh) {
            if self.emitters.is_some_and(|em| em.skip().leaves_out(s)) {
                continue;
            }
            let l = match f {
                Fresh::Value(b) => [0, 1, 2].map(|c| s.weight[c] as f64 * b[c]),
                Fresh::Grid => s.light(self.grids)?,
                Fresh::Corrected(d) => {
                    let b = crate::grid::grid_of(self.grids, s.side)?.at(s.u, s.v);
                    [0, 1, 2].map(|c| s.weight[c] as f64 * (b[c] + d[c]).max(0.0))
                }
            };
            for c in 0..3 {
                e[c] += l[c];
            }
        }
        Ok(e)
    }

    /// The near field's evaluations, [`Gather::radiosity`] run over each owner's in turn: a
    /// query's evaluations then form their own requests one level down, and group their own
    /// near hits together ([`Grouping::Shared`]) whatever else was asked.
    fn per_owner(&self, near: &NearField, levels: u32) -> anyhow::Result<Vec<[f64; 3]>> {
        let mut out = Vec::with_capacity(near.points.len());
        let mut start = 0;
        while start < near.points.len() {
            let owner = near.owners[start];
            let len = near.owners[start..]
                .iter()
                .take_while(|&&o| o == owner)
                .count();
            out.extend(self.radiosity(&near.points[start..start + len], levels)?);
            start += len;
        }
        Ok(out)
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
