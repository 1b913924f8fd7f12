#!/usr/bin/env python3
"""hemi against Radiance 6.0a, side by side: irradiance at points of a hemi scene.

Not run in CI. It installs nothing; to get Radiance:

    pip install pyradiance        # PyPI; its wheel bundles the Radiance 6.0a binaries

The script finds the installed pyradiance package itself and puts its `bin` folder on PATH and
its `lib` folder on RAYPATH for the Radiance programs it runs (oconv, rtrace), so no manual step
is needed. Without pyradiance it falls back to an `rtrace` already on PATH (then RAYPATH is
yours to set).

What it does:
  1. reads a hemi scene (TOML, docs/scene-format.md) with tomllib and writes an equivalent
     Radiance scene (.rad; see `convert` and tests/radiance/README.md for the mapping);
  2. runs `rtrace -I` at the query points (`x y z dx dy dz` lines, the convention of
     `hemi irradiance`), each point repeated --repeats times in one run (with -aa 0 and the
     default -u+ every line is an independent Monte Carlo estimate), and takes the mean and
     standard error per channel;
  3. runs `hemi irradiance SCENE [--hemi-args]` on the same points;
  4. prints a markdown table: point, Radiance mean ± s.e., hemi, relative error per channel,
     and the RMS / worst relative error over points, with both tools' wall times.

Examples (from the repository root):

    python3 tests/radiance/compare.py --scene scenes/cornell.toml
    python3 tests/radiance/compare.py --scene scenes/cornell.toml \\
        --hemi-args "--circles 128 --samples 8" --repeats 32
    python3 tests/radiance/compare.py --scene scenes/mirror-wall.toml --write-rad /tmp/m.rad

Python 3.11 (tomllib), standard library only.
"""

from __future__ import annotations

import argparse
import json
import importlib.util
import math
import os
import shlex
import shutil
import subprocess
import sys
import tempfile
import time
import tomllib
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent

# Radiance settings for an unbiased, uncached path-traced irradiance (issue 17's traps):
# -ab 64 -lr -64: up to 64 bounces with Russian roulette below weight -lw (the default -lr -10
#   stops every path at 10 reflections whatever -ab says);
# -aa 0 -as 0: no irradiance cache, no super-sampling: each query is independent Monte Carlo;
# -dj 1 -dp 0 -dt 0 -dc 1: jittered area-source samples, no pretest, every source shadow-tested
#   (the default -dt/-dc estimate weak sources statistically);
# -ds 0.01: light sources cut into pieces of at most 1 % of their distance (less noise in the
#   direct part per unit of time than the default 0.2);
# -st 0: every specular ray traced.
DEFAULT_RTRACE = "-ab 64 -lr -64 -lw 1e-4 -ad 1024 -aa 0 -as 0 -dj 1 -dp 0 -dt 0 -dc 1 -ds 0.01 -st 0"

# Built-in query points per scene (by file stem), tests/radiance/points/<stem>.txt.
POINTS_DIR = HERE / "points"
POINT_SETS = {"cornell-issue17": "cornell"}

# `rtrace -I` evaluates the irradiance at org + 1e-4·dir (scene units; rtrace.c: the ray starts
# at org + 1.1e-4·dir and "hits" 1e-5 later). The script moves each query back by this much so
# that both tools measure at the same point (--no-offset to turn this off).
RTRACE_I_AHEAD = 1e-4


class SceneError(Exception):
    pass


# ----------------------------------------------------------------------------------------------
# Radiance location


def find_radiance() -> dict[str, str]:
    """Environment with pyradiance's Radiance binaries on PATH and its lib on RAYPATH."""
    env = dict(os.environ)
    spec = importlib.util.find_spec("pyradiance")
    if spec is not None and spec.origin is not None:
        pkg = Path(spec.origin).parent
        bindir, libdir = pkg / "bin", pkg / "lib"
        if (bindir / "rtrace").exists():
            env["PATH"] = str(bindir) + os.pathsep + env.get("PATH", "")
            raypath = [p for p in env.get("RAYPATH", "").split(os.pathsep) if p]
            env["RAYPATH"] = os.pathsep.join([".", str(libdir)] + raypath)
            return env
    if shutil.which("rtrace", path=env.get("PATH")):
        return env
    sys.exit(
        "compare.py: Radiance not found. Install it with `pip install pyradiance` "
        "(it bundles Radiance 6.0a), or put rtrace and oconv on PATH and set RAYPATH."
    )


def radiance_version(env: dict[str, str]) -> str:
    out = subprocess.run(["rtrace", "-version"], env=env, capture_output=True, text=True)
    return (out.stdout + out.stderr).strip()


# ----------------------------------------------------------------------------------------------
# Vectors


def sub(a, b):
    return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]


def add(a, b):
    return [a[0] + b[0], a[1] + b[1], a[2] + b[2]]


def scale(a, s):
    return [a[0] * s, a[1] * s, a[2] * s]


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def norm(a):
    return math.sqrt(dot(a, a))


def unit(a):
    n = norm(a)
    if n == 0:
        raise ValueError("zero vector")
    return scale(a, 1.0 / n)


def hemi_normal(v):
    """hemi's front normal (docs/scene-format.md): (P1−P0)×(P2−P0) for triangles, the
    diagonals' cross product (P2−P0)×(P3−P1) for quads (kernel/src/geometry/polygon.rs)."""
    if len(v) == 4:
        return unit(cross(sub(v[2], v[0]), sub(v[3], v[1])))
    return unit(cross(sub(v[1], v[0]), sub(v[2], v[0])))


# ----------------------------------------------------------------------------------------------
# Scene conversion

MATERIAL_KEYS = {"name", "diffuse", "emission", "specular", "transmission", "translucency",
                 "phong", "frustum"}
PATCH_KEYS = {"name", "material", "vertices"}
KNOWN_TOP = {"material", "quad", "triangle", "camera"}
REFUSED_TOP = {"obj": "OBJ meshes", "bezier": "Bezier patches", "bpt": ".bpt Bezier files"}


def rgb(m, key):
    v = m.get(key, [0.0, 0.0, 0.0])
    if len(v) != 3:
        raise SceneError(f"material `{m.get('name')}`: `{key}` needs 3 values")
    return [float(x) for x in v]


def fmt(x: float) -> str:
    return f"{x:.9g}"


def fmt3(c) -> str:
    return " ".join(fmt(x) for x in c)


def rad_id(name: str) -> str:
    """A Radiance identifier: no whitespace."""
    return "".join(ch if (ch.isalnum() or ch in "_-.:") else "_" for ch in name)


class Converted:
    def __init__(self):
        self.lines: list[str] = []
        self.notes: list[str] = []

    def text(self) -> str:
        return "\n".join(self.lines) + "\n"


def material_defs(m, opts, out: Converted) -> dict:
    """Writes the Radiance modifiers of one hemi material; returns how patches use them."""
    name = m["name"]
    rid = rad_id(name)
    rho = rgb(m, "diffuse")
    emit = rgb(m, "emission")
    ks = rgb(m, "specular")
    kt = rgb(m, "transmission")
    ky = rgb(m, "translucency")
    phong = float(m.get("phong", 0.0))
    if "frustum" in m and (any(ks) or any(kt)):
        raise SceneError(f"material `{name}`: `frustum` (a glossy lobe) has no Radiance "
                         "equivalent here; only perfect mirrors and clear sheets (phong = inf)")
    if (any(ks) or any(kt)) and not math.isinf(phong):
        raise SceneError(
            f"material `{name}`: glossy specular (phong = {phong}) is refused: Radiance's "
            "Ward lobes are not hemi's discretised Phong lobe; only phong = inf converts")
    use = {"emitter": None, "surface": None, "reflector": None}
    if any(emit):
        if any(ks) or any(kt) or any(ky):
            raise SceneError(f"material `{name}`: an emitter that is also specular or "
                             "translucent is not converted")
        le = [e / math.pi for e in emit]  # exitance E → radiance E/π
        out.lines += [f"# {name}: emitter, exitance E = {fmt3(emit)} → radiance E/π",
                      f"void light {rid} 0 0 3 {fmt3(le)}", ""]
        use["emitter"] = rid
        if any(rho) and opts.emitter_reflect:
            # `light` does not reflect; hemi's emitter does (B = E + ρH). A sheet just in
            # front: specular transmission 1 (the light shows through, shadow rays pass),
            # diffuse reflection ρ on the front, nothing on the back.
            refl = f"{rid}__reflector"
            out.lines += [
                f"# {name}: its reflectance ρ = {fmt3(rho)}, as a clear reflecting sheet in "
                "front of the light",
                f"void BRTDfunc {refl}",
                "10 0 0 0  1 1 1  0 0 0  .",
                "0",
                f"9 {fmt3(rho)}  0 0 0  0 0 0", ""]
            use["reflector"] = refl
            out.notes.append(f"`{name}`: emitter with ρ > 0: a BRTDfunc sheet (τ_s = 1, "
                             f"front ρ) {opts.reflector_offset_rel:g}·diagonal in front")
        elif any(rho):
            out.notes.append(f"`{name}`: emitter's ρ = {fmt3(rho)} dropped (--no-emitter-reflect)")
        return use
    if any(ky) or any(kt) or (any(ks) and any(rho)) or opts.one_sided:
        # BRTDfunc: ideal specular reflection k_r, ideal (straight-through) transmission k_t,
        # front diffuse ρ, back diffuse ρ only for translucent (two-sided) sheets, diffuse
        # transmission k_y. `trans` ties ρ and τ to one scalar ratio for all channels and
        # adds a specular lobe, so it cannot express hemi's per-channel ρ and τ in general.
        back = rho if any(ky) else [0.0, 0.0, 0.0]
        out.lines += [
            f"# {name}: ρ = {fmt3(rho)}, k_r = {fmt3(ks)}, k_t = {fmt3(kt)}, k_y = {fmt3(ky)}"
            + (" (one-sided)" if not any(ky) else " (two-sided sheet)"),
            f"void BRTDfunc {rid}",
            f"10 {fmt3(ks)}  {fmt3(kt)}  0 0 0  .",
            "0",
            f"9 {fmt3(rho)}  {fmt3(back)}  {fmt3(ky)}", ""]
        if any(ks):
            out.notes.append(f"`{name}`: BRTDfunc's mirror part reflects on both sides (hemi: "
                             "front only) and makes no virtual sources (Radiance `mirror` does)")
        use["surface"] = rid
        return use
    if any(ks):
        out.lines += [f"# {name}: perfect mirror k_r = {fmt3(ks)}",
                      f"void mirror {rid} 0 0 3 {fmt3(ks)}", ""]
        use["surface"] = rid
        return use
    out.lines += [f"# {name}: diffuse ρ = {fmt3(rho)} (plastic, no specularity; two-sided)",
                  f"void plastic {rid} 0 0 5 {fmt3(rho)} 0 0", ""]
    use["surface"] = rid
    return use


def planarity(v) -> float:
    """Largest distance of a vertex from the plane through v[0] with hemi's normal, over the
    quad's size."""
    n = hemi_normal(v)
    size = max(norm(sub(p, v[0])) for p in v)
    return max(abs(dot(sub(p, v[0]), n)) for p in v) / size


def polygon(mod: str, name: str, verts) -> list[str]:
    out = [f"{mod} polygon {rad_id(name)}", "0", "0", f"{3 * len(verts)}"]
    out += ["    " + fmt3(p) for p in verts]
    return out + [""]


def convert(scene_path: Path, opts) -> Converted:
    with open(scene_path, "rb") as f:
        doc = tomllib.load(f)
    for key in doc:
        if key in REFUSED_TOP:
            raise SceneError(f"{scene_path}: `[[{key}]]` ({REFUSED_TOP[key]}) is not converted; "
                             "only [[quad]] and [[triangle]] patches are")
        if key not in KNOWN_TOP:
            raise SceneError(f"{scene_path}: unknown table `{key}`")
    out = Converted()
    out.lines += [f"# {scene_path.name}, converted for Radiance by tests/radiance/compare.py",
                  "# Polygons keep hemi's vertex order: both take the front side as the one the",
                  "# vertices run counter-clockwise around (right-handed).", ""]
    uses = {}
    for m in doc.get("material", []):
        extra = set(m) - MATERIAL_KEYS
        if extra:
            raise SceneError(f"material `{m.get('name')}`: unknown keys {sorted(extra)}")
        uses[m["name"]] = material_defs(m, opts, out)
    patches = [("quad", p) for p in doc.get("quad", [])] + \
              [("triangle", p) for p in doc.get("triangle", [])]
    allv = [p for _, q in patches for p in q["vertices"]]
    lo = [min(p[i] for p in allv) for i in range(3)]
    hi = [max(p[i] for p in allv) for i in range(3)]
    diag = norm(sub(hi, lo))
    offset = opts.reflector_offset_rel * diag
    # Patch order does not matter to Radiance (hemi's order across quads/triangles only
    # numbers its matrix rows).
    for kind, p in patches:
        extra = set(p) - PATCH_KEYS
        if extra:
            raise SceneError(f"{kind} `{p.get('name')}`: unknown keys {sorted(extra)}")
        v = [[float(x) for x in q] for q in p["vertices"]]
        need = 4 if kind == "quad" else 3
        if len(v) != need:
            raise SceneError(f"{kind} `{p['name']}`: needs {need} vertices")
        use = uses.get(p["material"])
        if use is None:
            raise SceneError(f"{kind} `{p['name']}`: unknown material `{p['material']}`")
        pieces = [v]
        if kind == "quad":
            warp = planarity(v)
            if warp > opts.planar_tol:
                # Radiance fits one plane to a polygon; a warped quad as two triangles along
                # the P0–P2 diagonal keeps every vertex where it is (as issue 17's model did).
                pieces = [[v[0], v[1], v[2]], [v[0], v[2], v[3]]]
                out.notes.append(f"quad `{p['name']}`: warped by {100 * warp:.2f} % of its size, "
                                 "written as two triangles (P0 P1 P2, P0 P2 P3)")
        for i, piece in enumerate(pieces):
            nm = p["name"] if len(pieces) == 1 else f"{p['name']}.{i}"
            if use["emitter"]:
                out.lines += polygon(use["emitter"], nm, piece)
                if use["reflector"]:
                    n = hemi_normal(piece)
                    front = [add(q, scale(n, offset)) for q in piece]
                    out.lines += polygon(use["reflector"], nm + "__reflector", front)
            else:
                out.lines += polygon(use["surface"], nm, piece)
    return out


# ----------------------------------------------------------------------------------------------
# Points


def read_points(path: Path):
    """(label, [x y z dx dy dz]) per line; `#` starts a comment, whose text labels the point."""
    pts = []
    for n, line in enumerate(path.read_text().splitlines(), 1):
        body, _, comment = line.partition("#")
        if not body.strip():
            continue
        v = [float(t) for t in body.split()]
        if len(v) != 6:
            sys.exit(f"{path}:{n}: expected `x y z dx dy dz`, got `{line}`")
        label = comment.strip() or f"({fmt3(v[:3])}) ({fmt3(v[3:])})"
        pts.append((label, v))
    if not pts:
        sys.exit(f"{path}: no points")
    return pts


# ----------------------------------------------------------------------------------------------
# Runs


def run_rtrace(rad_text: str, points, repeats: int, rtrace_args: str, env, offset: bool,
               workdir: Path):
    rad = workdir / "scene.rad"
    rad.write_text(rad_text)
    oct_ = workdir / "scene.oct"
    with open(oct_, "wb") as f:
        r = subprocess.run(["oconv", str(rad)], stdout=f, stderr=subprocess.PIPE, env=env,
                           text=False)
    if r.returncode != 0:
        sys.exit("oconv failed:\n" + r.stderr.decode())
    lines = []
    for _, v in points:
        d = unit(v[3:])
        o = v[:3]
        if offset:
            o = sub(o, scale(d, RTRACE_I_AHEAD))
        line = f"{fmt3(o)} {fmt3(d)}\n"
        lines.append(line * repeats)
    cmd = ["rtrace", "-h-", "-I+", "-ov", "-w-"] + shlex.split(rtrace_args) + [str(oct_)]
    t0 = time.perf_counter()
    r = subprocess.run(cmd, input="".join(lines), capture_output=True, text=True, env=env)
    wall = time.perf_counter() - t0
    if r.returncode != 0:
        sys.exit(f"rtrace failed ({shlex.join(cmd)}):\n{r.stderr}")
    vals = [[float(t) for t in ln.split()] for ln in r.stdout.splitlines() if ln.strip()]
    if len(vals) != repeats * len(points):
        sys.exit(f"rtrace gave {len(vals)} lines, expected {repeats * len(points)}:\n{r.stderr}")
    stats = []
    for i in range(len(points)):
        block = vals[i * repeats:(i + 1) * repeats]
        mean = [sum(b[c] for b in block) / repeats for c in range(3)]
        if repeats > 1:
            var = [sum((b[c] - mean[c]) ** 2 for b in block) / (repeats - 1) for c in range(3)]
            se = [math.sqrt(x / repeats) for x in var]
        else:
            se = [float("nan")] * 3
        stats.append((mean, se))
    return stats, wall, shlex.join(cmd)


def reference(conv, points, opts):
    """Radiance's mean and standard error per point: from `opts.reference` when it holds a run
    of exactly this input, else by rtrace (and saved there)."""
    key = {"rad": conv.text(), "points": [v for _, v in points], "rtrace": opts.rtrace_args,
           "repeats": opts.repeats, "offset": opts.offset}
    if opts.reference and opts.reference.exists():
        saved = json.loads(opts.reference.read_text())
        if saved.get("key") == key:
            print(f"- Radiance: {saved['version']}; `{saved['command']}`, {opts.repeats} "
                  f"estimates per point: {saved['wall']:.1f} s wall (read from {opts.reference})")
            return [(m, s) for m, s in saved["stats"]]
        # a reference of other points or settings is minutes of rtrace: never overwritten
        sys.exit(f"compare.py: {opts.reference} holds a run of other input (scene, points, "
                 f"options or repeats); give another --reference file, or delete this one")
    env = find_radiance()
    with tempfile.TemporaryDirectory(prefix="hemi-radiance-") as tmp:
        stats, wall, cmd = run_rtrace(conv.text(), points, opts.repeats, opts.rtrace_args, env,
                                      opts.offset, Path(tmp))
    version = radiance_version(env)
    print(f"- Radiance: {version}; `{cmd}` (scene.oct from oconv), "
          f"{opts.repeats} estimates per point: {wall:.1f} s wall")
    if opts.reference:
        opts.reference.write_text(json.dumps({"key": key, "version": version, "command": cmd,
                                              "wall": wall, "stats": stats}))
    return stats


def run_hemi(hemi: Path, scene: Path, points, hemi_args: str):
    text = "".join(f"{fmt3(v)}\n" for _, v in points)
    cmd = [str(hemi), "irradiance", str(scene)] + shlex.split(hemi_args)
    t0 = time.perf_counter()
    r = subprocess.run(cmd, input=text, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if r.returncode != 0:
        sys.exit(f"hemi failed ({shlex.join(cmd)}):\n{r.stderr}")
    vals = [[float(t) for t in ln.split()] for ln in r.stdout.splitlines() if ln.strip()]
    if len(vals) != len(points):
        sys.exit(f"hemi gave {len(vals)} lines for {len(points)} points:\n{r.stderr}")
    return vals, wall, shlex.join(cmd), r.stderr.strip()


# ----------------------------------------------------------------------------------------------
# Report


def pct(x: float) -> str:
    return f"{100 * x:+.2f} %"


def table(points, rad_stats, hemi_vals, chans: str = "rgb"):
    rows = ["| point | Radiance r | g | b | hemi r | g | b | error r | g | b |",
            "|---|---|---|---|---|---|---|---|---|---|"]
    errs = []
    for (label, _), (mean, se), h in zip(points, rad_stats, hemi_vals):
        e = [(h[c] - mean[c]) / mean[c] if mean[c] != 0 else float("nan") for c in range(3)]
        errs.append(e)
        rcol = [f"{mean[c]:.4f} ± {se[c]:.2g}" for c in range(3)]
        hcol = [f"{h[c]:.4f}" for c in range(3)]
        rows.append(f"| {label} | " + " | ".join(rcol + hcol + [pct(x) for x in e]) + " |")
    flat = [x for e in errs for x in e if not math.isnan(x)]
    rms = math.sqrt(sum(x * x for x in flat) / len(flat))
    worst = max(flat, key=abs)
    per = []
    for c in range(3):
        col = [e[c] for e in errs if not math.isnan(e[c])]
        per.append(math.sqrt(sum(x * x for x in col) / len(col)))
    # Relative standard error of the reference, for reading the errors.
    rel_se = [se[c] / mean[c] for mean, se in rad_stats for c in range(3) if mean[c] > 0]
    summary = (f"RMS relative error over {len(points)} points × 3 channels: {100 * rms:.2f} % "
               f"(r {100 * per[0]:.2f} %, g {100 * per[1]:.2f} %, b {100 * per[2]:.2f} %); "
               f"worst {pct(worst)}; mean {pct(sum(flat) / len(flat))}; Radiance relative s.e. "
               f"{100 * min(rel_se):.2f}–{100 * max(rel_se):.2f} %")
    return "\n".join(rows), summary, rms, worst


def main_options(argv=None):
    """compare.py's options, parsed (chart.py reuses them)."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scene", type=Path, default=ROOT / "scenes" / "cornell.toml")
    ap.add_argument("--points", type=Path,
                    help="query points, `x y z dx dy dz [# label]` per line "
                         "(default tests/radiance/points/<scene stem>.txt)")
    ap.add_argument("--repeats", type=int, default=64,
                    help="rtrace estimates per point, averaged (default 64)")
    ap.add_argument("--hemi-args", action="append",
                    help="extra options of `hemi irradiance`; give it several times to compare "
                         "several settings against one Radiance run (default: none, i.e. "
                         "hemi's defaults)")
    ap.add_argument("--rtrace-args", default=DEFAULT_RTRACE,
                    help=f"rtrace options (default: {DEFAULT_RTRACE})")
    ap.add_argument("--hemi", type=Path, default=ROOT / "target" / "release" / "hemi",
                    help="the hemi binary (default target/release/hemi; built with "
                         "`cargo build --release -p hemi-cli` if missing)")
    ap.add_argument("--skip-hemi", action="store_true", help="Radiance only")
    ap.add_argument("--skip-radiance", action="store_true", help="hemi only (prints its values)")
    ap.add_argument("--write-rad", type=Path, help="also write the converted scene here")
    ap.add_argument("--reference", type=Path,
                    help="Radiance's results as JSON: read from this file when it holds a run "
                         "of the same scene text, points, options and repeats, computed and "
                         "written there when it does not exist (so hemi's settings can be "
                         "iterated against one run); a file of another run is an error, never "
                         "overwritten")
    ap.add_argument("--no-offset", dest="offset", action="store_false",
                    help="do not move points back by rtrace -I's 1e-4 look-ahead")
    ap.add_argument("--no-emitter-reflect", dest="emitter_reflect", action="store_false",
                    help="emitters do not reflect (no reflector sheet in front of `light`)")
    ap.add_argument("--one-sided", action="store_true",
                    help="diffuse surfaces black on the back, as hemi's (BRTDfunc instead of "
                         "two-sided plastic)")
    ap.add_argument("--reflector-offset-rel", type=float, default=1e-4,
                    help="emitter reflector distance in front of the light, × scene diagonal")
    ap.add_argument("--planar-tol", type=float, default=1e-4,
                    help="quads warped by more than this fraction of their size become two "
                         "triangles")
    return ap.parse_args(argv)


def main(argv=None):
    opts = main_options(argv)
    scene = opts.scene.resolve()
    try:
        conv = convert(scene, opts)
    except SceneError as e:
        sys.exit(f"compare.py: {e}")
    if opts.write_rad:
        opts.write_rad.write_text(conv.text())
        if opts.skip_hemi and opts.skip_radiance:
            return
    stem = POINT_SETS.get(scene.stem, scene.stem)
    points_path = opts.points or POINTS_DIR / f"{stem}.txt"
    if not points_path.exists():
        sys.exit(f"no points: give --points FILE (no built-in set {points_path})")
    points = read_points(points_path)

    print(f"## {scene.relative_to(ROOT) if scene.is_relative_to(ROOT) else scene}\n")
    for n in conv.notes:
        print(f"- converter: {n}")
    rad_stats = hemi_vals = None
    if not opts.skip_radiance:
        rad_stats = reference(conv, points, opts)
    runs = []
    if not opts.skip_hemi:
        hemi = opts.hemi
        if not hemi.exists():
            print(f"- {hemi} missing: cargo build --release -p hemi-cli", file=sys.stderr)
            subprocess.run(["cargo", "build", "--release", "-p", "hemi-cli"], cwd=ROOT,
                           check=True)
        for args in opts.hemi_args or [""]:
            hemi_vals, hwall, hcmd, herr = run_hemi(hemi, scene, points, args)
            runs.append((args, hemi_vals, hwall, hcmd, herr))
    print()
    for args, hemi_vals, hwall, hcmd, herr in runs:
        print(f"### hemi {args or '(defaults)'}\n")
        print(f"- `{hcmd}`: {hwall:.2f} s wall (pass 1, solve and queries)")
        for ln in herr.splitlines():
            print(f"  - stderr: {ln}")
        print()
        if rad_stats:
            tab, summary, _, _ = table(points, rad_stats, hemi_vals)
            print(tab)
            print()
            print(summary)
        else:
            print("| point | hemi r | g | b |\n|---|---|---|---|")
            for (label, _), h in zip(points, hemi_vals):
                print(f"| {label} | " + " | ".join(f"{x:.4f}" for x in h) + " |")
        print()
    if rad_stats and not runs:
        print("| point | Radiance r | g | b |\n|---|---|---|---|")
        for (label, _), (mean, se) in zip(points, rad_stats):
            print(f"| {label} | " + " | ".join(f"{mean[c]:.4f} ± {se[c]:.2g}"
                                                for c in range(3)) + " |")


if __name__ == "__main__":
    main()
