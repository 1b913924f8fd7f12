//! The kernel's optics table for a scene: which patches are diffuse (and their form-factor
//! columns), and the specular lobes cut from the hemisphere of a run (paper §3.3).

use crate::scene::{Material, Scene};
use anyhow::{anyhow, Result};
use hemi_kernel::frustum::{lobe_weights, size_for_angle, size_for_phong};
use hemi_kernel::hemisphere::Hemisphere;
use hemi_kernel::optics::{Lobe, Optics, Specular, Surface};
use hemi_kernel::patch::Patch;
use hemi_kernel::skeleton::Frame;
use hemi_kernel::skeleton::Skeleton;
use hemi_kernel::specular::{Pending, SpecularStats, DEFAULT_THRESHOLD};
use hemi_kernel::tracer::TraceScratch;

/// Settings of the specular transport (both passes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpecularSettings {
    /// Δ of §6.5: frustums carrying less than this fraction of their primary ray are not shot.
    pub threshold: f32,
    /// Capacity of the skeleton stack (§6.2): the frustums waiting to be shot.
    pub stack: usize,
    /// The most specular bounces one path may take (§5).
    pub max_bounces: u16,
}

impl Default for SpecularSettings {
    fn default() -> Self {
        SpecularSettings {
            threshold: DEFAULT_THRESHOLD,
            // 64 frames: a frame waits per frustum still to shoot, deepest on top; a mirror chain
            // of k_r = 0.93 falls below Δ = 1 % in 64 bounces, so only near-lossless parallel
            // mirrors reach the bound (and report what they lose).
            stack: 64,
            // a mirror chain of k_r = 0.83 falls below Δ = 1 % in 24 bounces
            max_bounces: 24,
        }
    }
}

/// The optics of a scene for one hemisphere table, owning its storage.
#[derive(Clone, Debug)]
pub struct SceneOptics {
    /// The kernel's patch memory.
    pub patches: Vec<Patch>,
    /// One surface per patch.
    pub surfaces: Vec<Surface>,
    /// The lobe-weight table the surfaces' lobes index.
    pub weights: Vec<f32>,
    /// Scene patch index of each form-factor column.
    pub columns: Vec<usize>,
    /// R of the hemisphere the lobes were cut from.
    pub circles: u32,
}

/// The frustum size k of specular material `m` on a hemisphere of `circles` circles: from its
/// `frustum` angle if the scene gives one, else from its Phong power. 0 is a single ray (a
/// perfect mirror's, or a lobe narrower than a ring).
pub fn lobe_size(m: &Material, circles: u32) -> u32 {
    match m.frustum_deg {
        Some(deg) => size_for_angle(deg as f32, circles),
        None => size_for_phong(m.phong as f32, circles),
    }
}

impl SceneOptics {
    /// Builds the table: columns for the diffuse patches in scene order (the back sides of
    /// translucent sheets last, as in the scene), one lobe per specular material (its frustum size from `frustum` degrees if given, else from `phong`).
    pub fn new(scene: &Scene, hemi: &Hemisphere<'_>) -> Result<SceneOptics> {
        let circles = hemi.circles();
        let mut weights = Vec::new();
        let mut lobes: Vec<Option<Lobe>> = Vec::with_capacity(scene.materials.len());
        for m in &scene.materials {
            if !(m.reflects() || m.transmits()) {
                lobes.push(None);
                continue;
            }
            let n = m.phong as f32;
            let size = lobe_size(m, circles);
            let first = weights.len();
            weights.resize(first + size as usize + 1, 0.0);
            lobe_weights(hemi, n, size, &mut weights[first..])
                .map_err(|e| anyhow!("material `{}`: frustum: {e:?}", m.name))?;
            lobes.push(Some(Lobe {
                first: u16::try_from(first)
                    .map_err(|_| anyhow!("too many specular lobes for the lobe table"))?,
                size: size as u16,
            }));
        }
        let mut columns = Vec::new();
        let mut surfaces: Vec<Surface> = (0..scene.fronts())
            .map(|i| {
                let m = scene.material_of(i);
                let lobe = lobes[scene.patches[i].material];
                let spec = |k: [f64; 3]| -> Option<Specular> {
                    let k = k.map(|x| x as f32);
                    (k.iter().any(|x| *x > 0.0)).then_some(Specular {
                        k,
                        lobe: lobe.unwrap_or_default(),
                    })
                };
                let column = m.is_diffuse().then(|| {
                    columns.push(i);
                    columns.len() as u32 - 1
                });
                Surface {
                    column,
                    back_column: None,
                    reflect: spec(m.specular),
                    transmit: spec(m.transmission),
                }
            })
            .collect();
        // the back sides of translucent sheets: columns after the fronts', as in scene order
        for i in scene.fronts()..scene.patches.len() {
            if let crate::scene::Sides::Back { front } = scene.patches[i].sides {
                columns.push(i);
                surfaces[front].back_column = Some(columns.len() as u32 - 1);
            }
        }
        Ok(SceneOptics {
            patches: scene.kernel_patches(),
            surfaces,
            weights,
            columns,
            circles,
        })
    }

    /// The kernel's view.
    pub fn view(&self) -> Optics<'_> {
        Optics::new(&self.patches, &self.surfaces, &self.weights, self.circles)
            .expect("built consistent by SceneOptics::new")
    }

    /// Rays in the frustum of each specular material, by name (for reports).
    pub fn frustum_rays(&self, scene: &Scene, hemi: &Hemisphere<'_>) -> Vec<(String, u32, u32)> {
        let mut out = Vec::new();
        let mut seen = std::collections::HashSet::new();
        for (i, s) in self.surfaces.iter().enumerate() {
            let m = scene.material_of(i);
            if let Some(spec) = s.reflect.or(s.transmit) {
                if seen.insert(m.name.clone()) {
                    let rays = hemi_kernel::frustum::ray_count(hemi, spec.lobe.size as u32);
                    out.push((m.name.clone(), spec.lobe.size as u32, rays));
                }
            }
        }
        out
    }
}

/// Specular hits one frustum may park: a frustum's rays number at most the hemisphere's (13 k at
/// R = 64), but those that reach specular surfaces and matter are few; beyond this they are
/// counted as overflows.
const PARKED: usize = 4096;

/// Owned tracer scratch for one worker thread.
pub struct Scratch {
    pending: Vec<Pending>,
    parked: Vec<Pending>,
    frames: Vec<Frame>,
    threshold: f32,
    max_depth: u16,
}

impl Scratch {
    /// Room for `pending` parked hits and a stack of `settings.stack` frames.
    pub fn new(pending: usize, settings: &SpecularSettings) -> Scratch {
        Scratch {
            pending: vec![Pending::EMPTY; pending],
            parked: vec![Pending::EMPTY; PARKED],
            frames: vec![Frame::EMPTY; settings.stack],
            threshold: settings.threshold,
            max_depth: settings.max_bounces,
        }
    }

    /// The kernel's view, with a fresh (empty) stack.
    pub fn view(&mut self) -> TraceScratch<'_> {
        TraceScratch {
            pending: &mut self.pending,
            parked: &mut self.parked,
            skeleton: Skeleton::new(&mut self.frames),
            threshold: self.threshold,
            max_depth: self.max_depth,
        }
    }
}

/// Room to park every specular hit of a whole hemisphere (one cast per shot).
pub fn pending_for(hemi: &Hemisphere<'_>) -> usize {
    hemi.ray_count() as usize
}

/// A check `threshold` and `stack` are usable.
pub fn check(settings: &SpecularSettings) -> Result<()> {
    anyhow::ensure!(
        settings.threshold.is_finite() && settings.threshold > 0.0 && settings.threshold < 1.0,
        "--specular-threshold must be in (0, 1)"
    );
    anyhow::ensure!(
        (1..=1000).contains(&settings.max_bounces),
        "--max-bounces must be between 1 and 1000"
    );
    anyhow::ensure!(
        (1..=4096).contains(&settings.stack),
        "--stack must be between 1 and 4096 frames"
    );
    Ok(())
}

/// One line on what the frustums of a pass did, for stderr: counts, and the weights that did
/// not reach a diffuse patch as a mean per primary ray (`primaries` of them; weights are in the
/// pass's units, so pass 1's are form factors and pass 2's fractions of a pixel).
pub fn describe(
    label: &str,
    s: &SpecularStats,
    primaries: u64,
    settings: &SpecularSettings,
) -> String {
    let per = |w: f64| w / primaries.max(1) as f64;
    format!(
        "{label}: {} frustums, {} frustum rays; stack high-water {}/{} frames; per primary ray: \
         {:.2e} cut below Δ = {} ({} frustums), {:.2e} cut at {} bounces ({}), {:.2e} lost to a \
         full stack ({}), {:.2e} cut past the work budget of {} frustums a primary ray ({}), \
         {:.2e} absorbed by lobes, {:.2e} escaped",
        s.frustums,
        s.rays,
        s.high_water,
        settings.stack,
        per(s.cut_weight),
        settings.threshold,
        s.below_threshold,
        per(s.too_deep_weight),
        settings.max_bounces,
        s.too_deep,
        per(s.overflow_weight),
        s.overflows,
        per(s.over_budget_weight),
        hemi_kernel::specular::TREE_BUDGET,
        s.over_budget,
        per(s.absorbed_weight),
        per(s.escaped_weight),
    )
}
