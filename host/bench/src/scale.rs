//! Scenes at growing scale, for pass 1's cost against the patch count (docs/PERFORMANCE.md,
//! "Pass 1 at scale"): the Cornell box with every polygon cut n × n (20 n² patches: its warped
//! red wall loads as two triangles, `hemi::scene::load::WARP`), and a closed
//! room of 12 quads holding a tessellated sphere. Each scene is written as scene TOML, so
//! `hemi form-factors` reads the very file the benchmark measured, and optionally as a ray file
//! that the Embree comparison (`host/bench/embree/`) casts: the same geometry, the same sample
//! points and frames, the same hemisphere directions. With `--embree` the benchmark runs that
//! program on each scene right after hemi's pass 1, so both are measured in one run.

use anyhow::{ensure, Result};
use hemi::pass1::form_factors;
use hemi::scene::Scene;
use hemi::settings::Pass1Settings;
use hemi_kernel::geometry::Vec3;
use hemi_kernel::hemisphere::OwnedHemisphere;
use hemi_kernel::patch::Shape;
use hemi_kernel::rotation::{spin_for_sample, Rotation};
use std::fmt::Write as _;
use std::io::Write;
use std::path::Path;
use std::time::Instant;

/// A scene of the scale series.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ScaleScene {
    /// The base scene (the Cornell box) with every quad cut into n × n quads.
    Subdivided(usize),
    /// The closed room with a sphere of about this many triangles.
    Room(usize),
}

impl ScaleScene {
    /// The file stem the scene is written under.
    pub fn name(self) -> String {
        match self {
            ScaleScene::Subdivided(n) => format!("cornell-{n}x{n}"),
            ScaleScene::Room(t) => format!("room-sphere-{t}"),
        }
    }

    /// The K the series measures it at, when none is given: K = 8/n on the subdivided boxes
    /// (so every size casts about the same rays per patch area), 1 in the room.
    pub fn default_samples(self) -> u32 {
        match self {
            ScaleScene::Subdivided(n) => (8 / n.max(1)).max(1) as u32,
            ScaleScene::Room(_) => 1,
        }
    }

    /// The scene as TOML; `base` is the scene the subdivided boxes cut (needed by those only).
    pub fn toml(self, base: Option<&Scene>) -> Result<String> {
        match self {
            ScaleScene::Subdivided(n) => subdivided(
                base.ok_or_else(|| anyhow::anyhow!("no base scene to cut"))?,
                n,
            ),
            ScaleScene::Room(t) => Ok(room_with_sphere(t)),
        }
    }
}

/// The point `i/n` of the way along the edge a–b, computed the same way from both patches that
/// share the edge (endpoints in a fixed order, the ends exact), so cut walls meet without gaps.
fn edge_point(a: Vec3, b: Vec3, i: usize, n: usize) -> Vec3 {
    let (lo, hi, i) = if a.to_array() <= b.to_array() {
        (a, b, i)
    } else {
        (b, a, n - i)
    };
    match i {
        0 => lo,
        _ if i == n => hi,
        _ => lo + (hi - lo) * (i as f32 / n as f32),
    }
}

/// Vertex (i, j) of the n × n cut of quad `v` (i along P0→P1, j along P0→P3): on an edge by
/// [`edge_point`], inside by the bilinear map of the quad.
fn grid_point(v: &[Vec3; 4], i: usize, j: usize, n: usize) -> Vec3 {
    match (i, j) {
        (_, 0) => edge_point(v[0], v[1], i, n),
        (_, _) if j == n => edge_point(v[3], v[2], i, n),
        (0, _) => edge_point(v[0], v[3], j, n),
        (_, _) if i == n => edge_point(v[1], v[2], j, n),
        _ => {
            let (u, w) = (i as f32 / n as f32, j as f32 / n as f32);
            v[0] * ((1.0 - u) * (1.0 - w))
                + v[1] * (u * (1.0 - w))
                + v[2] * (u * w)
                + v[3] * ((1.0 - u) * w)
        }
    }
}

/// Triangle `v` cut into n² triangles of the same facing, named `name/i.j.k`: its edges are
/// cut at [`edge_point`], as its neighbours' are.
fn cut_triangle(out: &mut String, name: &str, material: &str, v: &[Vec3], n: usize) {
    let (a, b, c) = (v[0], v[1], v[2]);
    // i steps along a → b, j along a → c
    let at = |i: usize, j: usize| match (i, j) {
        (_, 0) => edge_point(a, b, i, n),
        (0, _) => edge_point(a, c, j, n),
        _ if i + j == n => edge_point(b, c, j, n),
        _ => a + (b - a) * (i as f32 / n as f32) + (c - a) * (j as f32 / n as f32),
    };
    for j in 0..n {
        for i in 0..n - j {
            let up = [at(i, j), at(i + 1, j), at(i, j + 1)];
            push_patch(out, "triangle", &format!("{name}/{i}.{j}.0"), material, &up);
            if i + j + 1 < n {
                let down = [at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
                push_patch(
                    out,
                    "triangle",
                    &format!("{name}/{i}.{j}.1"),
                    material,
                    &down,
                );
            }
        }
    }
}

fn push_materials(out: &mut String, scene: &Scene) -> Result<()> {
    for m in &scene.materials {
        ensure!(
            !m.reflects() && !m.transmits() && !m.is_translucent(),
            "the scale series cuts diffuse scenes only (material `{}` is not)",
            m.name
        );
        writeln!(out, "[[material]]\nname = {:?}", m.name)?;
        writeln!(out, "diffuse = {:?}", m.diffuse)?;
        if m.emission != [0.0; 3] {
            writeln!(out, "emission = {:?}", m.emission)?;
        }
        out.push('\n');
    }
    Ok(())
}

fn push_patch(out: &mut String, kind: &str, name: &str, material: &str, v: &[Vec3]) {
    let verts: Vec<String> = v
        .iter()
        .map(|p| format!("[{:?}, {:?}, {:?}]", p.x, p.y, p.z))
        .collect();
    let _ = writeln!(
        out,
        "[[{kind}]]\nname = {name:?}\nmaterial = {material:?}\nvertices = [{}]\n",
        verts.join(", ")
    );
}

/// `base` with every quad cut into n × n quads and every triangle into n × n triangles.
pub fn subdivided(base: &Scene, n: usize) -> Result<String> {
    ensure!((1..=64).contains(&n), "subdivision n must be in 1..=64");
    let mut out = format!(
        "# generated by `hemi bench scale`: the base scene with every quad cut {n} × {n}\n\n"
    );
    push_materials(&mut out, base)?;
    for p in &base.patches[..base.fronts()] {
        let material = &base.materials[p.material].name;
        let Shape::Polygon(poly) = &p.shape else {
            anyhow::bail!("the scale series cuts polygon scenes only (`{}`)", p.name);
        };
        if poly.sides == 3 {
            cut_triangle(&mut out, &p.name, material, poly.vertices(), n);
            continue;
        }
        for j in 0..n {
            for i in 0..n {
                let q = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)]
                    .map(|(a, b)| grid_point(&poly.v, a, b, n));
                let name = format!("{}/{i}.{j}", p.name);
                push_patch(&mut out, "quad", &name, material, &q);
            }
        }
    }
    if let Some(c) = &base.camera {
        let v = |p: Vec3| format!("[{:?}, {:?}, {:?}]", p.x, p.y, p.z);
        writeln!(
            out,
            "[camera]\neye = {}\nlook_at = {}\nup = {}\nfov_y_deg = {:?}\nwidth = {}\nheight = {}",
            v(c.eye),
            v(c.look_at),
            v(c.up),
            c.fov_y_deg,
            c.width,
            c.height
        )?;
    }
    Ok(out)
}

/// Stacks and slices of a UV sphere of `2·slices·(stacks−1)` triangles closest to `triangles`,
/// with stacks − 1 the divisor of triangles/2 nearest √(triangles/4) (bands about as tall as
/// they are wide).
fn sphere_grid(triangles: usize) -> (usize, usize) {
    let half = (triangles / 2).max(2);
    let target = ((triangles as f64) / 4.0).sqrt();
    let bands = (1..=half)
        .filter(|d| half.is_multiple_of(*d))
        .min_by(|a, b| {
            let da = (*a as f64 - target).abs();
            let db = (*b as f64 - target).abs();
            da.total_cmp(&db)
        })
        .unwrap_or(1)
        .max(2);
    (bands + 1, (half / bands).max(3))
}

/// A closed room, 10 × 6 × 10 units of 12 quads (one ceiling quad the light), holding a UV
/// sphere of about `triangles` triangles facing out: the scale series' large scenes.
pub fn room_with_sphere(triangles: usize) -> String {
    let mut out = format!(
        "# generated by `hemi bench scale`: a closed room of 12 quads with a sphere of {triangles} triangles\n\n"
    );
    out += "[[material]]\nname = \"white\"\ndiffuse = [0.7, 0.7, 0.7]\n\n";
    out += "[[material]]\nname = \"grey\"\ndiffuse = [0.5, 0.5, 0.5]\n\n";
    out += "[[material]]\nname = \"light\"\ndiffuse = [0.7, 0.7, 0.7]\nemission = [10.0, 10.0, 10.0]\n\n";
    let v = Vec3::new;
    // each face as two quads, counter-clockwise seen from inside the room
    let (x, y, z) = (10.0, 6.0, 10.0);
    let faces: [(&str, &str, [Vec3; 4]); 6] = [
        (
            "floor",
            "white",
            [v(0., 0., 0.), v(0., 0., z), v(x, 0., z), v(x, 0., 0.)],
        ),
        (
            "ceiling",
            "white",
            [v(0., y, 0.), v(x, y, 0.), v(x, y, z), v(0., y, z)],
        ),
        (
            "wall_x0",
            "white",
            [v(0., 0., 0.), v(0., y, 0.), v(0., y, z), v(0., 0., z)],
        ),
        (
            "wall_x1",
            "white",
            [v(x, 0., 0.), v(x, 0., z), v(x, y, z), v(x, y, 0.)],
        ),
        (
            "wall_z0",
            "white",
            [v(0., 0., 0.), v(x, 0., 0.), v(x, y, 0.), v(0., y, 0.)],
        ),
        (
            "wall_z1",
            "white",
            [v(0., 0., z), v(0., y, z), v(x, y, z), v(x, 0., z)],
        ),
    ];
    for (name, material, q) in faces {
        let mid_a = (q[0] + q[1]) * 0.5;
        let mid_b = (q[3] + q[2]) * 0.5;
        let material_b = if name == "ceiling" { "light" } else { material };
        push_patch(
            &mut out,
            "quad",
            &format!("{name}/0"),
            material,
            &[q[0], mid_a, mid_b, q[3]],
        );
        push_patch(
            &mut out,
            "quad",
            &format!("{name}/1"),
            material_b,
            &[mid_a, q[1], q[2], mid_b],
        );
    }
    let (stacks, slices) = sphere_grid(triangles);
    let (centre, radius) = (v(5.0, 2.6, 5.0), 2.4f32);
    let at = |i: usize, k: usize| -> Vec3 {
        if i == 0 {
            return centre + v(0.0, radius, 0.0);
        }
        if i == stacks {
            return centre - v(0.0, radius, 0.0);
        }
        let theta = std::f64::consts::PI * i as f64 / stacks as f64;
        let phi = std::f64::consts::TAU * (k % slices) as f64 / slices as f64;
        let (st, ct) = theta.sin_cos();
        let (sp, cp) = phi.sin_cos();
        centre + v((st * cp) as f32, ct as f32, (st * sp) as f32) * radius
    };
    let mut count = 0;
    let mut tri = |out: &mut String, a: Vec3, b: Vec3, c: Vec3| {
        let n = (b - a).cross(c - a);
        let outward = n.dot((a + b + c) * (1.0 / 3.0) - centre) > 0.0;
        let t = if outward { [a, b, c] } else { [a, c, b] };
        push_patch(out, "triangle", &format!("sphere/{count}"), "grey", &t);
        count += 1;
    };
    for i in 0..stacks {
        for k in 0..slices {
            let (a, b) = (at(i, k), at(i, k + 1));
            let (c, d) = (at(i + 1, k + 1), at(i + 1, k));
            if i > 0 {
                tri(&mut out, a, b, c);
            }
            if i + 1 < stacks {
                tri(&mut out, a, c, d);
            }
        }
    }
    out
}

/// Writes the ray file of `scene` at `settings` for the Embree comparison: little-endian,
/// `HEMIRAY1`; quads (triangles with the last vertex repeated) as 12 f32 each; the hemisphere's
/// directions in its own frame (3 f32 each, rings in order); and per sample point its origin,
/// its patch and its frame (the columns of the rotation the tracer places the hemisphere by).
pub fn write_rays(scene: &Scene, settings: &Pass1Settings, path: &Path) -> Result<()> {
    let mut buf: Vec<u8> = b"HEMIRAY1".to_vec();
    let f = |buf: &mut Vec<u8>, x: f32| buf.extend_from_slice(&x.to_le_bytes());
    let u = |buf: &mut Vec<u8>, x: u32| buf.extend_from_slice(&x.to_le_bytes());
    let patches = scene.kernel_patches();
    u(&mut buf, patches.len() as u32);
    for p in &patches {
        let Shape::Polygon(poly) = &p.shape else {
            anyhow::bail!("ray files hold polygon scenes only");
        };
        for k in 0..4 {
            let vtx = poly.v[k.min(poly.sides as usize - 1)];
            vtx.to_array().iter().for_each(|x| f(&mut buf, *x));
        }
    }
    let hemi = OwnedHemisphere::new(settings.circles, settings.rule)
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    let view = hemi.view();
    u(&mut buf, view.ray_count());
    for (j, ring) in view.rings().iter().enumerate() {
        for k in 0..ring.count {
            view.direction(j, k)
                .to_array()
                .iter()
                .for_each(|x| f(&mut buf, *x));
        }
    }
    let shots: Vec<_> = (0..scene.patches.len())
        .flat_map(|i| hemi::shots::uniform_shots(scene, i, settings.samples))
        .collect();
    u(&mut buf, shots.len() as u32);
    for s in &shots {
        let rot = Rotation::onto_spun(s.point.normal, spin_for_sample(s.cell.q()));
        s.point
            .position
            .to_array()
            .iter()
            .for_each(|x| f(&mut buf, *x));
        u(&mut buf, scene.kernel_id(s.patch) as u32);
        for axis in [Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0), Vec3::Z] {
            rot.apply(axis)
                .to_array()
                .iter()
                .for_each(|x| f(&mut buf, *x));
        }
    }
    std::fs::write(path, buf)?;
    Ok(())
}

/// What one pass 1 of the series measured.
#[derive(Clone, Copy, Debug)]
pub struct ScaleRun {
    /// Patches of the scene.
    pub patches: usize,
    /// Hemispheres shot.
    pub hemispheres: usize,
    /// Rays cast.
    pub rays: u64,
    /// Wall time of pass 1 (form factors included), seconds.
    pub seconds: f64,
    /// CPU time of the process over pass 1 (all threads), seconds, if the system says.
    pub cpu_seconds: Option<f64>,
    /// Rays that hit a patch (front or back).
    pub hits: u64,
    /// Bytes the patch form factors take.
    pub matrix_bytes: usize,
    /// Non-zero form factors.
    pub nonzeros: usize,
}

/// The fastest of `repeat` runs of [`measure`] (at least one): a pass 1 of a few tens of
/// milliseconds moves by a third between single runs.
pub fn measure_best(
    scene: &Scene,
    settings: &Pass1Settings,
    repeat: usize,
    progress: &hemi::backend::Progress<'_>,
) -> Result<ScaleRun> {
    let mut best = measure(scene, settings, progress)?;
    for _ in 1..repeat {
        let run = measure(scene, settings, progress)?;
        if run.seconds < best.seconds {
            best = run;
        }
    }
    Ok(best)
}

/// Pass 1 of `scene` on the soft backend at `settings`, timed; `progress` gets the
/// hemispheres done.
pub fn measure(
    scene: &Scene,
    settings: &Pass1Settings,
    progress: &hemi::backend::Progress<'_>,
) -> Result<ScaleRun> {
    let backend = hemi::backend::soft(scene, settings)?;
    let (t0, cpu0) = (Instant::now(), cpu_seconds());
    let ff = form_factors(&backend, progress)?;
    let seconds = t0.elapsed().as_secs_f64();
    Ok(ScaleRun {
        patches: scene.patches.len(),
        hemispheres: ff.elements.len(),
        rays: ff.stats.rays as u64,
        seconds,
        cpu_seconds: cpu_seconds().zip(cpu0).map(|(b, a)| b - a),
        hits: (ff.stats.front_hits + ff.stats.back_hits) as u64,
        matrix_bytes: ff.matrix_bytes(),
        nonzeros: ff.nonzeros(),
    })
}

/// What the Embree program measured on one ray file: its fastest mode.
#[derive(Clone, Debug)]
pub struct EmbreeRun {
    /// single, packet8 or packet16.
    pub mode: String,
    /// Wall time of the fastest mode, seconds.
    pub seconds: f64,
    /// Rays that hit a patch.
    pub hits: u64,
}

/// Runs the Embree program `program` (`host/bench/embree/hemi_embree.cpp`) on `rays` with
/// `threads` threads, each mode the fastest of `repeat` runs, and keeps its fastest mode.
pub fn run_embree(program: &Path, rays: &Path, threads: usize, repeat: usize) -> Result<EmbreeRun> {
    let out = std::process::Command::new(program)
        .arg(rays)
        .arg(threads.to_string())
        .arg(repeat.max(1).to_string())
        .output()
        .map_err(|e| anyhow::anyhow!("--embree {}: {e}", program.display()))?;
    ensure!(
        out.status.success(),
        "--embree {} failed: {}",
        program.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    let field = |line: &str, key: &str| -> Option<String> {
        line.split_whitespace()
            .find_map(|w| w.strip_prefix(key)?.strip_prefix('=').map(str::to_string))
    };
    let text = String::from_utf8_lossy(&out.stdout);
    text.lines()
        .filter_map(|l| {
            Some(EmbreeRun {
                mode: field(l, "mode")?,
                seconds: field(l, "seconds")?.parse().ok()?,
                hits: field(l, "hits")?.parse().ok()?,
            })
        })
        .min_by(|a, b| a.seconds.total_cmp(&b.seconds))
        .ok_or_else(|| anyhow::anyhow!("--embree {}: no result line", program.display()))
}

/// The table's header (markdown); with Embree's columns when `embree`.
pub fn header(out: &mut impl Write, embree: bool) -> Result<()> {
    let (extra, rule) = match embree {
        true => (
            " Embree s (fastest mode) | Embree Mrays/s | hemi / Embree (wall) | hits, hemi − Embree |",
            "---|---|---|---|",
        ),
        false => ("", ""),
    };
    writeln!(
        out,
        "| scene | patches | R | K | hemispheres | rays | pass 1 s | CPU s | Mrays/s | µs per hemisphere | F non-zeros | F MiB | peak RSS MiB |{extra}"
    )?;
    writeln!(
        out,
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|{rule}"
    )?;
    Ok(())
}

/// One row of the table for `run` of scene `name` (and Embree's run of the same rays).
pub fn row(
    out: &mut impl Write,
    name: &str,
    settings: &Pass1Settings,
    run: &ScaleRun,
    embree: Option<&EmbreeRun>,
) -> Result<()> {
    let peak = peak_rss_bytes().map_or("—".into(), |b| format!("{:.0}", b as f64 / MIB));
    let cpu = run.cpu_seconds.map_or("—".into(), |c| format!("{c:.2}"));
    let mut line = format!(
        "| {name} | {} | {} | {} | {} | {} | {:.3} | {cpu} | {:.2} | {:.1} | {} | {:.2} | {peak} |",
        run.patches,
        settings.circles,
        settings.samples,
        run.hemispheres,
        run.rays,
        run.seconds,
        run.rays as f64 / run.seconds / 1e6,
        run.seconds / run.hemispheres.max(1) as f64 * 1e6,
        run.nonzeros,
        run.matrix_bytes as f64 / MIB,
    );
    if let Some(e) = embree {
        line += &format!(
            " {:.3} ({}) | {:.2} | {:.2} | {} |",
            e.seconds,
            e.mode,
            run.rays as f64 / e.seconds / 1e6,
            e.seconds / run.seconds,
            run.hits as i64 - e.hits as i64
        );
    }
    writeln!(out, "{line}")?;
    Ok(())
}

impl ScaleScene {
    /// The family the chart draws the scene's point in (cut boxes and rooms grow differently).
    pub fn family(self) -> &'static str {
        match self {
            ScaleScene::Subdivided(_) => "cut box",
            ScaleScene::Room(_) => "room",
        }
    }
}

/// The log–log chart of one hemisphere's time against the patch count, `(family, P, hemi µs,
/// Embree µs)` per scene: a line per family for hemi and (when measured) for Embree, each with
/// the exponent of its least-squares line in the legend.
pub fn chart(rows: &[(&str, usize, f64, Option<f64>)]) -> String {
    let mut families: Vec<&str> = rows.iter().map(|r| r.0).collect();
    families.dedup();
    let mut series = Vec::new();
    for (engine, pick) in [
        (
            "hemi",
            (|r| Some(r.2)) as fn(&(&str, usize, f64, Option<f64>)) -> Option<f64>,
        ),
        ("Embree", |r| r.3),
    ] {
        for family in &families {
            let points: Vec<(f64, f64)> = rows
                .iter()
                .filter(|r| r.0 == *family)
                .filter_map(|r| Some((r.1 as f64, pick(r)?)))
                .collect();
            if points.is_empty() {
                continue;
            }
            let slope = fitted_exponent(&points);
            series.push(crate::chart::Series {
                name: format!("{engine}, {family}: P^{slope:.2}"),
                points,
            });
        }
    }
    crate::chart::log_log(
        "One hemisphere's time against the patch count",
        "patches P",
        "µs per hemisphere (wall, 2 threads)",
        "hemi bench scale --embree (docs/PERFORMANCE.md)",
        &series,
    )
}

/// The slope of the least-squares line through `points` on log–log axes.
pub fn fitted_exponent(points: &[(f64, f64)]) -> f64 {
    let logs: Vec<(f64, f64)> = points.iter().map(|(x, y)| (x.ln(), y.ln())).collect();
    let n = logs.len() as f64;
    let (mx, my) = logs
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
    let sxy: f64 = logs.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = logs.iter().map(|(x, _)| (x - mx) * (x - mx)).sum();
    if sxx > 0.0 {
        sxy / sxx
    } else {
        0.0
    }
}

/// This process's CPU time so far (user + system, all threads), from Linux's /proc.
fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // the fields after the command name, which is in parentheses and may hold spaces
    let rest = stat.rsplit_once(')')?.1;
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let ticks: f64 = fields.get(11)?.parse::<f64>().ok()? + fields.get(12)?.parse::<f64>().ok()?;
    // the kernel's USER_HZ, 100 on every Linux this runs on
    Some(ticks / 100.0)
}

const MIB: f64 = 1024.0 * 1024.0;

/// The process's peak resident memory so far (Linux `VmHWM`), if the system says.
fn peak_rss_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sphere_grid_hits_the_asked_counts() {
        for t in [10_000, 50_000] {
            let (stacks, slices) = sphere_grid(t);
            assert_eq!(2 * slices * (stacks - 1), t, "{t}");
        }
    }

    #[test]
    fn the_fitted_exponent_of_a_power_law_is_its_power() {
        let points: Vec<(f64, f64)> = [10.0, 100.0, 1000.0]
            .iter()
            .map(|&x: &f64| (x, 3.0 * x.powf(0.5)))
            .collect();
        assert!((fitted_exponent(&points) - 0.5).abs() < 1e-12);
    }

    #[test]
    fn cut_edges_are_shared_exactly() {
        let (a, b) = (Vec3::new(0.1, 0.2, 0.3), Vec3::new(7.0, -3.0, 1.0));
        for i in 0..=7 {
            assert_eq!(edge_point(a, b, i, 7), edge_point(b, a, 7 - i, 7));
        }
        assert_eq!(edge_point(a, b, 7, 7), b);
    }

    #[test]
    fn a_cut_triangle_is_n_squared_triangles_covering_its_area() {
        let v = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 3.0, 0.0),
        ];
        let mut out = String::from("[[material]]\nname = \"m\"\ndiffuse = [0.5, 0.5, 0.5]\n\n");
        cut_triangle(&mut out, "t", "m", &v, 5);
        let scene = hemi::scene::parse(&out, "cut.toml").unwrap();
        assert_eq!(scene.patches.len(), 25);
        let area: f32 = scene.patches.iter().map(|p| p.area).sum();
        assert!((area - 3.0).abs() < 1e-4, "{area}");
        // every piece faces as the triangle does (the loader refuses none as inverted)
        let normal = |p: &hemi::scene::ScenePatch| match &p.shape {
            Shape::Polygon(q) => q.normal,
            _ => panic!("a polygon"),
        };
        assert!(scene.patches.iter().all(|p| normal(p).z > 0.99));
    }
}
