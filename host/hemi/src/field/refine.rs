//! Refinement driven by the field's own error: patches whose grid cannot carry their light are
//! sampled twice as finely, within an element budget, and the field is solved again.
//!
//! A grid of spacing h interpolates bilinearly, so its error where the light curves is about
//! C·h². The field's element values on a k×k patch are the light at k×k points; averaged 2 × 2
//! they make the grid the patch would have at k/2, and that coarser grid's miss at each fine
//! point is C·(2h)² − (the fine grid's own miss there, nil at its sample points):
//!
//! ```text
//!     e_k/2(x_q) = |B̃_k/2(x_q) − B_q|,      e_k ≈ e_k/2 / 4      (Richardson, bilinear: h²)
//! ```
//!
//! so the estimate of the k grid's error on patch i is `max_q e_k/2(x_q) / (4 s_q)`, relative to
//! `s_q = max(B_q, floor · B̄_i)` per channel (B̄_i the patch's mean: a contact shadow is
//! judged against its own light, down to the floor). Unlike paper §4's gradient test, which runs on
//! the patch solution's element values (4.2) — whose noise is the hemisphere's quantisation of
//! the lamps, and which it then refines forever (the teapot's Bezier patches reached 64 × 64) —
//! this reads the field, whose direct light is exact ([`crate::direct`]).
//!
//! Each round doubles k on the patches whose estimate exceeds the tolerance, worst first, as
//! long as the scene's element count stays within the budget (the two sides of a translucent
//! sheet together, so their lattices stay paired); the new elements are shot as a level of
//! adaptive sampling is (`shots::level_shot`: the same spins), the patch system (4.3), (2.6) is
//! solved again, and so is the field.

use super::{solve_field_with, Field, FieldSettings};
use crate::backend::{shoot_checked, Backend, Progress};
use crate::direct::{self, Direct, DirectPaths, Emitters};
use crate::grid::Grid;
use crate::pass1::FormFactors;
use crate::radiosity::{combine, patch_gather, ElementIndex};
use crate::scene::Scene;
use crate::shots::{level_shot, ElementRow, Shot};
use crate::solve::Solution;
use hemi_kernel::geometry::Vec3;

/// How the field refines itself.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RefineSettings {
    /// Rounds of refinement at most (0: the field at pass 1's sampling).
    pub rounds: u32,
    /// A patch is refined while its estimated grid error exceeds this fraction of its light.
    pub tolerance: f64,
    /// The least light an error is relative to, as a fraction of the patch's mean.
    pub floor: f64,
    /// The most elements the scene may reach (all patches together); `None`:
    /// [`default_budget`] of pass 1's, so that refinement multiplies the cost of the field by a
    /// bounded factor, whatever a ray costs in the scene (a Bezier patch's hemisphere costs
    /// tens of a polygon scene's).
    pub max_elements: Option<usize>,
    /// The most cells per side one patch may reach.
    pub max_side: u32,
}

/// Elements refinement may reach when not told: 11/4 of pass 1's `elements`. Twice pass 1's
/// ran out before the floor in front of the Cornell box's short block was split finely enough
/// (its last round left 13 cells over the tolerance), which read +1.1 to +2.1 % too bright
/// there against Radiance; 11/4 keeps the Cornell field within 10 s on a 2-core machine
/// (docs/ACCURACY.md, "Four times the query's circles").
pub fn default_budget(elements: usize) -> usize {
    elements.saturating_mul(11) / 4
}

impl Default for RefineSettings {
    fn default() -> Self {
        RefineSettings {
            rounds: 0,
            tolerance: 0.01,
            floor: 0.1,
            max_elements: None,
            max_side: 256,
        }
    }
}

/// What a round of refinement did.
#[derive(Clone, Debug, PartialEq)]
pub struct Round {
    /// Patches refined (scene indices), with the side k they went to.
    pub refined: Vec<(usize, u32)>,
    /// Patches whose estimate exceeded the tolerance but did not fit the budget (or
    /// `max_side`).
    pub left: usize,
    /// Elements after the round.
    pub elements: usize,
}

/// The field refined: the pass-1 output and solve it ended on, the field, and the rounds.
#[derive(Clone, Debug)]
pub struct Refined {
    /// Element rows of the last round (grouped by patch) and their F_ij (4.3).
    pub form_factors: FormFactors,
    /// The solve of (2.6) on them.
    pub solution: Solution,
    /// The field on them.
    pub field: Field,
    /// The rounds done.
    pub rounds: Vec<Round>,
    /// The element budget the rounds had ([`RefineSettings::max_elements`]).
    pub budget: usize,
    /// The worst estimate left on the field, and its patch (`None` if no patch has one).
    pub worst: Option<(usize, f64)>,
}

/// The patch solve of a round's form factors (the caller's solver).
pub type Solve<'a> = dyn Fn(&FormFactors) -> anyhow::Result<Solution> + 'a;

/// The field of `ff`'s solve `sol`, refined by `refine` (see the module notes): the rounds
/// judge the element values (4.2) with the lamps' light exact, which cost no transport, and
/// the field's sweeps ([`solve_field_with`]) run once, on the last round's elements; `solve`
/// solves (2.6) again after each round, `progress` counts shots and sweeps.
pub fn refine_field(
    backend: &dyn Backend,
    mut ff: FormFactors,
    mut sol: Solution,
    settings: &FieldSettings,
    refine: &RefineSettings,
    solve: &Solve<'_>,
    progress: &Progress<'_>,
) -> anyhow::Result<Refined> {
    let scene = backend.scene();
    let budget = refine
        .max_elements
        .unwrap_or(default_budget(ff.elements.len()));
    let emitters =
        (settings.direct == Direct::Exact && direct::applies(backend)).then(|| Emitters::of(scene));
    let mut paths = match &emitters {
        Some(e) => Some(e.paths(backend, &points(&ff.elements))?),
        None => None,
    };
    let mut rounds = Vec::new();
    while rounds.len() < refine.rounds as usize && settings.sweeps > 0 {
        let index = ElementIndex::of(scene, &ff.elements);
        let values = lit_values(
            scene,
            &index,
            &ff.elements,
            &sol,
            emitters.as_ref(),
            paths.as_ref(),
        )?;
        let estimates = estimates(scene, &index, &values, refine.floor);
        let (chosen, left) = choose(scene, &index, &estimates, ff.elements.len(), budget, refine);
        if chosen.is_empty() {
            break;
        }
        ff = subdivide(backend, ff, &index, &chosen, progress)?;
        if let (Some(e), Some(old)) = (&emitters, &paths) {
            paths = Some(carry_paths(backend, e, old, &index, &chosen, &ff.elements)?);
        }
        sol = solve(&ff)?;
        rounds.push(Round {
            refined: chosen,
            left,
            elements: ff.elements.len(),
        });
    }
    let field = solve_field_with(backend, &ff, &sol, settings, paths.as_ref(), progress)?;
    let index = ElementIndex::of(scene, &ff.elements);
    let worst = estimates(scene, &index, &field.values, refine.floor)
        .into_iter()
        .enumerate()
        .filter_map(|(i, e)| e.map(|e| (i, e)))
        .max_by(|a, b| a.1.total_cmp(&b.1));
    Ok(Refined {
        form_factors: ff,
        solution: sol,
        field,
        rounds,
        budget,
        worst,
    })
}

/// The elements' (position, normal), as the lamps' paths take them.
fn points(elements: &[ElementRow]) -> Vec<(Vec3, Vec3)> {
    elements
        .iter()
        .map(|e| (e.point.position, e.point.normal))
        .collect()
}

/// The element values the rounds judge: (4.2) from the patch solution, with the lamps' light
/// from their exact paths instead of the hemisphere's rays where exact direct light applies
/// (so the hemisphere's quantisation of a small lamp is not taken for a gradient). A pass-1
/// row's lamp column sums every path to the lamp, through glossy and several mirrors too, of
/// which the exact paths hold only the direct and once-mirrored ones: in a scene with a
/// reflector the rows are taken as they are.
fn lit_values(
    scene: &Scene,
    index: &ElementIndex,
    elements: &[ElementRow],
    sol: &Solution,
    emitters: Option<&Emitters>,
    paths: Option<&DirectPaths>,
) -> anyhow::Result<Vec<[f64; 3]>> {
    let reflects = scene.materials.iter().any(|m| m.reflects());
    let (Some(emitters), Some(paths), false) = (emitters, paths, reflects) else {
        return Ok(index.values(scene, elements, &sol.radiosity));
    };
    let grids = index.grids(scene, &index.values(scene, elements, &sol.radiosity));
    let direct = paths.irradiance(&grids)?;
    let gathered = |k: usize| {
        let mut h = patch_gather(&elements[k].row, &sol.radiosity, emitters.handled());
        (0..3).for_each(|c| h[c] += direct[k][c]);
        h
    };
    Ok((0..elements.len())
        .map(|k| {
            let patch = elements[k].patch;
            let through = index.twin(scene, patch, k).map(gathered);
            combine(scene.material_of(patch), gathered(k), through)
        })
        .collect())
}

/// The lamps' paths of the elements after a round: the kept elements' carried over from `old`
/// (in `index`'s grouping), the new levels' cast afresh.
fn carry_paths(
    backend: &dyn Backend,
    emitters: &Emitters,
    old: &DirectPaths,
    index: &ElementIndex,
    chosen: &[(usize, u32)],
    elements: &[ElementRow],
) -> anyhow::Result<DirectPaths> {
    let refined = |i: usize| chosen.iter().any(|&(c, _)| c == i);
    let fresh: Vec<(Vec3, Vec3)> = elements
        .iter()
        .filter(|e| refined(e.patch))
        .map(|e| (e.point.position, e.point.normal))
        .collect();
    let new = emitters.paths(backend, &fresh)?;
    let mut picks = Vec::with_capacity(elements.len());
    let (mut next_new, mut seen) = (0, vec![0usize; backend.scene().patches.len()]);
    for e in elements {
        if refined(e.patch) {
            picks.push((1, next_new));
            next_new += 1;
        } else {
            let q = seen[e.patch];
            seen[e.patch] += 1;
            picks.push((0, index.range(e.patch).start + q));
        }
    }
    Ok(DirectPaths::assemble(&[old, &new], &picks))
}

/// Per scene patch, the estimated relative error of its grid (module notes; `floor` as
/// [`RefineSettings::floor`]), `None` where it cannot be estimated (no elements, or an odd side: no coarser grid to compare).
pub fn estimates(
    scene: &Scene,
    index: &ElementIndex,
    values: &[[f64; 3]],
    floor: f64,
) -> Vec<Option<f64>> {
    (0..scene.patches.len())
        .map(|i| estimate(&values[index.range(i)], floor))
        .collect()
}

/// The estimated relative error of the grid of one patch's k×k element values (v-major).
pub fn estimate(values: &[[f64; 3]], floor: f64) -> Option<f64> {
    let k = (values.len() as f64).sqrt().round() as usize;
    if k < 2 || k % 2 == 1 || k * k != values.len() {
        return None;
    }
    let h = k / 2;
    let coarse: Vec<[f64; 3]> = (0..h * h)
        .map(|q| {
            let (a, b) = (2 * (q % h), 2 * (q / h));
            let mut m = [0.0; 3];
            for (da, db) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let v = values[(b + db) * k + a + da];
                (0..3).for_each(|c| m[c] += 0.25 * v[c]);
            }
            m
        })
        .collect();
    let grid = Grid::from_samples(h, &coarse);
    let grey = |x: [f64; 3]| x[0] + x[1] + x[2];
    let mean = values.iter().map(|&v| grey(v)).sum::<f64>() / values.len() as f64;
    let mut worst = 0.0f64;
    for (q, &v) in values.iter().enumerate() {
        let (u, w) = (
            ((q % k) as f64 + 0.5) / k as f64,
            ((q / k) as f64 + 0.5) / k as f64,
        );
        let p = grid.at(u as f32, w as f32);
        let scale = grey(v).max(floor * mean);
        if scale > 0.0 {
            worst = worst.max((grey(p) - grey(v)).abs() / (4.0 * scale));
        }
    }
    Some(worst)
}

/// The patches to refine this round, worst first within the budget (a translucent sheet's two
/// sides together), with their new sides; and how many over the tolerance were left out.
fn choose(
    scene: &Scene,
    index: &ElementIndex,
    estimates: &[Option<f64>],
    elements: usize,
    budget: usize,
    refine: &RefineSettings,
) -> (Vec<(usize, u32)>, usize) {
    let side = |i: usize| (index.range(i).len() as f64).sqrt().round() as u32;
    let mut over: Vec<(usize, f64)> = estimates
        .iter()
        .enumerate()
        .filter_map(|(i, e)| e.filter(|&e| e > refine.tolerance).map(|e| (i, e)))
        .collect();
    over.sort_by(|a, b| b.1.total_cmp(&a.1));
    let (mut total, mut chosen, mut left) = (elements, Vec::new(), 0);
    for (i, _) in over {
        if chosen.iter().any(|&(c, _)| c == i) {
            continue;
        }
        let group: Vec<usize> = std::iter::once(i).chain(scene.twin(i)).collect();
        let k = side(i);
        let cost: usize = group.iter().map(|&g| 3 * index.range(g).len()).sum();
        if 2 * k > refine.max_side || total + cost > budget {
            left += 1;
            continue;
        }
        total += cost;
        chosen.extend(group.into_iter().map(|g| (g, 2 * k)));
    }
    chosen.sort_unstable();
    (chosen, left)
}

/// `ff` with the elements of the `chosen` patches replaced by their new k×k levels, shot on
/// `backend`, and F_ij (4.3) summed again.
fn subdivide(
    backend: &dyn Backend,
    ff: FormFactors,
    index: &ElementIndex,
    chosen: &[(usize, u32)],
    progress: &Progress<'_>,
) -> anyhow::Result<FormFactors> {
    let scene = backend.scene();
    let shots: Vec<Shot> = chosen
        .iter()
        .flat_map(|&(i, k)| (0..k * k).map(move |q| level_shot(scene, i, k, (q % k, q / k))))
        .collect();
    let (rows, stats) = shoot_checked(backend, &shots, progress)?;
    let mut fresh: Vec<Option<Vec<ElementRow>>> = vec![None; scene.patches.len()];
    let mut rows = rows.into_iter();
    for &(i, k) in chosen {
        fresh[i] = Some(rows.by_ref().take((k * k) as usize).collect());
    }
    let FormFactors {
        elements,
        samples,
        stats: before,
        ..
    } = ff;
    let mut elements = elements.into_iter();
    let mut next = Vec::new();
    for (i, new) in fresh.into_iter().enumerate() {
        let old = elements.by_ref().take(index.range(i).len());
        match new {
            Some(rows) => {
                old.for_each(drop);
                next.extend(rows);
            }
            None => next.extend(old),
        }
    }
    let mut stats_all = before;
    stats_all += stats;
    Ok(FormFactors::from_elements(
        scene.patches.len(),
        next,
        samples,
        stats_all,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lattice(k: usize, f: impl Fn(f64, f64) -> f64) -> Vec<[f64; 3]> {
        (0..k * k)
            .map(|q| {
                let (u, v) = (
                    ((q % k) as f64 + 0.5) / k as f64,
                    ((q / k) as f64 + 0.5) / k as f64,
                );
                [f(u, v); 3]
            })
            .collect()
    }

    #[test]
    fn a_plane_of_light_needs_no_refinement() {
        let values = lattice(8, |u, v| 1.0 + 0.5 * u - 0.25 * v);
        let e = estimate(&values, 0.1).unwrap();
        assert!(e < 1e-12, "linear light is interpolated exactly: {e}");
    }

    #[test]
    fn the_estimate_falls_as_h_squared_on_curved_light() {
        let f = |u: f64, v: f64| 1.0 + (3.0 * u).sin() * (2.0 * v).cos();
        let (e8, e16) = (
            estimate(&lattice(8, f), 0.1).unwrap(),
            estimate(&lattice(16, f), 0.1).unwrap(),
        );
        let ratio = e8 / e16;
        assert!(
            (3.0..5.0).contains(&ratio),
            "h² ratio {ratio} ({e8} → {e16})"
        );
    }

    #[test]
    fn the_estimate_bounds_the_grids_own_error() {
        // the k grid's true error between its samples, against the estimate
        let f = |u: f64, v: f64| 1.0 + 0.8 * (-((u - 0.4).powi(2) + (v - 0.6).powi(2)) * 8.0).exp();
        for k in [8usize, 16, 32] {
            let values = lattice(k, f);
            let grid = Grid::from_samples(k, &values);
            let mut truth = 0.0f64;
            for i in 0..=200 {
                for j in 0..=200 {
                    let (u, v) = (0.1 + 0.8 * i as f64 / 200.0, 0.1 + 0.8 * j as f64 / 200.0);
                    let err = (grid.at(u as f32, v as f32)[0] - f(u, v)).abs() / f(u, v);
                    truth = truth.max(err);
                }
            }
            let e = estimate(&values, 0.1).unwrap();
            assert!(
                e > 0.4 * truth && e < 3.0 * truth,
                "k = {k}: estimate {e:.2e}, worst interior error {truth:.2e}"
            );
        }
    }

    #[test]
    fn odd_and_single_lattices_have_no_estimate() {
        assert_eq!(estimate(&lattice(3, |_, _| 1.0), 0.1), None);
        assert_eq!(estimate(&lattice(1, |_, _| 1.0), 0.1), None);
        assert_eq!(estimate(&[], 0.1), None);
    }
}
