//! Hardware-in-the-loop over QEMU: the firmware as the ray engine. Form factors, a small render
//! and an irradiance query through two QEMU boards (jobs spread over both, through ptys and the
//! `serialport` crate) equal the in-process `model` backend's bit for bit: same kernel, same
//! accelerator model. Adaptive sampling through the two boards (`ShootLevel` jobs) equals it
//! in-process too. Small R and K keep it quick. The same, and an irradiance query, through the mirror of
//! `scenes/mirror-wall.toml` on one board (protocol 3: the optics table uploaded), at two
//! CORDIC settings sent to the board.
//!
//! Skips (passes with a printed notice) only when qemu-system-arm is missing and
//! HEMI_REQUIRE_QEMU is unset.

use hemi::backend::{Backend, Query};
use hemi::irradiance::{Direct, Light, QuerySettings};
use hemi::pass1::{self, form_factors};
use hemi::scene::Scene;
use hemi::settings::Pass1Settings;
use hemi_boards::{BoardSpec, Boards, Farm, FarmOptions};
use hemi_hdl_model::ModelConfig;
use hemi_kernel::geometry::Vec3;
use hemi_kernel::hemisphere::DeltaRule;
use hemi_kernel::jobs::ENGINE_CAPACITIES;
use hemi_kernel::link::{AccelKind, Capacities, PROTOCOL_VERSION};
use hemi_tests::{big_stack, cornell_scene, qemu_or_skip};

fn settings() -> Pass1Settings {
    Pass1Settings {
        circles: 8,
        samples: 2,
        rule: DeltaRule::Band,
        ..Pass1Settings::default()
    }
}

/// The in-process model backend of `config`.
fn model<'s>(scene: &'s Scene, settings: &Pass1Settings, config: ModelConfig) -> impl Backend + 's {
    hemi::backend::model(scene, settings, config).expect("the model loads the scene")
}

/// The farm's boards as a backend (each board's own engine).
fn boards<'a>(farm: &'a Farm, scene: &'a Scene, settings: &Pass1Settings) -> Boards<'a> {
    Boards::new(farm, scene, settings, AccelKind::None).expect("the boards take the scene")
}

/// Pass 1 on `backend`.
fn pass1_on(backend: &dyn Backend) -> pass1::FormFactors {
    form_factors(backend, &|_| {}).unwrap()
}

fn solve(scene: &Scene, ff: &pass1::FormFactors) -> Vec<hemi::radiosity::Grid> {
    let f = ff.channels();
    let sol = hemi::solve::gauss_seidel_scene(scene, f, &Default::default()).unwrap();
    hemi::radiosity::grids(scene, ff, &sol)
}

/// Bit patterns, so that equality means identical, not merely close.
fn bits(m: &hemi::matrix::FormMatrix) -> Vec<Vec<u64>> {
    m.iter()
        .map(|r| r.iter().map(|x| x.to_bits()).collect())
        .collect()
}

/// Two pass-1 results are the same: every row, once, at the same point, and the matrix, bit
/// for bit.
fn assert_same_pass1(got: &pass1::FormFactors, want: &pass1::FormFactors, what: &str) {
    assert_eq!(
        got.elements.len(),
        want.elements.len(),
        "{what}: every row, once"
    );
    for (g, w) in got.elements.iter().zip(&want.elements) {
        assert_eq!((g.patch, g.point), (w.patch, w.point), "{what}");
        assert_eq!(g.row, w.row, "{what}: row of patch {} differs", g.patch);
    }
    assert_eq!(bits(&got.matrix), bits(&want.matrix), "{what}");
}

/// Adaptive sampling through the farm's boards equals it in-process on the model of `config`:
/// the same rows computed, in the same rounds, and the same result. Returns the in-process one.
fn assert_same_adaptive(
    farm: &Farm,
    scene: &Scene,
    settings: &Pass1Settings,
    adaptive: &hemi::adaptive::AdaptiveSettings,
    config: ModelConfig,
) -> hemi::adaptive::Refined {
    let refine = |b: &dyn Backend| hemi::adaptive::refine(b, adaptive, &|_| {}).unwrap();
    let want = refine(&model(scene, settings, config));
    let got = refine(&boards(farm, scene, settings));
    assert_eq!(got.rows_computed(), want.rows_computed());
    assert_eq!(got.rounds, want.rounds);
    assert_same_pass1(&got.form_factors, &want.form_factors, "adaptive");
    want
}

/// A `width` × `height` render (2 samples per pixel) of `scene`'s camera through the boards
/// equals the in-process model's, bit for bit; returns it.
fn assert_same_small_render(
    farm: &Farm,
    scene: &Scene,
    settings: &Pass1Settings,
    grids: &[hemi::radiosity::Grid],
    config: ModelConfig,
    (width, height): (u32, u32),
) -> hemi::render::Rendered {
    let mut small = scene.clone();
    if let Some(c) = small.camera.as_mut() {
        c.width = width;
        c.height = height;
    }
    let camera = hemi::render::camera_of(&small).unwrap();
    let render =
        |b: &dyn Backend| hemi::render::render(b, Light::of(grids), &camera, 2, &|_| {}).unwrap();
    let want = render(&model(&small, settings, config));
    let got = render(&boards(farm, scene, settings));
    assert_eq!((got.image.width, got.image.height), (width, height));
    let px = |img: &hemi::render::Image| -> Vec<[u32; 3]> {
        img.pixels.iter().map(|p| p.map(f32::to_bits)).collect()
    };
    assert_eq!(px(&got.image), px(&want.image));
    want
}

/// Point queries as the paper gathers them: every hit read off the grids, the lamps' light from
/// the hemisphere (the near field and exact direct light only make more of the same requests).
const HEMISPHERE_ONLY: QuerySettings = QuerySettings {
    direct: Direct::Hemisphere,
    near_levels: 0,
    near_cells: hemi::irradiance::near::NEAR,
};

/// The irradiance at `p` facing `n` through the boards equals the in-process model's, bit for
/// bit; returns it.
fn assert_same_irradiance(
    farm: &Farm,
    scene: &Scene,
    settings: &Pass1Settings,
    grids: &[hemi::radiosity::Grid],
    config: ModelConfig,
    (point, normal): (Vec3, Vec3),
) -> [f64; 3] {
    let query = [Query { point, normal }];
    let gather = |b: &dyn Backend| {
        hemi::irradiance::irradiance(b, Light::of(grids), &query, &HEMISPHERE_ONLY).unwrap()[0]
    };
    let want = gather(&model(scene, settings, config));
    let got = gather(&boards(farm, scene, settings));
    assert_eq!(got.map(f64::to_bits), want.map(f64::to_bits));
    got
}

/// The field solved on `backend` as `hemi solve` solves it (pass 1, the patch solve, exact
/// direct light where the scene allows, the element transport recorded, the gather sweeps),
/// with `rounds` of refinement by the field's own error.
fn field_on(backend: &dyn Backend, rounds: u32) -> hemi::field::refine::Refined {
    use hemi::field::{refine, FieldSettings};
    let ff = pass1_on(backend);
    let scene = backend.scene();
    let patch_solve = |ff: &pass1::FormFactors| {
        hemi::solve::gauss_seidel_scene(scene, ff.channels(), &Default::default())
    };
    let sol = patch_solve(&ff).unwrap();
    let settings = FieldSettings {
        sweeps: 20,
        refine: refine::RefineSettings {
            rounds,
            ..Default::default()
        },
        ..Default::default()
    };
    refine::refine_field(
        backend,
        ff,
        sol,
        &settings,
        &settings.refine,
        &patch_solve,
        &|_| {},
    )
    .unwrap()
}

/// The field through the farm's boards (protocol 5: `Hemisphere` jobs for the transport, `Cast`
/// jobs for the shadow rays of exact direct light) equals it in-process on the model, bit for
/// bit: the same refinement, the same sweeps, the same grids. Returns the in-process one.
fn assert_same_field(
    farm: &Farm,
    scene: &Scene,
    settings: &Pass1Settings,
    config: ModelConfig,
    rounds: u32,
) -> hemi::field::refine::Refined {
    let want = field_on(&model(scene, settings, config), rounds);
    let got = field_on(&boards(farm, scene, settings), rounds);
    assert_eq!(got.rounds, want.rounds);
    assert_eq!(got.field.sweeps, want.field.sweeps);
    assert_eq!(got.field.how, want.field.how);
    let grid_bits = |f: &hemi::field::Field| -> Vec<Vec<u64>> {
        f.values
            .iter()
            .map(|v| v.map(f64::to_bits).to_vec())
            .collect()
    };
    assert_eq!(grid_bits(&got.field), grid_bits(&want.field));
    assert_eq!(
        got.field.direct.is_some(),
        want.field.direct.is_some(),
        "exact direct light on both or on neither"
    );
    want
}

/// Point queries as `hemi irradiance` makes them (each query's own hemisphere on a finer
/// backend: here 2R, which keeps QEMU quick, where the CLI's default is 4R; exact direct light
/// with shadow rays, shadows' edges relit, `near_levels` of near field) through the boards
/// equal the in-process model's, bit for bit; returns them. On the boards the queries' own
/// hemispheres are a second backend on the same farm, so the boards are configured for 2R and
/// back for every request. Each near-field level below the first is
/// the same requests again, and the default four cost about 200 s a query on a QEMU board at
/// R = 8 (every evaluation its own hemisphere and shadow rays).
fn assert_same_full_irradiance(
    farm: &Farm,
    scene: &Scene,
    (settings, field): (&Pass1Settings, &hemi::field::Field),
    config: ModelConfig,
    queries: &[Query],
    near_levels: u32,
) -> Vec<[f64; 3]> {
    let light = Light {
        grids: &field.grids,
        direct: field.direct.as_ref(),
    };
    let gather = |b: &dyn Backend, own: &dyn Backend| {
        let settings = QuerySettings {
            near_levels,
            ..QuerySettings::default()
        };
        hemi::irradiance::irradiance_with(b, own, light, queries, &settings).unwrap()
    };
    let own_settings = Pass1Settings {
        circles: 2 * settings.circles,
        ..*settings
    };
    let want = gather(
        &model(scene, settings, config),
        &model(scene, &own_settings, config),
    );
    let got = gather(
        &boards(farm, scene, settings),
        &boards(farm, scene, &own_settings),
    );
    let bits =
        |e: &[[f64; 3]]| -> Vec<[u64; 3]> { e.iter().map(|x| x.map(f64::to_bits)).collect() };
    assert_eq!(bits(&got), bits(&want));
    want
}

#[test]
fn form_factors_render_and_irradiance_through_two_qemu_boards_equal_the_model_backend() {
    if !qemu_or_skip("hil_jobs") {
        return;
    }
    big_stack(run);
}

fn run() {
    let scene = cornell_scene();
    let settings = settings();
    let farm = Farm::connect(&[BoardSpec::Qemu, BoardSpec::Qemu], FarmOptions::default())
        .expect("boot two boards");
    for hello in farm.hellos() {
        let hello = hello.expect("connected");
        assert_eq!(hello.protocol, PROTOCOL_VERSION);
        assert_eq!(
            hello.accel,
            AccelKind::Model,
            "QEMU builds run the HDL model"
        );
        // the QEMU model build has RAM for hemispheres up to R = 256 (kernel `large-engine`)
        assert_eq!(
            hello.caps,
            Capacities {
                max_circles: 256,
                ..ENGINE_CAPACITIES
            }
        );
    }

    // Pass 1.
    let make = ModelConfig::default();
    let want = pass1_on(&model(&scene, &settings, make));
    let got = pass1_on(&boards(&farm, &scene, &settings));
    assert_same_pass1(&got, &want, "pass 1");
    // and at the host's default R = 64, which the QEMU build's engine holds (K = 1 keeps it
    // quick)
    let r64 = Pass1Settings {
        circles: 64,
        samples: 1,
        ..settings
    };
    let want64 = pass1_on(&model(&scene, &r64, make));
    let got64 = pass1_on(&boards(&farm, &scene, &r64));
    assert_eq!(bits(&got64.matrix), bits(&want64.matrix));

    // Pass 2 on a small image.
    let grids = solve(&scene, &want);
    let img = assert_same_small_render(&farm, &scene, &settings, &grids, make, (24, 20)).image;
    assert!(
        img.pixels.iter().any(|p| p[0] > 0.0),
        "the image is not black"
    );

    // An irradiance query (the gather job), against the model in-process.
    let at = (Vec3::new(278.0, 1.0, 280.0), Vec3::new(0.0, 1.0, 0.0));
    let e = assert_same_irradiance(&farm, &scene, &settings, &grids, make, at);
    assert!(e[0] > 0.0);

    // Adaptive sampling (protocol 4, ShootLevel jobs at each level's k), against the same
    // refinement in-process: the same rows computed, the same rows, the same solution.
    let adaptive = hemi::adaptive::AdaptiveSettings {
        margin: 0.1,
        max_depth: 2,
        ..Default::default()
    };
    let refined = assert_same_adaptive(&farm, &scene, &settings, &adaptive, make);
    assert!(
        refined.patches.iter().any(|p| p.depth > 0),
        "the test should refine some patch"
    );

    // The element field (protocol 5) and point queries on it, against the model in-process:
    // refinement, sweeps, exact direct light and the near field on the boards.
    let field = assert_same_field(&farm, &scene, &settings, make, 1);
    assert!(field.field.sweeps > 1 && field.field.direct.is_some());
    assert!(!field.rounds.is_empty() && !field.rounds[0].refined.is_empty());
    let corner = [Query {
        point: Vec3::new(1.0, 1.0, 550.0),
        normal: Vec3::new(1.0, 0.0, 0.0),
    }];
    let e = assert_same_full_irradiance(&farm, &scene, (&settings, &field.field), make, &corner, 1);
    assert!(e[0][0] > 0.0);

    // The boards' counters: every job counted once, nothing refused, the stack measured.
    let stats: Vec<_> = farm
        .engine_stats()
        .into_iter()
        .map(|s| s.unwrap())
        .collect();
    let jobs: u32 = stats.iter().map(|s| s.jobs).sum();
    let events = farm.events();
    assert_eq!(u64::from(jobs), events.answered, "{stats:?} {events:?}");
    for s in &stats {
        eprintln!("board: {s:?}");
        assert_eq!(s.refused, 0);
        assert_eq!(s.link.bad_crc + s.link.bad_framing + s.link.too_long, 0);
        assert!(s.rays > 0 && s.accel_cycles > 0, "{s:?}");
        // The model build's stack carries the model's state while it is built (~70 KiB).
        assert!(
            s.stack_high_water > 0 && s.stack_high_water < s.stack_size,
            "{s:?}"
        );
    }
}

/// The paper's picture 2 (`scenes/mirror-wall.toml`: a perfect mirror, k_r = 0.9) at small R and
/// K through one QEMU board: the optics table goes up with the scene (protocol 3), the board's
/// tracer follows the mirror through the same walker with its skeleton stack in SRAM and its
/// small park of specular hits (casting the hemisphere again when it is full), and the rows
/// equal the in-process model's bit for bit. Then the same with another CORDIC, sent to the
/// board (`--cordic-iterations 16 --cordic-width 24`); a CORDIC the model cannot build is
/// refused with an error frame; and a small render through the mirror (whole rows per job,
/// weighted hits back) equals the model's pixels bit for bit.
#[test]
fn form_factors_and_a_render_through_a_mirror_on_a_qemu_board_equal_the_model_backend() {
    if !qemu_or_skip("hil_jobs mirror") {
        return;
    }
    big_stack(run_mirror);
}

fn run_mirror() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let scene = hemi::scene::load(&root.join("scenes/mirror-wall.toml")).unwrap();
    let settings = settings();
    let farm = Farm::connect(&[BoardSpec::Qemu], FarmOptions::default()).expect("boot a board");
    let hello = farm.hellos()[0].clone().expect("connected");
    assert_eq!(hello.protocol, PROTOCOL_VERSION);

    for (iterations, width) in [(24, 32), (16, 24)] {
        let config = ModelConfig {
            iterations,
            width,
            ..ModelConfig::default()
        };
        farm.set_cordic(iterations, width).unwrap();
        let want = pass1_on(&model(&scene, &settings, config));
        let got = pass1_on(&boards(&farm, &scene, &settings));
        assert_same_pass1(&got, &want, &format!("CORDIC {iterations}/{width}"));
        let t = farm.trace_stats().remove(0).unwrap();
        eprintln!("CORDIC {iterations}/{width}: board trace stats {t:?}");
        assert!(t.frustums > 0, "the mirror spawned frustums: {t:?}");
        assert!(t.stack_high_water >= 1 && t.stack_high_water <= t.stack_frames);
        assert!(
            t.recasts > 0,
            "the mirror takes more hits than the board parks: {t:?}"
        );
    }
    let s = farm.engine_stats().remove(0).unwrap();
    eprintln!("board: {s:?}");
    assert_eq!(s.refused, 0);

    // An engine that cannot apply a CORDIC refuses it with an error frame.
    farm.set_cordic(3, 32).unwrap();
    let err = Boards::new(&farm, &scene, &settings, AccelKind::None)
        .and_then(|b| form_factors(&b, &|_| {}))
        .unwrap_err();
    assert!(format!("{err:#}").contains("cordic"), "{err:#}");

    // Pass 2 through the mirror on a small image: whole rows per job, weighted hits back.
    let make = ModelConfig::default();
    farm.set_cordic(make.iterations, make.width).unwrap();
    let ff = pass1_on(&model(&scene, &settings, make));
    let grids = solve(&scene, &ff);
    let want = assert_same_small_render(&farm, &scene, &settings, &grids, make, (16, 12));
    assert!(want.specular.frustums > 0, "the camera sees the mirror");
    let t = farm.trace_stats().remove(0).unwrap();
    eprintln!("after pass 2: board trace stats {t:?}");

    // Irradiance facing the mirror (protocol 4, Query jobs: the whole hemisphere in one shoot
    // call, weighted reports back a window at a time), against the model in-process.
    let (p, n) = (Vec3::new(2.5, 1.5, 2.0), Vec3::new(-1.0, 0.0, 0.0));
    let before = farm.trace_stats().remove(0).unwrap();
    let got_e = assert_same_irradiance(&farm, &scene, &settings, &grids, make, (p, n));
    let after = farm.trace_stats().remove(0).unwrap();
    assert!(
        after.frustums > before.frustums,
        "the query sees the mirror: {after:?}"
    );
    // facing away from the mirror the answer differs: the mirror's light is in it
    let away = Query {
        point: p,
        normal: -n,
    };
    let away = hemi::irradiance::irradiance(
        &boards(&farm, &scene, &settings),
        Light::of(&grids),
        &[away],
        &HEMISPHERE_ONLY,
    )
    .unwrap()[0];
    assert_ne!(away, got_e);

    // The field and a query facing the mirror (protocol 5): the board's reports say which came
    // once through the mirror, so the lamp's image there is left to exact direct light on the
    // board as it is in-process. (No refinement and no near field here: through a mirror every
    // window of a hemisphere's reports shoots it again with its frustums; the two-board test
    // above covers both.)
    let field = assert_same_field(&farm, &scene, &settings, make, 0);
    assert!(
        field.field.direct.is_some(),
        "exact direct light with the mirror"
    );
    let facing = [Query {
        point: p,
        normal: n,
    }];
    let e = assert_same_full_irradiance(&farm, &scene, (&settings, &field.field), make, &facing, 0);
    assert!(e[0][0] > 0.0);
}

/// `scenes/paper-screen.toml` (a translucent paper screen, k_y) through one QEMU board
/// (protocol 4): the back side of the sheet is shot as patch `n + i` from the front's points
/// facing the other way, rows carry the back side's column, and a query behind the screen sees
/// the back side's radiosity; form factors, a small render and the query equal the in-process
/// model's bit for bit.
#[test]
fn a_translucent_sheet_through_a_qemu_board_equals_the_model_backend() {
    if !qemu_or_skip("hil_jobs") {
        return;
    }
    big_stack(run_translucent);
}

fn run_translucent() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let scene = hemi::scene::load(&root.join("scenes/paper-screen.toml")).unwrap();
    assert!(scene.has_translucency());
    let fronts = scene.fronts();
    let settings = settings();
    let farm = Farm::connect(&[BoardSpec::Qemu], FarmOptions::default()).expect("boot a board");

    let make = ModelConfig::default();
    let want = pass1_on(&model(&scene, &settings, make));
    let got = pass1_on(&boards(&farm, &scene, &settings));
    assert_same_pass1(&got, &want, "paper-screen");
    // the back side was shot, and is seen through its own column
    assert!(got.elements.iter().any(|e| e.patch >= fronts));
    assert!(got
        .elements
        .iter()
        .any(|e| e.row.iter().any(|&(j, _)| j as usize >= fronts)));

    let grids = solve(&scene, &want);
    assert_same_small_render(&farm, &scene, &settings, &grids, make, (16, 12));

    // behind the screen, facing it: the rays that reach it see its back side
    let behind = (Vec3::new(2.0, 1.0, 2.5), Vec3::new(0.0, 0.0, -1.0));
    let e = assert_same_irradiance(&farm, &scene, &settings, &grids, make, behind);
    assert!(e[0] > 0.0);

    // adaptive sampling, the screen's sides refined together (ShootLevel on n + i for the back)
    let adaptive = hemi::adaptive::AdaptiveSettings {
        margin: 0.1,
        max_depth: 1,
        ..Default::default()
    };
    let refined = assert_same_adaptive(&farm, &scene, &settings, &adaptive, make);
    let back = scene.twin(
        scene
            .patches
            .iter()
            .position(|p| p.name == "screen")
            .unwrap(),
    );
    assert!(
        refined.patches[back.unwrap()].depth > 0,
        "the screen's back side is refined"
    );
    let s = farm.engine_stats().remove(0).unwrap();
    assert_eq!(s.refused, 0, "{s:?}");
}
