//! Pass 1: place sample points, have the backend shoot a hemisphere from
//! each, and form patch form factors from the element rows by (4.3).

use crate::backend::{shoot_checked, Backend, Progress};
use crate::shots::{self, ElementRow};
use hemi_kernel::tracer::ShotStats;

/// The outcome of pass 1.
#[derive(Clone, Debug)]
pub struct FormFactors {
    /// Element rows, grouped by patch, each patch's K×K in v-major order (diffuse patches only:
    /// a pure specular patch shoots no hemispheres).
    pub elements: Vec<ElementRow>,
    /// Patch form factors F_ij (dense, patches × patches in scene order), from (4.3); the mean
    /// of the three channels when coloured mirrors make them differ. Rows and columns of pure
    /// specular patches are zero: the kernel's rows run over diffuse columns only, and the host
    /// spreads them back to scene order for the solve and the JSON of `hemi form-factors --json`.
    pub matrix: Vec<Vec<f64>>,
    /// Per-channel F_ij when some specular k is coloured (indirect form factors then differ by
    /// channel); `None` when every channel equals `matrix`.
    pub tinted: Option<[Vec<Vec<f64>>; 3]>,
    /// K used (elements per patch = K²).
    pub samples: u32,
    /// Rays cast and what they hit.
    pub stats: ShotStats,
}

impl FormFactors {
    /// F_ij of channel `c`.
    pub fn channel(&self, c: usize) -> &[Vec<f64>] {
        match &self.tinted {
            Some(t) => &t[c],
            None => &self.matrix,
        }
    }

    /// Bytes the patch form factors take (the grey matrix and the tinted ones).
    pub fn matrix_bytes(&self) -> usize {
        let one = |m: &[Vec<f64>]| m.iter().map(|r| r.len() * 8).sum::<usize>();
        one(&self.matrix)
            + self
                .tinted
                .as_ref()
                .map_or(0, |t| t.iter().map(|m| one(m)).sum())
    }

    /// Non-zero patch form factors F_ij (of the grey matrix).
    pub fn nonzeros(&self) -> usize {
        self.matrix
            .iter()
            .map(|r| r.iter().filter(|f| **f != 0.0).count())
            .sum()
    }

    /// F_ij of the three channels, as the solvers take them.
    pub fn channels(&self) -> [&[Vec<f64>]; 3] {
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
    let (scene, settings) = (backend.scene(), backend.settings());
    anyhow::ensure!(settings.samples >= 1, "--samples must be at least 1");
    let shots: Vec<_> = (0..scene.patches.len())
        .flat_map(|i| shots::uniform_shots(scene, i, settings.samples))
        .collect();
    let (elements, stats) = shoot_checked(backend, &shots, progress)?;
    Ok(FormFactors::from_elements(
        scene.patches.len(),
        elements,
        settings.samples,
        stats,
    ))
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
pub type PatchMatrix = (Vec<Vec<f64>>, Option<[Vec<Vec<f64>>; 3]>);

/// F_ij = Σ_q W_iq F_iq,j (4.3) over `elements`, for `n` patches: the grey matrix (the mean of
/// the channels) and, when coloured mirrors make the channels differ, the three per-channel
/// matrices (see [`FormFactors::matrix`] and [`FormFactors::tinted`]).
pub fn patch_matrix<'a>(n: usize, elements: impl Iterator<Item = &'a ElementRow>) -> PatchMatrix {
    let mut rgb = [
        vec![vec![0.0f64; n]; n],
        vec![vec![0.0f64; n]; n],
        vec![vec![0.0f64; n]; n],
    ];
    for e in elements {
        add_element(e, |j, c, x| rgb[c][e.patch][j] += x);
    }
    if rgb[0] == rgb[1] && rgb[1] == rgb[2] {
        let [r, _, _] = rgb;
        (r, None)
    } else {
        let mean = (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| (rgb[0][i][j] + rgb[1][i][j] + rgb[2][i][j]) / 3.0)
                    .collect()
            })
            .collect();
        (mean, Some(rgb))
    }
}
