//! What the CLI's test binaries share.

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
