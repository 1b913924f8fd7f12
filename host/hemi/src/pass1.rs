//! Pass 1: place sample points, have the backend shoot a hemisphere from
//! each, and form patch form factors from the element rows by (4.3).

use crate::backend::{Backend, Progress};
use crate::footprint;
use crate::matrix::{FormMatrix, Row};
use crate::shots::{self, ElementRow};
use hemi_kernel::tracer::ShotStats;

/// The outcome of pass 1.
#[derive(Clone, Debug)]
pub struct FormFactors {
    /// Element rows, grouped by patch, each patch's K×K in v-major order (diffuse patches only:
    /// a pure specular patch shoots no hemispheres).
    pub elements: Vec<ElementRow>,
    /// Patch form factors F_ij (patches × patches in scene order, as sparse rows: what the
    /// hemispheres saw), from (4.3); the mean of the three channels when coloured mirrors make
    /// them differ. Rows and columns of pure specular patches are empty: the kernel's rows run
    /// over diffuse columns only, and the host spreads them back to scene order for the solve
    /// and the JSON of `hemi form-factors --json`.
    pub matrix: FormMatrix,
    /// Per-channel F_ij when some specular k is coloured (indirect form factors then differ by
    /// channel); `None` when every channel equals `matrix`.
    pub tinted: Option<[FormMatrix; 3]>,
    /// K used (elements per patch = K²).
    pub samples: u32,
    /// Rays cast and what they hit.
    pub stats: ShotStats,
}

impl FormFactors {
    /// F_ij of channel `c`.
    pub fn channel(&self, c: usize) -> &FormMatrix {
        match &self.tinted {
            Some(t) => &t[c],
            None => &self.matrix,
        }
    }

    /// Bytes the patch form factors take (the grey matrix and the tinted ones).
    pub fn matrix_bytes(&self) -> usize {
        let tinted = self.tinted.as_ref();
        self.matrix.bytes() + tinted.map_or(0, |t| t.iter().map(FormMatrix::bytes).sum())
    }

    /// Non-zero patch form factors F_ij (of the grey matrix).
    pub fn nonzeros(&self) -> usize {
        self.matrix.nonzeros()
    }

    /// F_ij of the three channels, as the solvers take them.
    pub fn channels(&self) -> [&FormMatrix; 3] {
        [self.channel(0), self.channel(1), self.channel(2)]
    }

    /// Patch form factors of `n` patches from element rows by (4.3),
    /// F_ij = Σ_q W_iq F_iq,j, with W_iq each element's area share (`SamplePoint::weight`).
    /// `samples` and `stats` are recorded as given.
    pub fn from_elements(
        n: usize,
        elements: Vec<ElementRow>,
        samples: u32,
        stats: ShotStats,
    ) -> FormFactors {
        let (matrix, tinted) = patch_matrix(n, elements.iter());
        FormFactors {
            elements,
            matrix,
            tinted,
            samples,
            stats,
        }
    }
}

/// Pass 1 with uniform sampling on `backend`: K×K points per polygon patch (4×4 on a Bezier
/// patch, §7), one hemisphere each; `progress` gets the elements finished.
pub fn form_factors(backend: &dyn Backend, progress: &Progress<'_>) -> anyhow::Result<FormFactors> {
    form_factors_within(backend, progress, u64::MAX, "")
}

/// [`form_factors`] within `limit` bytes of rows (see [`footprint::shoot_within`]; `raise`
/// names the option that raises it).
pub fn form_factors_within(
    backend: &dyn Backend,
    progress: &Progress<'_>,
    limit: u64,
    raise: &str,
) -> anyhow::Result<FormFactors> {
    let (scene, settings) = (backend.scene(), backend.settings());
    anyhow::ensure!(settings.samples >= 1, "--samples must be at least 1");
    let shots = shots::all_uniform_shots(scene, settings.samples);
    let (elements, stats) = footprint::shoot_within(backend, &shots, progress, limit, raise)?;
    Ok(assemble(backend, elements, stats))
}

/// Pass 1's outcome from its element rows.
fn assemble(backend: &dyn Backend, elements: Vec<ElementRow>, stats: ShotStats) -> FormFactors {
    let (n, k) = (backend.scene().patches.len(), backend.settings().samples);
    FormFactors::from_elements(n, elements, k, stats)
}

/// One element's share of its patch's row by (4.3): `add(j, c, W_iq F_iq,j)` for each patch j
/// and channel c it saw (the one place the weighting is written; whole matrices here, single
/// rows in `on_demand`).
pub fn add_element(e: &ElementRow, mut add: impl FnMut(usize, usize, f64)) {
    for &(j, f) in &e.row {
        for (c, fc) in f.iter().enumerate() {
            add(j as usize, c, e.point.weight as f64 * *fc as f64);
        }
    }
}

/// The patch matrices of [`FormFactors`]: the grey one, and the three channels when they
/// differ.
pub type PatchMatrix = (FormMatrix, Option<[FormMatrix; 3]>);

/// F_ij = Σ_q W_iq F_iq,j (4.3) over `elements`, for `n` patches: the grey matrix (the mean of
/// the channels) and, when coloured mirrors make the channels differ, the three per-channel
/// matrices (see [`FormFactors::matrix`] and [`FormFactors::tinted`]). Each entry sums its
/// elements in the order given, as a dense matrix would, so the values are the same bits; the
/// memory is one dense row of scratch and the non-zeros.
pub fn patch_matrix<'a>(n: usize, elements: impl Iterator<Item = &'a ElementRow>) -> PatchMatrix {
    // the elements of each patch, in the order given
    let mut by_patch: Vec<Vec<&ElementRow>> = vec![Vec::new(); n];
    for e in elements {
        by_patch[e.patch].push(e);
    }
    // coloured mirrors make an element's channels differ, and only then are they kept apart
    let tinted = by_patch
        .iter()
        .flatten()
        .any(|e| e.row.iter().any(|(_, f)| f[0] != f[1] || f[1] != f[2]));
    let channels = if tinted { 4 } else { 1 };
    let mut rows: Vec<Vec<Row>> = (0..channels).map(|_| Vec::with_capacity(n)).collect();
    let mut dense = vec![[0.0f64; 3]; n];
    let mut marked = vec![false; n];
    let mut seen: Vec<u32> = Vec::new();
    for elements in &by_patch {
        for e in elements {
            add_element(e, |j, c, x| {
                if !marked[j] {
                    marked[j] = true;
                    seen.push(j as u32);
                }
                dense[j][c] += x;
            });
        }
        for (c, out) in rows.iter_mut().enumerate() {
            let value = |v: &[f64; 3]| match c {
                3 => (v[0] + v[1] + v[2]) / 3.0,
                c => v[c],
            };
            let entries = seen.iter().map(|&j| (j, value(&dense[j as usize])));
            out.push(Row::from_entries(n, entries.collect()));
        }
        for &j in &seen {
            dense[j as usize] = [0.0; 3];
            marked[j as usize] = false;
        }
        seen.clear();
    }
    let mut matrices = rows.into_iter().map(FormMatrix::from_rows);
    let first = matrices.next().unwrap_or_else(|| FormMatrix::zeros(n));
    match (matrices.next(), matrices.next(), matrices.next()) {
        (Some(g), Some(b), Some(mean)) => (mean, Some([first, g, b])),
        _ => (first, None),
    }
}
