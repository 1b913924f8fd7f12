//! Adaptive patch sampling (paper §4): where it refines, where it does not, and what refinement
//! does to the energy of a scene. Small hemispheres (R = 16..32) keep these quick; what they
//! test does not depend on R.

use hemi::adaptive::{refine, AdaptiveSettings, Refined, Test};
use hemi::backend::soft;
use hemi::pass1::{form_factors, FormFactors};
use hemi::radiosity::element_value;
use hemi::scene::{parse, Scene};
use hemi::settings::Pass1Settings;
use hemi::solve::Solution;
use hemi_tests::*;
use std::path::PathBuf;

const TESTS: [Test; 2] = [Test::Surplus, Test::Spread];

fn settings(circles: u32, samples: u32) -> Pass1Settings {
    Pass1Settings {
        circles,
        samples,
        ..Pass1Settings::default()
    }
}

fn adaptive(margin: f64, max_depth: u32, test: Test) -> AdaptiveSettings {
    AdaptiveSettings {
        margin,
        max_depth,
        test,
        ..AdaptiveSettings::default()
    }
}

fn solve(scene: &Scene, ff: &FormFactors) -> Solution {
    hemi::solve::gauss_seidel_scene(scene, ff.channels(), &Default::default()).unwrap()
}

/// Total radiant power leaving the surfaces, Σ_i A_i B_i, per channel.
fn power(scene: &Scene, b: &[[f64; 3]]) -> [f64; 3] {
    let mut p = [0.0; 3];
    for (patch, bi) in scene.patches.iter().zip(b) {
        for c in 0..3 {
            p[c] += patch.area as f64 * bi[c];
        }
    }
    p
}

#[test]
fn a_uniformly_lit_patch_never_refines() {
    // In a closed furnace every element has B = E/(1−ρ) = 2 (rows sum to one), so no window
    // sees a difference and every patch keeps its initial 2×2, even at a 1 % margin and with
    // four levels allowed.
    let src = material("m", 0.5, 1.0) + &closed_box([1.0, 2.0, 1.5], 2, "m");
    let scene = parse(&src, "furnace.toml").unwrap();
    for test in TESTS {
        let r = refine(
            &soft(&scene, &settings(16, 2)).unwrap(),
            &adaptive(0.01, 4, test),
            &|_| {},
        )
        .unwrap();
        assert_eq!(r.rounds, 1, "{test:?}: one solve, no refinement");
        for (p, rep) in scene.patches.iter().zip(&r.patches) {
            assert_eq!((rep.depth, rep.k), (0, 2), "{test:?}: {} refined", p.name);
            assert_eq!(rep.rows_computed(), 4, "{test:?}: {}", p.name);
        }
        for e in &r.form_factors.elements {
            let b = element_value(&scene, e, None, &r.solution.radiosity);
            assert!((b[0] - 2.0).abs() < 1e-4, "{test:?}: element B {}", b[0]);
        }
    }
}

/// A floor (x, z in [0, 1], y = 0; u runs along z, v along x) under a strip light along z at
/// x = 0.5, height 1, and an opaque plate at height 0.25 over x < 0.5: the plate's edge casts a
/// straight shadow edge along z at x = 0.5, with a penumbra only 0.033 wide
/// (0.1 · 0.25 / 0.75): dark for x < 0.483, fully lit for x > 0.517.
fn shadow_scene() -> Scene {
    let mut s = material("floor", 0.6, 0.0) + &material("plate", 0.5, 0.0);
    s += &material("lamp", 0.0, 10.0);
    s += &quad(
        "floor",
        "floor",
        [
            [0.0, 0.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 1.0],
            [1.0, 0.0, 0.0],
        ],
    );
    s += &quad(
        "plate",
        "plate",
        [
            [-1.0, 0.25, -1.0],
            [-1.0, 0.25, 2.0],
            [0.5, 0.25, 2.0],
            [0.5, 0.25, -1.0],
        ],
    );
    s += &quad(
        "lamp",
        "lamp",
        [
            [0.45, 1.0, -0.5],
            [0.55, 1.0, -0.5],
            [0.55, 1.0, 1.5],
            [0.45, 1.0, 1.5],
        ],
    );
    parse(&s, "shadow.toml").unwrap()
}

#[test]
fn a_patch_crossed_by_a_hard_shadow_refines_along_it() {
    let scene = shadow_scene();
    let depth = 4;
    for test in TESTS {
        let r = refine(
            &soft(&scene, &settings(32, 2)).unwrap(),
            // 0.2, not 0.3: the slope stencil of `lattice` predicts a step centred between two
            // samples to within 1/8 of the jump (the plain bilinear one to 1/4), so the
            // surplus of this edge is half what it was
            &adaptive(0.2, depth, test),
            &|_| {},
        )
        .unwrap();
        let floor = &r.patches[0];
        assert_eq!(
            floor.depth, depth,
            "{test:?}: the floor reaches the depth limit"
        );
        let k = floor.k;
        assert_eq!(k, 2 << depth);
        let deepest: Vec<_> = floor.computed.iter().filter(|s| s.depth == depth).collect();
        // along it: every one of the k rows of cells along the edge (u, i.e. z) has a sample
        // shot at the deepest level, and each of those rows has one within a cell of the edge
        let h = 1.0 / k as f32;
        for a in 0..k {
            let near = deepest
                .iter()
                .filter(|s| s.cell.0 == a)
                .map(|s| (s.point.position.x - 0.5).abs())
                .fold(f32::INFINITY, f32::min);
            assert!(
                near <= h,
                "{test:?}: row {a}: nearest deepest sample {near} off the edge"
            );
        }
        // ...and only along it: the deepest samples stay within a band of the edge and are a
        // small part of the deepest lattice
        let widest = deepest
            .iter()
            .map(|s| (s.point.position.x - 0.5).abs())
            .fold(0.0f32, f32::max);
        let share = deepest.len() as f64 / (k * k) as f64;
        println!(
            "{test:?}: floor depth {}, {} rows computed, {} at the deepest level ({:.0} % of {k}×{k}), all within {widest:.3} of the edge",
            floor.depth,
            floor.rows_computed(),
            deepest.len(),
            100.0 * share
        );
        assert!(
            widest < 0.2,
            "{test:?}: a deepest sample {widest} off the edge"
        );
        assert!(
            share < 0.3,
            "{test:?}: {:.0} % of the deepest level shot",
            100.0 * share
        );
        // the lamp is evenly lit by nothing and the plate's top evenly by the lamp's far field:
        // neither goes as deep as the floor
        assert!(
            r.patches[2].depth < depth,
            "{test:?}: lamp depth {}",
            r.patches[2].depth
        );
    }
}

/// A closed box (walls cut 2×2, shared vertices) with one ceiling panel a lamp and a floating
/// block inside: every hemisphere sees only front sides, so every row sums to one.
fn closed_scene() -> Scene {
    let mut s = material("m", 0.5, 0.0) + &material("lamp", 0.5, 10.0);
    s += &closed_box([1.0, 1.0, 1.0], 2, "m").replacen(
        "name = \"f3_0_0\"\nmaterial = \"m\"",
        "name = \"f3_0_0\"\nmaterial = \"lamp\"",
        1,
    );
    // the block [0.4, 0.7] × [0.2, 0.45] × [0.3, 0.6], faces outward
    let (lo, hi) = ([0.4, 0.2, 0.3], [0.7, 0.45, 0.6]);
    let corner = |i: usize| {
        [
            if i & 1 == 0 { lo[0] } else { hi[0] },
            if i & 2 == 0 { lo[1] } else { hi[1] },
            if i & 4 == 0 { lo[2] } else { hi[2] },
        ]
    };
    // counter-clockwise seen from outside
    for (n, f) in [
        [0, 4, 6, 2], // x = lo
        [1, 3, 7, 5], // x = hi
        [0, 1, 5, 4], // y = lo
        [2, 6, 7, 3], // y = hi
        [0, 2, 3, 1], // z = lo
        [4, 5, 7, 6], // z = hi
    ]
    .iter()
    .enumerate()
    {
        s += &quad(&format!("block{n}"), "m", f.map(corner));
    }
    parse(&s, "closed.toml").unwrap()
}

#[test]
fn refinement_keeps_the_energy_totals() {
    let scene = closed_scene();
    let n = scene.patches.len();
    let fine = form_factors(&soft(&scene, &settings(16, 8)).unwrap(), &|_| {}).unwrap();
    let p_fine = power(&scene, &solve(&scene, &fine).radiosity);
    let coarse = form_factors(&soft(&scene, &settings(16, 2)).unwrap(), &|_| {}).unwrap();
    let p_coarse = power(&scene, &solve(&scene, &coarse).radiosity);
    for test in TESTS {
        let r: Refined = refine(
            &soft(&scene, &settings(16, 2)).unwrap(),
            &adaptive(0.1, 2, test),
            &|_| {},
        )
        .unwrap();
        let ff = &r.form_factors;
        assert!(
            r.patches.iter().any(|p| p.depth == 2),
            "{test:?}: something refines"
        );
        // 1. Closure: every element row, shot or interpolated, and every patch row still sums
        //    to one (interpolated rows are affine combinations of shot ones: weights sum to 1).
        for e in &ff.elements {
            let sum: f64 = e.row.iter().map(|(_, f)| f[0] as f64).sum();
            assert!((sum - 1.0).abs() < 1e-4, "{test:?}: element row sum {sum}");
        }
        for (i, row) in ff.matrix.iter().enumerate() {
            let sum: f64 = row.iter().sum();
            assert!(
                (sum - 1.0).abs() < 1e-4,
                "{test:?}: patch {i} row sum {sum}"
            );
        }
        // 2. Balance: in a closed enclosure all emitted power is absorbed,
        //    Σ A_i E_i = Σ A_i (1 − ρ_i) Σ_j F_ij B_j (exact with reciprocity; F's reciprocity
        //    error shows here).
        let b = &r.solution.radiosity;
        let (mut emitted, mut absorbed) = (0.0, 0.0);
        for i in 0..n {
            let m = scene.material_of(i);
            let a = scene.patches[i].area as f64;
            let h: f64 = (0..n).map(|j| ff.matrix[i][j] * b[j][0]).sum();
            emitted += a * m.emission[0];
            absorbed += a * (1.0 - m.diffuse[0]) * h;
        }
        let balance = (absorbed - emitted).abs() / emitted;
        // 3. Totals: the power leaving the surfaces, Σ A_i B_i. With one ρ everywhere in a
        //    closed box it is fixed by closure and reciprocity alone (E_tot/(1 − ρ) when both
        //    hold), so what moves it is that refining patch i improves F_ij but not yet F_ji.
        let p = power(&scene, b);
        let change = (p[0] - p_coarse[0]).abs() / p_coarse[0];
        let to_fine = (p[0] - p_fine[0]).abs() / p_fine[0];
        println!(
            "{test:?}: {} rows; absorbed/emitted − 1 = {balance:.2e}; total power {:.5} (2×2: {:.5}, 8×8: {:.5}): changed by {:.3} %, off 8×8 by {:.3} %",
            r.rows_computed(),
            p[0],
            p_coarse[0],
            p_fine[0],
            100.0 * change,
            100.0 * to_fine
        );
        assert!(balance < 1e-2, "{test:?}: absorbed/emitted − 1 = {balance}");
        assert!(
            change < 5e-3,
            "{test:?}: refinement changed the total power by {change}"
        );
        assert!(
            to_fine < 5e-3,
            "{test:?}: total power off uniform 8×8 by {to_fine}"
        );
    }
}

#[test]
fn margin_zero_reproduces_uniform_sampling_exactly() {
    // With margin 0 every window with any difference fails, so every point of every level is
    // shot, with the same point and hemisphere spin as uniform sampling at that resolution:
    // two levels above a 2×2 guess are uniform 8×8, bit for bit.
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let src = std::fs::read_to_string(root.join("../scenes/cornell.toml")).unwrap();
    let scene = parse(&src, "cornell.toml").unwrap();
    let r = refine(
        &soft(&scene, &settings(16, 2)).unwrap(),
        &adaptive(0.0, 2, Test::Spread),
        &|_| {},
    )
    .unwrap();
    for (p, rep) in scene.patches.iter().zip(&r.patches) {
        assert_eq!(rep.k, 8, "{} stopped at {}", p.name, rep.k);
        assert_eq!(rep.rows_computed(), 4 + 16 + 64);
    }
    let uniform = form_factors(&soft(&scene, &settings(16, 8)).unwrap(), &|_| {}).unwrap();
    assert_eq!(r.form_factors.matrix, uniform.matrix);
    for (a, u) in r.form_factors.elements.iter().zip(&uniform.elements) {
        assert_eq!((a.patch, a.point, &a.row), (u.patch, u.point, &u.row));
    }
}

#[test]
fn bezier_patches_refine_in_the_same_hierarchy() {
    // A domed Bezier sheet (facing up) under a small light off to one side starts from the 16
    // points of §7 and refines to the 8×8 cells of the same (u,v) hierarchy; the weights of a
    // level are its cells' area shares and still sum to one.
    let mut cp = Vec::new();
    for r in 0..4 {
        for c in 0..4 {
            let inner = (1..3).contains(&r) && (1..3).contains(&c);
            let y = if inner { 0.4 } else { 0.0 };
            cp.push(format!("[{}, {y}, {}]", r as f64 / 3.0, c as f64 / 3.0));
        }
    }
    let mut s = material("m", 0.6, 0.0) + &material("lamp", 0.0, 20.0);
    s += &format!(
        "[[bezier]]\nname = \"dome\"\nmaterial = \"m\"\ncontrol_points = [{}]\n\n",
        cp.join(", ")
    );
    s += &quad(
        "lamp",
        "lamp",
        [
            [-0.1, 1.0, -0.1],
            [0.2, 1.0, -0.1],
            [0.2, 1.0, 0.2],
            [-0.1, 1.0, 0.2],
        ],
    );
    let scene = parse(&s, "dome.toml").unwrap();
    let r = refine(
        &soft(&scene, &settings(16, 2)).unwrap(),
        &adaptive(0.05, 1, Test::Surplus),
        &|_| {},
    )
    .unwrap();
    let dome = &r.patches[0];
    assert_eq!((dome.depth, dome.k), (1, 8), "the dome refines once");
    let elements: Vec<_> = r
        .form_factors
        .elements
        .iter()
        .filter(|e| e.patch == 0)
        .collect();
    assert_eq!(elements.len(), 64);
    let w: f64 = elements.iter().map(|e| e.point.weight as f64).sum();
    assert!((w - 1.0).abs() < 1e-3, "weights sum to {w}");
    // the shot points lie on the surface, with its front normal (up, towards the lamp)
    for s in &dome.computed {
        assert!(s.point.normal.y > 0.0, "{:?}", s.point);
    }
}
