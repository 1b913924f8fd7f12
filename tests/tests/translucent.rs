//! Diffuse transmission, k_y ρ_y of (2.2) (`translucency` in the scene format): a two-sided
//! sheet against Howell's C-11 through it, energy balance in a closed box divided by a sheet,
//! and pass 2 and irradiance seeing the back side.
//! `cargo test -p hemi-tests --release --test translucent -- --nocapture` prints the errors.

use hemi::backend::soft;
use hemi::pass1::{form_factors, FormFactors};
use hemi::scene::{parse, Scene};
use hemi::settings::Pass1Settings;
use hemi::solve::{self, SceneParts, Solution};
use hemi_tests::*;

fn sheet_material(name: &str, rho: f64, tau: f64) -> String {
    format!(
        "[[material]]\nname = \"{name}\"\ndiffuse = [{rho}, {rho}, {rho}]\ntranslucency = [{tau}, {tau}, {tau}]\n\n"
    )
}

fn solved(scene: &Scene, ff: &FormFactors) -> Solution {
    let parts = SceneParts::new(scene, ff.channels());
    solve::solve(
        &parts.system(ff.channels()).unwrap(),
        solve::Solver::Auto,
        &Default::default(),
        &mut |_| {},
    )
    .unwrap()
}

const RHO: f64 = 0.3;
const TAU: f64 = 0.5;

/// A light (a × a at z = 0, facing +z), a translucent sheet of the same size at z = c facing the
/// light, and a black receiver at z = 2c facing down: the light reaches the receiver only
/// through the sheet.
fn sandwich(a: f64, c: f64) -> Scene {
    let src = material("light", 0.0, 1.0)
        + &material("black", 0.0, 0.0)
        + &sheet_material("sheet", RHO, TAU)
        + &quad(
            "light",
            "light",
            [[0.0, 0.0, 0.0], [a, 0.0, 0.0], [a, a, 0.0], [0.0, a, 0.0]],
        )
        + &quad(
            "sheet",
            "sheet",
            [[0.0, 0.0, c], [0.0, a, c], [a, a, c], [a, 0.0, c]],
        )
        + &quad(
            "receiver",
            "black",
            [
                [0.0, 0.0, 2.0 * c],
                [0.0, a, 2.0 * c],
                [a, a, 2.0 * c],
                [a, 0.0, 2.0 * c],
            ],
        )
        + &format!(
            "[camera]\neye = [{h}, {h}, {z}]\nlook_at = [{h}, {h}, 0]\nup = [0, 1, 0]\nfov_y_deg = 10\nwidth = 5\nheight = 5\n",
            h = a / 2.0,
            z = 1.5 * c
        );
    parse(&src, "sandwich.toml").unwrap()
}

#[test]
fn the_back_side_is_a_patch_of_its_own() {
    let scene = sandwich(1.0, 1.0);
    let names: Vec<&str> = scene.patches.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["light", "sheet", "receiver", "sheet:back"]);
    assert_eq!(scene.kernel_patches().len(), 3);
    assert_eq!(scene.twin(1), Some(3));
    assert_eq!(scene.twin(3), Some(1));
    assert_eq!(scene.side_seen(1, false), 3);
    assert_eq!(scene.side_seen(1, true), 1);
}

#[test]
fn each_side_sees_its_own_half_space() {
    let (a, c) = (1.0, 1.0);
    let scene = sandwich(a, c);
    let ff = form_factors_at(&scene, 48, 12);
    let m = &ff.matrix;
    let (light, sheet, receiver, back) = (0, 1, 2, 3);
    let howell = opposed_rectangles(a, a, c);
    let rel = |x: f64| (x - howell).abs() / howell;
    println!(
        "F(light→sheet) {:.5}, F(back→receiver) {:.5}, F(receiver→back) {:.5}; Howell C-11 {howell:.5}",
        m[light][sheet], m[back][receiver], m[receiver][back]
    );
    for f in [
        m[light][sheet],
        m[sheet][light],
        m[back][receiver],
        m[receiver][back],
    ] {
        assert!(rel(f) < 5e-3, "{f} against {howell}");
    }
    // the sheet blocks: nothing passes geometrically, and a side sees nothing behind it
    for (i, j) in [
        (light, receiver),
        (receiver, light),
        (light, back),
        (receiver, sheet),
        (sheet, receiver),
        (back, light),
    ] {
        assert_eq!(m[i][j], 0.0, "F[{i}][{j}]");
    }
}

#[test]
fn light_through_the_sheet_is_tau_of_what_its_front_gathers() {
    let (a, c) = (1.0, 1.0);
    let scene = sandwich(a, c);
    let settings = Pass1Settings {
        circles: 48,
        samples: 12,
        ..Pass1Settings::default()
    };
    let ff = form_factors(&soft(&scene, &settings).unwrap(), &|_| {}).unwrap();
    let sol = solved(&scene, &ff);
    let b = &sol.radiosity;
    // B_front = ρ F E, B_back = τ F E (the receiver is black, the light does not reflect)
    let f = ff.matrix[1][0];
    let howell = opposed_rectangles(a, a, c);
    println!(
        "B(sheet) {:.5} = ρF {:.5}; B(sheet:back) {:.5} = τF {:.5}; τ·Howell {:.5}",
        b[1][0],
        RHO * f,
        b[3][0],
        TAU * f,
        TAU * howell
    );
    assert!((b[1][0] - RHO * f).abs() < 1e-9);
    assert!((b[3][0] - TAU * f).abs() < 1e-9);
    assert!((b[3][0] - TAU * howell).abs() < 5e-3 * TAU * howell);
    assert_eq!(b[2][0], 0.0);

    // pass 2 sees the back side's radiosity from behind the sheet
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
    let centre = out.image.pixels[2 * 5 + 2];
    let want = grids[3].at(0.5, 0.5)[0] / std::f64::consts::PI;
    println!("centre pixel {centre:?}, B(back)/π at the centre {want:.5}");
    assert!(want > 0.0);
    assert!((centre[0] as f64 - want).abs() < 1e-4 * want.max(1.0));

    // irradiance at the receiver's centre, facing the sheet, gathers the back side
    let backend = soft(&scene, &settings).unwrap();
    let query = hemi::backend::Query {
        point: hemi_kernel::geometry::Vec3::new(0.5, 0.5, 2.0 * c as f32 - 1e-4),
        normal: hemi_kernel::geometry::Vec3::new(0.0, 0.0, -1.0),
    };
    let e = hemi::irradiance::irradiance(
        &backend,
        hemi::irradiance::Light::of(&grids),
        &[query],
        &hemi::irradiance::QuerySettings {
            direct: hemi::irradiance::Direct::Hemisphere,
            near_levels: 0,
            ..hemi::irradiance::QuerySettings::default()
        },
    )
    .unwrap()[0];
    // E = ∫ B_back(x) cos θ cos θ' / (π r²) dA over the sheet, by a fine midpoint sum over its
    // grid (the configuration is symmetric in x and y, so the grid's (u,v) orientation does
    // not matter)
    let steps = 400;
    let mut want = 0.0;
    for i in 0..steps {
        for j in 0..steps {
            let (u, v) = (
                (i as f64 + 0.5) / steps as f64,
                (j as f64 + 0.5) / steps as f64,
            );
            let (dx, dy) = (a * u - 0.5, a * v - 0.5);
            let r2 = dx * dx + dy * dy + c * c;
            let b = grids[3].at(u as f32, v as f32)[0];
            want += b * c * c / (std::f64::consts::PI * r2 * r2) * (a * a) / (steps * steps) as f64;
        }
    }
    // The hemisphere at one point and R = 48 overestimates the point's form factor to the sheet
    // by about 1.4 % (its own discretisation, as for any point), so compare what the back side
    // contributes per unit of form factor: E / E(B_back = 1) against ∫B dF / F(Howell).
    let mut flat = grids.clone();
    flat[3] = hemi::radiosity::Grid::from_samples(1, &[[1.0; 3]]);
    let e1 = hemi::irradiance::irradiance(
        &backend,
        hemi::irradiance::Light::of(&flat),
        &[query],
        &hemi::irradiance::QuerySettings {
            direct: hemi::irradiance::Direct::Hemisphere,
            near_levels: 0,
            ..hemi::irradiance::QuerySettings::default()
        },
    )
    .unwrap()[0];
    let f_point = 4.0 * element_to_parallel_rectangle_corner(a / 2.0, a / 2.0, c);
    let (got, expect) = (e[0] / e1[0], want / f_point);
    println!(
        "irradiance {:.5}, with B(back) = 1 {:.5} (Howell {f_point:.5}); mean B(back) seen {got:.5}, by quadrature {expect:.5} ({:+.3} %)",
        e[0],
        e1[0],
        100.0 * (got - expect) / expect
    );
    assert!((got - expect).abs() < 5e-3 * expect);
}

#[test]
fn a_divided_box_balances_emitted_and_absorbed_power() {
    // A closed unit box of grey walls cut in two by a translucent sheet at x = 0.5; the light is
    // a ceiling quad on the x < 0.5 side. The x > 0.5 half is lit only through the sheet.
    let n = 2;
    let (rho, tau) = (0.35, 0.45);
    let src = material("white", 0.5, 0.0)
        + &material("light", 0.0, 4.0)
        + &sheet_material("sheet", rho, tau)
        + &closed_box([1.0, 1.0, 1.0], n, "white")
        + &quad(
            "sheet",
            "sheet",
            [
                [0.5, 0.0, 0.0],
                [0.5, 1.0, 0.0],
                [0.5, 1.0, 1.0],
                [0.5, 0.0, 1.0],
            ],
        );
    // the light: the ceiling quad (y = 1, face 3) over z, x ∈ [0, 0.5]
    let mut scene = parse(&src, "divided.toml").unwrap();
    let lamp = scene.patch_index("f3_0_0").unwrap();
    scene.patches[lamp].material = 1;
    let ff = form_factors_at(&scene, 48, 8);
    let sol = solved(&scene, &ff);
    let b = &sol.radiosity;
    let m = &ff.matrix;
    let mut emitted = 0.0;
    let mut absorbed = 0.0;
    for (i, p) in scene.patches.iter().enumerate() {
        let mat = scene.material_of(i);
        let area = p.area as f64;
        emitted += area * mat.emission[0];
        let h: f64 = (0..b.len()).map(|j| m[i][j] * b[j][0]).sum();
        absorbed += area * (1.0 - mat.diffuse[0] - mat.translucency[0]) * h;
    }
    let balance = (absorbed - emitted).abs() / emitted;
    let lit = |name: &str| {
        let ids: Vec<usize> = (0..scene.patches.len())
            .filter(|&i| scene.patches[i].name.starts_with(name))
            .collect();
        ids.iter().map(|&i| b[i][0]).sum::<f64>() / ids.len() as f64
    };
    println!(
        "emitted {emitted:.5}, absorbed {absorbed:.5}: balance {:.3} %; B(sheet) {:.4}, B(sheet:back) {:.4}, B(far wall x=1) {:.4}, B(near wall x=0) {:.4}",
        100.0 * balance,
        lit("sheet"),
        lit("sheet:back"),
        lit("f1_"),
        lit("f0_"),
    );
    assert!(balance < 0.02, "balance {balance}");
    assert!(lit("f1_") > 0.0, "the far half is lit through the sheet");
}

#[test]
fn adaptive_sampling_refines_the_sides_of_a_sheet_together() {
    let scene = sandwich(1.0, 1.0);
    let settings = Pass1Settings {
        circles: 16,
        samples: 2,
        ..Pass1Settings::default()
    };
    // margin 0: every window with any difference fails, so the lit sheet's level is uniform
    // 4×4 sampling, bit for bit, on both its sides (the back side at its front's points, facing
    // the other way)
    let every = hemi::adaptive::AdaptiveSettings {
        margin: 0.0,
        max_depth: 1,
        ..Default::default()
    };
    let got = hemi::adaptive::refine(&soft(&scene, &settings).unwrap(), &every, &|_| {}).unwrap();
    let four = Pass1Settings {
        samples: 4,
        ..settings
    };
    let uniform = form_factors(&soft(&scene, &four).unwrap(), &|_| {}).unwrap();
    let (front, back) = (1, scene.twin(1).unwrap());
    let sheet = |e: &&hemi::shots::ElementRow| e.patch == front || e.patch == back;
    let g: Vec<_> = got.form_factors.elements.iter().filter(sheet).collect();
    let w: Vec<_> = uniform.elements.iter().filter(sheet).collect();
    assert_eq!(g.len(), 32, "both sides at 4×4");
    assert_eq!(g.len(), w.len());
    for (g, w) in g.iter().zip(&w) {
        assert_eq!((g.patch, g.point, &g.row), (w.patch, w.point, &w.row));
    }
    // The light is a step across the sheet's front (bright in the middle, the receiver black):
    // with a margin, the sheet and its back side reach the same depth and lattice, and the
    // back side's radiosity is τF·E as with uniform sampling.
    let adaptive = hemi::adaptive::AdaptiveSettings {
        margin: 0.02,
        max_depth: 2,
        ..Default::default()
    };
    let got =
        hemi::adaptive::refine(&soft(&scene, &settings).unwrap(), &adaptive, &|_| {}).unwrap();
    let (pf, pb) = (&got.patches[front], &got.patches[back]);
    assert_eq!(
        (pf.k, pf.depth),
        (pb.k, pb.depth),
        "twins refined in lockstep"
    );
    assert_eq!(pf.k, 8, "the sheet refined to its depth limit");
    let f = got.form_factors.matrix[1][0];
    let b = &got.solution.radiosity;
    println!(
        "adaptive: sheet k = {}, B(sheet) {:.5} (ρF {:.5}), B(back) {:.5} (τF {:.5})",
        pf.k,
        b[front][0],
        RHO * f,
        b[back][0],
        TAU * f
    );
    assert!((b[front][0] - RHO * f).abs() < 1e-6 * f);
    assert!((b[back][0] - TAU * f).abs() < 1e-6 * f);
}

#[test]
fn a_sheet_may_not_reflect_and_transmit_more_than_it_receives() {
    let bad = sheet_material("s", 0.6, 0.5)
        + &quad(
            "q",
            "s",
            [
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [0.0, 1.0, 0.0],
            ],
        );
    let err = parse(&bad, "bad.toml").unwrap_err();
    assert!(format!("{err:#}").contains("translucency"), "{err:#}");
}

#[test]
fn progressive_refinement_with_rows_on_demand_solves_the_coupled_sides() {
    // Rows shot on demand (no matrix): the shooter's column of K = ρF + τF_twin comes from its
    // row of F alone by reciprocity, F_ji = F_ij A_i / A_j (a sheet's sides have one area), as
    // Cohen et al. turn the shooter's row into its column. So it solves the system whose F is
    // the reciprocal of the stored matrix: against that, solved with the coupled matrices.
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let scene = hemi::scene::load(&root.join("scenes/paper-screen.toml")).unwrap();
    let settings = Pass1Settings {
        circles: 12,
        samples: 2,
        ..Pass1Settings::default()
    };
    let ff = form_factors(&soft(&scene, &settings).unwrap(), &|_| {}).unwrap();
    let n = scene.patches.len();
    let area = |i: usize| scene.patches[i].area as f64;
    let reciprocal: Vec<Vec<f64>> = (0..n)
        .map(|j| {
            (0..n)
                .map(|i| ff.matrix[i][j] * area(i) / area(j))
                .collect()
        })
        .collect();
    let reciprocal = hemi::matrix::FormMatrix::from(reciprocal);
    let k = hemi::solve::coupled(&scene, [&reciprocal, &reciprocal, &reciprocal])
        .expect("the scene is translucent");
    let e: Vec<[f64; 3]> = (0..n).map(|i| scene.material_of(i).emission).collect();
    let ones = vec![[1.0; 3]; n];
    let want = solve::gauss_seidel([&k[0], &k[1], &k[2]], &ones, &e, &Default::default()).unwrap();

    let backend = soft(&scene, &settings).unwrap();
    let mut shooter = hemi::on_demand::RowShooter::new(&backend, 0).unwrap();
    let got = hemi::on_demand::solve_streaming(&mut shooter, &Default::default(), &mut |_, _| {})
        .unwrap();
    let scale = want
        .radiosity
        .iter()
        .flatten()
        .fold(0.0f64, |m, x| m.max(*x));
    let mut worst = 0.0f64;
    for (g, w) in got.radiosity.iter().zip(&want.radiosity) {
        for c in 0..3 {
            worst = worst.max((g[c] - w[c]).abs() / scale);
        }
    }
    let back = scene.twin(
        scene
            .patches
            .iter()
            .position(|p| p.name == "screen")
            .unwrap(),
    );
    let back = back.unwrap();
    println!(
        "progressive on demand: worst |ΔB| / max B = {worst:.1e}; B(screen:back) {:.5} vs {:.5}",
        got.radiosity[back][0], want.radiosity[back][0]
    );
    assert!(worst < 1e-7, "{worst}");
    assert!(got.radiosity[back][0] > 0.1);

    // The grids from rows shot again equal the stored rows' grids for the same solution: each
    // side adds what comes through from its twin's element at the same point.
    let got_grids = hemi::on_demand::grids_streaming(&mut shooter, &got).unwrap();
    let want_grids = hemi::radiosity::grids(&scene, &ff, &got);
    for (i, (g, w)) in got_grids.iter().zip(&want_grids).enumerate() {
        for (u, v) in [(0.1, 0.1), (0.5, 0.5), (0.9, 0.3)] {
            let (a, b) = (g.at(u, v), w.at(u, v));
            for c in 0..3 {
                assert!(
                    (a[c] - b[c]).abs() <= 1e-12 * scale,
                    "{}: {a:?} vs {b:?}",
                    scene.patches[i].name
                );
            }
        }
    }
}
