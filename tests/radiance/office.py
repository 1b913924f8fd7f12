# Writes office.toml beside this file: a closed room (5 x 3 x 4 m) with a ceiling lamp, a table on
# four 5 cm legs and a cabinet against a wall; a scene none of hemi's defaults were tuned on, for
# the held-out points of points/office.txt (docs/ACCURACY.md, "An office, held out").
from pathlib import Path

def quad(name, mat, v):
    vs = ", ".join(f"[{p[0]:g}, {p[1]:g}, {p[2]:g}]" for p in v)
    return f'[[quad]]\nname = "{name}"\nmaterial = "{mat}"\nvertices = [{vs}]\n\n'

def box(name, mat, lo, hi, skip=()):
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    faces = {
        "xm": [(x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0)],
        "xp": [(x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1)],
        "ym": [(x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)],
        "yp": [(x0, y1, z0), (x0, y1, z1), (x1, y1, z1), (x1, y1, z0)],
        "zm": [(x0, y0, z0), (x0, y1, z0), (x1, y1, z0), (x1, y0, z0)],
        "zp": [(x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)],
    }
    return "".join(quad(f"{name}_{k}", mat, v) for k, v in faces.items() if k not in skip)

W, H, D = 5.0, 3.0, 4.0
out = []
for n, d in [("wall", (0.70, 0.68, 0.64)), ("floor", (0.42, 0.36, 0.30)), ("wood", (0.55, 0.38, 0.22)),
             ("blue", (0.18, 0.28, 0.55))]:
    out.append(f'[[material]]\nname = "{n}"\ndiffuse = [{d[0]}, {d[1]}, {d[2]}]\n\n')
out.append('[[material]]\nname = "lamp"\ndiffuse = [0.8, 0.8, 0.8]\nemission = [18.0, 17.0, 15.0]\n\n')
# the room, faces inward
out.append(quad("floor", "floor", [(0, 0, 0), (0, 0, D), (W, 0, D), (W, 0, 0)]))
out.append(quad("ceiling", "wall", [(0, H, 0), (W, H, 0), (W, H, D), (0, H, D)]))
out.append(quad("back", "wall", [(0, 0, D), (0, H, D), (W, H, D), (W, 0, D)]))
out.append(quad("front", "wall", [(0, 0, 0), (W, 0, 0), (W, H, 0), (0, H, 0)]))
out.append(quad("left", "wall", [(0, 0, 0), (0, H, 0), (0, H, D), (0, 0, D)]))
out.append(quad("right", "wall", [(W, 0, 0), (W, 0, D), (W, H, D), (W, H, 0)]))
out.append(quad("lamp", "lamp", [(2.0, H - 0.01, 1.5), (3.0, H - 0.01, 1.5), (3.0, H - 0.01, 2.5), (2.0, H - 0.01, 2.5)]))
# the table: a top 1.6 x 0.8 at 0.71-0.75 m on four 5 cm legs
out.append(box("top", "wood", (1.0, 0.71, 2.6), (2.6, 0.75, 3.4)))
for i, (x, z) in enumerate([(1.05, 2.65), (2.5, 2.65), (1.05, 3.3), (2.5, 3.3)]):
    out.append(box(f"leg{i}", "wood", (x, 0, z), (x + 0.05, 0.71, z + 0.05), skip=("ym", "yp")))
# a cabinet against the right wall
out.append(box("cab", "blue", (4.4, 0, 0.5), (W, 2.0, 1.5), skip=("ym", "xp")))
(Path(__file__).parent / "office.toml").write_text("".join(out))
