//! The TOML scene format of docs/scene-format.md. Every error names the file, the line and the key.

use super::bpt::{bezier_patch, load_bpt, RawBpt, Reject};
use super::ctx::Ctx;
use super::file::{read_text, Limits};
use super::obj::{load_obj, RawObj};
use super::range::{coordinate, not_f32, show, too_small};
use super::{Camera, Material, Scene, ScenePatch, Sides};
use anyhow::{anyhow, bail, Result};
use hemi_kernel::geometry::{Polygon, PolygonError, Vec3};
use hemi_kernel::patch::Shape;
use serde::Deserialize;
use std::collections::HashMap;
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
struct RawCamera {
    eye: Spanned<Vec<f64>>,
    look_at: Spanned<Vec<f64>>,
    up: Spanned<Vec<f64>>,
    fov_y_deg: Spanned<f64>,
    width: Spanned<u32>,
    height: Spanned<u32>,
}

/// Reads and validates the scene file at `path`, within the default [`Limits`].
pub fn load(path: &Path) -> Result<Scene> {
    load_with(path, &Limits::default())
}

/// Reads and validates the scene file at `path`, refusing any file past `limits`.
pub fn load_with(path: &Path, limits: &Limits) -> Result<Scene> {
    let src = read_text(path, limits).map_err(|e| anyhow!("cannot read scene file: {e}"))?;
    parse_with(&src, &path.display().to_string(), limits)
}

/// Parses and validates scene text; `file` names it in errors (within the default [`Limits`]
/// for the files it includes).
pub fn parse(src: &str, file: &str) -> Result<Scene> {
    parse_with(src, file, &Limits::default())
}

/// Parses and validates scene text; `file` names it in errors, and `limits` bounds the files it
/// includes.
pub fn parse_with(src: &str, file: &str, limits: &Limits) -> Result<Scene> {
    let raw = read_toml(src, file)?;
    let cx = Ctx {
        src,
        file,
        limits: *limits,
    };
    let mut by_name = HashMap::new();
    let mut materials = Vec::new();
    for m in &raw.material {
        let name = m.get_ref().name.get_ref().clone();
        cx.check_name(&m.get_ref().name, "material.name")?;
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
    if let Some((a, b)) = super::overlap::first_duplicate(&patches) {
        anyhow::bail!(
            "{file}: patch `{}` has the vertices and facing of `{}`: coplanar patches must not \
             overlap, since a ray cannot tell them apart (docs/scene-format.md)",
            patches[b].name,
            patches[a].name
        );
    }
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
        let Some(span) = e.span() else {
            return anyhow!("{file}: {}", e.message());
        };
        let start = span.start.min(src.len());
        let line = src[..start].matches('\n').count() + 1;
        match key_at(src, start) {
            Some(key) => anyhow!("{file}:{line}: `{key}`: {}", e.message()),
            None => anyhow!("{file}:{line}: {}", e.message()),
        }
    })
}

/// The key of the `key = value` line holding byte `at`, when the error lies in its value: the
/// line number alone leaves a reader to find which of a table's keys was wrong.
fn key_at(src: &str, at: usize) -> Option<&str> {
    let begin = src[..at].rfind('\n').map_or(0, |i| i + 1);
    let (key, _) = src[begin..at].split_once('=')?;
    let key = key.trim();
    let plain = |c: char| c.is_ascii_alphanumeric() || "_-.\"".contains(c);
    (!key.is_empty() && key.chars().all(plain)).then_some(key)
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
    if !(material.reflects() || material.transmits()) {
        let lobes = [("phong", m.phong.as_ref()), ("frustum", m.frustum.as_ref())];
        for (key, given) in lobes {
            if let Some(v) = given {
                let why = "has no effect: the material has no specular or transmission part";
                cx.warn(v.span(), &format!("material.{key}"), why);
            }
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
                patches.extend(polygon(cx, p.get_ref(), kind, n, by_name, &mut names)?)
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

/// A user's patch name, checked ([`bad_name`]) and claimed: a second patch of that name is
/// refused.
fn claim_name(
    cx: &Ctx<'_>,
    name: &Spanned<String>,
    key: &str,
    names: &mut HashMap<String, ()>,
) -> Result<String> {
    cx.check_name(name, key)?;
    let n = name.get_ref().clone();
    if names.insert(n.clone(), ()).is_some() {
        // a `/` is in every name an [[obj]] or [[bpt]] entry gives its patches
        let why = match n.contains('/') {
            true => format!(
                "patch `{n}` defined twice, or named like a patch of an [[obj]] or [[bpt]] entry \
                 before it (`<object>/<index>`): choose a name without `/`"
            ),
            false => format!("patch `{n}` defined twice"),
        };
        return Err(cx.err(name.span(), key, why));
    }
    Ok(n)
}

/// One `[[bezier]]` patch, checked.
fn bezier(
    cx: &Ctx<'_>,
    r: &RawBezier,
    by_name: &HashMap<String, usize>,
    names: &mut HashMap<String, ()>,
) -> Result<ScenePatch> {
    let name = claim_name(cx, &r.name, "bezier.name", names)?;
    let material = cx.material_named(by_name, &r.material, "bezier.material")?;
    let pts = r.control_points.get_ref();
    let key = "bezier.control_points";
    let at = r.control_points.span();
    if pts.len() != 16 {
        return Err(cx.err(
            at,
            key,
            format!("a Bezier patch has 16 points, found {}", pts.len()),
        ));
    }
    let mut cp = Vec::with_capacity(16);
    for (i, p) in pts.iter().enumerate() {
        if p.len() != 3 {
            let e = format!("point {i} has {} numbers, not 3", p.len());
            return Err(cx.err(at, key, e));
        }
        for x in p {
            if let Some(why) = not_f32(*x) {
                return Err(cx.err(at, key, format!("point {i}: {} {why}", show(*x))));
            }
        }
        cp.push([p[0], p[1], p[2]]);
    }
    bezier_patch(name.clone(), material, &cp, 1.0, [0.0; 3], false).map_err(|e| match e {
        Reject::Range(e) => cx.err(at, key, format!("patch `{name}`: {e}")),
        Reject::Degenerate(why) => cx.err(at, key, format!("patch `{name}` {why}")),
    })
}

/// A quad whose vertices lie further than this fraction of its size from the plane through
/// its first vertex (with its diagonals' normal) is loaded as two triangles, P0 P1 P2 and
/// P0 P2 P3, as Radiance takes such a polygon: one plane would put some vertices off the
/// surface. The published Cornell box's red wall is warped by 0.20 % (1.6 mm); as one plane
/// its corners sat 1.6 mm from where Radiance has them, which read +1.0 and +1.8 % red at
/// points 3 mm from them (docs/ACCURACY.md, "The warped red wall").
pub const WARP: f64 = 1e-4;

/// One `[[quad]]` (n = 4) or `[[triangle]]` (n = 3), checked: one patch, or two triangles
/// `name/0` and `name/1` for a quad warped past [`WARP`].
fn polygon(
    cx: &Ctx<'_>,
    r: &RawPolygon,
    kind: &str,
    n: usize,
    by_name: &HashMap<String, usize>,
    names: &mut HashMap<String, ()>,
) -> Result<Vec<ScenePatch>> {
    let name = claim_name(cx, &r.name, &format!("{kind}.name"), names)?;
    let material = cx.material_named(by_name, &r.material, &format!("{kind}.material"))?;
    let key = format!("{kind}.vertices");
    let verts = r.vertices.get_ref();
    let at = r.vertices.span();
    if verts.len() != n {
        return Err(cx.err(
            at,
            &key,
            format!("a {kind} has {n} vertices, found {}", verts.len()),
        ));
    }
    let (mut pts, mut reach, mut size) = ([Vec3::ZERO; 4], 0.0f64, 0.0f64);
    for (i, v) in verts.iter().enumerate() {
        if v.len() != 3 {
            let e = format!("vertex {i} has {} numbers, not 3", v.len());
            return Err(cx.err(at, &key, e));
        }
        let mut c = [0.0f32; 3];
        for k in 0..3 {
            c[k] = coordinate(v[k])
                .map_err(|e| cx.err(at.clone(), &key, format!("vertex {i}: {e}")))?;
            reach = reach.max(v[k].abs());
        }
        pts[i] = Vec3::new(c[0], c[1], c[2]);
        for w in &verts[..i] {
            let d = (0..3).map(|k| (v[k] - w[k]).powi(2)).sum::<f64>().sqrt();
            size = size.max(d);
        }
    }
    if let Some(why) = too_small(size, reach) {
        return Err(cx.err(at, &key, format!("patch `{name}` {why}")));
    }
    if n == 4 && f64::from(Polygon::warp(&pts)) > WARP {
        // checked whole first (a warp past 1 %, a concave quad are refused as for any quad)
        planar(cx, &at, &key, &name, Polygon::quad(pts))?;
        let halves = [[pts[0], pts[1], pts[2]], [pts[0], pts[2], pts[3]]];
        return halves
            .into_iter()
            .enumerate()
            .map(|(i, t)| {
                let piece = cx.claim_piece(at.clone(), &key, names, format!("{name}/{i}"))?;
                let polygon = planar(cx, &at, &key, &piece, Polygon::triangle(t))?;
                Ok(opaque(piece, material, polygon))
            })
            .collect();
    }
    let polygon = if n == 4 {
        Polygon::quad(pts)
    } else {
        Polygon::triangle([pts[0], pts[1], pts[2]])
    };
    let polygon = planar(cx, &at, &key, &name, polygon)?;
    Ok(vec![opaque(name, material, polygon)])
}

/// An opaque scene patch of `polygon`.
fn opaque(name: String, material: usize, polygon: Polygon) -> ScenePatch {
    ScenePatch {
        name,
        material,
        area: polygon.area,
        shape: Shape::Polygon(polygon),
        sides: Sides::Opaque,
    }
}

/// `polygon`, or the error of the patch `name` at `at` that says why it is not one.
fn planar(
    cx: &Ctx<'_>,
    at: &std::ops::Range<usize>,
    key: &str,
    name: &str,
    polygon: Result<Polygon, PolygonError>,
) -> Result<Polygon> {
    polygon.map_err(|e| {
        let why = match e {
            PolygonError::NotFinite => "has a NaN or infinite coordinate",
            PolygonError::Degenerate => "is degenerate: zero area or collinear vertices",
            PolygonError::NotPlanar => {
                "is not planar: a vertex lies off the plane by more than 1 % of its size"
            }
            PolygonError::NotConvex => "is not convex, or its vertices are not in order around it",
        };
        cx.err(at.clone(), key, format!("patch `{name}` {why}"))
    })
}

/// The `[camera]`, checked: a field of view, a size, and a view direction apart from `up`.
fn camera(cx: &Ctx<'_>, c: &RawCamera) -> Result<Camera> {
    let fov = *c.fov_y_deg.get_ref();
    if !(fov > 0.0 && fov < 180.0) {
        return Err(cx.err(
            c.fov_y_deg.span(),
            "camera.fov_y_deg",
            format!("{} is not between 0 and 180", show(fov)),
        ));
    }
    for (w, key) in [(&c.width, "camera.width"), (&c.height, "camera.height")] {
        if *w.get_ref() == 0 || *w.get_ref() > 16384 {
            return Err(cx.err(w.span(), key, "must be between 1 and 16384"));
        }
    }
    let (eye, _) = cx.point(&c.eye, "camera.eye")?;
    let (look_at, _) = cx.point(&c.look_at, "camera.look_at")?;
    let (up, _) = cx.point(&c.up, "camera.up")?;
    let fwd = (look_at - eye).try_normalize().ok_or_else(|| {
        let why = if look_at == eye {
            "equals the eye position"
        } else {
            "is too close to the eye position for f32 to give a view direction"
        };
        cx.err(c.look_at.span(), "camera.look_at", why)
    })?;
    if fwd.cross(up).try_normalize().is_none() {
        return Err(cx.err(
            c.up.span(),
            "camera.up",
            "is zero or parallel to the view direction",
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

    #[test]
    fn a_value_of_the_wrong_type_is_named_by_its_key() {
        let e = parse("[[material]]\nname = \"m\"\ndiffuse = \"grey\"\n", "t.toml").unwrap_err();
        let e = e.to_string();
        assert!(
            e.starts_with("t.toml:3: `diffuse`: invalid type: string"),
            "{e}"
        );
        // no `key = value` on the line: the line alone
        let e = parse("nonsense\n", "t.toml").unwrap_err().to_string();
        assert!(e.starts_with("t.toml:1: expected"), "{e}");
    }

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
    fn a_warped_quad_is_two_triangles_on_its_vertices_and_a_flat_one_is_one_quad() {
        use crate::scene::Shape;
        // the published Cornell box's red wall: 1.6 mm (0.20 %) off the plane through P0
        let wall = "[[material]]\nname = \"m\"\ndiffuse = [0.5, 0.5, 0.5]\n\n[[quad]]\n\
                    name = \"red_wall\"\nmaterial = \"m\"\nvertices = [[552.8, 0, 0], \
                    [549.6, 0, 559.2], [556, 548.8, 559.2], [556, 548.8, 0]]\n";
        let s = parse(wall, "w.toml").unwrap();
        let names: Vec<&str> = s.patches.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(names, ["red_wall/0", "red_wall/1"]);
        let corners = |i: usize| match &s.patches[i].shape {
            Shape::Polygon(p) => p.vertices().to_vec(),
            _ => panic!("a polygon"),
        };
        let v = [
            Vec3::new(552.8, 0.0, 0.0),
            Vec3::new(549.6, 0.0, 559.2),
            Vec3::new(556.0, 548.8, 559.2),
            Vec3::new(556.0, 548.8, 0.0),
        ];
        assert_eq!(corners(0), [v[0], v[1], v[2]]);
        assert_eq!(corners(1), [v[0], v[2], v[3]]);
        let total: f32 = s.patches.iter().map(|p| p.area).sum();
        assert!((total - 3.07e5).abs() < 1e3, "{total}");
        // 0.005 % off: one quad, as the data say
        let flat = wall.replace("549.6, 0, 559.2", "552.8, 0.04, 559.2");
        let s = parse(&flat, "f.toml").unwrap();
        assert_eq!(s.patches.len(), 1);
        assert_eq!(s.patches[0].name, "red_wall");
        // a piece's name taken already is refused, not shadowed
        let taken = format!(
            "{wall}\n[[quad]]\nname = \"red_wall/1\"\nmaterial = \"m\"\n\
                             vertices = [[0,0,0],[1,0,0],[1,1,0],[0,1,0]]\n"
        );
        assert!(err(&taken).contains("defined twice"), "{}", err(&taken));
    }

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

    #[test]
    fn numbers_beyond_f32_are_named_as_such_not_as_nan() {
        let quad = "[[0,0,1],[0,1,1],[1,1,1],[1,0,1]]";
        let e = err(&GOOD.replace(quad, "[[0,0,1],[0,1e39,1],[1,1,1],[1,0,1]]"));
        assert!(
            e.contains("bad.toml:19: `quad.vertices`: vertex 1: 1e39 is beyond f32's range"),
            "{e}"
        );
        let e = err(&GOOD.replace(
            quad,
            "[[0,0,1e38],[0,1e38,1e38],[1e38,1e38,1e38],[1e38,0,1e38]]",
        ));
        assert!(
            e.contains("vertex 0: 1e38 is beyond the ±1e9 coordinates"),
            "{e}"
        );
        let e = err(&GOOD.replace(quad, "[[0,0,1],[0,1e-12,1],[1e-12,1e-12,1],[1e-12,0,1]]"));
        assert!(
            e.contains("patch `q` is 1.414e-12 across") && e.contains("underflow"),
            "{e}"
        );
        let e = err(&GOOD.replace(quad, "[[0,0,1e8],[0,1,1e8],[1,1,1e8],[1,0,1e8]]"));
        assert!(e.contains("a millionth of its distance"), "{e}");
        let e = err(&GOOD.replace("[10.0, 10.0, 10.0]", "[1e300, 1, 1]"));
        assert!(
            e.contains("`material.emission`: component 0: 1e300 is beyond f32's range"),
            "{e}"
        );
        let e = err(&GOOD.replace("[10.0, 10.0, 10.0]", "[1e20, 1, 1]"));
        assert!(e.contains("1e20 is beyond the 1e12 W/m² emission"), "{e}");
        let e = err(&GOOD.replace("[10.0, 10.0, 10.0]", "[nan, 1, 1]"));
        assert!(e.contains("component 0: NaN is NaN"), "{e}");
    }

    #[test]
    fn a_camera_far_away_is_out_of_range_not_at_the_eye() {
        let cam = "\n[camera]\neye = [0, 0, -1e38]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\n\
                   fov_y_deg = 40\nwidth = 8\nheight = 8\n";
        let e = err(&format!("{GOOD}{cam}"));
        assert!(
            e.contains("`camera.eye`: component 2: -1e38 is beyond the ±1e9"),
            "{e}"
        );
        let e = err(&format!("{GOOD}{}", cam.replace("-1e38", "1e-30")));
        assert!(
            e.contains("`camera.look_at`: is too close to the eye position"),
            "{e}"
        );
    }

    #[test]
    fn names_that_break_lines_or_clash_with_generated_ones_are_refused() {
        let e = err(&GOOD.replace("name = \"q\"", "name = \"t:back\""));
        assert!(
            e.contains("`quad.name`: the name `t:back` contains `:`"),
            "{e}"
        );
        let e = err(&GOOD.replace("name = \"q\"", "name = \"a b\""));
        assert!(
            e.contains("`quad.name`: the name `a b` contains ' '"),
            "{e}"
        );
        let e = err(&GOOD.replace("name = \"white\"", "name = \"wh\\nite\""));
        assert!(
            e.contains("`material.name`: the name `wh\\nite` contains '\\n'"),
            "{e}"
        );
    }

    /// Writes `files` into a fresh folder and loads its `scene.toml`.
    fn load_files(tag: &str, files: &[(&str, &str)], limits: &Limits) -> Result<Scene> {
        let dir = std::env::temp_dir().join(format!("hemi-load-{tag}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for (name, text) in files {
            std::fs::write(dir.join(name), text).unwrap();
        }
        load_with(&dir.join("scene.toml"), limits)
    }

    const OBJ_SCENE: &str = "[[obj]]\npath = \"m.obj\"\n";
    const OBJ: &str = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n";

    #[test]
    fn obj_and_mtl_numbers_are_checked_with_their_file_and_line() {
        let d = Limits::default();
        let s = load_files(
            "ok",
            &[
                ("scene.toml", OBJ_SCENE),
                ("m.obj", OBJ),
                ("m.mtl", "newmtl a\nKd 0.5 0.5 0.5\n"),
            ],
            &d,
        )
        .unwrap();
        assert_eq!(s.material_of(0).diffuse, [0.5; 3]);
        let mtl = "newmtl a\nKd 0.5 nan 0.5\n";
        let e = format!(
            "{:#}",
            load_files(
                "kd",
                &[("scene.toml", OBJ_SCENE), ("m.obj", OBJ), ("m.mtl", mtl)],
                &d
            )
            .unwrap_err()
        );
        assert!(
            e.contains("scene.toml:2: `obj.path`: ") && e.contains("m.mtl:2: `Kd`: `nan` is NaN"),
            "{e}"
        );
        let obj = OBJ.replace("v 1 0 0", "v 1e39 0 0");
        let e = format!(
            "{:#}",
            load_files(
                "v",
                &[("scene.toml", OBJ_SCENE), ("m.obj", &obj), ("m.mtl", "")],
                &d
            )
            .unwrap_err()
        );
        assert!(
            e.contains("m.obj:3: `v`: `1e39` is beyond f32's range"),
            "{e}"
        );
        let scaled = format!("{OBJ_SCENE}scale = 1e10\n");
        let e = format!(
            "{:#}",
            load_files(
                "s",
                &[("scene.toml", &scaled), ("m.obj", OBJ), ("m.mtl", "")],
                &d
            )
            .unwrap_err()
        );
        assert!(
            e.contains("vertex 2 placed at 1e10 is beyond the ±1e9"),
            "{e}"
        );
        let obj = OBJ.replace("usemtl a", "o my mesh:1\nusemtl a");
        let s = load_files(
            "o",
            &[("scene.toml", OBJ_SCENE), ("m.obj", &obj), ("m.mtl", "")],
            &d,
        )
        .unwrap();
        assert_eq!(s.patches[0].name, "my_mesh_1/0");
    }

    #[test]
    fn every_file_is_read_within_the_budget() {
        let tiny = Limits { file_bytes: 64 };
        let big = format!("{GOOD}{}", "#".repeat(100));
        let e = format!(
            "{:#}",
            load_files("big", &[("scene.toml", &big)], &tiny).unwrap_err()
        );
        assert!(
            e.contains("scene.toml is larger than 64 bytes") && e.contains("--max-file-mib"),
            "{e}"
        );
        let obj = format!("{OBJ}{}", "#".repeat(100));
        let e = format!(
            "{:#}",
            load_files(
                "bigobj",
                &[("scene.toml", OBJ_SCENE), ("m.obj", &obj)],
                &tiny
            )
            .unwrap_err()
        );
        assert!(e.contains("m.obj is larger than"), "{e}");
    }
}
