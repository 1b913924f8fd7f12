//! What the CLI's test binaries share.

use std::io::Write;
use std::process::{Command, Stdio};

/// A unit square lit by a unit square lamp one above it: the smallest scene with a solve.
pub const TWO_SQUARES: &str = r#"
[[material]]
name = "m"
diffuse = [0.5, 0.5, 0.5]

[[material]]
name = "lamp"
diffuse = [0.0, 0.0, 0.0]
emission = [2.0, 3.0, 4.0]

[[quad]]
name = "p1"
material = "m"
vertices = [[0,0,0],[1,0,0],[1,1,0],[0,1,0]]

[[quad]]
name = "p2"
material = "lamp"
vertices = [[0,0,1],[0,1,1],[1,1,1],[1,0,1]]
"#;

/// `hemi trace` input: `n` rays from above the Cornell box's blocks in directions spread over
/// the sphere, then one that leaves through the box's open front.
#[allow(
    dead_code,
    reason = "not every test binary that includes this module traces the Cornell box"
)]
pub fn cornell_rays(n: usize) -> String {
    let mut rays = String::new();
    for i in 0..n {
        let a = i as f64 * 0.41;
        let line = format!("278 450 279 {} {} {}\n", a.cos(), (a * 0.7).sin(), a.sin());
        rays.push_str(&line);
    }
    rays.push_str("278 450 279 0 0 -1\n");
    rays
}

/// Runs hemi with `args`, feeding `stdin`; returns (success, stdout, stderr).
#[allow(
    dead_code,
    reason = "not every test binary that includes this module feeds stdin"
)]
pub fn run(args: &[&str], stdin: impl AsRef<[u8]>) -> (bool, String, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_hemi"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut input = child.stdin.take().unwrap();
    let bytes = stdin.as_ref().to_vec();
    // written on a thread of its own: hemi may stop reading at the first bad line
    let feeder = std::thread::spawn(move || {
        let _ = input.write_all(&bytes);
    });
    let out = child.wait_with_output().unwrap();
    feeder.join().unwrap();
    (
        out.status.success(),
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8(out.stderr).unwrap(),
    )
}
