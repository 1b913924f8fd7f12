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
