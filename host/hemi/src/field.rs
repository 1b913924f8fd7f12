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
//! (a two-grid cycle, `coarse_correction`): each sweep re-casts the same hemispheres as
//! pass 1 (spin and origin patch alike) through [`Backend::gather_field`] and stores nothing but
//! the K×K values, so memory stays that of the grids. The sweeps stop when the largest change of
//! an element value, relative to the largest reflected value, falls below the tolerance.

use crate::backend::{Backend, Progress};
use crate::direct::{self, Direct, Emitters};
use crate::grid::Grid;
use crate::pass1::FormFactors;
use crate::radiosity::{combine, ElementIndex};
use crate::scene::Scene;
use crate::shots::{Cell, ElementRow, Shot};
use crate::solve::{gauss_seidel, SceneParts, Solution, SolveSettings, System};

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
}

impl Default for FieldSettings {
    fn default() -> Self {
        FieldSettings {
            sweeps: 0,
            tolerance: 1e-3,
            direct: Direct::Exact,
        }
    }
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
    let scene = backend.scene();
    let index = ElementIndex::of(scene, &ff.elements);
    let mut values = index.values(scene, &ff.elements, &sol.radiosity);
    let mut field = Field {
        grids: index.grids(scene, &values),
        sweeps: 0,
        change: f64::INFINITY,
    };
    if settings.sweeps == 0 || ff.elements.is_empty() {
        return Ok(field);
    }
    let shots = element_shots(&index, &ff.elements);
    let parts = SceneParts::new(scene, ff.channels());
    let system = parts.system(ff.channels())?;
    let emitters =
        (settings.direct == Direct::Exact && direct::applies(backend)).then(|| Emitters::of(scene));
    let skip = emitters
        .as_ref()
        .map_or(vec![false; scene.patches.len()], |e| e.handled().to_vec());
    let points: Vec<_> = shots
        .iter()
        .map(|s| (s.point.position, s.point.normal))
        .collect();
    // the cells each element sees of the lamps and their shadows: fixed over the sweeps
    let direct = match &emitters {
        Some(e) => Some(e.paths(backend, &points)?),
        None => None,
    };
    while field.sweeps < settings.sweeps && field.change > settings.tolerance {
        let gathered = backend.gather_field(&shots, &field.grids, &skip, progress)?;
        let mut light: Vec<[f64; 3]> = gathered.iter().map(|g| g.light).collect();
        if let Some(direct) = &direct {
            for (h, d) in light.iter_mut().zip(direct.irradiance(&field.grids)?) {
                for c in 0..3 {
                    h[c] += d[c];
                }
            }
        }
        let mut next = swept_values(scene, &index, &ff.elements, &light);
        // fill first: the residual the correction spreads must not hold the buried values
        let buried: Vec<bool> = gathered.iter().map(|g| g.blocked > BURIED).collect();
        fill_buried(scene, &index, &mut next, &buried);
        coarse_correction(&system, &ff.elements, &values, &mut next)?;
        field.change = relative_change(scene, &ff.elements, &values, &next);
        // welded across the seams of smooth surfaces (`crate::seams`)
        field.grids = index.grids(scene, &next);
        crate::seams::weld(scene, &mut field.grids);
        values = next;
        field.sweeps += 1;
    }
    Ok(field)
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

/// Replaces the value of every buried element (see [`BURIED`]) by the mean of its patch's
/// unburied neighbours (8-neighbourhood on the k×k lattice), growing inwards from the edge of
/// the buried region until it is filled; a patch buried whole keeps its values.
fn fill_buried(scene: &Scene, index: &ElementIndex, values: &mut [[f64; 3]], buried: &[bool]) {
    for i in 0..scene.patches.len() {
        let range = index.range(i);
        if range.is_empty() {
            continue;
        }
        let k = (range.len() as f64).sqrt().round() as usize;
        let mut open: Vec<bool> = buried[range.clone()].to_vec();
        fill_lattice(k, &mut values[range], &mut open);
    }
}

/// One patch's k×k lattice: every `open` value (v-major) replaced by the mean of its known
/// 8-neighbours, in rounds, until none is open or no round fills one.
fn fill_lattice(k: usize, values: &mut [[f64; 3]], open: &mut [bool]) {
    if open.iter().all(|o| *o) {
        return;
    }
    while open.iter().any(|o| *o) {
        let mut filled = Vec::new();
        for q in (0..k * k).filter(|&q| open[q]) {
            let (a, b) = ((q % k) as isize, (q / k) as isize);
            let (mut sum, mut count) = ([0.0f64; 3], 0.0);
            for (da, db) in (-1..=1).flat_map(|x| (-1..=1).map(move |y| (x, y))) {
                let (x, y) = (a + da, b + db);
                if x < 0 || y < 0 || x >= k as isize || y >= k as isize {
                    continue;
                }
                let r = y as usize * k + x as usize;
                if !open[r] {
                    for c in 0..3 {
                        sum[c] += values[r][c];
                    }
                    count += 1.0;
                }
            }
            if count > 0.0 {
                filled.push((q, sum.map(|s| s / count)));
            }
        }
        if filled.is_empty() {
            return;
        }
        for (q, v) in filled {
            values[q] = v;
            open[q] = false;
        }
    }
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
