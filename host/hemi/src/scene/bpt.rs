//! Bicubic Bezier patches: `[[bezier]]` entries and `[[bpt]]` files in the common `.bpt` text
//! format (the number of patches, then per patch its degrees "3 3" and 16 points "x y z").

use super::ctx::Ctx;
use super::file::read_text;
use super::range::{coordinate, not_f32, show, too_small};
use super::{ScenePatch, Sides};
use anyhow::Result;
use hemi_kernel::geometry::{Bezier, Vec3};
use hemi_kernel::patch::Shape;
use hemi_kernel::sampling::bezier_area;
use serde::Deserialize;
use std::collections::HashMap;
use toml::Spanned;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawBpt {
    /// Path of the .bpt file, relative to the scene file.
    pub(super) path: Spanned<String>,
    /// Patches are named `<name>/<index>`.
    pub(super) name: Spanned<String>,
    pub(super) material: Spanned<String>,
    #[serde(default)]
    pub(super) scale: Option<Spanned<f64>>,
    #[serde(default)]
    pub(super) translate: Option<Spanned<Vec<f64>>>,
    /// Swap u and v, turning every patch's front side over (for files whose patches face inward).
    #[serde(default)]
    pub(super) flip: bool,
}

/// Why a Bezier patch was not made.
pub enum Reject {
    /// A control point is outside the coordinates hemi takes: always an error.
    Range(String),
    /// Zero area, or too small for f32: an error in `[[bezier]]`, skipped in a `.bpt` file.
    Degenerate(String),
}

/// A Bezier scene patch from 16 control points (row-major, c along u), scaled then translated.
/// `flip` swaps u and v, which turns the front side over.
pub fn bezier_patch(
    name: String,
    material: usize,
    cp: &[[f64; 3]],
    scale: f64,
    translate: [f64; 3],
    flip: bool,
) -> std::result::Result<ScenePatch, Reject> {
    let mut pts = [Vec3::ZERO; 16];
    let mut reach = 0.0f64;
    for r in 0..4 {
        for c in 0..4 {
            let p = cp[4 * r + c];
            let mut q = [0.0f32; 3];
            for k in 0..3 {
                let x = p[k] * scale + translate[k];
                reach = reach.max(x.abs());
                q[k] = coordinate(x)
                    .map_err(|e| Reject::Range(format!("control point {}: {e}", 4 * r + c)))?;
            }
            pts[if flip { 4 * c + r } else { 4 * r + c }] = Vec3::new(q[0], q[1], q[2]);
        }
    }
    let degenerate = || Reject::Degenerate("is degenerate: zero area".into());
    let bez = Bezier::new(pts).ok_or_else(degenerate)?;
    let size = bez.bounds().size();
    if let Some(why) = too_small(f64::from(size), reach) {
        return Err(Reject::Degenerate(why));
    }
    let area = bezier_area(&bez);
    if !(area.is_finite() && area > 1e-8 * size * size) {
        return Err(degenerate());
    }
    Ok(ScenePatch {
        name,
        material,
        shape: Shape::Bezier(bez),
        area,
        sides: Sides::Opaque,
    })
}

/// Reads the `.bpt` text format: the number of patches, then per patch its degrees ("3 3") and
/// 16 lines "x y z". The count must match what follows: a file with more patches than it
/// declares is refused, not cut short.
pub fn parse_bpt(text: &str) -> std::result::Result<Vec<Vec<[f64; 3]>>, String> {
    let mut tokens = text.split_whitespace();
    let mut next = |what: &str| -> std::result::Result<f64, String> {
        let t = tokens
            .next()
            .ok_or_else(|| format!("file ends before {what}"))?;
        let x = t
            .parse::<f64>()
            .map_err(|_| format!("{what}: `{t}` is not a number"))?;
        match not_f32(x) {
            Some(why) => Err(format!("{what}: `{t}` {why}")),
            None => Ok(x),
        }
    };
    let n = next("the patch count")?;
    if !(n >= 0.0 && n.fract() == 0.0 && n < 1e6) {
        return Err(format!(
            "the patch count {} is not a whole number below a million",
            show(n)
        ));
    }
    let mut out = Vec::new();
    for i in 0..n as usize {
        let what = format!("patch {i}'s degrees");
        let (du, dv) = (next(&what)?, next(&what)?);
        if du != 3.0 || dv != 3.0 {
            return Err(format!(
                "patch {i}: degrees {du} {dv}; only bicubic (3 3) patches are supported"
            ));
        }
        let mut cp = Vec::with_capacity(16);
        for j in 0..16 {
            let what = format!("patch {i}'s control point {j}");
            cp.push([next(&what)?, next(&what)?, next(&what)?]);
        }
        out.push(cp);
    }
    if let Some(t) = tokens.next() {
        return Err(format!(
            "the file declares {n} patches but goes on after them (at `{t}`): its count is wrong"
        ));
    }
    Ok(out)
}

/// Appends the patches of a `[[bpt]]` entry, named `<name>/<index>`, skipping (and counting on
/// stderr) degenerate ones.
pub fn load_bpt(
    cx: &Ctx,
    b: &RawBpt,
    by_name: &HashMap<String, usize>,
    patches: &mut Vec<ScenePatch>,
    names: &mut HashMap<String, ()>,
) -> Result<()> {
    let path = cx.base().join(b.path.get_ref());
    let fail = |e: String| {
        cx.err(
            b.path.span(),
            "bpt.path",
            format!("{}: {e}", path.display()),
        )
    };
    let text = read_text(&path, &cx.limits).map_err(|e| cx.err(b.path.span(), "bpt.path", e))?;
    let list = parse_bpt(&text).map_err(fail)?;
    let material = cx.material_named(by_name, &b.material, "bpt.material")?;
    cx.check_name(&b.name, "bpt.name")?;
    let (scale, translate) = cx.placement(&b.scale, &b.translate, "bpt")?;
    let mut skipped = Vec::new();
    for (i, cp) in list.iter().enumerate() {
        let name = cx.claim_piece(
            b.name.span(),
            "bpt.name",
            names,
            format!("{}/{i}", b.name.get_ref()),
        )?;
        match bezier_patch(name, material, cp, scale, translate, b.flip) {
            Ok(p) => patches.push(p),
            Err(Reject::Range(e)) => return Err(fail(format!("patch {i}: {e}"))),
            Err(Reject::Degenerate(why)) => skipped.push(format!("{i} {why}")),
        }
    }
    if skipped.len() == list.len() {
        return Err(fail(format!(
            "adds no patch ({} declared, {} degenerate{})",
            list.len(),
            skipped.len(),
            match skipped.first() {
                Some(first) => format!(": {first}"),
                None => String::new(),
            }
        )));
    }
    if !skipped.is_empty() {
        cx.warn(
            b.path.span(),
            "bpt.path",
            format!(
                "{}: skipped {} degenerate patch(es): {}",
                path.display(),
                skipped.len(),
                skipped.join("; ")
            ),
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bpt(count: usize, patches: usize) -> String {
        let mut s = format!("{count}\n");
        for _ in 0..patches {
            s.push_str("3 3\n");
            for r in 0..4 {
                for c in 0..4 {
                    s.push_str(&format!("{c} {r} 0\n"));
                }
            }
        }
        s
    }

    #[test]
    fn a_count_that_disagrees_with_the_contents_is_refused() {
        assert_eq!(parse_bpt(&bpt(2, 2)).unwrap().len(), 2);
        let e = parse_bpt(&bpt(1, 2)).unwrap_err();
        assert!(e.contains("declares 1 patches but goes on"), "{e}");
        let e = parse_bpt(&bpt(3, 2)).unwrap_err();
        assert!(e.contains("file ends before patch 2's degrees"), "{e}");
        let e = parse_bpt(&bpt(1, 1).replacen("1 0 0", "1e39 0 0", 1)).unwrap_err();
        assert!(
            e.contains("patch 0's control point 1: `1e39` is beyond f32's range"),
            "{e}"
        );
    }
}
