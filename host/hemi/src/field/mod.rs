//! The radiosity field solved at the elements, not only at the patches.
//!
//! The solve (2.6) runs on patches, and the element values (4.2) see every other surface only
//! through its patch average, `B_iq = E_i + ρ_i Σ_j F_iq,j B_j`. Where the light varies across a
//! wall (a lamp's hot spot, a contact shadow, a bright corner), that average is wrong for most
//! of the wall, and the field is biased: low in the open, far off in corners.
//!
//! Here each element gathers from the *field* instead: every ray of its hemisphere reads the
//! radiosity where it lands, interpolated on the grid of the patch it hits at the hit's (u,v)
//! ([`Grid::at`], the same interpolation pass 2 shows):
//!
//! ```text
//!     B_iq ← E_i + ρ_i Σ_k w_k B_side(k)(u_k, v_k)   [+ τ_i Σ_k' w_k' B(u_k', v_k') of its twin]
//! ```
//!
//! with w_k the ray's δD (times what mirrors on its way pass on). It is the element-level
//! system with the renderer's own interpolation between elements, solved by Jacobi sweeps that
//! start from the patch solution's element values, each followed by a patch-level correction
//! (a two-grid cycle, `coarse_correction`). The hemispheres are those of pass 1 (spin and
//! origin patch alike), cast once more to record what each element gathers from each grid
//! vertex ([`crate::transport`]), after which a sweep is a sparse product and costs no rays;
//! where that record would not fit [`FieldSettings::transport_bytes`] (or the backend does not
//! record it), each sweep re-casts them through [`Backend::gather_field`] and memory stays that
//! of the grids. The sweeps stop when the largest change of an element value, relative to the
//! largest reflected value, falls below the tolerance.

mod fill;
pub mod refine;

use crate::backend::{Backend, Gathered, Progress, Skip};
use crate::direct::{self, Direct, DirectPaths, Emitters};
use crate::grid::Grid;
use crate::pass1::FormFactors;
use crate::radiosity::{combine, ElementIndex};
use crate::scene::Scene;
use crate::shots::{Cell, ElementRow, Shot};
use crate::solve::{gauss_seidel, SceneParts, Solution, SolveSettings, System};
use crate::transport::{Layout, TransportRow};
use fill::fill_buried;
use rayon::prelude::*;

/// How the field is solved at the elements.
#[derive(Clone, Copy, Debug)]
pub struct FieldSettings {
    /// The most gather sweeps (0: the patch solution's element values (4.2), as the paper).
    pub sweeps: u32,
    /// Stop when no element value changes by more than this fraction of the largest reflected
    /// value (B − E).
    pub tolerance: f64,
    /// Where each element's direct light from the emitters comes from in the sweeps.
    pub direct: Direct,
    /// The most memory the recorded element transport may take; past it the sweeps re-cast.
    pub transport_bytes: u64,
    /// Refinement by the field's own error ([`refine`]; it needs sweeps).
    pub refine: refine::RefineSettings,
}

impl Default for FieldSettings {
    fn default() -> Self {
        FieldSettings {
            sweeps: 0,
            tolerance: 1e-4,
            direct: Direct::Exact,
            transport_bytes: 1 << 30,
            refine: refine::RefineSettings::default(),
        }
    }
}

/// How the sweeps gathered.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Sweeps {
    /// From the element transport, recorded once in this many bytes.
    Recorded {
        /// Bytes of the record.
        bytes: u64,
    },
    /// By re-casting the hemispheres each sweep: the backend does not record the transport.
    Recast,
    /// By re-casting the hemispheres each sweep: the record would need about `estimate`
    /// bytes, more than the budget.
    OverBudget {
        /// The estimate, from the first elements recorded.
        estimate: u64,
    },
}

/// The field and how its sweeps went.
#[derive(Clone, Debug)]
pub struct Field {
    /// The radiosity grid of every scene patch.
    pub grids: Vec<Grid>,
    /// Sweeps done.
    pub sweeps: u32,
    /// The last sweep's largest change of an element value, relative to the largest reflected
    /// value (B − E).
    pub change: f64,
    /// How the sweeps gathered (`None` without sweeps).
    pub how: Option<Sweeps>,
    /// The element values the grids were built from, in the order of the pass-1 elements.
    pub values: Vec<[f64; 3]>,
    /// Where the emitters' direct light is exact: the part of the radiosity that is that light
    /// reflected once.
    pub direct: Option<Reflected>,
}

/// The part of each patch's radiosity that is the emitters' direct light reflected once (ρD),
/// and where its grid cannot carry it: there (a shadow's edge) point queries evaluate it afresh
/// at the hit instead ([`crate::irradiance::relight`]).
#[derive(Clone, Debug)]
pub struct Reflected {
    /// Per scene patch, the grid of ρD, built as [`Field::grids`] is.
    pub grids: Vec<Grid>,
    /// Per scene patch and cell, how far that grid misses its own samples
    /// ([`crate::grid::misses`]).
    pub misses: Vec<Vec<[f32; 3]>>,
}

/// The field of a solved scene: the element values (4.2) of `sol` over `ff`'s elements, then up
/// to `settings.sweeps` gather sweeps on `backend` (see the module notes).
pub fn solve_field(
    backend: &dyn Backend,
    ff: &FormFactors,
    sol: &Solution,
    settings: &FieldSettings,
    progress: &Progress<'_>,
) -> anyhow::Result<Field> {
    solve_field_with(backend, ff, sol, settings, None, progress)
}

/// [`solve_field`] with the lamps' paths of `ff`'s elements given, when the caller has them
/// ([`Emitters::paths`] at the elements' points, in their order; used only where exact direct
/// light applies).
pub fn solve_field_with(
    backend: &dyn Backend,
    ff: &FormFactors,
    sol: &Solution,
    settings: &FieldSettings,
    paths: Option<&DirectPaths>,
    progress: &Progress<'_>,
) -> anyhow::Result<Field> {
    let scene = backend.scene();
    let index = ElementIndex::of(scene, &ff.elements);
    let mut values = index.values(scene, &ff.elements, &sol.radiosity);
    let mut field = Field {
        grids: index.grids(scene, &values),
        sweeps: 0,
        change: f64::INFINITY,
        how: None,
        values: Vec::new(),
        direct: None,
    };
    if settings.sweeps == 0 || ff.elements.is_empty() {
        field.values = values;
        return Ok(field);
    }
    let shots = element_shots(&index, &ff.elements);
    let parts = SceneParts::new(scene, ff.channels());
    let system = parts.system(ff.channels())?;
    let emitters =
        (settings.direct == Direct::Exact && direct::applies(backend)).then(|| Emitters::of(scene));
    let skip = emitters
        .as_ref()
        .map_or_else(Skip::none, |e| e.skip().clone());
    let points: Vec<_> = shots
        .iter()
        .map(|s| (s.point.position, s.point.normal))
        .collect();
    // the cells each element sees of the lamps and their shadows: fixed over the sweeps
    let computed;
    let direct = match (&emitters, paths) {
        (Some(_), Some(p)) if p.len() == points.len() => Some(p),
        (Some(e), _) => {
            computed = e.paths(backend, &points)?;
            Some(&computed)
        }
        (None, _) => None,
    };

    let layout = Layout::of(&field.grids)?;
    // progress counts hemispheres cast: one per element to record, or one per element and
    // sweep re-cast
    let (recorded, how) = record(backend, &shots, &layout, &skip, settings, progress)?;
    field.how = Some(how);
    let mut buried = vec![false; shots.len()];
    while field.sweeps < settings.sweeps && field.change > settings.tolerance {
        let gathered = match &recorded {
            Some(rows) => {
                let vertices = layout.values(&field.grids);
                rows.par_iter()
                    .map(|r| Gathered {
                        light: r.gather(&vertices),
                        blocked: r.blocked,
                    })
                    .collect()
            }
            None => backend.gather_field(&shots, &field.grids, &skip, progress)?,
        };
        let mut light: Vec<[f64; 3]> = gathered.iter().map(|g| g.light).collect();
        if let Some(direct) = direct {
            for (h, d) in light.iter_mut().zip(direct.irradiance(&field.grids)?) {
                for c in 0..3 {
                    h[c] += d[c];
                }
            }
        }
        let mut next = swept_values(scene, &index, &ff.elements, &light);
        // fill first: the residual the correction spreads must not hold the buried values
        buried = gathered.iter().map(|g| g.blocked > BURIED).collect();
        fill_buried(scene, &index, &mut next, &buried);
        coarse_correction(&system, &ff.elements, &values, &mut next)?;
        field.change = relative_change(scene, &ff.elements, &values, &next);
        // welded across the seams of smooth surfaces (`crate::seams`)
        field.grids = index.grids(scene, &next);
        crate::seams::weld(scene, &mut field.grids);
        values = next;
        field.sweeps += 1;
    }
    if let Some(direct) = direct {
        let lit = reflected(scene, &ff.elements, &direct.irradiance(&field.grids)?);
        field.direct = Some(reflected_grids(scene, &index, lit, &buried));
    }
    field.values = values;
    Ok(field)
}

/// The part of each element's value that is the emitters' direct light `d` reflected once,
/// `ρ_i D_q` (exact direct light applies only without translucent sheets, so there is no
/// twin's share).
fn reflected(scene: &Scene, elements: &[ElementRow], d: &[[f64; 3]]) -> Vec<[f64; 3]> {
    elements
        .iter()
        .zip(d)
        .map(|(e, d)| {
            let rho = scene.material_of(e.patch).diffuse;
            [0, 1, 2].map(|c| rho[c] * d[c])
        })
        .collect()
}

/// The grids of the reflected direct light `values` as the sweeps build theirs (buried
/// elements filled, seams welded), and where they miss their samples.
fn reflected_grids(
    scene: &Scene,
    index: &ElementIndex,
    mut values: Vec<[f64; 3]>,
    buried: &[bool],
) -> Reflected {
    fill_buried(scene, index, &mut values, buried);
    let mut grids = index.grids(scene, &values);
    crate::seams::weld(scene, &mut grids);
    let misses = grids
        .iter()
        .enumerate()
        .map(|(i, g)| crate::grid::misses(g, &values[index.range(i)]))
        .collect();
    Reflected { grids, misses }
}

/// Elements whose transport is recorded in one request: enough to keep every core busy, and
/// the first request's size is the estimate the budget is checked against.
const RECORD_CHUNK: usize = 256;

/// The element transport of `shots` ([`crate::transport`]), if the backend records it and it
/// fits `settings.transport_bytes`: estimated from the first chunk before the rest is recorded,
/// and checked as it grows.
fn record(
    backend: &dyn Backend,
    shots: &[Shot],
    layout: &Layout,
    skip: &Skip,
    settings: &FieldSettings,
    progress: &Progress<'_>,
) -> anyhow::Result<(Option<Vec<TransportRow>>, Sweeps)> {
    let mut rows: Vec<TransportRow> = Vec::with_capacity(shots.len());
    let mut bytes = 0u64;
    for chunk in shots.chunks(RECORD_CHUNK) {
        let Some(part) = backend.transport(chunk, layout, skip, progress)? else {
            return Ok((None, Sweeps::Recast));
        };
        bytes += part.iter().map(|r| r.bytes() as u64).sum::<u64>();
        rows.extend(part);
        let estimate = bytes / rows.len() as u64 * shots.len() as u64;
        if estimate.max(bytes) > settings.transport_bytes {
            return Ok((None, Sweeps::OverBudget { estimate }));
        }
    }
    Ok((Some(rows), Sweeps::Recorded { bytes }))
}

/// An element whose hemisphere meets backs of opaque patches with more than this fraction of
/// its rays is taken to be buried in another body (a floor's sample under a block): its value is
/// not the surface's, and bilinear interpolation would spread its darkness over the visible
/// cells around it, so [`fill_buried`] replaces it.
const BURIED: f32 = 0.5;

/// The patch-level correction of a sweep (two-grid): the sweep's residual r = next − values
/// leaves the error e of `next` with `e = ρT e + ρT r`, T the element transport. Its patch
/// average — the slowest part to decay under sweeps — is solved exactly on the patch system,
/// `ē = ρF ē + ρF r̄` (T averaged over a patch is F, and r̄ is r's area-weighted mean per patch),
/// and added to every element of the patch. The sweeps are left with the detail only, which
/// decays fast (light spreads over the hemisphere), so a few sweeps reach the tolerance.
fn coarse_correction(
    system: &System<'_>,
    elements: &[ElementRow],
    values: &[[f64; 3]],
    next: &mut [[f64; 3]],
) -> anyhow::Result<()> {
    let n = system.len();
    let mut mean = vec![[0.0f64; 3]; n];
    for ((e, v), x) in elements.iter().zip(values).zip(next.iter()) {
        for c in 0..3 {
            mean[e.patch][c] += e.point.weight as f64 * (x[c] - v[c]);
        }
    }
    let rhs: Vec<[f64; 3]> = (0..n)
        .map(|i| {
            [0, 1, 2].map(|c| {
                let row = &system.f[c][i];
                system.rho[i][c] * row.iter().zip(&mean).map(|(f, r)| f * r[c]).sum::<f64>()
            })
        })
        .collect();
    let settings = SolveSettings::default();
    let correction = gauss_seidel(system.f, system.rho, &rhs, &settings)?.radiosity;
    for (e, x) in elements.iter().zip(next.iter_mut()) {
        for c in 0..3 {
            x[c] += correction[e.patch][c];
        }
    }
    Ok(())
}

/// One shot per element, at its point, with its index in its patch's lattice as the cell
/// (which picks the hemisphere's spin, as in pass 1).
fn element_shots(index: &ElementIndex, elements: &[ElementRow]) -> Vec<Shot> {
    elements
        .iter()
        .enumerate()
        .map(|(k, e)| Shot {
            patch: e.patch,
            cell: Cell::Uniform {
                q: index.within(e.patch, k) as u32,
            },
            point: e.point,
        })
        .collect()
}

/// The element values of one sweep from what each element gathered ([`combine`], with its
/// twin's on a translucent sheet).
fn swept_values(
    scene: &Scene,
    index: &ElementIndex,
    elements: &[ElementRow],
    gathered: &[[f64; 3]],
) -> Vec<[f64; 3]> {
    elements
        .iter()
        .enumerate()
        .map(|(k, e)| {
            let through = index.twin(scene, e.patch, k).map(|t| gathered[t]);
            combine(scene.material_of(e.patch), gathered[k], through)
        })
        .collect()
}

/// The largest change of an element value from `a` to `b`, relative to the largest reflected
/// part `b − E` (emission does not change between sweeps and would hide the change on a
/// scene whose lamps are far brighter than its walls), over elements and channels.
fn relative_change(scene: &Scene, elements: &[ElementRow], a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    let (mut worst, mut scale) = (0.0f64, 0.0f64);
    for ((e, x), y) in elements.iter().zip(a).zip(b) {
        let emission = scene.material_of(e.patch).emission;
        for c in 0..3 {
            worst = worst.max((y[c] - x[c]).abs());
            scale = scale.max((y[c] - emission[c]).abs());
        }
    }
    if scale > 0.0 {
        worst / scale
    } else {
        worst
    }
}
