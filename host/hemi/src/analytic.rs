//! Closed-form form factors from Howell's catalog ("A Catalog of Radiation Heat Transfer
//! Configuration Factors"): the independent references of the accuracy tests and benchmarks.

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

/// Element at the origin facing +z, rectangle `[x0, x0+a] × [y0, y0+b]` at height c: B-3
/// combined by superposition (the signs take care of offsets on either side).
pub fn element_to_offset_rectangle(x0: f64, y0: f64, a: f64, b: f64, c: f64) -> f64 {
    let g = |x: f64, y: f64| {
        x.signum() * y.signum() * element_to_parallel_rectangle_corner(x.abs(), y.abs(), c)
    };
    g(x0 + a, y0 + b) - g(x0, y0 + b) - g(x0 + a, y0) + g(x0, y0)
}

/// The closed-form cases of the accuracy table and the presets bench: (name, scene TOML of two
/// quads of reflectance 0.5, Howell value of F_01 from patch 0 to patch 1).
pub fn howell_cases() -> Vec<(&'static str, String, f64)> {
    let mat = "[[material]]\nname = \"m\"\ndiffuse = [0.5, 0.5, 0.5]\n";
    let quad = |name: &str, v: [[f64; 3]; 4]| {
        let vs: Vec<String> = v
            .iter()
            .map(|p| format!("[{}, {}, {}]", p[0], p[1], p[2]))
            .collect();
        format!(
            "[[quad]]\nname = \"{name}\"\nmaterial = \"m\"\nvertices = [{}]\n",
            vs.join(", ")
        )
    };
    let opposed = |a: f64, b: f64, c: f64| {
        mat.to_string()
            + &quad(
                "p1",
                [[0.0, 0.0, 0.0], [a, 0.0, 0.0], [a, b, 0.0], [0.0, b, 0.0]],
            )
            + &quad("p2", [[0.0, 0.0, c], [0.0, b, c], [a, b, c], [a, 0.0, c]])
    };
    let perpendicular = |l: f64, w: f64, h: f64| {
        mat.to_string()
            + &quad(
                "floor",
                [[0.0, 0.0, 0.0], [0.0, 0.0, w], [l, 0.0, w], [l, 0.0, 0.0]],
            )
            + &quad(
                "wall",
                [[0.0, 0.0, 0.0], [l, 0.0, 0.0], [l, h, 0.0], [0.0, h, 0.0]],
            )
    };
    vec![
        (
            "opposed 1×1 at 1 (C-11)",
            opposed(1.0, 1.0, 1.0),
            opposed_rectangles(1.0, 1.0, 1.0),
        ),
        (
            "opposed 1×1 at 3 (C-11)",
            opposed(1.0, 1.0, 3.0),
            opposed_rectangles(1.0, 1.0, 3.0),
        ),
        (
            "opposed 2×1 at 0.5 (C-11)",
            opposed(2.0, 1.0, 0.5),
            opposed_rectangles(2.0, 1.0, 0.5),
        ),
        (
            "perpendicular 1,1,1 (C-14)",
            perpendicular(1.0, 1.0, 1.0),
            perpendicular_common_edge(1.0, 1.0, 1.0),
        ),
        (
            "perpendicular 1,2,1 (C-14)",
            perpendicular(1.0, 2.0, 1.0),
            perpendicular_common_edge(1.0, 2.0, 1.0),
        ),
    ]
}

// --- Bezier patches: an f64 reference independent of the kernel's f32 subdivision ---

use hemi_kernel::geometry::Bezier;

/// A point or vector in f64.
pub type D3 = [f64; 3];

fn bern(t: f64) -> [f64; 4] {
    let s = 1.0 - t;
    [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t]
}
fn bern_d(t: f64) -> [f64; 4] {
    let s = 1.0 - t;
    [
        -3.0 * s * s,
        3.0 * s * s - 6.0 * t * s,
        6.0 * t * s - 3.0 * t * t,
        3.0 * t * t,
    ]
}

/// P, ∂P/∂u, ∂P/∂v in f64: the reference's own evaluation, independent of the kernel's f32 code.
pub fn bezier_eval(b: &Bezier, u: f64, v: f64) -> (D3, D3, D3) {
    let (bu, bv, du, dv) = (bern(u), bern(v), bern_d(u), bern_d(v));
    let mut out = ([0.0; 3], [0.0; 3], [0.0; 3]);
    for r in 0..4 {
        for c in 0..4 {
            let p = b.cp[4 * r + c].to_array().map(|x| x as f64);
            for (k, pk) in p.iter().enumerate() {
                out.0[k] += bv[r] * bu[c] * pk;
                out.1[k] += bv[r] * du[c] * pk;
                out.2[k] += dv[r] * bu[c] * pk;
            }
        }
    }
    out
}

/// Newton on P(u,v) − o − t d = 0 from the best seed of a dense 48×48 grid (the point nearest
/// the ray); `None` unless it converges (to 1e-5 of the line, the f32 inputs' resolution)
/// inside the patch with t > 0.
pub fn bezier_newton(b: &Bezier, o: D3, d: D3) -> Option<(f64, f64, f64)> {
    let line_dist = |p: D3| {
        let w = [p[0] - o[0], p[1] - o[1], p[2] - o[2]];
        let t = w[0] * d[0] + w[1] * d[1] + w[2] * d[2];
        let q = [w[0] - t * d[0], w[1] - t * d[1], w[2] - t * d[2]];
        (q[0] * q[0] + q[1] * q[1] + q[2] * q[2], t)
    };
    let mut best = (f64::INFINITY, 0.0, 0.0, 0.0);
    for i in 0..=48 {
        for j in 0..=48 {
            let (u, v) = (i as f64 / 48.0, j as f64 / 48.0);
            let (dist, t) = line_dist(bezier_eval(b, u, v).0);
            if t > 0.0 && dist < best.0 {
                best = (dist, u, v, t);
            }
        }
    }
    let (_, mut u, mut v, mut t) = best;
    for _ in 0..30 {
        let (p, pu, pv) = bezier_eval(b, u, v);
        let f = [
            p[0] - o[0] - t * d[0],
            p[1] - o[1] - t * d[1],
            p[2] - o[2] - t * d[2],
        ];
        // J = [pu pv −d]; solve J x = −f by Cramer's rule
        let col = [pu, pv, [-d[0], -d[1], -d[2]]];
        let det3 = |a: D3, b: D3, c: D3| {
            a[0] * (b[1] * c[2] - b[2] * c[1]) - b[0] * (a[1] * c[2] - a[2] * c[1])
                + c[0] * (a[1] * b[2] - a[2] * b[1])
        };
        let det = det3(col[0], col[1], col[2]);
        if det.abs() < 1e-14 {
            return None;
        }
        let rhs = [-f[0], -f[1], -f[2]];
        let du = det3(rhs, col[1], col[2]) / det;
        let dv = det3(col[0], rhs, col[2]) / det;
        let dt = det3(col[0], col[1], rhs) / det;
        u += du;
        v += dv;
        t += dt;
        if du.abs() + dv.abs() < 1e-12 {
            break;
        }
    }
    let (p, _, _) = bezier_eval(b, u, v);
    let (dist, _) = line_dist(p);
    ((0.0..=1.0).contains(&u) && (0.0..=1.0).contains(&v) && t > 0.0 && dist < 1e-10)
        .then_some((t, u, v))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn catalog_values() {
        // tabulated values: unit squares one apart, opposed 0.1998, perpendicular 0.2000
        assert!((opposed_rectangles(1.0, 1.0, 1.0) - 0.19982).abs() < 1e-4);
        assert!((perpendicular_common_edge(1.0, 1.0, 1.0) - 0.20004).abs() < 1e-4);
        // an element under the centre of a huge plate sees all of it
        assert!((element_to_offset_rectangle(-1e4, -1e4, 2e4, 2e4, 1.0) - 1.0).abs() < 1e-3);
        // superposition reproduces the corner case
        let c = element_to_parallel_rectangle_corner(1.0, 2.0, 0.5);
        assert!((element_to_offset_rectangle(0.0, 0.0, 1.0, 2.0, 0.5) - c).abs() < 1e-12);
    }
}
