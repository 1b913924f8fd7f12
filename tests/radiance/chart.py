#!/usr/bin/env python3
"""Error against time for hemi and Radiance on one scene: an SVG chart and a markdown table.

Each tool runs at several settings over the same query points; the error of a run is the RMS
over points and channels of (value − reference) / reference, with the reference a long
Radiance run (compare.py's defaults, `--repeats` estimates averaged, cached with
`--reference`). Radiance's runs vary its ambient divisions and the estimates averaged; hemi's
vary its pass-1 settings, the field and the near field. Times are wall seconds of the whole
command on this machine (hemi: pass 1, solve, field and queries; Radiance: rtrace on the
octree). Not in CI.

    python3 tests/radiance/chart.py --scene scenes/cornell.toml --reference /tmp/cornell.json \\
        --svg docs/figures/radiance-error-vs-time.svg
"""

import argparse
import math
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import compare  # noqa: E402

HEMI_RUNS = [
    ("paper: K = 16, patch field (4.2)", "--gather 0 --near 0 --direct hemisphere"),
    ("K = 16, element field", "--near 0"),
    ("defaults (K = 16, element field, near field)", ""),
    ("R = 32, adaptive, field, near field", "--adaptive --circles 32"),
    ("R = 64, adaptive, field, near field", "--adaptive"),
    ("adaptive, near field 6 cells", "--adaptive --near-cells 6"),
]

RADIANCE_RUNS = [(ad, n) for ad in (64, 256, 1024) for n in (1, 4, 16)]


def rms(values, reference):
    errs = [(v[c] - m[c]) / m[c] for v, (m, _) in zip(values, reference) for c in range(3)
            if m[c] > 0]
    return math.sqrt(sum(e * e for e in errs) / len(errs))


def svg(series, path: Path, title: str):
    """A log-log scatter of (seconds, RMS %) per series, each point labelled."""
    w, h, left, bottom, top, right = 760, 460, 70, 50, 40, 260
    pts = [p for _, ps, _ in series for p in ps]
    xs = [math.log10(s) for s, _, _ in pts]
    ys = [math.log10(max(e, 1e-4)) for _, e, _ in pts]
    x0, x1 = math.floor(min(xs)), math.ceil(max(xs))
    y0, y1 = math.floor(min(ys)), math.ceil(max(ys))
    sx = lambda x: left + (math.log10(x) - x0) / (x1 - x0) * (w - left - right)  # noqa: E731
    sy = lambda y: h - bottom - (math.log10(max(y, 1e-4)) - y0) / (y1 - y0) * (h - top - bottom)  # noqa: E731,E501
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" '
           f'font-family="sans-serif" font-size="11">',
           f'<rect width="{w}" height="{h}" fill="white"/>',
           f'<text x="{left}" y="20" font-size="13">{title}</text>']
    for d in range(x0, x1 + 1):
        x = sx(10 ** d)
        out.append(f'<line x1="{x:.1f}" y1="{top}" x2="{x:.1f}" y2="{h - bottom}" stroke="#ddd"/>')
        out.append(f'<text x="{x:.1f}" y="{h - bottom + 15}" text-anchor="middle">{10 ** d:g} s</text>')
    for d in range(y0, y1 + 1):
        y = sy(10 ** d)
        out.append(f'<line x1="{left}" y1="{y:.1f}" x2="{w - right}" y2="{y:.1f}" stroke="#ddd"/>')
        out.append(f'<text x="{left - 6}" y="{y + 4:.1f}" text-anchor="end">{100 * 10 ** d:g} %</text>')
    out.append(f'<text x="{(left + w - right) / 2}" y="{h - 12}" text-anchor="middle">wall time '
               f'(s, log)</text>')
    out.append(f'<text x="16" y="{(top + h - bottom) / 2}" transform="rotate(-90 16 '
               f'{(top + h - bottom) / 2})" text-anchor="middle">RMS error against the reference '
               f'(log)</text>')
    for n, (name, ps, colour) in enumerate(series):
        ly = top + 16 * n
        out.append(f'<circle cx="{w - right + 16}" cy="{ly}" r="4" fill="{colour}"/>')
        out.append(f'<text x="{w - right + 26}" y="{ly + 4}">{name}</text>')
        if name.startswith("Radiance"):
            by_ad = {}
            for s, e, label in ps:
                by_ad.setdefault(label.split(",")[0], []).append((s, e))
            for line in by_ad.values():
                d = " ".join(f"{sx(s):.1f},{sy(e):.1f}" for s, e in sorted(line))
                out.append(f'<polyline points="{d}" fill="none" stroke="{colour}" '
                           f'stroke-opacity="0.5"/>')
        for s, e, label in ps:
            out.append(f'<circle cx="{sx(s):.1f}" cy="{sy(e):.1f}" r="4" fill="{colour}"><title>'
                       f'{label}: {s:.2f} s, {100 * e:.2f} %</title></circle>')
    out.append("</svg>")
    path.write_text("\n".join(out) + "\n")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scene", type=Path, default=compare.ROOT / "scenes" / "cornell.toml")
    ap.add_argument("--points", type=Path)
    ap.add_argument("--repeats", type=int, default=256, help="estimates of the reference")
    ap.add_argument("--reference", type=Path, help="cache of the reference run (compare.py)")
    ap.add_argument("--hemi", type=Path, default=compare.ROOT / "target" / "release" / "hemi")
    ap.add_argument("--svg", type=Path, help="write the chart here")
    opts = ap.parse_args(argv)
    copts = compare.main_options(["--scene", str(opts.scene), "--repeats", str(opts.repeats)]
                                 + (["--points", str(opts.points)] if opts.points else [])
                                 + (["--reference", str(opts.reference)] if opts.reference
                                    else []))
    conv = compare.convert(opts.scene.resolve(), copts)
    stem = compare.POINT_SETS.get(opts.scene.stem, opts.scene.stem)
    points = compare.read_points(opts.points or compare.POINTS_DIR / f"{stem}.txt")
    reference = compare.reference(conv, points, copts)
    rows, hemi_pts, rad_pts = [], [], []
    for label, args in HEMI_RUNS:
        vals, wall, _, _ = compare.run_hemi(opts.hemi, opts.scene.resolve(), points, args)
        e = rms(vals, reference)
        hemi_pts.append((wall, e, label))
        rows.append(f"| hemi | {label} (`{args or 'no options'}`) | {wall:.2f} | {100 * e:.2f} % |")
    env = compare.find_radiance()
    for ad, n in RADIANCE_RUNS:
        args = compare.DEFAULT_RTRACE.replace("-ad 1024", f"-ad {ad}")
        with tempfile.TemporaryDirectory(prefix="hemi-radiance-") as tmp:
            stats, wall, _ = compare.run_rtrace(conv.text(), points, n, args, env, copts.offset,
                                                Path(tmp))
        e = rms([m for m, _ in stats], reference)
        label = f"-ad {ad}, {n} estimate{'s' if n > 1 else ''}"
        rad_pts.append((wall, e, label))
        rows.append(f"| Radiance | `{label}` | {wall:.2f} | {100 * e:.2f} % |")
    print("| tool | settings | wall s | RMS error |\n|---|---|---|---|")
    print("\n".join(rows))
    if opts.svg:
        svg([("hemi", hemi_pts, "#c0392b"), ("Radiance 6.0a (lines: one -ad)", rad_pts,
                                             "#2c3e50")],
            opts.svg, f"{opts.scene.name}: error against time, {len(points)} points")


if __name__ == "__main__":
    main()
