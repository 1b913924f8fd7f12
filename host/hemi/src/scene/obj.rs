//! `[[obj]]`: a Wavefront OBJ mesh and its MTL materials, read by `tobj` from text this module
//! has first read within the size budget and scanned line by line, so that a bad number is
//! refused with its file and line (tobj reports neither, and reads NaN as a colour).

use super::ctx::Ctx;
use super::file::read_text;
use super::range::{coordinate, not_f32, safe_name, too_small, EMISSION_LIMIT};
use super::{Material, ScenePatch, Sides};
use anyhow::Result;
use hemi_kernel::geometry::{Polygon, Vec3};
use hemi_kernel::patch::Shape;
use serde::Deserialize;
use std::cell::RefCell;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use toml::Spanned;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawObj {
    /// Path of the .obj file, relative to the scene file.
    pub(super) path: Spanned<String>,
    /// A scene material for every face (else the MTL's materials).
    #[serde(default)]
    pub(super) material: Option<Spanned<String>>,
    /// Uniform scale applied to the mesh, then `translate`.
    #[serde(default)]
    pub(super) scale: Option<Spanned<f64>>,
    #[serde(default)]
    pub(super) translate: Option<Spanned<Vec<f64>>>,
}

/// The MTL keywords tobj reads as exactly three numbers (it panics on fewer).
const MTL_TRIPLES: &[&str] = &["Ka", "Kd", "Ks", "Ke"];

/// `text` with every line trimmed: tobj slices lines at fixed byte offsets after their
/// keyword, which leading white space (multi-byte white space especially) would break.
fn trimmed(text: &str) -> String {
    text.lines().map(str::trim).collect::<Vec<_>>().join("\n")
}

/// The keywords whose arguments are numbers, in OBJ and MTL files.
const OBJ_NUMBERS: &[&str] = &["v", "vt", "vn", "vp"];
const MTL_NUMBERS: &[&str] = &["Ka", "Kd", "Ks", "Ke", "Kt", "Tf", "Ns", "Ni", "d", "Tr"];

/// Checks every number of a line-based file (`keywords` say which lines hold numbers): each
/// must be one f32 can hold, and `Kd`/`Ke` colours must be in range. Returns warnings for what
/// is accepted but clamped.
pub fn scan_numbers(
    text: &str,
    file: &str,
    keywords: &[&str],
) -> std::result::Result<Vec<String>, String> {
    let mut warnings = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let mut tokens = line.split_whitespace();
        let Some(key) = tokens.next() else { continue };
        if !keywords.contains(&key) {
            continue;
        }
        let at = |msg: String| format!("{file}:{}: `{key}`: {msg}", i + 1);
        let count = tokens.clone().count();
        if MTL_TRIPLES.contains(&key) && count != 3 {
            return Err(at(format!("expected 3 numbers (r g b), found {count}")));
        }
        for t in tokens {
            // `d -halo 0.5` is the one option a number line may hold
            let Ok(x) = t.parse::<f64>() else {
                if t == "-halo" {
                    continue;
                }
                return Err(at(format!("`{t}` is not a number")));
            };
            if let Some(why) = not_f32(x) {
                return Err(at(format!("`{t}` {why}")));
            }
            match key {
                "Kd" | "Ke" if x < 0.0 => return Err(at(format!("`{t}` is negative"))),
                "Ke" if x > EMISSION_LIMIT => {
                    return Err(at(format!(
                        "`{t}` is beyond the {EMISSION_LIMIT:e} emission hemi takes"
                    )))
                }
                "Kd" if x >= 1.0 => warnings.push(at(format!(
                    "`{t}` is a reflectance of 1 or more, clamped to 0.999"
                ))),
                _ => {}
            }
        }
    }
    Ok(warnings)
}

/// What the MTL loader found wrong: tobj's loader callback can return only its own error.
struct MtlLog {
    base: PathBuf,
    limits: super::file::Limits,
    error: RefCell<Option<String>>,
    warnings: RefCell<Vec<String>>,
}

impl MtlLog {
    fn load(&self, p: &Path) -> tobj::MTLLoadResult {
        let path = self.base.join(p);
        let checked = read_text(&path, &self.limits).and_then(|text| {
            let w = scan_numbers(&text, &path.display().to_string(), MTL_NUMBERS)?;
            Ok((text, w))
        });
        match checked {
            Ok((text, w)) => {
                self.warnings.borrow_mut().extend(w);
                tobj::load_mtl_buf(&mut trimmed(&text).as_bytes())
            }
            Err(e) => {
                self.error.borrow_mut().get_or_insert(e);
                Err(tobj::LoadError::OpenFileFailed)
            }
        }
    }
}

/// The OBJ of entry `o`, read and checked: its models and MTL materials.
fn read(cx: &Ctx, o: &RawObj) -> Result<(Vec<tobj::Model>, Vec<tobj::Material>, PathBuf)> {
    let base = cx.base();
    let path = base.join(o.path.get_ref());
    let fail = |e: String| cx.err(o.path.span(), "obj.path", e);
    let text = read_text(&path, &cx.limits).map_err(fail)?;
    for w in scan_numbers(&text, &path.display().to_string(), OBJ_NUMBERS).map_err(fail)? {
        cx.warn(o.path.span(), "obj.path", w);
    }
    let dir = path.parent().unwrap_or(Path::new(".")).to_path_buf();
    let log = MtlLog {
        base: dir,
        limits: cx.limits,
        error: RefCell::new(None),
        warnings: RefCell::new(Vec::new()),
    };
    let text = trimmed(&text);
    // tobj is checked by the fuzz targets (fuzz/), but it is not our code: a panic left in it
    // is still an error about this file, never a crash
    let loaded = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        tobj::load_obj_buf(
            &mut text.as_bytes(),
            &tobj::LoadOptions {
                triangulate: true,
                single_index: false,
                ..Default::default()
            },
            |p| log.load(p),
        )
    }))
    .map_err(|_| {
        fail(format!(
            "{}: the OBJ reader (tobj) failed on it",
            path.display()
        ))
    })?;
    let (models, mtls) =
        loaded.map_err(|e| fail(format!("cannot load {}: {e}", path.display())))?;
    if let Some(e) = log.error.into_inner() {
        return Err(fail(e));
    }
    for w in log.warnings.into_inner() {
        cx.warn(o.path.span(), "obj.path", w);
    }
    let mtls = mtls.unwrap_or_default();
    for w in unknown_materials(&text, &path.display().to_string(), &mtls) {
        cx.warn(o.path.span(), "obj.path", w);
    }
    Ok((models, mtls, path))
}

/// A warning for every `usemtl` naming a material its MTL files do not define (at its first
/// line): tobj gives those faces no material, so they would take `default` without a word.
fn unknown_materials(text: &str, file: &str, mtls: &[tobj::Material]) -> Vec<String> {
    let mut unknown: Vec<(usize, String)> = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let mut tokens = line.split_whitespace();
        if tokens.next() != Some("usemtl") {
            continue;
        }
        let name = tokens.collect::<Vec<_>>().join(" ");
        let known = mtls.iter().any(|m| m.name == name);
        if !known && !unknown.iter().any(|(_, n)| *n == name) {
            unknown.push((i + 1, name));
        }
    }
    unknown
        .into_iter()
        .map(|(line, name)| {
            format!(
                "{file}:{line}: `usemtl {name}`: no MTL file defines it; its faces get `default`"
            )
        })
        .collect()
}

/// A scene material for an MTL material (its `Kd` clamped below 1, as [`scan_numbers`] warned).
fn mtl_material(m: &tobj::Material) -> Material {
    let kd = m
        .diffuse
        .unwrap_or([0.8, 0.8, 0.8])
        .map(|x| f64::from(x).clamp(0.0, 0.999));
    let ke = m.emissive.map(|e| e.map(f64::from)).unwrap_or([0.0; 3]);
    plain(kd, ke)
}

/// A diffuse material (named by [`material_index`]) with no specular part.
fn plain(diffuse: [f64; 3], emission: [f64; 3]) -> Material {
    Material {
        name: String::new(),
        diffuse,
        emission,
        specular: [0.0; 3],
        transmission: [0.0; 3],
        translucency: [0.0; 3],
        phong: 0.0,
        frustum_deg: None,
    }
}

/// The index of material `name`, made (by `make`) if the scene has none of that name.
fn material_index(
    materials: &mut Vec<Material>,
    by_name: &mut HashMap<String, usize>,
    name: &str,
    make: impl FnOnce() -> Material,
) -> usize {
    if let Some(&i) = by_name.get(name) {
        return i;
    }
    materials.push(Material {
        name: name.to_string(),
        ..make()
    });
    by_name.insert(name.to_string(), materials.len() - 1);
    materials.len() - 1
}

/// Appends the triangles of an OBJ mesh (with its MTL materials unless the entry names one).
pub fn load_obj(
    cx: &Ctx,
    o: &RawObj,
    materials: &mut Vec<Material>,
    by_name: &mut HashMap<String, usize>,
    patches: &mut Vec<ScenePatch>,
    names: &mut HashMap<String, ()>,
) -> Result<()> {
    let (models, mtls, path) = read(cx, o)?;
    let (scale, translate) = cx.placement(&o.scale, &o.translate, "obj")?;
    let fixed = match &o.material {
        Some(m) => Some(cx.material_named(by_name, m, "obj.material")?),
        None => None,
    };
    // MTL materials become scene materials named "<mtl name>" unless the scene defines that name.
    let mtl_index: Vec<usize> = mtls
        .iter()
        .map(|m| material_index(materials, by_name, &safe_name(&m.name), || mtl_material(m)))
        .collect();
    let default_material = match fixed {
        Some(i) => i,
        None => material_index(materials, by_name, "default", || plain([0.8; 3], [0.0; 3])),
    };
    let (mut skipped, mut small, before) = (0usize, 0usize, patches.len());
    for model in &models {
        let mesh = &model.mesh;
        let material = fixed.unwrap_or_else(|| {
            mesh.material_id
                .and_then(|i| mtl_index.get(i).copied())
                .unwrap_or(default_material)
        });
        let vert = |i: u32| -> Result<(Vec3, f64)> {
            let at = i as usize * 3;
            let mut c = [0.0f32; 3];
            let mut reach = 0.0f64;
            for k in 0..3 {
                let raw = f64::from(*mesh.positions.get(at + k).unwrap_or(&f32::NAN));
                let x = raw * scale + translate[k];
                reach = reach.max(x.abs());
                c[k] = coordinate(x).map_err(|e| {
                    cx.err(
                        o.path.span(),
                        "obj",
                        format!("{}: vertex {} placed at {e}", path.display(), i + 1),
                    )
                })?;
            }
            Ok((Vec3::new(c[0], c[1], c[2]), reach))
        };
        let base_name = safe_name(&model.name);
        for (f, tri) in mesh.indices.chunks_exact(3).enumerate() {
            let (a, b, c) = (vert(tri[0])?, vert(tri[1])?, vert(tri[2])?);
            let size = f64::from((a.0 - b.0).length().max((b.0 - c.0).length()));
            if too_small(size, a.1.max(b.1).max(c.1)).is_some() {
                small += 1;
                continue;
            }
            match Polygon::triangle([a.0, b.0, c.0]) {
                Ok(polygon) => {
                    let name = unique(names, format!("{base_name}/{f}"));
                    patches.push(ScenePatch {
                        name,
                        material,
                        area: polygon.area,
                        shape: Shape::Polygon(polygon),
                        sides: Sides::Opaque,
                    });
                }
                Err(_) => skipped += 1,
            }
        }
    }
    if patches.len() == before {
        return Err(cx.err(
            o.path.span(),
            "obj.path",
            format!(
                "{}: adds no patch ({} face(s), {skipped} degenerate, {small} too small for f32)",
                path.display(),
                models
                    .iter()
                    .map(|m| m.mesh.indices.len() / 3)
                    .sum::<usize>()
            ),
        ));
    }
    if skipped + small > 0 {
        cx.warn(
            o.path.span(),
            "obj.path",
            format!(
                "{}: skipped {skipped} degenerate triangle(s) (zero area) and {small} too small \
                 for f32",
                path.display()
            ),
        );
    }
    Ok(())
}

/// `name`, or when another patch has it (the same OBJ included twice), `name:2`, `name:3`, …:
/// users' names hold no `:`, so these never take a name a user gives later.
fn unique(names: &mut HashMap<String, ()>, name: String) -> String {
    let mut candidate = name.clone();
    let mut n = 1;
    while names.insert(candidate.clone(), ()).is_some() {
        n += 1;
        candidate = format!("{name}:{n}");
    }
    candidate
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_numbers_are_named_by_file_line_and_keyword() {
        let e = scan_numbers("newmtl a\nKd 0.5 nan 0.5\n", "m.mtl", MTL_NUMBERS).unwrap_err();
        assert_eq!(e, "m.mtl:2: `Kd`: `nan` is NaN");
        let e = scan_numbers("v 0 0 0\nv 1e39 0 0\n", "m.obj", OBJ_NUMBERS).unwrap_err();
        assert!(
            e.starts_with("m.obj:2: `v`: `1e39` is beyond f32's range"),
            "{e}"
        );
        let w = scan_numbers("Kd 1.5 0 0\nKe 2 2 2\n", "m.mtl", MTL_NUMBERS).unwrap();
        assert!(w.len() == 1 && w[0].contains("clamped"), "{w:?}");
        let e = scan_numbers("Ke 1e300 0 0\n", "m.mtl", MTL_NUMBERS).unwrap_err();
        assert!(e.contains("beyond f32"), "{e}");
        let e = scan_numbers("newmtl a\nKd 0.7\n", "m.mtl", MTL_NUMBERS).unwrap_err();
        assert_eq!(e, "m.mtl:2: `Kd`: expected 3 numbers (r g b), found 1");
        let e = scan_numbers("Kd 0.5 0.5 0.5 0.5\n", "m.mtl", MTL_NUMBERS).unwrap_err();
        assert_eq!(e, "m.mtl:1: `Kd`: expected 3 numbers (r g b), found 4");
        let e = scan_numbers("Kd abc 0 0\n", "m.mtl", MTL_NUMBERS).unwrap_err();
        assert_eq!(e, "m.mtl:1: `Kd`: `abc` is not a number");
        let e = scan_numbers("v 0 zero 0\n", "m.obj", OBJ_NUMBERS).unwrap_err();
        assert_eq!(e, "m.obj:1: `v`: `zero` is not a number");
        assert!(scan_numbers("d -halo 0.5\n", "m.mtl", MTL_NUMBERS).is_ok());
        let e = scan_numbers("Ke 1e20 0 0\n", "m.mtl", MTL_NUMBERS).unwrap_err();
        assert!(e.contains("emission hemi takes"), "{e}");
    }
}
