//! The benchmarks' SVG line charts for the figures of docs/ACCURACY.md and docs/PERFORMANCE.md:
//! log–log axes here, linear axes in [`linear`]. A few dozen lines instead of a plotting crate,
//! so the benchmarks that regenerate the figures stay quick to build.

pub mod linear;

use std::fmt::Write;

/// One named polyline of (x, y) points (both > 0).
pub struct Series {
    /// Legend text.
    pub name: String,
    /// The points, in drawing order.
    pub points: Vec<(f64, f64)>,
}

const W: f64 = 640.0;
const H: f64 = 420.0;
const L: f64 = 80.0;
const R: f64 = 190.0;
const T: f64 = 40.0;
const B: f64 = 60.0;
const COLOURS: [&str; 8] = [
    "#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf",
];

/// One series as an SVG polyline through `path` ("x,y" in pixels) with a dot at each point, in
/// colour `c`: how both chart kinds draw their lines.
pub(crate) fn polyline(s: &mut String, path: &[String], c: &str) {
    let _ = writeln!(
        s,
        r#"<polyline points="{}" fill="none" stroke="{c}" stroke-width="2"/>"#,
        path.join(" ")
    );
    for p in path {
        let (x, y) = p.split_once(',').unwrap_or(("0", "0"));
        let _ = writeln!(s, r#"<circle cx="{x}" cy="{y}" r="3" fill="{c}"/>"#);
    }
}

fn decade_range(v: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = v.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
        (a.min(x), b.max(x))
    });
    (
        lo.log10().floor(),
        hi.log10().ceil().max(lo.log10().floor() + 1.0),
    )
}

/// Renders `series` on log–log axes with a title, axis labels and a note under the plot (the
/// reference the error is measured against).
pub fn log_log(title: &str, x_label: &str, y_label: &str, note: &str, series: &[Series]) -> String {
    let pts = || {
        series
            .iter()
            .flat_map(|s| s.points.iter())
            .filter(|p| p.0 > 0.0 && p.1 > 0.0)
    };
    let (x0, x1) = decade_range(pts().map(|p| p.0));
    let (y0, y1) = decade_range(pts().map(|p| p.1));
    let px = |x: f64| L + (x.log10() - x0) / (x1 - x0) * (W - L - R);
    let py = |y: f64| H - B - (y.log10() - y0) / (y1 - y0) * (H - T - B);
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
    for d in x0 as i32..=x1 as i32 {
        let x = px(10f64.powi(d));
        let _ = writeln!(
            s,
            r##"<line x1="{x}" y1="{T}" x2="{x}" y2="{}" stroke="#ddd"/><text x="{x}" y="{}" text-anchor="middle">1e{d}</text>"##,
            H - B,
            H - B + 16.0
        );
    }
    for d in y0 as i32..=y1 as i32 {
        let y = py(10f64.powi(d));
        let _ = writeln!(
            s,
            r##"<line x1="{L}" y1="{y}" x2="{}" y2="{y}" stroke="#ddd"/><text x="{}" y="{}" text-anchor="end">1e{d}</text>"##,
            W - R,
            L - 6.0,
            y + 4.0
        );
    }
    frame(&mut s, R, x_label, y_label, note);
    for (i, se) in series.iter().enumerate() {
        let c = COLOURS[i % COLOURS.len()];
        let path: Vec<String> = se
            .points
            .iter()
            .filter(|p| p.0 > 0.0 && p.1 > 0.0)
            .map(|p| format!("{:.1},{:.1}", px(p.0), py(p.1)))
            .collect();
        polyline(&mut s, &path, c);
        let ly = T + 14.0 + 18.0 * i as f64;
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

/// The plot frame every chart shares (`right`: the margin its legend takes): the plot area's
/// border, the axis labels and the note under
/// the chart (which states the reference the chart's error is measured against).
pub(crate) fn frame(s: &mut String, right: f64, x_label: &str, y_label: &str, note: &str) {
    let r = right;
    let _ = writeln!(
        s,
        r#"<rect x="{L}" y="{T}" width="{}" height="{}" fill="none" stroke="black"/>"#,
        W - L - r,
        H - T - B
    );
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" text-anchor="middle">{x_label}</text>"#,
        (W - r + L) / 2.0,
        H - B + 34.0
    );
    let _ = writeln!(
        s,
        r#"<text transform="translate(18,{}) rotate(-90)" text-anchor="middle">{y_label}</text>"#,
        (H - B + T) / 2.0
    );
    let _ = writeln!(
        s,
        r##"<text x="{L}" y="{}" font-size="11" fill="#444">{note}</text>"##,
        H - 8.0
    );
}
