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
