//! Pass 2: images against symmetry, uniformity, the trace command's hits, and a golden image.

use hemi::backend::soft;
use hemi::backend::SoftEngine;
use hemi::pass1::form_factors;
use hemi::radiosity::grids;
use hemi::render::{camera_of, read_png, render, write_png, Image};
use hemi::scene::{parse, Scene};
use hemi::settings::Pass1Settings;
use hemi_kernel::accel::{Accelerator, Ray};
use hemi_kernel::geometry::Vec3;
use hemi_kernel::hemisphere::DeltaRule;
use hemi_tests::*;
use std::path::PathBuf;

fn small() -> Pass1Settings {
    Pass1Settings {
        circles: 24,
        samples: 6,
        rule: DeltaRule::Band,
        ..Pass1Settings::default()
    }
}

fn solve_and_render(scene: &Scene, settings: &Pass1Settings, spp: u32) -> Image {
    let ff = form_factors(&soft(scene, settings).unwrap(), &|_| {}).unwrap();
    let sol = hemi::solve::gauss_seidel_scene(scene, ff.channels(), &Default::default()).unwrap();
    let g = grids(scene, &ff, &sol);
    let backend = soft(scene, settings).unwrap();
    render(
        &backend,
        hemi::irradiance::Light::of(&g),
        &camera_of(scene).unwrap(),
        spp,
        &|_| {},
    )
    .unwrap()
    .image
}

fn camera_toml(eye: [f64; 3], look: [f64; 3], w: u32, h: u32) -> String {
    format!(
        "[camera]\neye = [{}, {}, {}]\nlook_at = [{}, {}, {}]\nup = [0, 1, 0]\nfov_y_deg = 60\nwidth = {w}\nheight = {h}\n",
        eye[0], eye[1], eye[2], look[0], look[1], look[2]
    )
}

/// An open box symmetric about x = 0.5 with a coloured left and right wall swapped in
/// reflectance (so the mirror image of the render is the render with the channels kept).
fn symmetric_scene() -> String {
    let mut s = material("white", 0.6, 0.0) + &material("lamp", 0.0, 10.0);
    s += &quad(
        "floor",
        "white",
        [
            [0.0, 0.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 1.0],
            [1.0, 0.0, 0.0],
        ],
    );
    s += &quad(
        "back",
        "white",
        [
            [0.0, 0.0, 1.0],
            [0.0, 1.0, 1.0],
            [1.0, 1.0, 1.0],
            [1.0, 0.0, 1.0],
        ],
    );
    s += &quad(
        "left",
        "white",
        [
            [0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 1.0, 1.0],
            [0.0, 0.0, 1.0],
        ],
    );
    s += &quad(
        "right",
        "white",
        [
            [1.0, 0.0, 0.0],
            [1.0, 0.0, 1.0],
            [1.0, 1.0, 1.0],
            [1.0, 1.0, 0.0],
        ],
    );
    s += &quad(
        "ceiling",
        "white",
        [
            [0.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
            [1.0, 1.0, 1.0],
            [0.0, 1.0, 1.0],
        ],
    );
    s += &quad(
        "lamp",
        "lamp",
        [
            [0.4, 0.99, 0.4],
            [0.6, 0.99, 0.4],
            [0.6, 0.99, 0.6],
            [0.4, 0.99, 0.6],
        ],
    );
    // a block off to one side would break symmetry; a centred one keeps it
    s += &quad(
        "block_top",
        "white",
        [
            [0.35, 0.3, 0.35],
            [0.35, 0.3, 0.65],
            [0.65, 0.3, 0.65],
            [0.65, 0.3, 0.35],
        ],
    );
    s += &camera_toml([0.5, 0.5, -0.5], [0.5, 0.5, 0.5], 64, 48);
    s
}

#[test]
fn a_mirror_symmetric_scene_renders_mirror_symmetric() {
    let scene = parse(&symmetric_scene(), "sym.toml").unwrap();
    // R = 128: single elements (not patch averages) carry the hemisphere's discretisation noise,
    // largest in dark corners; it falls with R (p99 of the mirror difference: 7.8 % at R = 64,
    // 1.5 % at 128, 0.7 % at 256), which is what separates it from a symmetry bug.
    let settings = Pass1Settings {
        circles: 128,
        ..Pass1Settings::default()
    };
    let img = solve_and_render(&scene, &settings, 1);
    let (w, h) = (img.width as usize, img.height as usize);
    let mut diffs = Vec::new();
    for y in 0..h {
        for x in 0..w / 2 {
            let a = img.pixels[y * w + x];
            let b = img.pixels[y * w + (w - 1 - x)];
            for c in 0..3 {
                diffs.push((a[c] - b[c]).abs() / a[c].max(b[c]).max(1e-3));
            }
        }
    }
    let mean = diffs.iter().sum::<f32>() / diffs.len() as f32;
    diffs.sort_by(f32::total_cmp);
    let p99 = diffs[diffs.len() * 99 / 100];
    println!("mirror symmetry: mean relative difference {mean:.2e}, 99th percentile {p99:.2e}");
    // A handedness or (u,v) bug mirrors shadows wrongly and gives differences of tens of per cent.
    assert!(mean < 5e-3 && p99 < 3e-2, "mean {mean} p99 {p99}");
}

#[test]
fn a_uniformly_lit_patch_renders_uniform() {
    // Inside a closed furnace every surface has B = E/(1−ρ) exactly (rows sum to one), so the
    // image must be flat: no bilinear seams at cell or patch borders.
    let mut src = material("m", 0.5, 1.0) + &closed_box([1.0, 1.0, 1.0], 2, "m");
    src += &camera_toml([0.5, 0.5, 0.1], [0.5, 0.4, 0.9], 40, 40);
    let scene = parse(&src, "furnace.toml").unwrap();
    let img = solve_and_render(&scene, &small(), 1);
    let want = (2.0 / std::f64::consts::PI) as f32;
    for p in &img.pixels {
        for c in p {
            assert!((c - want).abs() < 2e-3 * want, "pixel {c} want {want}");
        }
    }
}

#[test]
fn pixel_hits_agree_with_the_trace_command() {
    // `hemi trace` answers with the accelerator's single-ray nearest hit; pass 2 casts pixel rays
    // as a shared-origin batch. Both must find the same patch, t and (u,v).
    let scene = parse(&symmetric_scene(), "sym.toml").unwrap();
    let camera = camera_of(&scene).unwrap();
    let patches = scene.kernel_patches();
    let mut accel = SoftEngine::new(&patches);
    let dirs: Vec<Vec3> = (0..camera.height)
        .flat_map(|y| (0..camera.width).map(move |x| (x, y)))
        .map(|(x, y)| camera.direction(x as f32 + 0.5, y as f32 + 0.5))
        .collect();
    let mut batch = vec![None; dirs.len()];
    accel.cast_from(camera.eye, &dirs, true, |i, h| batch[i] = h);
    let mut compared = 0;
    for (d, b) in dirs.iter().zip(&batch) {
        let single = accel.nearest_hit(
            &Ray {
                origin: camera.eye,
                dir: *d,
            },
            f32::INFINITY,
        );
        match (single, b) {
            (Some(s), Some(b)) => {
                assert_eq!(s.patch, b.patch);
                assert!((s.t - b.t).abs() < 1e-5 * s.t.max(1.0));
                assert!((s.u - b.u).abs() < 1e-4 && (s.v - b.v).abs() < 1e-4);
                compared += 1;
            }
            (None, None) => {}
            other => panic!("trace and pass 2 disagree: {other:?}"),
        }
    }
    assert!(compared > dirs.len() / 2);
}

#[test]
fn the_cornell_box_matches_its_golden_image() {
    // A 64×64 Cornell box at low settings against tests/golden/cornell-64.png. Compared with a
    // tolerance, not byte equality: the mean absolute difference must stay under 1.5/255 and
    // 99 % of the channel values within 6/255. Regenerate with HEMI_BLESS=1 after a deliberate
    // change of the method, and say why in the commit.
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let src = std::fs::read_to_string(root.join("../scenes/cornell.toml"))
        .unwrap()
        .replace("width = 512", "width = 64")
        .replace("height = 512", "height = 64");
    let scene = parse(&src, "cornell.toml").unwrap();
    let img = solve_and_render(&scene, &small(), 4);
    let out = std::env::temp_dir().join(format!("hemi-golden-{}.png", std::process::id()));
    write_png(&img, 2.0, &out).unwrap();
    let golden = root.join("golden/cornell-64.png");
    if std::env::var_os("HEMI_BLESS").is_some() {
        std::fs::copy(&out, &golden).unwrap();
    }
    let (w, h, got) = read_png(&out).unwrap();
    let (gw, gh, want) =
        read_png(&golden).expect("tests/golden/cornell-64.png (HEMI_BLESS=1 writes it)");
    assert_eq!((w, h), (gw, gh));
    let mut diffs: Vec<u8> = got.iter().zip(&want).map(|(a, b)| a.abs_diff(*b)).collect();
    let mean = diffs.iter().map(|d| *d as f64).sum::<f64>() / diffs.len() as f64;
    diffs.sort();
    let p99 = diffs[diffs.len() * 99 / 100];
    println!("golden image: mean |diff| {mean:.3}/255, 99th percentile {p99}/255");
    assert!(mean < 1.5 && p99 <= 6, "mean {mean} p99 {p99}");
    let _ = std::fs::remove_file(out);
}

#[test]
fn obj_meshes_import_with_their_mtl_materials() {
    let dir = std::env::temp_dir().join(format!("hemi-obj-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("quad.mtl"),
        "newmtl glow\nKd 0.2 0.3 0.4\nKe 5 5 5\n\nnewmtl grey\nKd 0.5 0.5 0.5\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("quad.obj"),
        "mtllib quad.mtl\no lamp\nv 0 1 0\nv 1 1 0\nv 1 1 1\nv 0 1 1\nusemtl glow\nf 1 2 3 4\no floor\nv 0 0 0\nv 0 0 1\nv 1 0 1\nv 1 0 0\nv 2 0 0\nusemtl grey\nf 5 6 7 8\nf 5 5 9\n",
    )
    .unwrap();
    let src = "[[obj]]\npath = \"quad.obj\"\nscale = 2.0\ntranslate = [1, 0, 0]\n";
    let scene = parse(src, dir.join("scene.toml").to_str().unwrap()).unwrap();
    // two quads, triangulated; the degenerate face `5 5 9` is skipped
    assert_eq!(scene.patches.len(), 4);
    let lamp = scene.material_of(0);
    assert_eq!(lamp.emission, [5.0; 3]);
    assert!((lamp.diffuse[2] - 0.4).abs() < 1e-6);
    assert_eq!(scene.material_of(3).name, "grey");
    let p = scene.patches[0].polygon().unwrap().v[1];
    assert_eq!(p, Vec3::new(3.0, 2.0, 0.0));
    // The lamp faces down (+z×... as written: 1-2-3 counter-clockwise seen from below).
    assert!(scene.patches[0].polygon().unwrap().normal.y < 0.0);
    let _ = std::fs::remove_dir_all(dir);
}
