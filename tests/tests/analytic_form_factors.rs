//! Pass 1 against Howell's closed forms and the enclosure identities, at default settings
//! (R = 64 circles, K = 8). Tolerances are stated per test; the measured errors are reported in
//! docs/ACCURACY.md (`cargo test -p hemi-tests --release --test analytic_form_factors -- --nocapture`).

// Matrix code: F[i][j] and A[r][c] read as the equations do.
#![expect(
    clippy::needless_range_loop,
    reason = "closed forms and quadratures index several arrays by one subscript"
)]

use hemi::backend::soft;
use hemi::pass1::form_factors;
use hemi::scene::parse;
use hemi::settings::Pass1Settings;
use hemi_kernel::accel::soft::{LocalPatch, SoftAccelerator, SoftScratch};
use hemi_kernel::geometry::{Polygon, Vec3};
use hemi_kernel::hemisphere::{DeltaRule, OwnedHemisphere};
use hemi_kernel::optics::{Optics, Surface};
use hemi_kernel::patch::Patch;
use hemi_kernel::skeleton::{Frame, Skeleton};
use hemi_kernel::tracer::{shoot_hemisphere, TraceScratch};
use hemi_tests::*;

fn ff(scene_src: &str, settings: &Pass1Settings) -> Vec<Vec<f64>> {
    let scene = parse(scene_src, "test.toml").unwrap();
    form_factors(&soft(&scene, settings).unwrap(), &|_| {})
        .unwrap()
        .matrix
        .to_dense()
}

fn rel(got: f64, want: f64) -> f64 {
    (got - want).abs() / want
}

#[test]
fn opposed_parallel_rectangles_within_half_a_percent() {
    for (a, b, c) in [
        (1.0, 1.0, 1.0),
        (2.0, 1.0, 0.5),
        (1.0, 1.0, 3.0),
        (3.0, 0.5, 1.0),
    ] {
        // patch 1 at z = 0 facing +z, patch 2 at z = c facing -z
        let src = material("m", 0.5, 0.0)
            + &quad(
                "p1",
                "m",
                [[0.0, 0.0, 0.0], [a, 0.0, 0.0], [a, b, 0.0], [0.0, b, 0.0]],
            )
            + &quad(
                "p2",
                "m",
                [[0.0, 0.0, c], [0.0, b, c], [a, b, c], [a, 0.0, c]],
            );
        let m = ff(&src, &Pass1Settings::default());
        let want = opposed_rectangles(a, b, c);
        let e = rel(m[0][1], want);
        println!(
            "opposed {a}x{b} at {c}: F = {:.6}, Howell {want:.6}, error {:.3} %",
            m[0][1],
            100.0 * e
        );
        assert!(e < 0.005, "error {e}");
    }
}

#[test]
fn perpendicular_rectangles_with_common_edge_within_half_a_percent() {
    for (l, w, h) in [
        (1.0, 1.0, 1.0),
        (1.0, 2.0, 1.0),
        (2.0, 1.0, 0.5),
        (1.0, 0.5, 2.0),
    ] {
        // common edge along x from 0 to l; patch 1 in the floor (y up), patch 2 the wall z = 0
        let src = material("m", 0.5, 0.0)
            + &quad(
                "floor",
                "m",
                [[0.0, 0.0, 0.0], [0.0, 0.0, w], [l, 0.0, w], [l, 0.0, 0.0]],
            )
            + &quad(
                "wall",
                "m",
                [[0.0, 0.0, 0.0], [l, 0.0, 0.0], [l, h, 0.0], [0.0, h, 0.0]],
            );
        let m = ff(&src, &Pass1Settings::default());
        let want = perpendicular_common_edge(l, w, h);
        let e = rel(m[0][1], want);
        println!(
            "perpendicular l={l} w={w} h={h}: F = {:.6}, Howell {want:.6}, error {:.3} %",
            m[0][1],
            100.0 * e
        );
        assert!(e < 0.005, "error {e}");
    }
}

fn point_ff(target: Polygon, origin: Vec3, normal: Vec3, circles: u32, rule: DeltaRule) -> f64 {
    let hemi = OwnedHemisphere::new(circles, rule).unwrap();
    let patches = [Patch::polygon(target)];
    let mut local = [LocalPatch::default(); 1];
    let mut best_t = vec![0.0; 4 * circles as usize];
    let mut best_id = vec![0; 4 * circles as usize];
    let mut accel = SoftAccelerator::new(
        &patches,
        SoftScratch {
            local: &mut local,
            best_t: &mut best_t,
            best_id: &mut best_id,
        },
    )
    .unwrap();
    let surfaces = [Surface::diffuse(0)];
    let optics = Optics::new(&patches, &surfaces, &[], circles).unwrap();
    let mut frames = [Frame::EMPTY; 1];
    let mut scratch = TraceScratch {
        pending: &mut [],
        parked: &mut [],
        skeleton: Skeleton::new(&mut frames),
        threshold: 0.01,
        max_depth: 8,
    };
    let mut row = [[0.0f32; 3]];
    shoot_hemisphere(
        &mut accel,
        &hemi.view(),
        &optics,
        &mut scratch,
        origin,
        normal,
        0.0,
        None,
        &mut row[..],
    );
    row[0][0] as f64
}

#[test]
fn element_to_rectangle_within_half_a_percent_under_any_orientation() {
    // The configuration is also turned so that the element's normal lies along other axes and a
    // skew direction (the rotation must not change the answer).
    let frames: [(Vec3, Vec3, Vec3); 4] = [
        (
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
        ),
        (
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, 0.0),
        ),
        (
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ),
        (
            Vec3::new(0.6, 0.8, 0.0),
            Vec3::new(-0.48, 0.36, 0.8),
            Vec3::new(0.64, -0.48, 0.6),
        ),
    ];
    let cases = [
        (0.2, 0.3, 1.0, 1.0, 1.0),
        (0.1, 0.1, 2.0, 0.5, 1.0),
        (-0.5, -0.5, 1.0, 1.0, 0.5),
        (0.5, -1.0, 2.0, 2.0, 1.0),
        (-1.5, -1.5, 3.0, 3.0, 0.5),
    ];
    for (x0, y0, a, b, c) in cases {
        let want = element_to_offset_rectangle(x0, y0, a, b, c);
        let (x0, y0, a, b, c) = (x0 as f32, y0 as f32, a as f32, b as f32, c as f32);
        for (ex, ey, ez) in frames {
            let at = |x: f32, y: f32, z: f32| ex * x + ey * y + ez * z;
            let target = Polygon::quad([
                at(x0, y0, c),
                at(x0, y0 + b, c),
                at(x0 + a, y0 + b, c),
                at(x0 + a, y0, c),
            ])
            .unwrap();
            let got = point_ff(target, Vec3::ZERO, ez, 64, DeltaRule::Band);
            let e = rel(got, want);
            println!("element to [{x0},{}]x[{y0},{}] at {c}, normal {:?}: F = {got:.6}, Howell {want:.6}, error {:.3} %", x0 + a, y0 + b, ez.to_array(), 100.0 * e);
            assert!(e < 0.005, "error {e}");
        }
    }
}

#[test]
fn band_rule_is_more_accurate_than_the_paper_rule_on_average() {
    // Element-to-rectangle configurations from a fixed-seed generator: rectangles of varied size,
    // height and offset; both rules at the same R. Rounding N_j to a multiple of four distorts
    // the paper's equal-area weights ring by ring; the band rule does not depend on it.
    let mut rng = hemi_bench::rng::XorShift::new(0x2545_f491_4f6c_dd1d);
    let mut rnd = || rng.f64();
    let (mut band_sum, mut paper_sum, mut n) = (0.0, 0.0, 0);
    for _ in 0..200 {
        let (a, b, c) = (0.1 + 2.0 * rnd(), 0.1 + 2.0 * rnd(), 0.2 + 1.5 * rnd());
        let want = element_to_parallel_rectangle_corner(a, b, c);
        let (a, b, c) = (a as f32, b as f32, c as f32);
        let target = Polygon::quad([
            Vec3::new(0.0, 0.0, c),
            Vec3::new(0.0, b, c),
            Vec3::new(a, b, c),
            Vec3::new(a, 0.0, c),
        ])
        .unwrap();
        band_sum += rel(
            point_ff(target, Vec3::ZERO, Vec3::Z, 32, DeltaRule::Band),
            want,
        );
        paper_sum += rel(
            point_ff(target, Vec3::ZERO, Vec3::Z, 32, DeltaRule::Paper),
            want,
        );
        n += 1;
    }
    let (band, paper) = (band_sum / n as f64, paper_sum / n as f64);
    println!(
        "R=32, 200 element-to-rectangle cases: mean error band rule {:.3} %, paper rule {:.3} %",
        100.0 * band,
        100.0 * paper
    );
    assert!(band < paper, "band {band} paper {paper}");
}

#[test]
fn closed_box_rows_sum_to_one_and_reciprocity_holds() {
    let src = material("m", 0.5, 0.0) + &closed_box([1.0, 0.7, 1.3], 2, "m");
    let scene = parse(&src, "box.toml").unwrap();
    let ffs = form_factors(&soft(&scene, &Pass1Settings::default()).unwrap(), &|_| {}).unwrap();
    let m = &ffs.matrix;
    let mut worst_sum = 0.0f64;
    let mut worst_recip = 0.0f64;
    for i in 0..m.len() {
        let s: f64 = m[i].iter().sum();
        worst_sum = worst_sum.max((s - 1.0).abs());
        for j in 0..m.len() {
            let (ai, aj) = (scene.patches[i].area as f64, scene.patches[j].area as f64);
            let (x, y) = (ai * m[i][j], aj * m[j][i]);
            if x.max(y) > 1e-3 * ai.min(aj) {
                worst_recip = worst_recip.max((x - y).abs() / x.max(y));
            }
        }
    }
    println!(
        "closed box: max |row sum - 1| = {worst_sum:.2e}, max reciprocity error {:.3} %",
        100.0 * worst_recip
    );
    assert!(worst_sum < 1e-4, "row sum off by {worst_sum}");
    assert!(worst_recip < 0.01, "reciprocity off by {worst_recip}");
}

#[test]
fn furnace_gives_e_over_one_minus_rho() {
    for rho in [0.5, 0.9] {
        let src = material("m", rho, 1.0) + &closed_box([1.0, 1.0, 1.0], 1, "m");
        let scene = parse(&src, "furnace.toml").unwrap();
        let ffs = form_factors(&soft(&scene, &Pass1Settings::default()).unwrap(), &|_| {}).unwrap();
        let rhos = vec![[rho; 3]; 6];
        let e = vec![[1.0; 3]; 6];
        let sol =
            hemi::solve::gauss_seidel(ffs.channels(), &rhos, &e, &Default::default()).unwrap();
        let want = 1.0 / (1.0 - rho);
        for b in &sol.radiosity {
            let err = rel(b[0], want);
            assert!(err < 1e-3, "rho {rho}: B = {} want {want}", b[0]);
        }
        println!(
            "furnace rho={rho}: B = {:.6} (want {want}), {} sweeps",
            sol.radiosity[0][0], sol.iterations
        );
    }
}

/// An independent reference: dense Gaussian elimination with partial pivoting in f64.
fn direct_solve(f: &[Vec<f64>], rho: f64, e: &[f64]) -> Vec<f64> {
    let n = f.len();
    let mut a: Vec<Vec<f64>> = (0..n)
        .map(|i| {
            let mut row: Vec<f64> = (0..n)
                .map(|j| if i == j { 1.0 } else { 0.0 } - rho * f[i][j])
                .collect();
            row.push(e[i]);
            row
        })
        .collect();
    for col in 0..n {
        let p = (col..n)
            .max_by(|&x, &y| a[x][col].abs().total_cmp(&a[y][col].abs()))
            .unwrap();
        a.swap(col, p);
        for r in col + 1..n {
            let k = a[r][col] / a[col][col];
            for c in col..=n {
                a[r][c] -= k * a[col][c];
            }
        }
    }
    let mut x = vec![0.0; n];
    for i in (0..n).rev() {
        let s: f64 = (i + 1..n).map(|j| a[i][j] * x[j]).sum();
        x[i] = (a[i][n] - s) / a[i][i];
    }
    x
}

#[test]
fn gauss_seidel_agrees_with_a_direct_solve_on_the_cornell_box() {
    let scene = hemi::scene::load(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../scenes/cornell.toml"
    )))
    .unwrap();
    let settings = Pass1Settings {
        circles: 24,
        samples: 3,
        ..Pass1Settings::default()
    };
    let ffs = form_factors(&soft(&scene, &settings).unwrap(), &|_| {}).unwrap();
    let n = scene.patches.len();
    let rho: Vec<[f64; 3]> = (0..n).map(|i| scene.material_of(i).diffuse).collect();
    let e: Vec<[f64; 3]> = (0..n).map(|i| scene.material_of(i).emission).collect();
    let sol = hemi::solve::gauss_seidel(ffs.channels(), &rho, &e, &Default::default()).unwrap();
    for c in 0..3 {
        // scale F rows by ρ_i into a uniform-ρ form: (I − diag(ρ)F)B = E
        let scaled: Vec<Vec<f64>> = (0..n)
            .map(|i| ffs.matrix[i].iter().map(|f| f * rho[i][c]).collect())
            .collect();
        let ec: Vec<f64> = e.iter().map(|x| x[c]).collect();
        let direct = direct_solve(&scaled, 1.0, &ec);
        for i in 0..n {
            let d = (sol.radiosity[i][c] - direct[i]).abs();
            assert!(
                d <= 1e-6 * direct[i].abs().max(1e-3),
                "patch {i} channel {c}: {} vs {}",
                sol.radiosity[i][c],
                direct[i]
            );
        }
    }
}
