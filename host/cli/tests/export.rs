//! What `hemi` writes for other programs, read back by their parsers: the solution as PLY
//! (ply-rs-bw) and binary glTF (the `gltf` crate), and the Radiance picture (radiant).

use std::path::PathBuf;
use std::process::Command;

/// A fresh folder for one test's files.
fn dir(test: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hemi-export-{}-{test}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Runs hemi with `args`; panics with its stderr if it fails, else returns stderr.
fn hemi(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_hemi"))
        .args(args)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "hemi {args:?}: {err}");
    err
}

/// A closed unit box of six inward faces (`f0_0_0` … `f5_0_0`), all emitting `e` and
/// reflecting `rho`: every point has B = E/(1−ρ).
fn furnace(e: f64, rho: f64) -> String {
    hemi_tests::material("m", rho, e) + &hemi_tests::closed_box([1.0; 3], 1, "m")
}

/// The worst relative deviation of `values` from `want`, over every channel.
fn worst(values: impl Iterator<Item = [f32; 3]>, want: f64) -> f64 {
    values
        .flatten()
        .map(|b| (b as f64 - want).abs() / want)
        .fold(0.0, f64::max)
}

#[test]
fn the_furnace_exported_as_ply_and_gltf_has_e_over_one_minus_rho_on_every_vertex() {
    let d = dir("furnace");
    let scene = d.join("furnace.toml");
    std::fs::write(&scene, furnace(1.0, 0.5)).unwrap();
    let (ply, glb) = (d.join("furnace.ply"), d.join("furnace.glb"));
    let args = ["--circles", "16", "--samples", "4"];
    let s = |p: &PathBuf| p.to_str().unwrap().to_string();
    let files = ["--ply".into(), s(&ply), "--gltf".into(), s(&glb)];
    let files: Vec<&str> = files.iter().map(String::as_str).collect();
    hemi(&[&["solve", scene.to_str().unwrap()], &args[..], &files[..]].concat());
    let want = 1.0 / (1.0 - 0.5);

    let parser = ply_rs_bw::parser::Parser::<ply_rs_bw::ply::DefaultElement>::new();
    let model = parser
        .read_ply(&mut std::fs::File::open(&ply).unwrap())
        .unwrap();
    let vertices = &model.payload["vertex"];
    // six faces, each the 5×5 vertex grid of its 4×4 elements, two triangles per cell
    assert_eq!(vertices.len(), 6 * 25);
    assert_eq!(model.payload["face"].len(), 6 * 32);
    let float = |v: &ply_rs_bw::ply::DefaultElement, k: &str| match v[k] {
        ply_rs_bw::ply::Property::Float(x) => x,
        ref p => panic!("{k}: {p:?}"),
    };
    let b = vertices
        .iter()
        .map(|v| ["radiosity_r", "radiosity_g", "radiosity_b"].map(|k| float(v, k)));
    let ply_worst = worst(b, want);
    println!(
        "PLY: worst relative error of B on {} vertices {ply_worst:.2e}",
        vertices.len()
    );
    assert!(ply_worst < 5e-3, "{ply_worst}");

    let gltf = gltf::Gltf::open(&glb).unwrap();
    let blob = gltf.blob.as_deref().unwrap();
    let mut seen = 0;
    for mesh in gltf.meshes() {
        for prim in mesh.primitives() {
            let (_, radiosity) = prim
                .attributes()
                .find(|(s, _)| *s == gltf::Semantic::Extras("RADIOSITY".into()))
                .expect("a _RADIOSITY attribute");
            let b: Vec<[f32; 3]> = gltf::accessor::Iter::new(radiosity, |_| Some(blob))
                .unwrap()
                .collect();
            let reader = prim.reader(|_| Some(blob));
            assert_eq!(reader.read_positions().unwrap().count(), b.len());
            assert_eq!(
                reader.read_colors(0).unwrap().into_rgb_f32().count(),
                b.len()
            );
            seen += b.len();
            let g = worst(b.into_iter(), want);
            assert!(g < 5e-3, "{}: {g}", mesh.name().unwrap_or("?"));
        }
    }
    assert_eq!(gltf.meshes().count(), 6);
    // shared vertex views must state their stride (the Khronos validator's
    // MESH_PRIMITIVE_ACCESSOR_WITHOUT_BYTESTRIDE); the index view must not
    let strides: Vec<Option<usize>> = gltf.views().map(|v| v.stride()).collect();
    assert_eq!(strides, [Some(12), Some(12), Some(12), None]);
    assert_eq!(seen, 6 * 25);
}

#[test]
fn a_render_to_hdr_reads_back_as_the_exr_of_the_same_render() {
    let d = dir("hdr");
    let scene = d.join("box.toml");
    let camera = "[camera]\neye = [0.5, 0.5, 0.05]\nlook_at = [0.5, 0.5, 1.0]\nup = [0, 1, 0]\n\
                  fov_y_deg = 60\nwidth = 4\nheight = 4\n";
    // the face behind the eye (z = 0) is the lamp, so the light varies over the picture
    let lit = furnace(0.0, 0.5).replacen(
        "name = \"f4_0_0\"\nmaterial = \"m\"",
        "name = \"f4_0_0\"\nmaterial = \"lamp\"",
        1,
    );
    assert!(lit.contains("\"lamp\""));
    let lamp = "[[material]]\nname = \"lamp\"\ndiffuse = [0, 0, 0]\nemission = [5, 3, 1]\n";
    std::fs::write(&scene, format!("{lamp}{lit}{camera}")).unwrap();
    let (hdr, exr) = (d.join("box.hdr"), d.join("box.exr"));
    let (h, e) = (hdr.to_str().unwrap(), exr.to_str().unwrap());
    // --size overrides the scene's 4×4; 40 is inside the run-length encoded widths
    let base = [
        "render",
        scene.to_str().unwrap(),
        "--circles",
        "8",
        "--samples",
        "2",
    ];
    hemi(&[&base[..], &["-o", h, "--exr", e, "--size", "40x30"]].concat());
    let picture =
        radiant::load(std::io::BufReader::new(std::fs::File::open(&hdr).unwrap())).unwrap();
    assert_eq!((picture.width, picture.height), (40, 30));
    let linear = exr::prelude::read_first_rgba_layer_from_file(
        &exr,
        |size, _| vec![[0f32; 3]; size.width() * size.height()],
        |px: &mut Vec<[f32; 3]>, at, (r, g, b, _): (f32, f32, f32, f32)| {
            px[at.y() * 40 + at.x()] = [r, g, b]
        },
    )
    .unwrap()
    .layer_data
    .channel_data
    .pixels;
    for (rgbe, want) in picture.data.iter().zip(&linear) {
        // RGBE keeps 8 bits of mantissa: within 1/128 of the pixel's largest channel
        let largest = want[0].max(want[1]).max(want[2]);
        assert!(largest > 0.0, "every pixel sees a lit wall");
        for (got, want) in [rgbe.r, rgbe.g, rgbe.b].iter().zip(want) {
            assert!((got - want).abs() <= largest / 100.0, "{got} vs {want}");
        }
    }
    // and a width of 4 is written flat, which the decoder reads too
    hemi(&[&base[..], &["-o", h]].concat());
    let small = radiant::load(std::io::BufReader::new(std::fs::File::open(&hdr).unwrap())).unwrap();
    assert_eq!((small.width, small.height), (4, 4));
    assert!(small.data.iter().all(|p| p.r > 0.0));
}
