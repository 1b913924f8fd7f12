//! The TOML scene format of docs/scene-format.md. Every error names the file, the line and the key.

use super::{Camera, Material, Scene, ScenePatch, Sides};
use anyhow::{anyhow, bail, Context, Result};
use hemi_kernel::geometry::{Bezier, Polygon, PolygonError, Vec3};
use hemi_kernel::patch::Shape;
use hemi_kernel::sampling::bezier_area;
use serde::Deserialize;
use std::collections::HashMap;
use std::ops::Range;
use std::path::Path;
use toml::Spanned;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawScene {
    #[serde(default)]
    material: Vec<Spanned<RawMaterial>>,
    #[serde(default)]
    quad: Vec<Spanned<RawPolygon>>,
    #[serde(default)]
    triangle: Vec<Spanned<RawPolygon>>,
    #[serde(default)]
    bezier: Vec<Spanned<RawBezier>>,
    #[serde(default)]
    bpt: Vec<Spanned<RawBpt>>,
    #[serde(default)]
    obj: Vec<Spanned<RawObj>>,
    camera: Option<Spanned<RawCamera>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMaterial {
    name: Spanned<String>,
    diffuse: Spanned<Vec<f64>>,
    #[serde(default)]
    emission: Option<Spanned<Vec<f64>>>,
    #[serde(default)]
    specular: Option<Spanned<Vec<f64>>>,
    #[serde(default)]
    phong: Option<Spanned<f64>>,
    #[serde(default)]
    transmission: Option<Spanned<Vec<f64>>>,
    #[serde(default)]
    translucency: Option<Spanned<Vec<f64>>>,
    #[serde(default)]
    frustum: Option<Spanned<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPolygon {
    name: Spanned<String>,
    material: Spanned<String>,
    vertices: Spanned<Vec<Vec<f64>>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawBezier {
    name: Spanned<String>,
    material: Spanned<String>,
    control_points: Spanned<Vec<Vec<f64>>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawBpt {
    /// Path of the .bpt file, relative to the scene file.
    path: Spanned<String>,
    /// Patches are named `<name>/<index>`.
    name: Spanned<String>,
    material: Spanned<String>,
    #[serde(default)]
    scale: Option<Spanned<f64>>,
    #[serde(default)]
    translate: Option<Spanned<Vec<f64>>>,
    /// Swap u and v, turning every patch's front side over (for files whose patches face inward).
    #[serde(default)]
    flip: bool,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawObj {
    /// Path of the .obj file, relative to the scene file.
    path: Spanned<String>,
    /// A scene material for every face (else the MTL's materials).
    #[serde(default)]
    material: Option<Spanned<String>>,
    /// Uniform scale applied to the mesh, then `translate`.
    #[serde(default)]
    scale: Option<Spanned<f64>>,
    #[serde(default)]
    translate: Option<Spanned<Vec<f64>>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCamera {
    eye: Spanned<Vec<f64>>,
    look_at: Spanned<Vec<f64>>,
    up: Spanned<Vec<f64>>,
    fov_y_deg: Spanned<f64>,
    width: Spanned<u32>,
    height: Spanned<u32>,
}

/// Reads and validates the scene file at `path`.
pub fn load(path: &Path) -> Result<Scene> {
    let src = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read scene file {}", path.display()))?;
    parse(&src, &path.display().to_string())
}

struct Ctx<'a> {
    src: &'a str,
    file: &'a str,
}

impl Ctx<'_> {
    fn line(&self, span: Range<usize>) -> usize {
        self.src[..span.start.min(self.src.len())]
            .matches('\n')
            .count()
            + 1
    }
    fn err(&self, span: Range<usize>, key: &str, msg: impl std::fmt::Display) -> anyhow::Error {
        anyhow!("{}:{}: `{}`: {}", self.file, self.line(span), key, msg)
    }
    fn rgb(&self, v: &Spanned<Vec<f64>>, key: &str, max: Option<f64>) -> Result<[f64; 3]> {
        let a = self.vec3(v, key)?;
        for x in a {
            if x < 0.0 {
                return Err(self.err(v.span(), key, "components must not be negative"));
            }
            if let Some(m) = max {
                if x >= m {
                    return Err(self.err(
                        v.span(),
                        key,
                        format!("components must be below {m} (a reflectance of 1 or more creates energy)"),
                    ));
                }
            }
        }
        Ok(a)
    }
    /// The optional `scale` (positive, default 1) and `translate` (default 0) of an imported
    /// file's entry `kind`.
    fn placement(
        &self,
        scale: &Option<Spanned<f64>>,
        translate: &Option<Spanned<Vec<f64>>>,
        kind: &str,
    ) -> Result<(f64, [f64; 3])> {
        let scale = match scale {
            Some(s) if s.get_ref().is_finite() && *s.get_ref() > 0.0 => *s.get_ref(),
            Some(s) => {
                return Err(self.err(
                    s.span(),
                    &format!("{kind}.scale"),
                    "must be a positive number",
                ))
            }
            None => 1.0,
        };
        let translate = match translate {
            Some(t) => self.vec3(t, &format!("{kind}.translate"))?,
            None => [0.0; 3],
        };
        Ok((scale, translate))
    }

    fn vec3(&self, v: &Spanned<Vec<f64>>, key: &str) -> Result<[f64; 3]> {
        let a = v.get_ref();
        if a.len() != 3 {
            return Err(self.err(
                v.span(),
                key,
                format!("expected 3 numbers, found {}", a.len()),
            ));
        }
        if a.iter().any(|x| !x.is_finite()) {
            return Err(self.err(v.span(), key, "NaN or infinite value"));
        }
        Ok([a[0], a[1], a[2]])
    }
}

fn v3(a: [f64; 3]) -> Vec3 {
    Vec3::new(a[0] as f32, a[1] as f32, a[2] as f32)
}

/// A Bezier scene patch from 16 control points (row-major, c along u), transformed; `None` when
/// degenerate (zero area). `flip` swaps u and v, which turns the front side over.
fn bezier_patch(
    name: String,
    material: usize,
    cp: &[[f64; 3]],
    scale: f64,
    translate: [f64; 3],
    flip: bool,
) -> Option<ScenePatch> {
    let mut pts = [Vec3::ZERO; 16];
    for r in 0..4 {
        for c in 0..4 {
            let p = cp[4 * r + c];
            let q = v3([0, 1, 2].map(|k| p[k] * scale + translate[k]));
            pts[if flip { 4 * c + r } else { 4 * r + c }] = q;
        }
    }
    let bez = Bezier::new(pts)?;
    let area = bezier_area(&bez);
    let size = bez.bounds().size();
    if !(area.is_finite() && area > 1e-8 * size * size) {
        return None;
    }
    Some(ScenePatch {
        name,
        material,
        shape: Shape::Bezier(bez),
        area,
        sides: Sides::Opaque,
    })
}

/// Reads the common `.bpt` text format: the number of patches, then per patch its degrees
/// ("3 3") and 16 lines "x y z", row by row.
pub fn parse_bpt(text: &str) -> std::result::Result<Vec<Vec<[f64; 3]>>, String> {
    let mut nums = text.split_whitespace().map(|t| {
        t.parse::<f64>()
            .map_err(|_| format!("`{t}` is not a number"))
    });
    let mut next = |what: &str| {
        nums.next()
            .ok_or_else(|| format!("file ends before {what}"))?
    };
    let n = next("the patch count")?;
    if !(n >= 0.0 && n.fract() == 0.0 && n < 1e6) {
        return Err(format!("bad patch count {n}"));
    }
    let mut out = Vec::new();
    for i in 0..n as usize {
        let (du, dv) = (next("the degrees")?, next("the degrees")?);
        if du != 3.0 || dv != 3.0 {
            return Err(format!(
                "patch {i}: degrees {du} {dv}; only bicubic (3 3) patches are supported"
            ));
        }
        let mut cp = Vec::with_capacity(16);
        for _ in 0..16 {
            let p = [
                next("a control point")?,
                next("a control point")?,
                next("a control point")?,
            ];
            if p.iter().any(|x| !x.is_finite()) {
                return Err(format!("patch {i}: non-finite control point"));
            }
            cp.push(p);
        }
        out.push(cp);
    }
    Ok(out)
}

fn load_bpt(
    cx: &Ctx,
    b: &RawBpt,
    by_name: &HashMap<String, usize>,
    patches: &mut Vec<ScenePatch>,
    names: &mut HashMap<String, ()>,
) -> Result<()> {
    let base = Path::new(cx.file).parent().unwrap_or(Path::new("."));
    let path = base.join(b.path.get_ref());
    let text = std::fs::read_to_string(&path).map_err(|e| {
        cx.err(
            b.path.span(),
            "bpt.path",
            format!("cannot read {}: {e}", path.display()),
        )
    })?;
    let list = parse_bpt(&text).map_err(|e| {
        cx.err(
            b.path.span(),
            "bpt.path",
            format!("{}: {e}", path.display()),
        )
    })?;
    let material = *by_name.get(b.material.get_ref()).ok_or_else(|| {
        cx.err(
            b.material.span(),
            "bpt.material",
            format!("unknown material `{}`", b.material.get_ref()),
        )
    })?;
    let (scale, translate) = cx.placement(&b.scale, &b.translate, "bpt")?;
    let mut skipped = 0;
    for (i, cp) in list.iter().enumerate() {
        let name = format!("{}/{i}", b.name.get_ref());
        if names.insert(name.clone(), ()).is_some() {
            return Err(cx.err(
                b.name.span(),
                "bpt.name",
                format!("patch `{name}` defined twice"),
            ));
        }
        match bezier_patch(name, material, cp, scale, translate, b.flip) {
            Some(p) => patches.push(p),
            None => skipped += 1,
        }
    }
    if skipped > 0 {
        eprintln!(
            "{}: {}: skipped {skipped} degenerate patch(es) (zero area)",
            cx.file,
            path.display()
        );
    }
    Ok(())
}

/// Appends the triangles of an OBJ mesh (with its MTL materials unless the entry names one).
fn load_obj(
    cx: &Ctx,
    o: &RawObj,
    materials: &mut Vec<Material>,
    by_name: &mut HashMap<String, usize>,
    patches: &mut Vec<ScenePatch>,
    names: &mut HashMap<String, ()>,
) -> Result<()> {
    let base = Path::new(cx.file).parent().unwrap_or(Path::new("."));
    let path = base.join(o.path.get_ref());
    let (models, mtls) = tobj::load_obj(
        &path,
        &tobj::LoadOptions {
            triangulate: true,
            single_index: false,
            ..Default::default()
        },
    )
    .map_err(|e| {
        cx.err(
            o.path.span(),
            "obj.path",
            format!("cannot load {}: {e}", path.display()),
        )
    })?;
    let (scale, translate) = cx.placement(&o.scale, &o.translate, "obj")?;
    let fixed = match &o.material {
        Some(m) => Some(*by_name.get(m.get_ref()).ok_or_else(|| {
            cx.err(
                m.span(),
                "obj.material",
                format!("unknown material `{}`", m.get_ref()),
            )
        })?),
        None => None,
    };
    // MTL materials become scene materials named "<mtl name>" unless the scene defines that name.
    let mtls = mtls.unwrap_or_default();
    let mut mtl_index = Vec::with_capacity(mtls.len());
    for m in &mtls {
        let idx = match by_name.get(&m.name) {
            Some(&i) => i,
            None => {
                let kd = m
                    .diffuse
                    .unwrap_or([0.8, 0.8, 0.8])
                    .map(|x| (x as f64).clamp(0.0, 0.999));
                let ke = m
                    .emissive
                    .map(|e| e.map(|x| x as f64))
                    .filter(|e| e.iter().all(|x| x.is_finite() && *x >= 0.0))
                    .unwrap_or([0.0; 3]);
                materials.push(Material {
                    name: m.name.clone(),
                    diffuse: kd,
                    emission: ke,
                    specular: [0.0; 3],
                    transmission: [0.0; 3],
                    translucency: [0.0; 3],
                    phong: 0.0,
                    frustum_deg: None,
                });
                by_name.insert(m.name.clone(), materials.len() - 1);
                materials.len() - 1
            }
        };
        mtl_index.push(idx);
    }
    let default_material = match fixed {
        Some(i) => i,
        None => match by_name.get("default") {
            Some(&i) => i,
            None => {
                materials.push(Material {
                    name: "default".into(),
                    diffuse: [0.8; 3],
                    emission: [0.0; 3],
                    specular: [0.0; 3],
                    transmission: [0.0; 3],
                    translucency: [0.0; 3],
                    phong: 0.0,
                    frustum_deg: None,
                });
                by_name.insert("default".into(), materials.len() - 1);
                materials.len() - 1
            }
        },
    };
    let mut skipped = 0usize;
    for model in &models {
        let mesh = &model.mesh;
        let material = fixed.unwrap_or_else(|| {
            mesh.material_id
                .and_then(|i| mtl_index.get(i).copied())
                .unwrap_or(default_material)
        });
        let vert = |i: u32| {
            let i = i as usize * 3;
            Vec3::new(
                (mesh.positions[i] as f64 * scale + translate[0]) as f32,
                (mesh.positions[i + 1] as f64 * scale + translate[1]) as f32,
                (mesh.positions[i + 2] as f64 * scale + translate[2]) as f32,
            )
        };
        for (f, tri) in mesh.indices.chunks_exact(3).enumerate() {
            match Polygon::triangle([vert(tri[0]), vert(tri[1]), vert(tri[2])]) {
                Ok(polygon) => {
                    let mut name = format!("{}/{f}", model.name);
                    while names.insert(name.clone(), ()).is_some() {
                        name.push('\'');
                    }
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
    if skipped > 0 {
        eprintln!(
            "{}: {}: skipped {skipped} degenerate triangle(s) (zero area or non-finite)",
            cx.file,
            path.display()
        );
    }
    Ok(())
}

/// Parses and validates scene text; `file` names it in errors.
pub fn parse(src: &str, file: &str) -> Result<Scene> {
    let raw = read_toml(src, file)?;
    let cx = Ctx { src, file };
    let mut by_name = HashMap::new();
    let mut materials = Vec::new();
    for m in &raw.material {
        let name = m.get_ref().name.get_ref().clone();
        if by_name.insert(name.clone(), materials.len()).is_some() {
            return Err(cx.err(
                m.get_ref().name.span(),
                "material.name",
                format!("material `{name}` defined twice"),
            ));
        }
        materials.push(material(&cx, m)?);
    }
    let mut patches = patches(&cx, &raw, &mut materials, &mut by_name)?;
    let camera = match &raw.camera {
        None => None,
        Some(c) => Some(camera(&cx, c.get_ref())?),
    };
    super::translucent::add_back_sides(&mut materials, &mut patches);
    Ok(Scene {
        materials,
        patches,
        camera,
    })
}

/// The TOML of a scene, with the line of a syntax error.
fn read_toml(src: &str, file: &str) -> Result<RawScene> {
    toml::from_str(src).map_err(|e| {
        let line = e
            .span()
            .map(|s| src[..s.start.min(src.len())].matches('\n').count() + 1);
        match line {
            Some(l) => anyhow!("{file}:{l}: {}", e.message()),
            None => anyhow!("{file}: {}", e.message()),
        }
    })
}

/// One `[[material]]`, checked: ranges per key, and (2.2)'s k_d + k_y + k_r + k_t ≤ 1.
fn material(cx: &Ctx<'_>, m: &Spanned<RawMaterial>) -> Result<Material> {
    let span = m.span();
    let m = m.get_ref();
    let name = m.name.get_ref().clone();
    let phong = match &m.phong {
        Some(p) if p.get_ref().is_nan() || *p.get_ref() < 0.0 => {
            return Err(cx.err(
                p.span(),
                "material.phong",
                "must be a non-negative number or inf",
            ))
        }
        Some(p) => *p.get_ref(),
        None => 0.0,
    };
    let frustum_deg = match &m.frustum {
        Some(f) if !(f.get_ref().is_finite() && *f.get_ref() > 0.0 && *f.get_ref() <= 90.0) => {
            return Err(cx.err(
                f.span(),
                "material.frustum",
                "must be a half-angle in degrees, above 0 and at most 90",
            ))
        }
        Some(f) => Some(*f.get_ref()),
        None => None,
    };
    // k_r and k_t may reach 1 (a lossless mirror or window passes on exactly what it gets:
    // frustum weights are normalised); a diffuse reflectance of 1 may not (it makes a closed
    // scene's system singular).
    let material = Material {
        name,
        diffuse: cx.rgb(&m.diffuse, "material.diffuse", Some(1.0))?,
        emission: match &m.emission {
            Some(e) => cx.rgb(e, "material.emission", None)?,
            None => [0.0; 3],
        },
        specular: match &m.specular {
            Some(s) => cx.rgb(s, "material.specular", Some(1.0 + 1e-12))?,
            None => [0.0; 3],
        },
        transmission: match &m.transmission {
            Some(s) => cx.rgb(s, "material.transmission", Some(1.0 + 1e-12))?,
            None => [0.0; 3],
        },
        translucency: match &m.translucency {
            Some(s) => cx.rgb(s, "material.translucency", Some(1.0))?,
            None => [0.0; 3],
        },
        phong,
        frustum_deg,
    };
    for c in 0..3 {
        let sum = material.diffuse[c]
            + material.translucency[c]
            + material.specular[c]
            + material.transmission[c];
        if sum > 1.0 + 1e-12 {
            return Err(cx.err(
                span.clone(),
                "material",
                format!(
                    "diffuse + translucency + specular + transmission must not exceed 1 per channel, (2.2) (channel {c} sums to {sum})"
                ),
            ));
        }
    }
    Ok(material)
}

/// The patches of every `[[quad]]`, `[[triangle]]`, `[[bezier]]`, `[[obj]]` and `[[bpt]]`, in
/// their order of appearance in the file (meshes may add materials).
fn patches(
    cx: &Ctx<'_>,
    raw: &RawScene,
    materials: &mut Vec<Material>,
    by_name: &mut HashMap<String, usize>,
) -> Result<Vec<ScenePatch>> {
    // Quads, triangles and meshes keep their order of appearance in the file.
    enum Entry<'a> {
        Poly(&'a Spanned<RawPolygon>, &'static str, usize),
        Obj(&'a Spanned<RawObj>),
        Bezier(&'a Spanned<RawBezier>),
        Bpt(&'a Spanned<RawBpt>),
    }
    let mut entries: Vec<(usize, Entry)> = raw
        .quad
        .iter()
        .map(|q| (q.span().start, Entry::Poly(q, "quad", 4)))
        .chain(
            raw.triangle
                .iter()
                .map(|t| (t.span().start, Entry::Poly(t, "triangle", 3))),
        )
        .chain(raw.obj.iter().map(|o| (o.span().start, Entry::Obj(o))))
        .chain(
            raw.bezier
                .iter()
                .map(|b| (b.span().start, Entry::Bezier(b))),
        )
        .chain(raw.bpt.iter().map(|b| (b.span().start, Entry::Bpt(b))))
        .collect();
    entries.sort_by_key(|p| p.0);

    let mut patches = Vec::new();
    let mut names = HashMap::new();
    for (_, entry) in entries {
        match entry {
            Entry::Poly(p, kind, n) => {
                patches.push(polygon(cx, p.get_ref(), kind, n, by_name, &mut names)?)
            }
            Entry::Obj(o) => load_obj(
                cx,
                o.get_ref(),
                materials,
                by_name,
                &mut patches,
                &mut names,
            )?,
            Entry::Bezier(b) => patches.push(bezier(cx, b.get_ref(), by_name, &mut names)?),
            Entry::Bpt(b) => load_bpt(cx, b.get_ref(), by_name, &mut patches, &mut names)?,
        }
    }
    if patches.is_empty() {
        bail!(
            "{}: the scene has no patches ([[quad]], [[triangle]], [[bezier]], [[obj]] or [[bpt]])",
            cx.file
        );
    }
    Ok(patches)
}

/// One `[[bezier]]` patch, checked.
fn bezier(
    cx: &Ctx<'_>,
    r: &RawBezier,
    by_name: &HashMap<String, usize>,
    names: &mut HashMap<String, ()>,
) -> Result<ScenePatch> {
    let name = r.name.get_ref().clone();
    if names.insert(name.clone(), ()).is_some() {
        return Err(cx.err(
            r.name.span(),
            "bezier.name",
            format!("patch `{name}` defined twice"),
        ));
    }
    let material = *by_name.get(r.material.get_ref()).ok_or_else(|| {
        cx.err(
            r.material.span(),
            "bezier.material",
            format!("unknown material `{}`", r.material.get_ref()),
        )
    })?;
    let pts = r.control_points.get_ref();
    let key = "bezier.control_points";
    if pts.len() != 16
        || pts
            .iter()
            .any(|p| p.len() != 3 || p.iter().any(|x| !x.is_finite()))
    {
        return Err(cx.err(
            r.control_points.span(),
            key,
            format!(
                "a Bezier patch has 16 points of 3 finite numbers, found {} points",
                pts.len()
            ),
        ));
    }
    let cp: Vec<[f64; 3]> = pts.iter().map(|p| [p[0], p[1], p[2]]).collect();
    let patch =
        bezier_patch(name.clone(), material, &cp, 1.0, [0.0; 3], false).ok_or_else(|| {
            cx.err(
                r.control_points.span(),
                key,
                format!("patch `{name}` is degenerate: zero area"),
            )
        })?;
    Ok(patch)
}

/// One `[[quad]]` (n = 4) or `[[triangle]]` (n = 3), checked.
fn polygon(
    cx: &Ctx<'_>,
    r: &RawPolygon,
    kind: &str,
    n: usize,
    by_name: &HashMap<String, usize>,
    names: &mut HashMap<String, ()>,
) -> Result<ScenePatch> {
    let name = r.name.get_ref().clone();
    if names.insert(name.clone(), ()).is_some() {
        return Err(cx.err(
            r.name.span(),
            &format!("{kind}.name"),
            format!("patch `{name}` defined twice"),
        ));
    }
    let material = *by_name.get(r.material.get_ref()).ok_or_else(|| {
        cx.err(
            r.material.span(),
            &format!("{kind}.material"),
            format!("unknown material `{}`", r.material.get_ref()),
        )
    })?;
    let key = format!("{kind}.vertices");
    let verts = r.vertices.get_ref();
    if verts.len() != n {
        return Err(cx.err(
            r.vertices.span(),
            &key,
            format!("a {kind} has {n} vertices, found {}", verts.len()),
        ));
    }
    let mut pts = [Vec3::ZERO; 4];
    for (i, v) in verts.iter().enumerate() {
        if v.len() != 3 || v.iter().any(|x| !x.is_finite()) {
            return Err(cx.err(
                r.vertices.span(),
                &key,
                format!("vertex {i} must be 3 finite numbers"),
            ));
        }
        pts[i] = v3([v[0], v[1], v[2]]);
    }
    let polygon = if n == 4 {
        Polygon::quad(pts)
    } else {
        Polygon::triangle([pts[0], pts[1], pts[2]])
    }
    .map_err(|e| {
        let why = match e {
            PolygonError::NotFinite => "has a NaN or infinite coordinate",
            PolygonError::Degenerate => "is degenerate: zero area or collinear vertices",
            PolygonError::NotPlanar => {
                "is not planar: a vertex lies off the plane by more than 1 % of its size"
            }
            PolygonError::NotConvex => "is not convex, or its vertices are not in order around it",
        };
        cx.err(r.vertices.span(), &key, format!("patch `{name}` {why}"))
    })?;
    Ok(ScenePatch {
        name,
        material,
        area: polygon.area,
        shape: Shape::Polygon(polygon),
        sides: Sides::Opaque,
    })
}

/// The `[camera]`, checked: a field of view, a size, and a view direction apart from `up`.
fn camera(cx: &Ctx<'_>, c: &RawCamera) -> Result<Camera> {
    let fov = *c.fov_y_deg.get_ref();
    if !(fov > 0.0 && fov < 180.0) {
        return Err(cx.err(
            c.fov_y_deg.span(),
            "camera.fov_y_deg",
            "must be between 0 and 180",
        ));
    }
    for (w, key) in [(&c.width, "camera.width"), (&c.height, "camera.height")] {
        if *w.get_ref() == 0 || *w.get_ref() > 16384 {
            return Err(cx.err(w.span(), key, "must be between 1 and 16384"));
        }
    }
    let eye = v3(cx.vec3(&c.eye, "camera.eye")?);
    let look_at = v3(cx.vec3(&c.look_at, "camera.look_at")?);
    let up = v3(cx.vec3(&c.up, "camera.up")?);
    let fwd = (look_at - eye).try_normalize().ok_or_else(|| {
        cx.err(
            c.look_at.span(),
            "camera.look_at",
            "equals the eye position",
        )
    })?;
    if fwd.cross(up).try_normalize().is_none() {
        return Err(cx.err(
            c.up.span(),
            "camera.up",
            "is parallel to the view direction",
        ));
    }
    Ok(Camera {
        eye,
        look_at,
        up,
        fov_y_deg: fov,
        width: *c.width.get_ref(),
        height: *c.height.get_ref(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = r#"
[[material]]
name = "white"
diffuse = [0.5, 0.5, 0.5]

[[material]]
name = "light"
diffuse = [0.0, 0.0, 0.0]
emission = [10.0, 10.0, 10.0]

[[triangle]]
name = "t"
material = "white"
vertices = [[0,0,0],[1,0,0],[0,1,0]]

[[quad]]
name = "q"
material = "light"
vertices = [[0,0,1],[0,1,1],[1,1,1],[1,0,1]]
"#;

    #[test]
    fn parses_and_keeps_file_order() {
        let s = parse(GOOD, "good.toml").unwrap();
        assert_eq!(s.patches[0].name, "t");
        assert_eq!(s.patches[1].name, "q");
        assert_eq!(s.material_of(1).emission, [10.0; 3]);
    }

    fn err(src: &str) -> String {
        format!("{:#}", parse(src, "bad.toml").unwrap_err())
    }

    #[test]
    fn errors_name_file_line_and_key() {
        let e = err(&GOOD.replace("material = \"light\"", "material = \"lamp\""));
        assert!(
            e.contains("bad.toml:18") && e.contains("quad.material") && e.contains("lamp"),
            "{e}"
        );
        let e = err(&GOOD.replace(
            "[[0,0,1],[0,1,1],[1,1,1],[1,0,1]]",
            "[[0,0,1],[0,1,1],[1,1,1]]",
        ));
        assert!(
            e.contains("bad.toml:19") && e.contains("quad.vertices") && e.contains("4 vertices"),
            "{e}"
        );
        let e = err(&GOOD.replace("[0.5, 0.5, 0.5]", "[0.5, nan, 0.5]"));
        assert!(
            e.contains("bad.toml:4") && e.contains("material.diffuse"),
            "{e}"
        );
        let e = err(&GOOD.replace("[[0,0,0],[1,0,0],[0,1,0]]", "[[0,0,0],[1,0,0],[2,0,0]]"));
        assert!(e.contains("degenerate"), "{e}");
        let e = err(&GOOD.replace("name = \"t\"", "name = \"t\"\ncolour = 3"));
        assert!(e.contains("bad.toml:13") && e.contains("colour"), "{e}");
        let e = err("[[quad]\n");
        assert!(e.contains("bad.toml:1"), "{e}");
        let e = err(&GOOD.replace("[0.5, 0.5, 0.5]", "[1.5, 0.5, 0.5]"));
        assert!(e.contains("below 1"), "{e}");
    }
}
