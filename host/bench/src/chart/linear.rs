//! A linear-axes SVG line chart with optional horizontal reference lines, for the charts the
//! log–log chart of [`super`] does not suit (a value converging, paper fig. 9a).

use super::Series;
use std::fmt::Write;

const W: f64 = 640.0;
const H: f64 = 420.0;
const L: f64 = 80.0;
const R: f64 = 210.0;
const T: f64 = 40.0;
const B: f64 = 60.0;
const COLOURS: [&str; 8] = [
    "#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf",
];

fn nice_step(span: f64) -> f64 {
    let raw = span / 6.0;
    let mag = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 2.5, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * mag)
}

/// Renders `series` on linear axes; `refs` are dashed horizontal lines (value, label) in the
/// colour of the series with the same index.
pub fn linear(
    title: &str,
    x_label: &str,
    y_label: &str,
    note: &str,
    series: &[Series],
    refs: &[(f64, String)],
) -> String {
    let xs = series.iter().flat_map(|s| s.points.iter().map(|p| p.0));
    let ys = series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.1))
        .chain(refs.iter().map(|r| r.0));
    let (x0, x1) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
        (a.min(x), b.max(x))
    });
    let (mut y0, mut y1) = ys.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), y| {
        (a.min(y), b.max(y))
    });
    let pad = 0.08 * (y1 - y0).max(1e-12);
    y0 -= pad;
    y1 += pad;
    let (x0, x1) = (x0.min(0.0), x1.max(x0 + 1e-12));
    let px = |x: f64| L + (x - x0) / (x1 - x0) * (W - L - R);
    let py = |y: f64| H - B - (y - y0) / (y1 - y0) * (H - T - B);
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" font-family="sans-serif" font-size="12"><rect width="100%" height="100%" fill="white"/>"#
    );
    let _ = writeln!(
        s,
        r#"<text x="{}" y="22" font-size="15" text-anchor="middle">{title}</text>"#,
        (W - R + L) / 2.0
    );
    let xs = nice_step(x1 - x0);
    let mut x = (x0 / xs).ceil() * xs;
    while x <= x1 + 1e-9 {
        let p = px(x);
        let _ = writeln!(
            s,
            r##"<line x1="{p}" y1="{T}" x2="{p}" y2="{}" stroke="#ddd"/><text x="{p}" y="{}" text-anchor="middle">{}</text>"##,
            H - B,
            H - B + 16.0,
            x
        );
        x += xs;
    }
    let ys = nice_step(y1 - y0);
    let mut y = (y0 / ys).ceil() * ys;
    while y <= y1 + 1e-12 {
        let p = py(y);
        let _ = writeln!(
            s,
            r##"<line x1="{L}" y1="{p}" x2="{}" y2="{p}" stroke="#ddd"/><text x="{}" y="{}" text-anchor="end">{:.4}</text>"##,
            W - R,
            L - 6.0,
            p + 4.0,
            y
        );
        y += ys;
    }
    super::frame(&mut s, R, x_label, y_label, note);
    let mut legend = 0;
    for (i, (v, label)) in refs.iter().enumerate() {
        let c = COLOURS[i % COLOURS.len()];
        let p = py(*v);
        let _ = writeln!(
            s,
            r#"<line x1="{L}" y1="{p}" x2="{}" y2="{p}" stroke="{c}" stroke-dasharray="6,4"/>"#,
            W - R
        );
        let ly = T + 14.0 + 18.0 * legend as f64;
        legend += 1;
        let _ = writeln!(
            s,
            r#"<line x1="{}" y1="{ly}" x2="{}" y2="{ly}" stroke="{c}" stroke-dasharray="6,4"/><text x="{}" y="{}">{label}</text>"#,
            W - R + 12.0,
            W - R + 32.0,
            W - R + 38.0,
            ly + 4.0
        );
    }
    for (i, se) in series.iter().enumerate() {
        let c = COLOURS[i % COLOURS.len()];
        let path: Vec<String> = se
            .points
            .iter()
            .map(|p| format!("{:.1},{:.1}", px(p.0), py(p.1)))
            .collect();
        super::polyline(&mut s, &path, c);
        let ly = T + 14.0 + 18.0 * legend as f64;
        legend += 1;
        let _ = writeln!(
            s,
            r#"<line x1="{}" y1="{ly}" x2="{}" y2="{ly}" stroke="{c}" stroke-width="2"/><text x="{}" y="{}">{}</text>"#,
            W - R + 12.0,
            W - R + 32.0,
            W - R + 38.0,
            ly + 4.0,
            se.name
        );
    }
    s.push_str("</svg>\n");
    s
}
