//! The `hemi` command line against hostile input: every bad number, budget and name is refused
//! with a message that names the file, line and key or the option, and says what is wrong; what
//! is accepted but changed is warned about. Each test asserts the message, not only the status.

mod common;

use common::{run, TWO_SQUARES};
use std::path::PathBuf;

/// A fresh folder for one test's files.
fn dir(test: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hemi-hostile-{}-{test}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Writes `files` into the folder of `test` and returns the path of the first.
fn files(test: &str, files: &[(&str, &str)]) -> String {
    let d = dir(test);
    for (name, text) in files {
        std::fs::write(d.join(name), text).unwrap();
    }
    d.join(files[0].0).to_str().unwrap().to_string()
}

/// `hemi ARGS` (stdin `input`) must succeed; its (stdout, stderr).
fn accepted(args: &[&str], input: &[u8]) -> (String, String) {
    let (ok, out, err) = run(args, input);
    assert!(ok, "hemi {args:?}: {err}");
    (out, err)
}

/// `hemi ARGS` (stdin `input`) must fail; its stderr.
fn rejected(args: &[&str], input: &[u8]) -> String {
    let (ok, _, err) = run(args, input);
    assert!(!ok, "hemi {args:?} succeeded");
    err
}

/// `hemi CMD SCENE` at the cheapest sampling, for tests about messages rather than light.
fn quick<'a>(cmd: &'a str, scene: &'a str) -> Vec<&'a str> {
    vec![cmd, scene, "--circles", "4", "--samples", "1"]
}

/// `hemi ARGS` on the two squares must fail with a message containing every one of `want`.
fn refused(test: &str, args: &[&str], want: &[&str]) {
    let p = files(test, &[("two.toml", TWO_SQUARES)]);
    let mut all = vec![args[0], p.as_str()];
    all.extend(&args[1..]);
    let (ok, _, err) = run(&all, b"");
    assert!(!ok, "hemi {all:?} succeeded");
    for w in want {
        assert!(err.contains(w), "hemi {all:?}: {w:?} not in {err}");
    }
}

#[test]
fn options_out_of_range_are_refused_with_the_option_named() {
    let out = "/tmp/hemi-hostile-unused.png";
    for ev in ["NaN", "inf", "1000"] {
        let args = [
            "render",
            "--exposure",
            ev,
            "--size",
            "4x4",
            "--eye",
            "0.5,0.5,3",
        ];
        let mut args = args.to_vec();
        args.extend(["--look-at", "0.5,0.5,0", "--output", out]);
        refused(
            "exposure",
            &args,
            &[&format!("--exposure {ev}: must be a number of stops")],
        );
    }
    refused(
        "cordic",
        &[
            "solve",
            "--backend",
            "model",
            "--cordic-iterations",
            "40",
            "--cordic-width",
            "32",
        ],
        &["--cordic-iterations 40 --cordic-width 32: the accelerator takes 4..=30 iterations"],
    );
    refused(
        "width",
        &["solve", "--backend", "model", "--cordic-width", "64"],
        &["--cordic-width 64", "widths 12..=32"],
    );
    refused(
        "threshold",
        &["solve", "--specular-threshold", "NaN"],
        &["--specular-threshold must be in (0, 1)"],
    );
    refused(
        "stack",
        &["solve", "--stack", "18446744073709551615"],
        &["--stack must be between 1 and 4096 frames"],
    );
    refused(
        "eye",
        &[
            "render",
            "--eye",
            "0,1e39,0",
            "--look-at",
            "0,0,0",
            "--output",
            out,
        ],
        &["--eye 0,1e39,0: component 1: 1e39 is beyond f32's range"],
    );
}

/// A floor of `n`×`n` unit tiles under a small lamp: each tile's hemispheres see the lamp and
/// little else, so its rows are sparse while the dense bound grows with the square.
fn tiled_floor(n: usize) -> String {
    let mut s = String::from(
        "[[material]]\nname = \"w\"\ndiffuse = [0.5, 0.5, 0.5]\n\
         [[material]]\nname = \"lamp\"\ndiffuse = [0, 0, 0]\nemission = [10, 10, 10]\n\
         [[quad]]\nname = \"lamp\"\nmaterial = \"lamp\"\n\
         vertices = [[4, 5, 4], [6, 5, 4], [6, 5, 6], [4, 5, 6]]\n",
    );
    for i in 0..n {
        for j in 0..n {
            let (x, z) = (i as f64 * 10.0 / n as f64, j as f64 * 10.0 / n as f64);
            let d = 10.0 / n as f64;
            s += &format!(
                "[[quad]]\nname = \"t{i}_{j}\"\nmaterial = \"w\"\nvertices = [[{x}, 0, {z}], \
                 [{x}, 0, {}], [{}, 0, {}], [{}, 0, {z}]]\n",
                z + d,
                x + d,
                z + d,
                x + d
            );
        }
    }
    s
}

#[test]
fn sparse_rows_are_measured_not_bounded_by_the_dense_matrix() {
    // 401 patches at K = 2: the dense bound is about 18 MiB, the rows well under 1 MiB
    let p = files("sparse", &[("floor.toml", &tiled_floor(20))]);
    let args = [
        "solve",
        &p,
        "--samples",
        "2",
        "--circles",
        "8",
        "--gather",
        "0",
    ];
    let mut within = args.to_vec();
    within.extend(["--matrix-mib", "1"]);
    let (out, err) = accepted(&within, b"");
    assert!(err.contains("pass 1 of 401 patches: about"), "{err}");
    assert!(err.contains("within --matrix-mib 1"), "{err}");
    assert!(err.contains("gauss-seidel"), "{err}");
    assert!(!err.contains("progressive"), "{err}");
    // the same answer as with room for the dense matrix
    let (ok, dense, err) = run(&args, b"");
    assert!(ok, "{err}");
    assert!(!err.contains("pilot"), "{err}");
    assert_eq!(out, dense);
    // the dense LU needs N² whatever the rows hold: 2.5 MiB here
    let mut lu = within.clone();
    lu.extend(["--solver", "direct"]);
    let err = rejected(&lu, b"");
    assert!(
        err.contains("--solver direct: the dense LU of 401 patches needs 2.5 MiB"),
        "{err}"
    );
    assert!(err.contains("more than --matrix-mib 1"), "{err}");
}

#[test]
fn refinement_keeps_within_the_memory_pass_1_left() {
    // 101 patches at K = 8: pass 1's rows take about 0.65 MiB of the 1 allowed
    let p = files("refine-budget", &[("floor.toml", &tiled_floor(10))]);
    let args = ["irradiance", &p, "--samples", "8", "--circles", "8"];
    let mut tight = args.to_vec();
    tight.extend(["--matrix-mib", "1"]);
    let (out, err) = accepted(&tight, b"5 0.001 5 0 1 0\n");
    assert_eq!(out.split_whitespace().count(), 3, "{out}");
    assert!(err.contains("field refinement: at most"), "{err}");
    assert!(
        err.contains("elements instead of 17776 (11/4 of pass 1's 6464): pass 1 holds"),
        "{err}"
    );
    assert!(err.contains("(--matrix-mib 1 raises it)"), "{err}");
    let (_, err) = accepted(&args, b"5 0.001 5 0 1 0\n");
    assert!(!err.contains("field refinement: at most"), "{err}");
    // an element budget asked for is held to the memory too
    let mut asked = args.to_vec();
    asked.extend(["--max-elements", "18446744073709551615"]);
    let (_, err) = accepted(&asked, b"5 0.001 5 0 1 0\n");
    assert!(
        err.contains("instead of 18446744073709551615 (--max-elements)"),
        "{err}"
    );
    let mut none = args.to_vec();
    none.extend(["--max-elements", "1"]);
    let (_, err) = accepted(&none, b"5 0.001 5 0 1 0\n");
    assert!(
        err.contains("none, --max-elements 1 is not above pass 1's 6464"),
        "{err}"
    );
}

#[test]
fn budgets_are_checked_before_the_memory_is_taken() {
    refused(
        "adaptive",
        &["solve", "--adaptive", "--samples", "64", "--max-depth", "8"],
        &[
            "--max-depth 8 from --samples 64",
            "16384×16384",
            "at K = 64 the depth is at most 3",
        ],
    );
    refused(
        "matrix",
        &["solve", "--solver", "gauss-seidel", "--matrix-mib", "0"],
        &[
            "--solver gauss-seidel: pass 1 of 2 patches needs about",
            "(estimated from a pilot of",
            "of form factors, more than --matrix-mib 0 (--solver progressive, or a larger",
        ],
    );
    refused(
        "ff-matrix",
        &["form-factors", "--matrix-mib", "0"],
        &[
            "form-factors: pass 1 of 2 patches needs about",
            "--matrix-mib 0",
        ],
    );
    refused(
        "file",
        &["solve", "--max-file-mib", "0"],
        &[
            "cannot read scene file: ",
            "two.toml is larger than 0 bytes",
            "--max-file-mib raises it",
        ],
    );
    let (ok, _, err) = run(&["solve", "/dev/zero", "--max-file-mib", "1"], b"");
    assert!(
        !ok && err.contains("/dev/zero is larger than 1 MiB"),
        "{err}"
    );
}

#[test]
fn a_huge_stdin_line_is_refused_without_echoing_it() {
    let p = files("huge", &[("two.toml", TWO_SQUARES)]);
    let line = vec![b'7'; 120 << 20];
    let (ok, _, err) = run(&["trace", &p], &line);
    assert!(
        !ok && err.contains("line 1: longer than 4096 bytes"),
        "{err}"
    );
    let first = err.lines().next().unwrap_or("");
    assert!(first.len() < 200, "the error echoes {} bytes", first.len());
    assert!(!err.contains(&"7".repeat(100)), "the error echoes the line");
}

#[test]
fn stdin_numbers_beyond_f32_and_points_beyond_its_precision_are_refused() {
    let p = files("stdin", &[("two.toml", TWO_SQUARES)]);
    let (ok, out, err) = run(&["trace", &p], b"0.5 0.5 0.5 0 0 -1\n0 0 0 1e39 0 0\n");
    assert!(
        !ok && err.contains("line 2: dx = 1e39 is beyond f32's range"),
        "{err}"
    );
    assert_eq!(out.lines().count(), 1, "the good line is answered: {out}");
    let (ok, _, err) = run(&["trace", &p], b"0.5 1e12 0.5 0 -1 0\n");
    assert!(
        !ok && err.contains("line 1: the point (0.5, 1000000000000, 0.5) is"),
        "{err}"
    );
}

const MTL_SCENE: &str = "[[obj]]\npath = \"m.obj\"\n";
const OBJ: &str = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\n\
                   usemtl a\nf 1 2 3\nusemtl lamp\nf 4 6 5\n";

#[test]
fn scene_numbers_are_refused_with_file_line_and_key() {
    let mtl = "newmtl a\nKd 0.5 nan 0.5\nnewmtl lamp\nKe 1 1 1\n";
    let p = files(
        "mtl",
        &[("s.toml", MTL_SCENE), ("m.obj", OBJ), ("m.mtl", mtl)],
    );
    let (ok, _, err) = run(&["solve", &p], b"");
    assert!(
        !ok && err.contains("s.toml:2: `obj.path`: ")
            && err.contains("m.mtl:2: `Kd`: `nan` is NaN"),
        "{err}"
    );
    let mtl = "newmtl a\nKd 1.5 0.5 0.5\nnewmtl lamp\nKe 1 1 1\n";
    let p = files(
        "clamp",
        &[("s.toml", MTL_SCENE), ("m.obj", OBJ), ("m.mtl", mtl)],
    );
    let (ok, _, err) = run(&["solve", &p, "--samples", "2", "--circles", "8"], b"");
    assert!(
        ok && err.contains("warning: ")
            && err.contains("m.mtl:2: `Kd`: `1.5` is a reflectance of 1 or more, clamped to 0.999"),
        "{err}"
    );
    let lamp = TWO_SQUARES.replace("[2.0, 3.0, 4.0]", "[1e300, 3.0, 4.0]");
    let p = files("emission", &[("s.toml", &lamp)]);
    let (ok, _, err) = run(&["solve", &p], b"");
    assert!(
        !ok && err
            .contains("s.toml:9: `material.emission`: component 0: 1e300 is beyond f32's range"),
        "{err}"
    );
    let far = TWO_SQUARES.replace("[[0,0,0],[1,0,0]", "[[0,0,0],[1e39,0,0]");
    let p = files("far", &[("s.toml", &far)]);
    let (ok, _, err) = run(&["solve", &p], b"");
    assert!(
        !ok && err.contains("`quad.vertices`: vertex 1: 1e39 is beyond f32's range (±3.4e38)"),
        "{err}"
    );
}

#[test]
fn names_that_break_output_or_clash_with_generated_ones_and_wrong_counts_are_refused() {
    for (name, want) in [("p1:back", "contains `:`"), ("p 1", "contains ' '")] {
        let s = TWO_SQUARES.replace("name = \"p1\"", &format!("name = \"{name}\""));
        let p = files("names", &[("s.toml", &s)]);
        let (ok, _, err) = run(&["solve", &p], b"");
        assert!(
            !ok && err.contains(&format!("`quad.name`: the name `{name}` {want}")),
            "{err}"
        );
    }
    let mut bpt = String::from("1\n");
    for _ in 0..2 {
        bpt.push_str("3 3\n");
        for r in 0..4 {
            for c in 0..4 {
                bpt.push_str(&format!("{c} {r} 0\n"));
            }
        }
    }
    let scene = "[[material]]\nname = \"m\"\ndiffuse = [0.5, 0.5, 0.5]\n[[bpt]]\nname = \"b\"\n\
                 path = \"b.bpt\"\nmaterial = \"m\"\n";
    let p = files("bpt", &[("s.toml", scene), ("b.bpt", &bpt)]);
    let (ok, _, err) = run(&["solve", &p], b"");
    assert!(
        !ok && err.contains("`bpt.path`: ")
            && err.contains("declares 1 patches but goes on after them"),
        "{err}"
    );
}

/// A unit box of lossless glossy mirrors around a diffuse lamp floor.
fn mirror_box() -> String {
    let faces = [
        ("bottom", "[[0,0,0],[1,0,0],[1,1,0],[0,1,0]]"),
        ("top", "[[0,0,1],[0,1,1],[1,1,1],[1,0,1]]"),
        ("x0", "[[0,0,0],[0,1,0],[0,1,1],[0,0,1]]"),
        ("x1", "[[1,0,0],[1,0,1],[1,1,1],[1,1,0]]"),
        ("y0", "[[0,0,0],[0,0,1],[1,0,1],[1,0,0]]"),
        ("y1", "[[0,1,0],[1,1,0],[1,1,1],[0,1,1]]"),
    ];
    let mut s = String::from(
        "[[material]]\nname = \"lamp\"\ndiffuse = [0.5, 0.5, 0.5]\nemission = [1, 1, 1]\n\
         [[material]]\nname = \"mirror\"\ndiffuse = [0, 0, 0]\nspecular = [1, 1, 1]\n\
         phong = 5\nfrustum = 20\n",
    );
    for (name, v) in faces {
        let m = if name == "bottom" { "lamp" } else { "mirror" };
        s.push_str(&format!(
            "[[quad]]\nname = \"{name}\"\nmaterial = \"{m}\"\nvertices = {v}\n"
        ));
    }
    s
}

#[test]
fn a_specular_tree_stops_at_its_work_budget_and_says_what_it_cut() {
    // without the budget this runs for minutes (Δ = 1e-6 with k = 1 bounds nothing)
    let p = files("budget", &[("box.toml", &mirror_box())]);
    let args = [
        "form-factors",
        &p,
        "--specular-threshold",
        "1e-6",
        "--circles",
        "4",
    ];
    let (_, err) = accepted(&[&args[..], &["--samples", "1"]].concat(), b"");
    let at = err.find("cut past the work budget of 4096 frustums a primary ray (");
    let cut: u64 = at
        .and_then(|i| err[i..].split(['(', ')']).nth(1))
        .and_then(|n| n.parse().ok())
        .unwrap_or(0);
    assert!(cut > 0, "no frustums cut by the budget: {err}");
}

#[test]
fn progressive_refinement_says_when_its_shots_missed_patches() {
    // a 32 × 32 tiled floor under a small lamp, shot with few rays: most tiles get nothing
    let mut s = String::from(
        "[[material]]\nname = \"m\"\ndiffuse = [0.5, 0.5, 0.5]\n[[material]]\nname = \"lamp\"\n\
         diffuse = [0, 0, 0]\nemission = [1, 1, 1]\n",
    );
    let n = 32;
    for i in 0..n {
        for j in 0..n {
            let (a, b, c, d) = (
                i as f64 / 32.0,
                j as f64 / 32.0,
                (i + 1) as f64 / 32.0,
                (j + 1) as f64 / 32.0,
            );
            s.push_str(&format!(
                "[[quad]]\nname = \"t{i}_{j}\"\nmaterial = \"m\"\n\
                 vertices = [[{a},0,{b}],[{a},0,{d}],[{c},0,{d}],[{c},0,{b}]]\n"
            ));
        }
    }
    s.push_str(
        "[[quad]]\nname = \"lamp\"\nmaterial = \"lamp\"\nvertices = [[0.375,1,0.375],\
         [0.625,1,0.375],[0.625,1,0.625],[0.375,1,0.625]]\n",
    );
    let p = files("progressive", &[("floor.toml", &s)]);
    let args = [
        "solve",
        &p,
        "--solver",
        "progressive",
        "--circles",
        "4",
        "--samples",
        "2",
    ];
    let (out, err) = accepted(&args, b"");
    let black = out
        .lines()
        .filter(|l| l.ends_with("0.000000 0.000000 0.000000"))
        .count();
    assert!(black > 0, "{out}");
    assert!(
        err.contains(&format!(
            "warning: progressive refinement left {black} of 1024 reflecting patches at exactly 0"
        )),
        "{black} black tiles, but: {err}"
    );
}

#[test]
fn a_dark_scene_and_a_black_picture_are_warned_about() {
    let dark = TWO_SQUARES.replace("emission = [2.0, 3.0, 4.0]", "");
    let p = files("dark", &[("dark.toml", &dark)]);
    let (_, err) = accepted(&quick("solve", &p), b"");
    assert!(
        err.contains("dark.toml emits light: every radiosity will be 0"),
        "{err}"
    );
    // the lit squares, with the camera looking away from them
    let p = files("away", &[("two.toml", TWO_SQUARES)]);
    let png = dir("away").join("away.png");
    let args = [
        "render",
        &p,
        "--circles",
        "4",
        "--samples",
        "1",
        "--size",
        "8x8",
        "--eye",
        "0.5,0.5,-2",
        "--look-at",
        "0.5,0.5,-5",
        "--output",
    ];
    let mut args = args.to_vec();
    args.push(png.to_str().unwrap());
    let (_, err) = accepted(&args, b"");
    assert!(
        err.contains("warning: the image is black: no lit surface is in view"),
        "{err}"
    );
}

#[test]
fn a_board_that_cannot_start_is_named_plainly() {
    let p = files("qemu", &[("two.toml", TWO_SQUARES)]);
    // the 52-byte header of a 32-bit little-endian ARM executable with no segments: enough
    // for the check, and QEMU here is /bin/true, which runs nothing
    let mut head = vec![0x7f, b'E', b'L', b'F', 1, 1, 1];
    head.resize(16, 0);
    head.extend([2, 0, 40, 0, 1, 0, 0, 0]); // e_type EXEC, e_machine ARM, e_version 1
    head.resize(40, 0); // e_entry, e_phoff, e_shoff, e_flags
    head.extend([52, 0, 32, 0, 0, 0, 40, 0, 0, 0, 0, 0]); // header sizes, no entries
    let elf = dir("qemu").join("fake.elf");
    std::fs::write(&elf, &head).unwrap();
    let qemu = [
        "solve",
        &p,
        "--backend",
        "qemu",
        "--qemu",
        "/bin/true",
        "--firmware",
    ];
    let with = |firmware: &str| {
        let mut args = qemu.to_vec();
        args.push(firmware);
        rejected(&args, b"")
    };
    let err = with(elf.to_str().unwrap());
    assert!(
        err.contains("QEMU did not announce its pty before it ended (exit status: 0)"),
        "{err}"
    );
    let err = with(&p);
    assert!(
        err.contains("two.toml: not an ELF file, not the Cortex-M firmware"),
        "{err}"
    );
    let err = with(dir("qemu").to_str().unwrap());
    assert!(err.contains("is not a file"), "{err}");
}

#[test]
fn an_output_never_overwrites_the_scene_or_the_other_output() {
    // a scene whose name ends in .png, and a link to one output under the other's name
    let p = files("overwrite", &[("scene.png", TWO_SQUARES)]);
    let view = [
        "--size",
        "4x4",
        "--eye",
        "0.5,0.5,3",
        "--look-at",
        "0.5,0.5,0",
    ];
    let mut args = vec!["render", p.as_str(), "--circles", "4", "--samples", "1"];
    args.extend(view);
    let mut onto_scene = args.clone();
    onto_scene.extend(["--output", p.as_str()]);
    let err = rejected(&onto_scene, b"");
    assert!(err.contains("that is the scene file"), "{err}");
    assert_eq!(std::fs::read_to_string(&p).unwrap(), TWO_SQUARES);
    let d = dir("overwrite");
    let (a, link) = (d.join("a.exr"), d.join("link.exr"));
    std::fs::write(&a, b"").unwrap();
    let _ = std::fs::remove_file(&link);
    std::os::unix::fs::symlink(&a, &link).unwrap();
    let mut linked = args.clone();
    linked.extend([
        "--output",
        a.to_str().unwrap(),
        "--exr",
        link.to_str().unwrap(),
    ]);
    let err = rejected(&linked, b"");
    assert!(err.contains("one would overwrite the other"), "{err}");
}

#[test]
fn an_include_that_adds_nothing_is_refused_and_a_repeated_one_is_named_apart() {
    let scene = "[[obj]]\npath = \"m.obj\"\n";
    let p = files(
        "empty-obj",
        &[("s.toml", scene), ("m.obj", "v 0 0 0\nv 1 0 0\n")],
    );
    let err = rejected(&quick("solve", &p), b"");
    assert!(err.contains("m.obj: adds no patch (0 face(s)"), "{err}");
    let lit = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let twice = format!(
        "{}[[obj]]\npath = \"m.obj\"\nmaterial = \"lamp\"\ntranslate = [0, 0, 2]\n\
         [[obj]]\npath = \"m.obj\"\nmaterial = \"m\"\n",
        TWO_SQUARES
    );
    let p = files("twice-obj", &[("s.toml", &twice), ("m.obj", lit)]);
    let (out, _) = accepted(&quick("solve", &p), b"");
    assert!(
        out.contains("unnamed_object/0 ") && out.contains("unnamed_object/0:2 "),
        "{out}"
    );
}

#[test]
fn options_that_would_be_ignored_are_refused_or_warned_about() {
    refused(
        "margin",
        &["solve", "--margin", "0.5"],
        &[
            "the following required arguments were not provided",
            "--adaptive",
        ],
    );
    refused(
        "near",
        &["irradiance", "--near", "4294967295"],
        &["--near 4294967295: at most 8"],
    );
    refused(
        "clock",
        &["solve", "--backend", "model", "--clock-mhz", "1e300"],
        &["--clock-mhz 1e300: must be a clock in MHz between 0.001 and 10000"],
    );
    refused(
        "circles",
        &["solve", "--circles", "1025"],
        &["--circles 1025: must be between 2 and 1024"],
    );
    refused(
        "spp",
        &["render", "--spp", "0", "--output", "/tmp/hemi-s.png"],
        &["--spp 0: must be"],
    );
    refused(
        "image",
        &["render", "--size", "16384x16384", "--eye", "0.5,0.5,3", "--look-at", "0.5,0.5,0", "--output", "/tmp/hemi-i.png"],
        &["render: a 16384×16384 picture needs about 6144 MiB (24 bytes a pixel), more than --image-mib 4096"],
    );
    refused(
        "view",
        &[
            "render",
            "--eye",
            "0.5,0.5,3",
            "--look-at",
            "0.5,0.5,3",
            "--output",
            "/tmp/hemi-v.png",
        ],
        &["--eye and --look-at: the view direction (0, 0, 0) is zero or parallel to up"],
    );
    refused(
        "near-cells",
        &["irradiance", "--near-cells", "NaN"],
        &["--near-cells NaN: must be a number of grid cells in (0, 64]"],
    );
    let view = [
        "--size",
        "4x4",
        "--eye",
        "0.5,0.5,3",
        "--look-at",
        "0.5,0.5,0",
    ];
    let out = dir("exr").join("a.png");
    let mut args = vec!["render", "--circles", "4", "--samples", "1"];
    args.extend(view);
    let mut exr = args.clone();
    exr.extend([
        "--output",
        out.to_str().unwrap(),
        "--exr",
        "/tmp/hemi-hostile-b.png",
    ]);
    refused(
        "exr",
        &exr,
        &["--exr /tmp/hemi-hostile-b.png: expected a .exr file"],
    );
    let p = files("exposure", &[("two.toml", TWO_SQUARES)]);
    let hdr = dir("exposure").join("a.hdr");
    let mut exposed = vec!["render", p.as_str(), "--exposure", "5"];
    exposed.extend(&args[1..]);
    exposed.extend(["--output", hdr.to_str().unwrap()]);
    let (_, err) = accepted(&exposed, b"");
    assert!(
        err.contains("warning: --exposure 5 does not change"),
        "{err}"
    );
}

#[test]
fn an_obj_material_that_does_not_parse_or_does_not_exist_is_named() {
    let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    let scene = format!("{TWO_SQUARES}[[obj]]\npath = \"m.obj\"\n");
    let obj = format!("mtllib m.mtl\n{tri}usemtl nothere\nf 1 2 3\n");
    let p = files(
        "usemtl",
        &[
            ("s.toml", &scene),
            ("m.obj", &obj),
            ("m.mtl", "newmtl a\nKd 0.5 0.5 0.5\n"),
        ],
    );
    let (_, err) = accepted(&quick("solve", &p), b"");
    assert!(
        err.contains("m.obj:5: `usemtl nothere`: no MTL file defines it; its faces get `default`"),
        "{err}"
    );
    let p = files(
        "kd-abc",
        &[
            ("s.toml", &scene),
            ("m.obj", &obj),
            ("m.mtl", "newmtl a\nKd abc 0 0\n"),
        ],
    );
    let err = rejected(&quick("solve", &p), b"");
    assert!(
        err.contains("m.mtl:2: `Kd`: `abc` is not a number"),
        "{err}"
    );
}

#[test]
fn a_patch_repeated_over_another_is_refused_and_a_two_sided_wall_is_not() {
    let repeat = format!(
        "{TWO_SQUARES}[[quad]]\nname = \"again\"\nmaterial = \"m\"\n\
         vertices = [[0,1,1],[1,1,1],[1,0,1],[0,0,1]]\n"
    );
    let p = files("repeat", &[("s.toml", &repeat)]);
    let err = rejected(&quick("solve", &p), b"");
    assert!(
        err.contains("patch `again` has the vertices and facing of `p2`"),
        "{err}"
    );
    let wall = format!(
        "{TWO_SQUARES}[[quad]]\nname = \"back\"\nmaterial = \"m\"\n\
         vertices = [[0,0,1],[1,0,1],[1,1,1],[0,1,1]]\n"
    );
    let p = files("two-sided", &[("s.toml", &wall)]);
    accepted(&quick("solve", &p), b"");
}

#[test]
fn a_lobe_without_a_mirror_is_warned_about_and_an_invisible_name_is_refused() {
    let lobe = TWO_SQUARES.replace(
        "diffuse = [0.5, 0.5, 0.5]",
        "diffuse = [0.5, 0.5, 0.5]\nphong = 50",
    );
    let p = files("lobe", &[("s.toml", &lobe)]);
    let (_, err) = accepted(&quick("solve", &p), b"");
    assert!(
        err.contains("`material.phong`: warning: has no effect"),
        "{err}"
    );
    let hidden = TWO_SQUARES.replace("name = \"p1\"", "name = \"p\u{200B}1\"");
    let p = files("zero-width", &[("s.toml", &hidden)]);
    let err = rejected(&quick("solve", &p), b"");
    assert!(err.contains("contains '\\u{200b}'"), "{err}");
}

#[test]
fn model_options_on_the_soft_backend_are_said_to_do_nothing() {
    let p = files("soft-lanes", &[("two.toml", TWO_SQUARES)]);
    let solve = ["solve", &p, "--circles", "4", "--samples", "1"];
    let mut lanes = solve.to_vec();
    lanes.extend(["--lanes", "8"]);
    let (_, err) = accepted(&lanes, b"");
    assert!(err.contains("have no effect with --backend soft"), "{err}");
    let (ok, _, err) = run(&solve, b"");
    assert!(ok && !err.contains("have no effect"), "{err}");
    let mut delta = solve.to_vec();
    delta.extend(["--method", "hemicube", "--delta", "paper"]);
    let (_, err) = accepted(&delta, b"");
    assert!(
        err.contains("--delta paper has no effect with --method hemicube"),
        "{err}"
    );
}
