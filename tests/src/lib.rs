//! Shared helpers for hemi's integration tests: Howell's closed-form form factors (the reference
//! values the accuracy tests compare against) and small scene builders.

use std::f64::consts::PI;

/// Howell B-3: a plane element to a parallel rectangle a × b at distance c, the element's normal
/// passing through one corner of the rectangle.
pub fn element_to_parallel_rectangle_corner(a: f64, b: f64, c: f64) -> f64 {
    let (x, y) = (a / c, b / c);
    let sx = (1.0 + x * x).sqrt();
    let sy = (1.0 + y * y).sqrt();
    (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / (2.0 * PI)
}

/// Howell C-11: identical, parallel, directly opposed rectangles a × b at distance c.
pub fn opposed_rectangles(a: f64, b: f64, c: f64) -> f64 {
    let (x, y) = (a / c, b / c);
    let x2 = x * x;
    let y2 = y * y;
    2.0 / (PI * x * y)
        * ((((1.0 + x2) * (1.0 + y2)) / (1.0 + x2 + y2)).sqrt().ln()
            + x * (1.0 + y2).sqrt() * (x / (1.0 + y2).sqrt()).atan()
            + y * (1.0 + x2).sqrt() * (y / (1.0 + x2).sqrt()).atan()
            - x * x.atan()
            - y * y.atan())
}

/// Howell C-14: from rectangle 1 (width w, common edge l) to rectangle 2 (height h, same common
/// edge), perpendicular and sharing the edge l.
pub fn perpendicular_common_edge(l: f64, w: f64, h: f64) -> f64 {
    let (hh, ww) = (h / l, w / l);
    let h2 = hh * hh;
    let w2 = ww * ww;
    let a = (1.0 + w2) * (1.0 + h2) / (1.0 + w2 + h2);
    let b = (w2 * (1.0 + w2 + h2) / ((1.0 + w2) * (w2 + h2))).powf(w2);
    let c = (h2 * (1.0 + h2 + w2) / ((1.0 + h2) * (h2 + w2))).powf(h2);
    (ww * (1.0 / ww).atan() + hh * (1.0 / hh).atan()
        - (h2 + w2).sqrt() * (1.0 / (h2 + w2).sqrt()).atan()
        + 0.25 * (a * b * c).ln())
        / (PI * ww)
}

/// TOML for one quad patch.
pub fn quad(name: &str, material: &str, v: [[f64; 3]; 4]) -> String {
    let vs: Vec<String> = v
        .iter()
        .map(|p| format!("[{}, {}, {}]", p[0], p[1], p[2]))
        .collect();
    format!(
        "[[quad]]\nname = \"{name}\"\nmaterial = \"{material}\"\nvertices = [{}]\n\n",
        vs.join(", ")
    )
}

/// TOML for one material.
pub fn material(name: &str, diffuse: f64, emission: f64) -> String {
    format!(
        "[[material]]\nname = \"{name}\"\ndiffuse = [{diffuse}, {diffuse}, {diffuse}]\nemission = [{emission}, {emission}, {emission}]\n\n"
    )
}

/// A closed axis-aligned box `[0,sx]×[0,sy]×[0,sz]` with inward-facing walls, each wall cut into
/// n × n quads that share their vertices exactly.
pub fn closed_box(size: [f64; 3], n: usize, material: &str) -> String {
    let mut out = String::new();
    // (axis fixed, value, inward sign), two in-plane axes chosen so that the normal points inward
    let faces = [
        (0usize, 0.0, 1.0),
        (0, size[0], -1.0),
        (1, 0.0, 1.0),
        (1, size[1], -1.0),
        (2, 0.0, 1.0),
        (2, size[2], -1.0),
    ];
    for (f, &(axis, value, sign)) in faces.iter().enumerate() {
        let (a1, a2) = ((axis + 1) % 3, (axis + 2) % 3);
        for i in 0..n {
            for j in 0..n {
                let corner = |di: usize, dj: usize| {
                    let mut p = [0.0; 3];
                    p[axis] = value;
                    p[a1] = size[a1] * (i + di) as f64 / n as f64;
                    p[a2] = size[a2] * (j + dj) as f64 / n as f64;
                    p
                };
                // (a1 × a2) = +axis: counter-clockwise about +axis is (0,0),(1,0),(1,1),(0,1)
                let v = if sign > 0.0 {
                    [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)]
                } else {
                    [corner(0, 0), corner(0, 1), corner(1, 1), corner(1, 0)]
                };
                out += &quad(&format!("f{f}_{i}_{j}"), material, v);
            }
        }
    }
    out
}
