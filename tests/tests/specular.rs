//! Indirect form factors through specular surfaces (paper §3.3, §6.2) against the image method,
//! energy conservation, the glossy → mirror limit, and the bounded skeleton stack.
//! `cargo test -p hemi-tests --release --test specular -- --nocapture` prints the measured errors.

use hemi::backend::soft;
use hemi::pass1::form_factors;
use hemi::scene::{parse, Material, Scene};
use hemi::settings::Pass1Settings;
use hemi_tests::*;

fn mirror(name: &str, k_r: f64, phong: &str) -> String {
    format!(
        "[[material]]\nname = \"{name}\"\ndiffuse = [0, 0, 0]\nspecular = [{k_r}, {k_r}, {k_r}]\nphong = {phong}\n\n"
    )
}

/// Patch p at z = 0 facing +z under a large mirror at z = c/2 facing down: p sees its own image,
/// the identical rectangle directly opposed at distance c, so its indirect self form factor is
/// S_pp = k_r · F(C-11: a × b at distance c).
fn self_image_scene(a: f64, b: f64, c: f64, k_r: f64, phong: &str) -> Scene {
    let h = c / 2.0;
    let big = 50.0;
    let src = material("white", 0.5, 0.0)
        + &mirror("mirror", k_r, phong)
        + &quad(
            "p",
            "white",
            [[0.0, 0.0, 0.0], [a, 0.0, 0.0], [a, b, 0.0], [0.0, b, 0.0]],
        )
        + &quad(
            "mirror",
            "mirror",
            [
                [-big, -big, h],
                [-big, big, h],
                [big, big, h],
                [big, -big, h],
            ],
        );
    parse(&src, "self-image.toml").unwrap()
}

#[test]
fn a_perfect_mirror_shows_the_image_form_factor() {
    // (a, b, c, R, K): near configurations need sample points (K), far ones circles (R), as
    // for direct form factors (docs/ACCURACY.md); the settings keep the test quick.
    for (a, b, c, r, k) in [
        (1.0, 1.0, 1.0, 32, 16),
        (2.0, 1.0, 0.5, 32, 16),
        (1.0, 1.0, 3.0, 64, 16),
    ] {
        let k_r = 0.8;
        let scene = self_image_scene(a, b, c, k_r, "inf");
        let ff = form_factors_at(&scene, r, k);
        let want = k_r * opposed_rectangles(a, b, c);
        let got = ff.matrix[0][0];
        let e = (got - want).abs() / want;
        println!(
            "mirror image {a}x{b} at {c}: S = {got:.6}, k_r·Howell = {want:.6}, error {:.3} %",
            100.0 * e
        );
        // The same tolerance as the direct form factors of the same configuration
        // (analytic_form_factors.rs): the mirror adds no error of its own.
        assert!(e < 0.005, "error {e}");
        // The mirror has no column: its row and column stay empty.
        assert!(ff.matrix[1].iter().all(|f| f == 0.0));
        assert_eq!(ff.matrix[0][1], 0.0);
        assert!(ff.elements.iter().all(|e| e.patch == 0));
    }
}

#[test]
fn coloured_mirrors_give_per_channel_form_factors() {
    let mut scene = self_image_scene(1.0, 1.0, 1.0, 0.8, "inf");
    let m = scene
        .materials
        .iter()
        .position(|m| m.name == "mirror")
        .unwrap();
    scene.materials[m].specular = [0.9, 0.5, 0.1];
    let ff = form_factors_at(&scene, 16, 2);
    let t = ff.tinted.as_ref().expect("coloured mirror: per-channel F");
    let f = [t[0][0][0], t[1][0][0], t[2][0][0]];
    // each channel is k_r of that channel times the same geometric factor
    for c in 1..3 {
        let ratio = f[c] / f[0];
        let want = scene.materials[m].specular[c] / 0.9;
        assert!(
            (ratio - want).abs() < 1e-5,
            "channel {c}: {ratio} vs {want}"
        );
    }
}

/// A closed unit cube of diffuse walls whose floor is a lossless mirror (k_r = 1).
fn mirror_floor_box(phong: &str) -> Scene {
    let mut scene = parse(
        &(material("white", 0.5, 0.0) + &closed_box([1.0, 1.0, 1.0], 2, "white")),
        "box.toml",
    )
    .unwrap();
    scene.materials.push(Material {
        name: "mirror".into(),
        diffuse: [0.0; 3],
        emission: [0.0; 3],
        specular: [1.0; 3],
        transmission: [0.0; 3],
        translucency: [0.0; 3],
        phong: phong.parse().unwrap(),
        frustum_deg: None,
    });
    // face 2 is y = 0, facing +y (tests/src/lib.rs::closed_box)
    for p in scene
        .patches
        .iter_mut()
        .filter(|p| p.name.starts_with("f2_"))
    {
        p.material = 1;
    }
    scene
}

#[test]
fn energy_is_conserved_in_a_closed_box_with_a_lossless_mirror() {
    let scene = mirror_floor_box("inf");
    let ff = form_factors_at(&scene, 32, 4);
    let mut worst = 0.0f64;
    for (i, p) in scene.patches.iter().enumerate() {
        let sum: f64 = ff.matrix[i].iter().sum();
        if p.name.starts_with("f2_") {
            assert_eq!(sum, 0.0, "the mirror has no row");
            continue;
        }
        // every ray ends on a diffuse wall, directly or after bounces on the floor
        assert!(sum <= 1.0 + 2e-3, "{}: row sum {sum}", p.name);
        worst = worst.max((sum - 1.0).abs());
    }
    println!("closed box, lossless mirror floor: worst |row sum − 1| = {worst:.2e}");
    assert!(worst < 2e-3, "worst row-sum error {worst}");
    // nothing was cut: a single mirror cannot bounce a ray twice
    assert_eq!(ff.stats.specular.overflows, 0);
    assert_eq!(ff.stats.specular.below_threshold, 0);
}

#[test]
fn a_glossy_lobe_loses_only_what_goes_through_the_surface() {
    let scene = mirror_floor_box("30");
    let ff = form_factors_at(&scene, 24, 3);
    let s = ff.stats.specular;
    let hemispheres = ff.elements.len() as f64;
    for (i, p) in scene.patches.iter().enumerate() {
        if p.name.starts_with("f2_") {
            continue;
        }
        let sum: f64 = ff.matrix[i].iter().sum();
        assert!(sum <= 1.0 + 2e-3, "{}: row sum {sum}", p.name);
        assert!(sum > 0.9, "{}: row sum {sum}", p.name);
    }
    // What the rows miss is accounted for: every element of this box has the same area weight
    // (1/16 of an equal patch), so Σ_i (1 − ΣF_ij) = Σ_elements (1 − row sum) / 16, and in a
    // closed box every hemisphere ray ends on a wall, so an element's row misses exactly what
    // its frustums absorbed, cut below Δ, lost to a full stack, or let out through the
    // box's seams.
    let rows: Vec<usize> = (0..scene.patches.len())
        .filter(|i| !scene.patches[*i].name.starts_with("f2_"))
        .collect();
    let missing: f64 = rows
        .iter()
        .map(|&i| 1.0 - ff.matrix[i].iter().sum::<f64>())
        .sum();
    let per_patch = hemispheres / rows.len() as f64;
    let accounted =
        (s.absorbed_weight + s.cut_weight + s.overflow_weight + s.escaped_weight) / per_patch;
    println!(
        "glossy floor n = 30: rows miss {missing:.5} in total; absorbed + cut + overflow + escaped = {accounted:.5}"
    );
    assert!(
        (missing - accounted).abs() < 2e-4,
        "{missing} vs {accounted}"
    );
    assert!(s.frustums > 0 && s.rays > 0);
}

#[test]
fn glossy_reflection_converges_to_the_mirror_as_the_power_grows() {
    let (a, b, c) = (1.0, 1.0, 1.0);
    let mirror = form_factors_at(&self_image_scene(a, b, c, 0.8, "inf"), 24, 4).matrix[0][0];
    let mut last = f64::INFINITY;
    for n in ["20", "200", "2000", "20000"] {
        let glossy = form_factors_at(&self_image_scene(a, b, c, 0.8, n), 24, 4).matrix[0][0];
        let d = (glossy - mirror).abs() / mirror;
        println!(
            "phong {n}: S = {glossy:.6}, mirror {mirror:.6}, difference {:.3} %",
            100.0 * d
        );
        assert!(d <= last + 1e-4, "not converging: {d} after {last}");
        last = d;
    }
    assert!(last < 0.01, "n = 20000 still {last} away from the mirror");
}

#[test]
fn cut_paths_are_reported_not_fatal() {
    // a diffuse patch between two parallel mirrors: rays along the normal bounce for ever
    let k = 0.99;
    let src = material("white", 0.5, 0.0)
        + &mirror("m", k, "inf")
        + &quad(
            "p",
            "white",
            [
                [0.4, 0.4, 0.5],
                [0.6, 0.4, 0.5],
                [0.6, 0.6, 0.5],
                [0.4, 0.6, 0.5],
            ],
        )
        + &quad(
            "top",
            "m",
            [
                [-5.0, -5.0, 1.0],
                [-5.0, 5.0, 1.0],
                [5.0, 5.0, 1.0],
                [5.0, -5.0, 1.0],
            ],
        )
        + &quad(
            "bottom",
            "m",
            [
                [-5.0, -5.0, 0.0],
                [5.0, -5.0, 0.0],
                [5.0, 5.0, 0.0],
                [-5.0, 5.0, 0.0],
            ],
        );
    let scene = parse(&src, "mirrors.toml").unwrap();
    let mut settings = Pass1Settings {
        circles: 16,
        samples: 2,
        ..Pass1Settings::default()
    };
    settings.specular.max_bounces = 6;
    let ff = form_factors(&soft(&scene, &settings).unwrap(), &|_| {}).unwrap();
    let s = ff.stats.specular;
    println!("{s:?}");
    // rays along the normal would bounce for ever: the depth limit cuts them and says so
    assert!(s.too_deep > 0 && s.too_deep_weight > 0.0, "{s:?}");
    assert_eq!(s.overflows, 0);

    // glossy parallel mirrors spawn many frustums per frustum: a small stack overflows, and
    // the cut is counted, not fatal
    let glossy = src.replace("phong = inf", "phong = 5\nfrustum = 20");
    let scene = parse(&glossy, "glossy-mirrors.toml").unwrap();
    settings.specular.stack = 3;
    settings.specular.threshold = 0.001;
    let g = form_factors(&soft(&scene, &settings).unwrap(), &|_| {}).unwrap();
    let s = g.stats.specular;
    println!("{s:?}");
    assert!(s.overflows > 0 && s.overflow_weight > 0.0, "{s:?}");
    assert_eq!(s.high_water, 3);
    assert!(g.matrix[0][0].is_finite());
    // the patch sees itself in the mirrors (through the gap around it) and nothing is NaN
    assert!(ff.matrix[0][0].is_finite() && ff.matrix[0][0] > 0.0);
}

#[test]
fn pass_2_sees_a_light_in_a_mirror_at_k_r_times_its_radiance() {
    // A mirror floor (k_r = 0.5) and an emitting wall of radiance 1 (E = π, no reflectance);
    // the camera looks down at the floor, where the wall's image fills the centre.
    let src = mirror("m", 0.5, "inf")
        + "[[material]]\nname = \"lamp\"\ndiffuse = [0, 0, 0]\nemission = [3.141592653589793, 3.141592653589793, 3.141592653589793]\n\n"
        + &quad(
            "floor",
            "m",
            [[-20.0, 0.0, -20.0], [-20.0, 0.0, 20.0], [20.0, 0.0, 20.0], [20.0, 0.0, -20.0]],
        )
        + &quad(
            "wall",
            "lamp",
            [[-3.0, 0.5, 5.0], [-3.0, 4.0, 5.0], [3.0, 4.0, 5.0], [3.0, 0.5, 5.0]],
        )
        + "[camera]\neye = [0, 1, -2]\nlook_at = [0, -1, 3]\nup = [0, 1, 0]\nfov_y_deg = 20\nwidth = 9\nheight = 9\n";
    let scene = parse(&src, "mirror-lamp.toml").unwrap();
    let settings = Pass1Settings {
        circles: 16,
        samples: 2,
        ..Pass1Settings::default()
    };
    let ff = form_factors(&soft(&scene, &settings).unwrap(), &|_| {}).unwrap();
    let sol = hemi::solve::gauss_seidel_scene(&scene, ff.channels(), &Default::default()).unwrap();
    let grids = hemi::radiosity::grids(&scene, &ff, &sol);
    let camera = hemi::render::camera_of(&scene).unwrap();
    let out = hemi::render::render(
        &soft(&scene, &settings).unwrap(),
        hemi::irradiance::Light::of(&grids),
        &camera,
        1,
        &|_| {},
    )
    .unwrap();
    let centre = out.image.pixels[4 * 9 + 4];
    println!("centre pixel {centre:?}, {:?}", out.specular);
    for c in centre {
        assert!((c - 0.5).abs() < 1e-4, "{centre:?}");
    }
    assert!(out.specular.frustums > 0);
}

#[test]
fn a_window_passes_k_t_of_the_form_factor_behind_it() {
    // p1 at z = 0 facing +z, p2 at z = 1 facing −z (Howell C-11), and between them a large
    // clear sheet (k_t = 0.7, phong = inf) whose front faces away from p1: transmission passes
    // light from either side, so F_12 = k_t · F(C-11).
    let k_t = 0.7;
    let src = material("white", 0.5, 0.0)
        + &format!(
            "[[material]]\nname = \"glass\"\ndiffuse = [0, 0, 0]\ntransmission = [{k_t}, {k_t}, {k_t}]\nphong = inf\n\n"
        )
        + &quad(
            "p1",
            "white",
            [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
        )
        + &quad(
            "p2",
            "white",
            [[0.0, 0.0, 1.0], [0.0, 1.0, 1.0], [1.0, 1.0, 1.0], [1.0, 0.0, 1.0]],
        )
        + &quad(
            "glass",
            "glass",
            [[-9.0, -9.0, 0.5], [9.0, -9.0, 0.5], [9.0, 9.0, 0.5], [-9.0, 9.0, 0.5]],
        );
    let scene = parse(&src, "window.toml").unwrap();
    let ff = form_factors_at(&scene, 32, 16);
    let want = k_t * opposed_rectangles(1.0, 1.0, 1.0);
    let got = ff.matrix[0][1];
    let e = (got - want).abs() / want;
    println!(
        "through a window: F = {got:.6}, k_t·Howell = {want:.6}, error {:.3} %",
        100.0 * e
    );
    assert!(e < 0.005, "error {e}");
    // and symmetric from the other side (the sheet's back)
    let back = ff.matrix[1][0];
    assert!((back - got).abs() / got < 0.005, "{back} vs {got}");
}

#[test]
fn the_model_backend_agrees_with_soft_through_a_mirror() {
    // scenes/mirror-wall.toml through the accelerator model (fixed-point CORDIC and intersection
    // unit) and the f32 soft engine: the same kernel walks the frustums on both.
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let scene = hemi::scene::load(&root.join("scenes/mirror-wall.toml")).unwrap();
    let settings = Pass1Settings {
        circles: 12,
        samples: 2,
        ..Pass1Settings::default()
    };
    let soft = form_factors(&soft(&scene, &settings).unwrap(), &|_| {}).unwrap();
    let model = hemi::backend::model(&scene, &settings, Default::default()).unwrap();
    let model = form_factors(&model, &|_| {}).unwrap();
    assert!(soft.stats.specular.frustums > 0);
    let mut worst = 0.0f64;
    for (a, b) in soft.matrix.iter().zip(&model.matrix) {
        for (x, y) in a.iter().zip(b) {
            worst = worst.max((x - y).abs());
        }
    }
    // The radiosities: what the model's fixed point changes in the answer.
    let solve = |ff: &hemi::pass1::FormFactors| {
        hemi::solve::gauss_seidel_scene(&scene, ff.channels(), &Default::default())
            .unwrap()
            .radiosity
    };
    let (bs, bm) = (solve(&soft), solve(&model));
    let mut worst_b = 0.0f64;
    for (x, y) in bs.iter().zip(&bm) {
        for c in 0..3 {
            worst_b = worst_b.max((x[c] - y[c]).abs() / x[c].max(1e-3));
        }
    }
    println!(
        "mirror-wall, soft vs model: worst |ΔF| = {worst:.2e}, worst relative ΔB = {worst_b:.2e}"
    );
    // The model's CORDIC moves a ray by up to its error (about 4e-6 rad at the reset
    // configuration, 20 iterations on 24-bit words; ~1e-7 at 24 on 32); a ray that then lands
    // on the other side of an edge moves one F by one δD (≈ 4e-3 at R = 12), so F agrees to a
    // few δD, and B, which averages over all rays, closer (at 24 on 32 2.2e-3 at worst, on a
    // small box face whose 4 samples see the light past an edge; at 20 on 24, 0).
    assert!(worst < 1.5e-2, "{worst}");
    assert!(worst_b < 5e-3, "{worst_b}");
}
