//! Stability: each test drives one failure regime of the method and checks its remedy, with the
//! tolerance stated where it is asserted. Small R and K keep every test to about a second.
//! `cargo test -p hemi-tests --release --test stability -- --nocapture` prints what they measure.

// Matrix code: F[i][j] reads as the equations do.

use hemi::backend::soft;
use hemi::method::Method;
use hemi::pass1::{form_factors, FormFactors};
use hemi::scene::{parse, Scene};
use hemi::settings::Pass1Settings;
use hemi::solve::{self, diagnose, SolveSettings, Solver, System};
use hemi_kernel::hemisphere::ray_count;
use hemi_kernel::peers::hemicube::Hemicube;
use hemi_tests::*;

const METHODS: [Method; 3] = [
    Method::Hemisphere,
    Method::Hemicube,
    Method::MonteCarlo { stratified: true },
];

fn run(scene: &Scene, method: Method, circles: u32, samples: u32) -> FormFactors {
    let settings = Pass1Settings {
        circles,
        samples,
        method,
        ..Pass1Settings::default()
    };
    form_factors(&soft(scene, &settings).unwrap(), &|_| {}).unwrap()
}

/// What a full hemisphere of `method` adds up to: 1 for the hemisphere (band rule) and Monte
/// Carlo; the centre-point hemicube's Σ ΔF, which is 1 only in the limit.
fn full_weight(method: Method, circles: u32) -> f64 {
    match method {
        Method::Hemicube => Hemicube::for_rays(ray_count(circles)).delta_sum(),
        _ => 1.0,
    }
}

fn system_of<'a>(
    scene: &Scene,
    ff: &'a FormFactors,
    rho: &'a mut Vec<[f64; 3]>,
    e: &'a mut Vec<[f64; 3]>,
) -> System<'a> {
    *rho = (0..scene.patches.len())
        .map(|i| scene.material_of(i).diffuse)
        .collect();
    *e = (0..scene.patches.len())
        .map(|i| scene.material_of(i).emission)
        .collect();
    System::new(ff.channels(), rho, e).unwrap()
}

#[test]
fn white_furnace_meets_e_over_one_minus_rho_through_the_solver_auto_picks() {
    // A closed box of 24 patches, all emitting 1 and reflecting ρ = 0.99: B = E/(1−ρ) = 100.
    // The spectral radius of ρF is 0.99, where Gauss-Seidel needs about a thousand sweeps; auto
    // must see that and take the dense LU.
    let rho = 0.99;
    let src = material("m", rho, 1.0) + &closed_box([1.0, 1.0, 1.0], 2, "m");
    let scene = parse(&src, "furnace.toml").unwrap();
    let ff = run(&scene, Method::Hemisphere, 16, 2);
    let (mut r, mut e) = (vec![], vec![]);
    let sys = system_of(&scene, &ff, &mut r, &mut e);
    let d = diagnose(&sys);
    assert!(d.radius_low > 0.985 && d.radius_high < 0.995, "{d:?}");
    let mut said = String::new();
    let sol = solve::solve(&sys, Solver::Auto, &SolveSettings::default(), &mut |m| {
        said += m
    })
    .unwrap();
    println!("{said}");
    assert_eq!(sol.solver, Solver::Direct, "{said}");
    assert!(said.contains("dense LU"), "{said}");
    let want = 1.0 / (1.0 - rho);
    let worst = sol
        .radiosity
        .iter()
        .flatten()
        .map(|b| (b - want).abs() / want)
        .fold(0.0, f64::max);
    println!("furnace ρ = {rho}: worst |B − E/(1−ρ)| / (E/(1−ρ)) = {worst:.2e}");
    // rows of a closed box sum to 1 within f32 accumulation (~1e-6), amplified by 1/(1−ρ) = 100
    assert!(worst < 1e-3, "{worst}");
    // the remedy is needed: Gauss-Seidel gets there too, but only after hundreds of sweeps
    let gs = solve::gauss_seidel::solve(&sys, &SolveSettings::default()).unwrap();
    println!("Gauss-Seidel: {} sweeps", gs.iterations);
    assert!(gs.iterations > 300, "{}", gs.iterations);
}

#[test]
fn oversampled_rows_with_rho_near_one_are_detected_and_scaled_back() {
    // Rows summing 1 % above 1 (sampling error) with ρ = 0.995: ρ ΣF > 1, no bounded solution
    // exists and Gauss-Seidel's residual grows. auto detects the rows, scales them back to 1
    // (energy conservation), and meets E/(1−ρ).
    let n = 6;
    let f: Vec<Vec<f64>> = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| if i == j { 0.0 } else { 1.01 / (n - 1) as f64 })
                .collect()
        })
        .collect();
    let rho = vec![[0.995; 3]; n];
    let e = vec![[1.0; 3]; n];
    let f = hemi::matrix::FormMatrix::from(f);
    let sys = System::new(solve::grey(&f), &rho, &e).unwrap();
    let err = solve::gauss_seidel::solve(&sys, &SolveSettings::default()).unwrap_err();
    assert!(format!("{err}").contains("diverge"), "{err}");
    let mut said = String::new();
    let sol = solve::solve(&sys, Solver::Auto, &SolveSettings::default(), &mut |m| {
        said += m
    })
    .unwrap();
    assert!(said.contains("6 rows of F above 1"), "{said}");
    for b in &sol.radiosity {
        assert!((b[0] - 200.0).abs() < 1e-6 * 200.0, "{b:?}");
    }
}

#[test]
fn grazing_rays_along_a_wall_neither_leak_nor_go_nan() {
    // A closed unit box whose floor has a strip ε wide along the wall x = 0: the strip's sample
    // points are within ε/2 of the wall, so half their hemisphere grazes it.
    for eps in [1e-2, 1e-4] {
        let mut src = material("m", 0.5, 0.0);
        let q = |name: &str, v: [[f64; 3]; 4]| quad(name, "m", v);
        src += &q(
            "strip",
            [
                [0.0, 0.0, 0.0],
                [0.0, 0.0, 1.0],
                [eps, 0.0, 1.0],
                [eps, 0.0, 0.0],
            ],
        );
        src += &q(
            "floor",
            [
                [eps, 0.0, 0.0],
                [eps, 0.0, 1.0],
                [1.0, 0.0, 1.0],
                [1.0, 0.0, 0.0],
            ],
        );
        src += &q(
            "wall_x0",
            [
                [0.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 1.0, 1.0],
                [0.0, 0.0, 1.0],
            ],
        );
        src += &q(
            "wall_x1",
            [
                [1.0, 0.0, 0.0],
                [1.0, 0.0, 1.0],
                [1.0, 1.0, 1.0],
                [1.0, 1.0, 0.0],
            ],
        );
        src += &q(
            "ceiling",
            [
                [0.0, 1.0, 0.0],
                [1.0, 1.0, 0.0],
                [1.0, 1.0, 1.0],
                [0.0, 1.0, 1.0],
            ],
        );
        src += &q(
            "wall_z0",
            [
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [0.0, 1.0, 0.0],
            ],
        );
        src += &q(
            "wall_z1",
            [
                [0.0, 0.0, 1.0],
                [0.0, 1.0, 1.0],
                [1.0, 1.0, 1.0],
                [1.0, 0.0, 1.0],
            ],
        );
        let scene = parse(&src, "grazing.toml").unwrap();
        for method in METHODS {
            let ff = run(&scene, method, 16, 3);
            let want = full_weight(method, 16);
            assert!(ff
                .matrix
                .iter()
                .flatten()
                .all(|f| f.is_finite() && f >= 0.0));
            let strip: f64 = ff.matrix[0].iter().sum();
            // half the strip's hemisphere is the wall beside it
            let wall = ff.matrix[0][2];
            println!(
                "ε = {eps:e} {}: strip row sum {strip:.6} (full {want:.6}), to the wall {wall:.4}",
                method.name()
            );
            // watertight: every ray from inside a closed box ends on a wall (f32 sums: 1e-4)
            assert!((strip - want).abs() < 1e-4, "{}: {strip}", method.name());
            // and half of it, less what passes beyond the wall's ends, is the wall (1 % above
            // half allows Monte Carlo's noise)
            assert!(
                wall > 0.45 && wall < 0.505 * want,
                "{}: {wall}",
                method.name()
            );
        }
    }
}

#[test]
fn rays_through_shared_edges_and_corners_do_not_leak() {
    // A closed 1×2×3 box, 3×3 quads per face sharing edges and corners exactly: no ray from
    // inside may leave it, so every row sums to the method's full weight.
    let src = material("m", 0.5, 0.0) + &closed_box([1.0, 2.0, 3.0], 3, "m");
    let scene = parse(&src, "box.toml").unwrap();
    for method in METHODS {
        let ff = run(&scene, method, 16, 2);
        let want = full_weight(method, 16);
        let worst = ff
            .matrix
            .iter()
            .map(|row| (row.iter().sum::<f64>() - want).abs())
            .fold(0.0, f64::max);
        println!(
            "{}: {} patches, worst |row sum − {want:.6}| = {worst:.2e} ({} rays)",
            method.name(),
            scene.patches.len(),
            ff.stats.rays
        );
        assert!(worst < 1e-4, "{}: {worst}", method.name());
    }
}

#[test]
fn normals_on_every_axis_give_the_same_form_factors() {
    // The unit cube, one patch per face: the faces' normals are ±x, ±y, ±z. Each face sees the
    // opposite face by Howell C-11 and each neighbour by C-14, whatever its axis.
    let src = material("m", 0.5, 0.0) + &closed_box([1.0, 1.0, 1.0], 1, "m");
    let scene = parse(&src, "cube.toml").unwrap();
    let opposite = opposed_rectangles(1.0, 1.0, 1.0);
    let adjacent = perpendicular_common_edge(1.0, 1.0, 1.0);
    // (method, tolerance against Howell at R = 32, K = 8): the hemisphere's is that of
    // docs/ACCURACY.md at these settings (1.4 % worst); the peers are held to 3 %.
    for (method, tol) in [
        (Method::Hemisphere, 0.02),
        (Method::Hemicube, 0.03),
        (Method::MonteCarlo { stratified: true }, 0.03),
    ] {
        let ff = run(&scene, method, 32, 8);
        let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
        for i in 0..6 {
            // closed_box orders faces (x=0, x=1, y=0, y=1, z=0, z=1): the opposite of i is i^1
            let o = ff.matrix[i][i ^ 1];
            lo = lo.min(o);
            hi = hi.max(o);
            assert!(
                (o - opposite).abs() / opposite < tol,
                "{} face {i}: {o} vs {opposite}",
                method.name()
            );
            for j in (0..6).filter(|j| *j != i && *j != (i ^ 1)) {
                let a = ff.matrix[i][j];
                assert!(
                    (a - adjacent).abs() / adjacent < tol,
                    "{} face {i}→{j}: {a} vs {adjacent}",
                    method.name()
                );
            }
        }
        println!(
            "{}: F(opposite) over the six axes in [{lo:.5}, {hi:.5}], Howell {opposite:.5}",
            method.name()
        );
        // the same sample pattern turned onto each axis: the spread is rotation rounding only
        assert!((hi - lo) / opposite < 2e-3, "{}: {lo}..{hi}", method.name());
    }
}

/// A flat bicubic patch that is the triangle (a, b, c) with the edge u = 0 collapsed onto `c`
/// (a pole): P(u, v) = c + u·((1−v)·a + v·b − c), bilinear, so its control points are its values
/// at (i/3, j/3).
fn pole_triangle(name: &str, a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> String {
    let mut pts = Vec::new();
    for r in 0..4 {
        for col in 0..4 {
            let (u, v) = (col as f64 / 3.0, r as f64 / 3.0);
            let p: Vec<String> = (0..3)
                .map(|k| format!("{}", c[k] + u * ((1.0 - v) * a[k] + v * b[k] - c[k])))
                .collect();
            pts.push(format!("[{}]", p.join(", ")));
        }
    }
    format!(
        "[[bezier]]\nname = \"{name}\"\nmaterial = \"m\"\ncontrol_points = [{}]\n\n",
        pts.join(", ")
    )
}

#[test]
fn pole_collapsed_and_degenerate_bezier_patches_stay_finite_and_bounded() {
    // The same triangle as a pole-collapsed Bezier patch and as a polygon, under a unit square
    // at height 1: the form factors both ways must agree within 3 % (16 Bezier sample points of
    // paper §7, several of them next to the pole where the normal is a limit, against K = 4),
    // and nothing may be NaN.
    let (a, b, c) = ([1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 0.5, 0.0]);
    let square = quad(
        "square",
        "m",
        [
            [0.0, 0.0, 1.0],
            [0.0, 1.0, 1.0],
            [1.0, 1.0, 1.0],
            [1.0, 0.0, 1.0],
        ],
    );
    let bez = parse(
        &(material("m", 0.5, 0.0) + &pole_triangle("tri", a, b, c) + &square),
        "pole.toml",
    )
    .unwrap();
    let fmt = |p: [f64; 3]| format!("[{}, {}, {}]", p[0], p[1], p[2]);
    let tri = format!(
        "[[triangle]]\nname = \"tri\"\nmaterial = \"m\"\nvertices = [{}, {}, {}]\n\n",
        fmt(c),
        fmt(a),
        fmt(b)
    );
    let poly = parse(&(material("m", 0.5, 0.0) + &tri + &square), "tri.toml").unwrap();
    let area_err = (bez.patches[0].area - poly.patches[0].area).abs() / poly.patches[0].area;
    assert!(
        area_err < 1e-3,
        "areas {} vs {}",
        bez.patches[0].area,
        poly.patches[0].area
    );
    let fb = run(&bez, Method::Hemisphere, 32, 4).matrix;
    let fp = run(&poly, Method::Hemisphere, 32, 4).matrix;
    assert!(fb.iter().flatten().all(|f| f.is_finite()), "{fb:?}");
    for (i, j) in [(0, 1), (1, 0)] {
        let e = (fb[i][j] - fp[i][j]).abs() / fp[i][j];
        println!(
            "pole-collapsed Bezier F[{i}][{j}] = {:.5}, polygon {:.5}: {:.2} %",
            fb[i][j],
            fp[i][j],
            100.0 * e
        );
        assert!(e < 0.03, "F[{i}][{j}]: {} vs {}", fb[i][j], fp[i][j]);
    }
    // a patch collapsed to a point has no area and no normal: refused, by name
    let point: Vec<String> = (0..16).map(|_| "[0.5, 0.5, 0.0]".to_string()).collect();
    let src = material("m", 0.5, 0.0)
        + &format!(
            "[[bezier]]\nname = \"dot\"\nmaterial = \"m\"\ncontrol_points = [{}]\n\n",
            point.join(", ")
        )
        + &square;
    let err = parse(&src, "dot.toml").unwrap_err();
    assert!(
        format!("{err:#}").contains("dot") && format!("{err:#}").contains("degenerate"),
        "{err:#}"
    );
}

#[test]
fn a_specular_loop_between_parallel_mirrors_keeps_the_stack_bound_and_reports_the_loss() {
    // A diffuse patch between two parallel mirrors k_r = 0.9 facing each other: rays near the
    // normal bounce until the depth limit, glossy lobes multiply frustums until the stack is full.
    let mirror = "[[material]]\nname = \"mirror\"\ndiffuse = [0, 0, 0]\nspecular = [0.9, 0.9, 0.9]\nphong = inf\n\n";
    let q = |name: &str, m: &str, v: [[f64; 3]; 4]| quad(name, m, v);
    let src = material("m", 0.5, 0.0)
        + mirror
        + &q(
            "p",
            "m",
            [
                [0.4, 0.4, 0.5],
                [0.6, 0.4, 0.5],
                [0.6, 0.6, 0.5],
                [0.4, 0.6, 0.5],
            ],
        )
        + &q(
            "top",
            "mirror",
            [
                [-5.0, -5.0, 1.0],
                [-5.0, 5.0, 1.0],
                [5.0, 5.0, 1.0],
                [5.0, -5.0, 1.0],
            ],
        )
        + &q(
            "bottom",
            "mirror",
            [
                [-5.0, -5.0, 0.0],
                [5.0, -5.0, 0.0],
                [5.0, 5.0, 0.0],
                [-5.0, 5.0, 0.0],
            ],
        );
    // perfect mirrors: a path carries 0.9^d after d bounces, so what the depth limit cuts is at
    // most 0.9^max_bounces of each hemisphere
    for max_bounces in [4u16, 8, 16] {
        let scene = parse(&src, "mirrors.toml").unwrap();
        let mut settings = Pass1Settings {
            circles: 16,
            samples: 2,
            ..Pass1Settings::default()
        };
        settings.specular.max_bounces = max_bounces;
        settings.specular.threshold = 1e-6;
        let ff = form_factors(&soft(&scene, &settings).unwrap(), &|_| {}).unwrap();
        let s = ff.stats.specular;
        let per_hemisphere = s.too_deep_weight / ff.elements.len() as f64;
        let bound = 0.9f64.powi(max_bounces as i32);
        println!("perfect mirrors, at most {max_bounces} bounces: cut {per_hemisphere:.4} per hemisphere (bound {bound:.4}), high water {}, S_pp = {:.5}", s.high_water, ff.matrix[0][0]);
        assert!(
            s.too_deep > 0 && per_hemisphere > 0.0 && per_hemisphere <= bound,
            "{s:?}"
        );
        assert!(ff.matrix[0][0].is_finite() && ff.matrix[0][0] > 0.0 && ff.matrix[0][0] < 1.0);
    }
    // glossy mirrors: frustums of many rays, each spawning more; the stack bound holds and what
    // a full stack drops is reported, less of it the larger the stack
    let glossy = src.replace("phong = inf", "phong = 5\nfrustum = 20");
    let scene = parse(&glossy, "glossy.toml").unwrap();
    let mut last = f64::INFINITY;
    for stack in [1usize, 2, 4, 8] {
        let mut settings = Pass1Settings {
            circles: 12,
            samples: 1,
            ..Pass1Settings::default()
        };
        settings.specular.stack = stack;
        settings.specular.max_bounces = 6;
        settings.specular.threshold = 1e-3;
        let ff = form_factors(&soft(&scene, &settings).unwrap(), &|_| {}).unwrap();
        let s = ff.stats.specular;
        println!(
            "glossy, stack {stack}: high water {}, {} overflows losing {:.4}, S_pp = {:.5}",
            s.high_water, s.overflows, s.overflow_weight, ff.matrix[0][0]
        );
        assert!(s.high_water as usize <= stack, "{s:?}");
        assert!(ff.matrix[0][0].is_finite() && ff.matrix[0][0] >= 0.0);
        assert!(
            s.overflow_weight <= last + 1e-9,
            "stack {stack}: {} after {last}",
            s.overflow_weight
        );
        last = s.overflow_weight;
        if stack == 1 {
            assert!(s.overflows > 0 && s.overflow_weight > 0.0, "{s:?}");
        }
    }
}
