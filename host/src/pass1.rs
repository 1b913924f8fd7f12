//! Pass 1 on the host side (spec §2 steps 1–2): place sample points, have the backend shoot a
//! hemisphere from each, and form patch form factors from the element rows by (4.3).

use crate::engine::SoftEngine;
use crate::method::Shooter;
use crate::optics::{pending_for, SceneOptics, Scratch, SpecularSettings};
use crate::scene::Scene;
use hemi_kernel::accel::Accelerator;
use hemi_kernel::hemisphere::{DeltaRule, OwnedHemisphere};
use hemi_kernel::patch::Shape;
use hemi_kernel::sampling::{bezier_sample, grid_sample, SamplePoint};
use hemi_kernel::tracer::ShotStats;
use rayon::prelude::*;

/// Settings of pass 1.
#[derive(Clone, Copy, Debug)]
pub struct Pass1Settings {
    /// R, hemisphere circles (M = 4R rays on the horizon).
    pub circles: u32,
    /// K: K×K initial sample points per polygon patch.
    pub samples: u32,
    /// How delta form factors are assigned to rings.
    pub rule: DeltaRule,
    /// Frustums through specular surfaces.
    pub specular: SpecularSettings,
    /// The hemisphere, or a peer method at the same ray budget (`--method`).
    pub method: crate::method::Method,
}

impl Default for Pass1Settings {
    fn default() -> Self {
        Pass1Settings {
            circles: 64,
            // K = 16, not 8: the K×K midpoint rule, not the hemisphere, dominates the error of
            // patch-to-patch form factors (docs/ACCURACY.md: 1.26 % at K = 8, 0.25 % at 16 on
            // perpendicular rectangles with a common edge).
            samples: 16,
            rule: DeltaRule::Band,
            specular: SpecularSettings::default(),
            method: crate::method::Method::Hemisphere,
        }
    }
}

/// One element's row: F_iq,j for every patch j (sparse, ascending j).
#[derive(Clone, Debug)]
pub struct ElementRow {
    /// Patch i the element belongs to.
    pub patch: usize,
    /// The sample point (centre of element q).
    pub point: SamplePoint,
    /// (j, F_iq,j per channel) for the patches j (scene indices) the hemisphere saw, directly
    /// or through specular surfaces.
    pub row: Vec<(u32, [f32; 3])>,
}

/// The outcome of pass 1.
#[derive(Clone, Debug)]
pub struct FormFactors {
    /// Element rows, grouped by patch, each patch's K×K in v-major order (diffuse patches only:
    /// a pure specular patch shoots no hemispheres).
    pub elements: Vec<ElementRow>,
    /// Patch form factors F_ij (dense, patches × patches in scene order), from (4.3); the mean
    /// of the three channels when coloured mirrors make them differ. Rows and columns of pure
    /// specular patches are zero: the kernel's rows run over diffuse columns only, and the host
    /// spreads them back to scene order for the solve and the JSON of spec §5.
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
    /// F_ij of the three channels, as the solvers take them.
    pub fn channels(&self) -> [&[Vec<f64>]; 3] {
        [self.channel(0), self.channel(1), self.channel(2)]
    }
}

/// How many sample points patch `i` gets (see [`sample_points`]), without placing them.
pub fn sample_count(scene: &Scene, i: usize, k: u32) -> usize {
    if !scene.material_of(i).is_diffuse() {
        return 0;
    }
    match scene.patches[i].shape {
        Shape::Polygon(_) => (k * k) as usize,
        Shape::Bezier(_) => 16,
    }
}

/// The sample points of patch `i`: K×K for a polygon, the 16 points of paper §7 for a Bezier
/// patch (4×4 whatever K); none for a pure specular patch. The back side of a translucent sheet
/// has its front's points, facing the other way.
pub fn sample_points(scene: &Scene, i: usize, k: u32) -> Vec<SamplePoint> {
    let patch = &scene.patches[i];
    if !scene.material_of(i).is_diffuse() {
        return Vec::new();
    }
    if let crate::scene::Sides::Back { front } = patch.sides {
        let mut points = sample_points(scene, front, k);
        for p in &mut points {
            p.normal = -p.normal;
        }
        return points;
    }
    match &patch.shape {
        Shape::Polygon(poly) => (0..k)
            .flat_map(|b| (0..k).map(move |a| (a, b)))
            .map(|(a, b)| grid_sample(poly, k, a, b))
            .collect(),
        Shape::Bezier(bez) => (0..4)
            .flat_map(|b| (0..4).map(move |a| (a, b)))
            .map(|(a, b)| bezier_sample(bez, a, b, patch.area))
            .collect(),
    }
}

/// Runs pass 1 with the software engine on all cores; `progress` is called with the number of
/// elements finished so far.
pub fn form_factors(
    scene: &Scene,
    settings: &Pass1Settings,
    progress: &(dyn Fn(u64) + Sync),
) -> anyhow::Result<FormFactors> {
    let patches = scene.kernel_patches();
    form_factors_with(scene, settings, &|| SoftEngine::new(&patches), progress)
}

/// Runs pass 1 on all cores with engines made by `make` (one per worker thread).
pub fn form_factors_with<A: Accelerator>(
    scene: &Scene,
    settings: &Pass1Settings,
    make: &(dyn Fn() -> A + Sync),
    progress: &(dyn Fn(u64) + Sync),
) -> anyhow::Result<FormFactors> {
    anyhow::ensure!(settings.samples >= 1, "--samples must be at least 1");
    let points: Vec<(usize, u32, SamplePoint)> = (0..scene.patches.len())
        .flat_map(|i| {
            sample_points(scene, i, settings.samples)
                .into_iter()
                .enumerate()
                .map(move |(q, p)| (i, q as u32, p))
        })
        .collect();
    let (elements, stats) = shoot_rows(scene, settings, make, &points, progress)?;
    Ok(FormFactors::from_elements(
        scene.patches.len(),
        elements,
        settings.samples,
        stats,
    ))
}

/// Shoots one hemisphere from each of `points` — (patch i, sample index q, the point) — on all
/// cores with engines made by `make`, and returns their rows F_iq,· in the order of `points`.
/// The index q only chooses the hemisphere's spin ψ (`spin_for_sample`), so the same q on the
/// same point gives the same row whichever caller asks (uniform K×K here, adaptive sampling in
/// [`crate::adaptive`]).
pub fn shoot_rows<A: Accelerator>(
    scene: &Scene,
    settings: &Pass1Settings,
    make: &(dyn Fn() -> A + Sync),
    points: &[(usize, u32, SamplePoint)],
    progress: &(dyn Fn(u64) + Sync),
) -> anyhow::Result<(Vec<ElementRow>, ShotStats)> {
    let hemi = OwnedHemisphere::new(settings.circles, settings.rule)
        .map_err(|e| anyhow::anyhow!("--circles {}: {e:?}", settings.circles))?;
    let view = hemi.view();
    crate::optics::check(&settings.specular)?;
    let optics = SceneOptics::new(scene, &view)?;
    let kernel_optics = optics.view();
    settings.method.check(&kernel_optics)?;
    let cols = optics.columns.len();
    let pending = if kernel_optics.has_specular() {
        pending_for(&view)
    } else {
        0
    };
    let results: Vec<(ElementRow, ShotStats)> = points
        .par_iter()
        .map_init(
            || {
                (
                    make(),
                    vec![[0.0f32; 3]; cols],
                    Scratch::new(pending, &settings.specular),
                    Shooter::new(settings.method, settings.circles),
                )
            },
            |(engine, row, scratch, shooter), &(i, q, point)| {
                row.fill([0.0; 3]);
                let stats = shooter.shoot(
                    engine,
                    &view,
                    &kernel_optics,
                    &mut scratch.view(),
                    &point,
                    q,
                    scene.kernel_id(i),
                    row,
                )?;
                let sparse = row
                    .iter()
                    .enumerate()
                    .filter(|(_, f)| **f != [0.0; 3])
                    .map(|(c, f)| (optics.columns[c] as u32, *f))
                    .collect();
                progress(1);
                Ok((
                    ElementRow {
                        patch: i,
                        point,
                        row: sparse,
                    },
                    stats,
                ))
            },
        )
        .collect::<anyhow::Result<_>>()?;
    let mut stats = ShotStats::default();
    let mut elements = Vec::with_capacity(results.len());
    for (e, s) in results {
        stats += s;
        elements.push(e);
    }
    Ok((elements, stats))
}

impl FormFactors {
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

/// F_ij = Σ_q W_iq F_iq,j (4.3) over `elements`, for `n` patches: the grey matrix (the mean of
/// the channels) and, when coloured mirrors make the channels differ, the three per-channel
/// matrices (see [`FormFactors::matrix`] and [`FormFactors::tinted`]).
#[allow(
    clippy::type_complexity,
    reason = "the two fields of FormFactors, as they are stored"
)]
pub fn patch_matrix<'a>(
    n: usize,
    elements: impl Iterator<Item = &'a ElementRow>,
) -> (Vec<Vec<f64>>, Option<[Vec<Vec<f64>>; 3]>) {
    let mut rgb = [
        vec![vec![0.0f64; n]; n],
        vec![vec![0.0f64; n]; n],
        vec![vec![0.0f64; n]; n],
    ];
    for e in elements {
        for &(j, f) in &e.row {
            for (c, m) in rgb.iter_mut().enumerate() {
                m[e.patch][j as usize] += e.point.weight as f64 * f[c] as f64;
            }
        }
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
