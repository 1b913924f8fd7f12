//! The `hemi` command line as a user drives it: the output shapes of the README's command table, errors, and the
//! irradiance query against a closed form.

mod common;

use common::{run, TWO_SQUARES};
use std::io::Write;
use std::path::PathBuf;
use std::process::{Command, Stdio};

fn hemi() -> Command {
    Command::new(env!("CARGO_BIN_EXE_hemi"))
}

/// Writes `text` to a fresh scene file and returns its path.
fn scene(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hemi-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn form_factors_json_has_the_spec_shape() {
    let p = scene("two.toml", TWO_SQUARES);
    let (ok, out, err) = run(
        &[
            "form-factors",
            p.to_str().unwrap(),
            "--json",
            "--circles",
            "32",
            "--samples",
            "4",
        ],
        "",
    );
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let names: Vec<&str> = v["patches"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["p1", "p2"]);
    assert!((v["patches"][0]["area"].as_f64().unwrap() - 1.0).abs() < 1e-6);
    let m = v["matrix"].as_array().unwrap();
    assert_eq!(m.len(), 2);
    let f01 = m[0][1].as_f64().unwrap();
    assert!((f01 - 0.1998).abs() < 0.01, "{f01}");
    assert_eq!(m[0][0].as_f64().unwrap(), 0.0);
}

#[test]
fn solve_json_has_the_spec_shape_and_the_lamp_keeps_its_emission() {
    let p = scene("two-solve.toml", TWO_SQUARES);
    let (ok, out, err) = run(
        &[
            "solve",
            p.to_str().unwrap(),
            "--json",
            "--circles",
            "32",
            "--samples",
            "4",
        ],
        "",
    );
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["patches"][1]["name"], "p2");
    let lamp: Vec<f64> = v["patches"][1]["radiosity"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert_eq!(lamp, [2.0, 3.0, 4.0]);
    // B1 = ρ F12 E2
    let b1 = v["patches"][0]["radiosity"][2].as_f64().unwrap();
    assert!((b1 - 0.5 * 0.1998 * 4.0).abs() < 0.01, "{b1}");
    assert!(v["iterations"].as_u64().unwrap() >= 1);
    assert!(v["residual"].as_f64().unwrap() < 1e-6);
}

#[test]
fn a_translucent_sheet_lists_its_back_side_last_in_the_json() {
    // p1 made translucent: its back side faces away from the lamp and sees nothing; its front
    // gathers the lamp and passes τ of it to the back
    let text = TWO_SQUARES.replace(
        "diffuse = [0.5, 0.5, 0.5]",
        "diffuse = [0.3, 0.3, 0.3]\ntranslucency = [0.5, 0.5, 0.5]",
    );
    let p = scene("two-translucent.toml", &text);
    let args = ["--circles", "32", "--samples", "4", "--json"];
    let (ok, out, err) = run(&[&["solve", p.to_str().unwrap()], &args[..]].concat(), "");
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let names: Vec<&str> = v["patches"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["p1", "p2", "p1:back"]);
    let b = |i: usize| v["patches"][i]["radiosity"][2].as_f64().unwrap();
    // B_front = ρ F E, B_back = τ F E
    assert!((b(0) - 0.3 * 0.1998 * 4.0).abs() < 0.01, "{}", b(0));
    assert!((b(2) - 0.5 * 0.1998 * 4.0).abs() < 0.01, "{}", b(2));
    let (ok, out, err) = run(
        &[&["form-factors", p.to_str().unwrap()], &args[..]].concat(),
        "",
    );
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let m = v["matrix"].as_array().unwrap();
    assert_eq!(m.len(), 3);
    assert!(
        m[2].as_array().unwrap().iter().all(|f| f == 0.0),
        "the back side sees nothing"
    );
}

#[test]
fn trace_prints_t_patch_u_v_or_miss() {
    let p = scene("two-trace.toml", TWO_SQUARES);
    let rays = "0.25 0.75 0.5 0 0 1\n# a comment line is skipped\n0.5 0.5 0.5 -1 0 0\n0.5 0.5 0.5 0 0 -2\n";
    let (ok, out, err) = run(&["trace", p.to_str().unwrap()], rays);
    assert!(ok, "{err}");
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines.len(), 3, "{out}");
    let f: Vec<&str> = lines[0].split_whitespace().collect();
    assert_eq!(f[1], "p2");
    let (t, u, v): (f64, f64, f64) = (
        f[0].parse().unwrap(),
        f[2].parse().unwrap(),
        f[3].parse().unwrap(),
    );
    assert!(
        (t - 0.5).abs() < 1e-6 && (u - 0.75).abs() < 1e-4 && (v - 0.25).abs() < 1e-4,
        "{}",
        lines[0]
    );
    assert_eq!(lines[1], "miss");
    // the direction is normalised: t is a distance
    let f: Vec<&str> = lines[2].split_whitespace().collect();
    assert_eq!(f[1], "p1");
    assert!((f[0].parse::<f64>().unwrap() - 0.5).abs() < 1e-6);
}

#[test]
fn bad_input_gets_a_clear_error_and_a_failing_status() {
    let p = scene(
        "bad.toml",
        &TWO_SQUARES.replace("material = \"lamp\"", "material = \"lamb\""),
    );
    let (ok, _, err) = run(&["solve", p.to_str().unwrap()], "");
    assert!(!ok);
    assert!(
        err.contains("bad.toml:18") && err.contains("quad.material") && err.contains("lamb"),
        "{err}"
    );
    let (ok, _, err) = run(&["solve", "/nonexistent/scene.toml"], "");
    assert!(!ok && err.contains("cannot read scene file"), "{err}");
    let p = scene("good.toml", TWO_SQUARES);
    let (ok, _, err) = run(&["trace", p.to_str().unwrap()], "1 2 3 oops\n");
    assert!(!ok && err.contains("line 1"), "{err}");
    let (ok, _, err) = run(
        &["solve", p.to_str().unwrap(), "--backend", "warp-drive"],
        "",
    );
    assert!(!ok && err.contains("warp-drive"), "{err}");
}

#[test]
fn the_model_backend_takes_the_bezier_units_depth_and_width() {
    let p = scene("bezier-flags.toml", TWO_SQUARES);
    let p = p.to_str().unwrap();
    let base = [
        "solve",
        p,
        "--backend",
        "model",
        "--circles",
        "4",
        "--samples",
        "1",
    ];
    let (ok, _, err) = run(&[&base[..], &["--bezier-depth", "14"]].concat(), "");
    assert!(!ok && err.contains("--bezier-depth 14"), "{err}");
    let (ok, _, err) = run(&[&base[..], &["--bezier-width", "11"]].concat(), "");
    assert!(!ok && err.contains("--bezier-width 11"), "{err}");
    let narrow = ["--bezier-depth", "6", "--bezier-width", "14"];
    let (ok, _, err) = run(&[&base[..], &narrow[..]].concat(), "");
    assert!(ok, "{err}");
}

#[test]
fn irradiance_under_a_lambertian_emitter_matches_the_closed_form() {
    // An emitting rectangle [0.2,1.2]×[0.3,1.3] at height 1, facing down, exitance M: the
    // irradiance at the origin facing up is M·F (Howell B-3 by superposition).
    let src = r#"
[[material]]
name = "lamp"
diffuse = [0.0, 0.0, 0.0]
emission = [1.0, 2.0, 10.0]

[[quad]]
name = "lamp"
material = "lamp"
vertices = [[0.2,0.3,1],[0.2,1.3,1],[1.2,1.3,1],[1.2,0.3,1]]
"#;
    let p = scene("lamp.toml", src);
    let (ok, out, err) = run(
        &["irradiance", p.to_str().unwrap()],
        "0 0 0 0 0 1\n0 0 0 0 0 -1\n",
    );
    assert!(ok, "{err}");
    let f = hemi::analytic::element_to_offset_rectangle(0.2, 0.3, 1.0, 1.0, 1.0);
    let lines: Vec<Vec<f64>> = out
        .lines()
        .map(|l| l.split_whitespace().map(|x| x.parse().unwrap()).collect())
        .collect();
    for (c, m) in [1.0, 2.0, 10.0].iter().enumerate() {
        let want = m * f;
        assert!(
            (lines[0][c] - want).abs() < 0.005 * want,
            "channel {c}: {} vs {want}",
            lines[0][c]
        );
    }
    assert_eq!(lines[1], [0.0, 0.0, 0.0], "facing away sees nothing");
}

#[test]
fn the_model_backend_gives_the_soft_backends_form_factors_and_reports_cycles() {
    let p = scene("two-model.toml", TWO_SQUARES);
    let args = |b: &'static str| {
        [
            "form-factors",
            "--json",
            "--circles",
            "16",
            "--samples",
            "2",
            "--backend",
            b,
        ]
    };
    let (ok, soft, err) = run(&[&args("soft")[..], &[p.to_str().unwrap()]].concat(), "");
    assert!(ok, "{err}");
    let (ok, model, err) = run(&[&args("model")[..], &[p.to_str().unwrap()]].concat(), "");
    assert!(ok, "{err}");
    assert!(err.contains("cycles/ray") && err.contains("MHz"), "{err}");
    let m = |s: &str| -> Vec<Vec<f64>> {
        let v: serde_json::Value = serde_json::from_str(s).unwrap();
        v["matrix"]
            .as_array()
            .unwrap()
            .iter()
            .map(|r| {
                r.as_array()
                    .unwrap()
                    .iter()
                    .map(|x| x.as_f64().unwrap())
                    .collect()
            })
            .collect()
    };
    let (a, b) = (m(&soft), m(&model));
    for (ra, rb) in a.iter().zip(&b) {
        for (x, y) in ra.iter().zip(rb) {
            assert!((x - y).abs() < 1e-6, "soft {x} model {y}");
        }
    }
}

/// A running `hemi` with piped stdin and stdout, whose stdout lines arrive on a channel (so a
/// test can wait for one with a deadline instead of hanging).
struct CoProcess {
    child: std::process::Child,
    stdin: Option<std::process::ChildStdin>,
    lines: std::sync::mpsc::Receiver<String>,
}

impl CoProcess {
    fn start(args: &[&str]) -> CoProcess {
        let mut child = hemi()
            .args(args)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        let stdout = child.stdout.take().unwrap();
        let (tx, lines) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            use std::io::BufRead;
            for l in std::io::BufReader::new(stdout).lines() {
                if tx.send(l.unwrap()).is_err() {
                    break;
                }
            }
        });
        let stdin = child.stdin.take();
        CoProcess {
            child,
            stdin,
            lines,
        }
    }

    /// Writes `line` (stdin stays open) and waits for one answer line.
    fn ask(&mut self, line: &str) -> String {
        let stdin = self.stdin.as_mut().unwrap();
        writeln!(stdin, "{line}").unwrap();
        stdin.flush().unwrap();
        self.lines
            .recv_timeout(std::time::Duration::from_secs(120))
            .unwrap_or_else(|e| panic!("no answer to `{line}` with stdin open: {e}"))
    }

    /// Closes stdin and waits for the exit status.
    fn finish(mut self) -> bool {
        drop(self.stdin.take());
        self.child.wait().unwrap().success()
    }
}

#[test]
fn irradiance_answers_each_line_before_the_input_closes() {
    let p = scene("stream.toml", TWO_SQUARES);
    let args = ["irradiance", p.to_str().unwrap(), "--circles", "16"];
    let mut co = CoProcess::start(&[&args[..], &["--samples", "2"]].concat());
    // p1 at z = 0 faces +z towards the lamp p2 at z = 1 (blue exitance 4)
    let first: Vec<f64> = co
        .ask("0.5 0.5 0.001 0 0 1")
        .split_whitespace()
        .map(|x| x.parse().unwrap())
        .collect();
    // the point-to-square form factor is about 0.24: E = F·M, in the lamp's 2:3:4
    assert!(first.len() == 3 && first[2] > 0.5, "{first:?}");
    assert!((first[0] / first[2] - 0.5).abs() < 1e-3, "{first:?}");
    // rtrace's convention: a zero direction is answered with a blank (zero) record at once
    assert_eq!(co.ask("0 0 0 0 0 0"), "0.000000e0 0.000000e0 0.000000e0");
    let again = co.ask("0.5 0.5 0.001 0 0 1");
    assert_eq!(again.split_whitespace().count(), 3, "{again}");
    assert!(co.finish());
}

#[test]
fn trace_answers_each_line_before_the_input_closes() {
    let p = scene("stream-trace.toml", TWO_SQUARES);
    let mut co = CoProcess::start(&["trace", p.to_str().unwrap()]);
    assert!(co.ask("0.25 0.75 0.5 0 0 1").contains(" p2 "));
    assert_eq!(co.ask("0.25 0.75 0.5 0 0 0"), "miss");
    assert!(co.ask("0.5 0.5 0.5 0 0 -1").contains(" p1 "));
    assert!(co.finish());
}

#[test]
fn render_refuses_bad_outputs_before_it_even_reads_the_scene() {
    // the scene does not exist: each error below must come from the output check, before it
    let missing = "/nonexistent/scene.toml";
    let cases: [(&[&str], &str); 5] = [
        (&["-o", "out.jpg"], "unknown image format"),
        (&["-o", "/nonexistent/dir/out.png"], "cannot write there"),
        (&["-o", "/tmp"], "unknown image format"),
        (&["-o", "same.exr", "--exr", "./same.exr"], "both name"),
        (
            &["-o", "out.png", "--exr", "/nonexistent/dir/x.exr"],
            "--exr",
        ),
    ];
    for (args, want) in cases {
        let (ok, _, err) = run(&[&["render", missing][..], args].concat(), "");
        assert!(!ok && err.contains(want), "{args:?}: {err}");
        assert!(
            !err.contains("scene"),
            "{args:?} was checked after the scene: {err}"
        );
    }
    assert!(
        !std::path::Path::new("same.exr").exists(),
        "the check leaves no file behind"
    );
    let p = scene("view.toml", TWO_SQUARES);
    let p = p.to_str().unwrap();
    for (args, want) in [
        (&["--size", "0x10"][..], "--size"),
        (&["--size", "640"][..], "--size"),
        (&["--fov", "180"][..], "--fov"),
        (&["--eye", "1,2"][..], "--eye"),
        (&[][..], "--eye X,Y,Z and --look-at"),
    ] {
        let out = std::env::temp_dir().join(format!("hemi-view-{}.png", std::process::id()));
        let o = out.to_str().unwrap();
        let (ok, _, err) = run(&[&["render", p, "-o", o][..], args].concat(), "");
        assert!(!ok && err.contains(want), "{args:?}: {err}");
    }
}

#[test]
fn render_writes_png_to_stdout_at_the_size_and_view_given() {
    // TWO_SQUARES has no camera: the view comes from the command line
    let p = scene("stdout.toml", TWO_SQUARES);
    let args = [
        "render",
        p.to_str().unwrap(),
        "-o",
        "-",
        "--size",
        "24x16",
        "--eye",
        "0.5,0.5,0.5",
        "--look-at",
        "0.5,0.5,1",
        "--fov",
        "90",
        "--circles",
        "8",
        "--samples",
        "2",
    ];
    let out = hemi().args(args).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    let png = out.stdout;
    assert_eq!(&png[1..4], b"PNG", "{err}");
    // the IHDR chunk: width and height, big endian, after the 8-byte signature and 8 bytes
    let be = |at: usize| u32::from_be_bytes(png[at..at + 4].try_into().unwrap());
    assert_eq!((be(16), be(20)), (24, 16));
}
