//! Adaptive patch sampling (paper §4): sample points are added where the light
//! changes across a patch and nowhere else, and the number of patches never grows.
//!
//! Every diffuse patch starts from an initial guess of K×K sample points (4×4 on a Bezier
//! patch, §7) and then:
//!
//! 1. the rows F_iq,· of the computed points come from the ray engine (one hemisphere each);
//! 2. patch form factors by (4.3), F_ij = Σ_q W_iq F_iq,j over all of the patch's current
//!    elements; the system (2.6) is solved; element radiosities follow from (4.2);
//! 3. the gradient test ([`gradient`], [`Test`]) runs over every 4-sample window of every patch
//!    not yet at the depth limit. A patch with a failing window (or whose translucent twin has
//!    one: the sides of a sheet go in lockstep, see below) is subdivided one level *as a whole*
//!    (k×k → 2k×2k, [`lattice`]): the new centre points on the part of the patch a failing
//!    window covers are shot (their rows replace the parent's, "removing the old row and
//!    inserting the four new rows", §4.2); everywhere else they are interpolated linearly
//!    from the previous level — rows, not just intensities, so that (4.3) and (4.2) stay one
//!    linear system and the next solve sees the interpolated elements too;
//! 4. back to 2 until no window fails or every failing patch is at `max_depth`.
//!
//! The last level of each patch is a uniform k×k lattice, so pass 2 gets the same vertex grid
//! ([`crate::radiosity::Grid`]) as uniform sampling, one resolution per patch (§4.3: "a uniform
//! intensity grid which is anyhow desired for the rendering process").
//!
//! A patch whose initial windows all pass keeps its initial K×K points: a flat, evenly lit
//! patch costs K² rows and no more (unless it is a side of a sheet whose other side refines). K = 1 would make that one row, but a single sample has no
//! window and so could never detect a gradient; the smallest guess that can is 2×2, which is
//! what the CLI starts from (`--adaptive`; docs/ACCURACY.md, "Adaptive patch sampling").
//!
//! The hemisphere spin of a computed point is chosen by its index in its level's lattice, as in
//! uniform sampling, so a level whose windows all failed holds exactly the rows uniform K·2^n
//! sampling would compute (margin 0 reproduces uniform sampling bit for bit).
//!
//! A translucent sheet's two sides are one system (`crate::scene::translucent`): the solve couples
//! them (K = ρF + τF_twin), an element's value adds what comes through from its twin's element
//! at the same point, and the sides are refined in lockstep (a window fails on both if it fails
//! on either), so their lattices stay the same and pass 2 pairs their grids point by point.

pub mod gradient;
pub mod lattice;

use crate::backend::{shoot_checked, Backend};
use crate::pass1::{patch_matrix, FormFactors, PatchMatrix};
use crate::radiosity::element_value;
use crate::scene::Scene;
use crate::shots::{cell_point, lattice_side, level_shot, ElementRow, Shot};
use crate::solve::{gauss_seidel, Channels, SceneParts, Solution, SolveSettings};
use hemi_kernel::sampling::SamplePoint;
use hemi_kernel::tracer::ShotStats;

/// Settings of adaptive patch sampling (the initial guess K is [`crate::settings::Pass1Settings::samples`]).
#[derive(Clone, Copy, Debug)]
pub struct AdaptiveSettings {
    /// The gradient test's margin: a window fails when its luminance differences ([`Test`])
    /// exceed this fraction of its mean luminance ([`gradient`]).
    pub margin: f64,
    /// The least intensity the margin is relative to, as a fraction of the patch's mean
    /// luminance: a window darker than that is judged against it ([`gradient`]). 0 makes the
    /// test purely local.
    pub floor: f64,
    /// The most levels a patch is subdivided beyond its initial guess (the paper's picture 4
    /// uses 4).
    pub max_depth: u32,
    /// The solver of step 2.
    pub solve: SolveSettings,
    /// What a window's four samples are compared by ([`Test`]).
    pub test: Test,
}

/// The comparison the gradient test makes in a 4-sample window ([`gradient`]). Both compare
/// luminance differences against `margin` times the window's mean luminance; they differ in
/// which differences.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Test {
    /// The paper's (§4.3): the differences among the four intensities themselves, max − min.
    /// It asks "is the light changing here?", so it also refines smooth slopes that linear
    /// interpolation reproduces exactly, and stops on curved ones whose steps are small.
    Spread,
    /// From level 1 on, each sample's difference from what the level before predicted for it
    /// by the linear interpolation of [`lattice`] (its hierarchical surplus, zero for an
    /// interpolated sample); level 0 has no level before and uses [`Test::Spread`]. It asks
    /// "did interpolating miss something here?", which is what decides the error of the grid
    /// pass 2 interpolates: on the Cornell box it reaches uniform K = 16's error with about
    /// half the rows the spread test needs (docs/ACCURACY.md).
    Surplus,
}

impl Default for AdaptiveSettings {
    fn default() -> Self {
        AdaptiveSettings {
            margin: 0.1,
            floor: 1.0,
            max_depth: 4,
            solve: SolveSettings::default(),
            test: Test::Surplus,
        }
    }
}

/// A sample point that was shot (not interpolated), and the level it was shot at.
#[derive(Clone, Copy, Debug)]
pub struct ComputedSample {
    /// Level: 0 is the initial guess.
    pub depth: u32,
    /// Index (a, b) in that level's k×k lattice.
    pub cell: (u32, u32),
    /// The point.
    pub point: SamplePoint,
}

/// What adaptive sampling did on one patch.
#[derive(Clone, Debug, Default)]
pub struct PatchReport {
    /// Levels subdivided beyond the initial guess.
    pub depth: u32,
    /// k of the last level: its lattice (and the vertex grid pass 2 reads) is k×k. 0 for a pure
    /// specular patch, which has no sample points.
    pub k: u32,
    /// Every sample point shot on the patch, at every level (the rows computed).
    pub computed: Vec<ComputedSample>,
}

impl PatchReport {
    /// Rows computed by form factors (hemisphere shots) on this patch, over all levels.
    pub fn rows_computed(&self) -> usize {
        self.computed.len()
    }
}

/// The outcome of adaptive sampling.
#[derive(Clone, Debug)]
pub struct Refined {
    /// The last level of every patch as pass-1 output: element rows (computed and interpolated,
    /// each patch's k×k v-major) and F_ij of (4.3). `samples` is the initial guess K.
    pub form_factors: FormFactors,
    /// The last solve of (2.6), on `form_factors`.
    pub solution: Solution,
    /// Per patch, in scene order.
    pub patches: Vec<PatchReport>,
    /// Solves done (one per level reached, the initial one included).
    pub rounds: u32,
}

impl Refined {
    /// Rows computed over all patches and levels: the hemispheres shot, the cost of pass 1.
    pub fn rows_computed(&self) -> usize {
        self.patches.iter().map(PatchReport::rows_computed).sum()
    }
}

/// What [`refine`] reports while it works.
#[derive(Clone, Copy, Debug)]
pub enum Progress {
    /// This many more rows are about to be shot (a new level).
    Planned(u64),
    /// This many rows are done.
    Done(u64),
}

/// One level of patch `i` subdivided into the next (k → 2k, §4.3): the 2k×2k elements
/// (v-major) with the rows of those outside every failing window interpolated from `rows` (the
/// k×k level) and `None` for those to shoot, and the list of the latter as (index, cell (a, b),
/// sample point). `failing` holds the (k−1)² windows of the gradient test.
#[expect(
    clippy::type_complexity,
    reason = "the level and its shot list, used together"
)]
pub fn subdivide(
    scene: &Scene,
    i: usize,
    k: u32,
    rows: &[ElementRow],
    failing: &[bool],
) -> (
    Vec<Option<ElementRow>>,
    Vec<(usize, (u32, u32), SamplePoint)>,
) {
    let k = k as usize;
    assert!(k >= 2 && rows.len() == k * k && failing.len() == (k - 1) * (k - 1));
    let k2 = 2 * k;
    let mut next: Vec<Option<ElementRow>> = Vec::with_capacity(k2 * k2);
    let mut shoot = Vec::new();
    for b in 0..k2 {
        for a in 0..k2 {
            let window = lattice::owner(k, b) * (k - 1) + lattice::owner(k, a);
            let point = cell_point(scene, i, k2 as u32, a as u32, b as u32);
            if failing[window] {
                shoot.push((next.len(), (a as u32, b as u32), point));
                next.push(None);
            } else {
                let parts: Vec<lattice::Part<'_>> = lattice::stencil(k, a, b)
                    .iter()
                    .map(|&(p, w)| (&rows[p].row[..], w))
                    .collect();
                next.push(Some(ElementRow {
                    patch: i,
                    point,
                    row: lattice::blend(&parts),
                }));
            }
        }
    }
    (next, shoot)
}

/// Adaptive sampling on `backend` from the initial guess K of its settings (see the module
/// documentation for the procedure).
pub fn refine(
    backend: &dyn Backend,
    adaptive: &AdaptiveSettings,
    progress: &(dyn Fn(Progress) + Sync),
) -> anyhow::Result<Refined> {
    let (scene, settings) = (backend.scene(), backend.settings());
    anyhow::ensure!(settings.samples >= 1, "--samples must be at least 1");
    anyhow::ensure!(
        adaptive.margin >= 0.0 && adaptive.margin.is_finite(),
        "--margin must be a finite number ≥ 0"
    );
    let done = |d: u64| progress(Progress::Done(d));
    let shoot = |shots: &[Shot]| {
        progress(Progress::Planned(shots.len() as u64));
        shoot_checked(backend, shots, &done)
    };
    let mut refinement = Refinement::start(scene, adaptive, settings.samples, &shoot)?;
    let mut rounds = 0;
    loop {
        // (4.3), (2.6)
        let (matrix, solution) = refinement.solve()?;
        rounds += 1;
        let plan = refinement.plan(&refinement.failing_windows(&solution));
        if plan.next.is_empty() {
            return Ok(refinement.finish(matrix, solution, rounds, settings.samples));
        }
        let (rows, stats) = shoot(&plan.shots)?;
        refinement.advance(plan, rows, stats);
    }
}

/// One patch's current level.
struct Level {
    k: u32,
    rows: Vec<ElementRow>,
    /// The level before (its k is half this one's), for the surplus test.
    parent: Option<Vec<ElementRow>>,
}

/// The next levels of the patches with a failing window: their elements (`None` where a row is
/// to be shot), the shots, and for each shot (entry of `next`, element index, cell (a, b)).
struct Plan {
    next: Vec<(usize, Vec<Option<ElementRow>>)>,
    shots: Vec<Shot>,
    targets: Vec<(usize, usize, (u32, u32))>,
}

/// Adaptive sampling between two solves: every patch's current level and what was shot.
struct Refinement<'a> {
    scene: &'a Scene,
    adaptive: &'a AdaptiveSettings,
    levels: Vec<Option<Level>>,
    reports: Vec<PatchReport>,
    stats: ShotStats,
}

type Shoot<'a> = dyn Fn(&[Shot]) -> anyhow::Result<(Vec<ElementRow>, ShotStats)> + 'a;

impl<'a> Refinement<'a> {
    /// Level 0: the initial guess (K×K, 4×4 on a Bezier patch, none on a mirror), every point
    /// shot.
    fn start(
        scene: &'a Scene,
        adaptive: &'a AdaptiveSettings,
        k0: u32,
        shoot: &Shoot<'_>,
    ) -> anyhow::Result<Self> {
        let mut reports = vec![PatchReport::default(); scene.patches.len()];
        let mut shots = Vec::new();
        let mut cells = Vec::new();
        for (i, report) in reports.iter_mut().enumerate() {
            let k = lattice_side(scene, i, k0);
            for b in 0..k {
                for a in 0..k {
                    shots.push(level_shot(scene, i, k, (a, b)));
                    cells.push((a, b));
                }
            }
            report.k = k;
        }
        let (rows, stats) = shoot(&shots)?;
        let mut levels: Vec<Option<Level>> = reports
            .iter()
            .map(|r| {
                (r.k > 0).then(|| Level {
                    k: r.k,
                    rows: Vec::new(),
                    parent: None,
                })
            })
            .collect();
        for (row, cell) in rows.into_iter().zip(cells) {
            reports[row.patch].computed.push(ComputedSample {
                depth: 0,
                cell,
                point: row.point,
            });
            let level = levels[row.patch].as_mut();
            level.expect("only diffuse patches are shot").rows.push(row);
        }
        Ok(Refinement {
            scene,
            adaptive,
            levels,
            reports,
            stats,
        })
    }

    /// (4.3) over every patch's current level, and the solve of (2.6) (the sides of translucent
    /// sheets coupled).
    fn solve(&self) -> anyhow::Result<(PatchMatrix, Solution)> {
        let rows = self.levels.iter().flatten().flat_map(|l| l.rows.iter());
        let matrix = patch_matrix(self.scene.patches.len(), rows);
        let channels: Channels<'_> = match &matrix.1 {
            Some(t) => [&t[0], &t[1], &t[2]],
            None => [&matrix.0; 3],
        };
        let parts = SceneParts::new(self.scene, channels);
        let system = parts.system(channels)?;
        let solution = gauss_seidel(system.f, system.rho, system.e, &self.adaptive.solve)?;
        Ok((matrix, solution))
    }

    /// Element values (4.2) of `rows`; a side of a translucent sheet adds what comes through it
    /// over its twin's element at the same point (`twin_rows`, paired by index: the twins are
    /// refined in lockstep, so their lattices stay the same).
    fn values(
        &self,
        rows: &[ElementRow],
        twin_rows: Option<&[ElementRow]>,
        b: &[[f64; 3]],
    ) -> Vec<[f64; 3]> {
        rows.iter()
            .enumerate()
            .map(|(q, r)| element_value(self.scene, r, twin_rows.and_then(|t| t.get(q)), b))
            .collect()
    }

    /// The gradient test on patch `i`'s current level: its failing windows, or `None` if the
    /// patch is at its depth limit (or has no windows).
    fn failing_of(&self, i: usize, solution: &Solution) -> Option<Vec<bool>> {
        let level = self.levels[i].as_ref()?;
        if self.reports[i].depth >= self.adaptive.max_depth || level.k < 2 {
            return None;
        }
        let k = level.k as usize;
        let twin = self.scene.twin(i).and_then(|t| self.levels[t].as_ref());
        if let Some(t) = twin {
            // the lockstep invariant the pairing by index rests on
            assert_eq!(
                (t.k, t.rows.len()),
                (level.k, level.rows.len()),
                "the sides of {} left lockstep",
                self.scene.patches[i].name
            );
        }
        let (b, margin, floor) = (
            &solution.radiosity,
            self.adaptive.margin,
            self.adaptive.floor,
        );
        let values = self.values(&level.rows, twin.map(|t| &t.rows[..]), b);
        Some(match (&level.parent, self.adaptive.test) {
            (Some(parent), Test::Surplus) => {
                let twin_parent = twin.and_then(|t| t.parent.as_deref());
                let predicted = predicted(k, &self.values(parent, twin_parent, b));
                gradient::failing_windows_surplus(k, &values, &predicted, margin, floor)
            }
            _ => gradient::failing_windows(k, &values, margin, floor),
        })
    }

    /// The failing windows of every patch, the twins of a translucent sheet failing together.
    fn failing_windows(&self, solution: &Solution) -> Vec<Option<Vec<bool>>> {
        let n = self.scene.patches.len();
        let mut failing: Vec<_> = (0..n).map(|i| self.failing_of(i, solution)).collect();
        for i in 0..n {
            let Some(t) = self.scene.twin(i).filter(|&t| t > i) else {
                continue;
            };
            match (&failing[i], &failing[t]) {
                (Some(a), Some(b)) => {
                    let both: Vec<bool> = a.iter().zip(b).map(|(x, y)| *x || *y).collect();
                    failing[i] = Some(both.clone());
                    failing[t] = Some(both);
                }
                (None, None) => {}
                _ => panic!(
                    "the sides of {} left lockstep: one is at its depth limit",
                    self.scene.patches[i].name
                ),
            }
        }
        failing
    }

    /// The next level of every patch with a failing window ([`subdivide`]).
    fn plan(&self, failing: &[Option<Vec<bool>>]) -> Plan {
        let mut plan = Plan {
            next: Vec::new(),
            shots: Vec::new(),
            targets: Vec::new(),
        };
        for (i, level) in self.levels.iter().enumerate() {
            let (Some(level), Some(failing)) = (level, &failing[i]) else {
                continue;
            };
            if !failing.iter().any(|f| *f) {
                continue;
            }
            let (rows, shoot) = subdivide(self.scene, i, level.k, &level.rows, failing);
            let k = 2 * level.k;
            for (q, cell, point) in shoot {
                plan.targets.push((plan.next.len(), q, cell));
                plan.shots.push(Shot {
                    patch: i,
                    cell: crate::shots::Cell::Level {
                        k,
                        q: cell.1 * k + cell.0,
                    },
                    point,
                });
            }
            plan.next.push((i, rows));
        }
        plan
    }

    /// Puts the shot `rows` into the planned levels, which replace the current ones.
    fn advance(&mut self, plan: Plan, rows: Vec<ElementRow>, stats: ShotStats) {
        self.stats += stats;
        let Plan {
            mut next, targets, ..
        } = plan;
        for (row, (slot, q, cell)) in rows.into_iter().zip(targets) {
            let report = &mut self.reports[row.patch];
            report.computed.push(ComputedSample {
                depth: report.depth + 1,
                cell,
                point: row.point,
            });
            next[slot].1[q] = Some(row);
        }
        for (i, rows) in next {
            let old = self.levels[i].take().expect("refined patches have a level");
            let k = old.k * 2;
            self.levels[i] = Some(Level {
                k,
                rows: rows
                    .into_iter()
                    .map(|r| r.expect("every element is shot or interpolated"))
                    .collect(),
                parent: Some(old.rows),
            });
            self.reports[i].depth += 1;
            self.reports[i].k = k;
        }
    }

    /// The last levels as pass-1 output, with the last solve.
    fn finish(
        self,
        (matrix, tinted): PatchMatrix,
        solution: Solution,
        rounds: u32,
        samples: u32,
    ) -> Refined {
        let elements: Vec<ElementRow> = self
            .levels
            .into_iter()
            .flatten()
            .flat_map(|l| l.rows)
            .collect();
        Refined {
            form_factors: FormFactors {
                elements,
                matrix,
                tinted,
                samples,
                stats: self.stats,
            },
            solution,
            patches: self.reports,
            rounds,
        }
    }
}

/// What the level before predicts for each element of a k×k level: the linear interpolation
/// of [`lattice`] over its values `parent` (the surplus test's reference).
fn predicted(k: usize, parent: &[[f64; 3]]) -> Vec<[f64; 3]> {
    (0..k * k)
        .map(|q| {
            let mut b = [0.0; 3];
            for (p, w) in lattice::stencil(k / 2, q % k, q / k) {
                for c in 0..3 {
                    b[c] += w * parent[p][c];
                }
            }
            b
        })
        .collect()
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::pass1::form_factors;
    use crate::settings::Pass1Settings;

    /// A floor under a small lamp (also the scene of `footprint`'s tests).
    pub(crate) const SCENE: &str = r#"
[[material]]
name = "m"
diffuse = [0.5, 0.5, 0.5]
[[material]]
name = "lamp"
diffuse = [0.0, 0.0, 0.0]
emission = [1.0, 1.0, 1.0]
[[quad]]
name = "floor"
material = "m"
vertices = [[0, 0, 0], [0, 0, 1], [1.5, 0, 1.2], [1.5, 0, 0.2]]
[[quad]]
name = "lamp"
material = "lamp"
vertices = [[0.2, 0.6, 0.2], [0.5, 0.6, 0.2], [0.5, 0.6, 0.5], [0.2, 0.6, 0.5]]
"#;

    #[test]
    fn interpolating_a_whole_level_changes_no_patch_form_factor() {
        // (4.3) over the interpolated 2k×2k level equals (4.3) over the k×k level: each
        // parent's children average to it (a parallelogram's cells are equal).
        let scene = crate::scene::parse(SCENE, "t.toml").unwrap();
        let settings = Pass1Settings {
            circles: 16,
            samples: 4,
            ..Pass1Settings::default()
        };
        let backend =
            crate::backend::InProcess::new(&scene, &settings, crate::backend::Soft::new()).unwrap();
        let ff = form_factors(&backend, &|_| {}).unwrap();
        let floor: Vec<ElementRow> = ff
            .elements
            .iter()
            .filter(|e| e.patch == 0)
            .cloned()
            .collect();
        let (next, shoot) = subdivide(&scene, 0, 4, &floor, &[false; 9]);
        assert!(shoot.is_empty());
        let next: Vec<ElementRow> = next.into_iter().map(Option::unwrap).collect();
        assert_eq!(next.len(), 64);
        let before = patch_matrix(2, floor.iter()).0;
        let after = patch_matrix(2, next.iter()).0;
        assert!(
            before[0][1] > 0.01,
            "the floor sees the lamp: {}",
            before[0][1]
        );
        assert!(
            (before[0][1] - after[0][1]).abs() < 1e-6 * before[0][1],
            "{} → {}",
            before[0][1],
            after[0][1]
        );
    }

    #[test]
    fn a_failing_window_shoots_the_children_between_its_samples() {
        let scene = crate::scene::parse(SCENE, "t.toml").unwrap();
        let rows: Vec<ElementRow> = (0..16)
            .map(|q| ElementRow {
                patch: 0,
                point: cell_point(&scene, 0, 4, q % 4, q / 4),
                row: vec![(1, [0.1; 3])],
            })
            .collect();
        let mut failing = [false; 9];
        failing[4] = true; // window (1, 1): samples 1..2 × 1..2
        let (next, shoot) = subdivide(&scene, 0, 4, &rows, &failing);
        let cells: Vec<(u32, u32)> = shoot.iter().map(|s| s.1).collect();
        assert_eq!(cells, [(3, 3), (4, 3), (3, 4), (4, 4)]);
        for (q, cell, point) in &shoot {
            assert!(next[*q].is_none());
            assert_eq!(*point, cell_point(&scene, 0, 8, cell.0, cell.1));
        }
        // the others are interpolated from rows that are all alike, so they are alike too
        for r in next.iter().flatten() {
            assert_eq!(r.row, vec![(1, [0.1; 3])]);
        }
    }
}
