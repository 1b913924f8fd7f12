//! The radiosity over one patch as a function of (u, v): the vertex grid of paper §4.3, built
//! from the patch's K×K element values and interpolated bilinearly.

use crate::contact::{crosses, orient, Cut};

/// Radiosity over one patch as the grid of §4.3: K×K sample points sit at the centres of the
/// cells of a (K+1)×(K+1) vertex grid; vertex values are the mean of the (up to four) samples
/// around them, extended to the patch boundary (the samples padded by a cell whose value
/// continues the parabola through the three nearest, or the line through two on a coarse grid);
/// inside a cell B is bilinear between its four vertices. Shading is then continuous across the
/// patch (no faceting) and a uniform patch stays exactly uniform.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Grid {
    k: usize,
    vertices: Vec<[f64; 3]>,
    /// Lines across the patch not to blend across ([`crate::contact`]).
    #[serde(default)]
    cuts: Cuts,
}

/// The lines across a patch that its grid does not blend across, and the cells they may
/// touch (only there is a blend checked against them).
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct Cuts {
    lines: Vec<Cut>,
    /// Per cell (v-major), whether a line's box touches it; empty when there are no lines.
    cells: Vec<bool>,
}

impl Cuts {
    /// `lines` over a k×k grid.
    fn new(k: usize, lines: &[Cut]) -> Cuts {
        if lines.is_empty() {
            return Cuts::default();
        }
        let h = 1.0 / k as f64;
        let cells = (0..k * k)
            .map(|q| {
                let (a, b) = ((q % k) as f64 * h, (q / k) as f64 * h);
                lines.iter().any(|[p, r]| {
                    p[0].min(r[0]) <= a + h
                        && p[0].max(r[0]) >= a
                        && p[1].min(r[1]) <= b + h
                        && p[1].max(r[1]) >= b
                })
            })
            .collect();
        Cuts {
            lines: lines.to_vec(),
            cells,
        }
    }

    /// Whether the path from `a` to `b` (in (u, v)) crosses a line.
    fn blocks(&self, a: [f64; 2], b: [f64; 2]) -> bool {
        self.lines.iter().any(|c| crosses(a, b, c))
    }

    /// Whether a line may touch cell (a, b) of a k-cell-a-side grid.
    fn touches(&self, k: usize, (a, b): (usize, usize)) -> bool {
        self.cells.get(b * k + a).copied().unwrap_or(false)
    }

    /// Which side of each line (u, v) lies on, as bits (bit 0 set, line i's side in bit
    /// 1 + i mod 63), or 0 where no line may touch its cell: points of one cell in the same
    /// region are on the same side of every line, so light read at one of them is theirs too,
    /// where a point across a line (a floor's other side of a screen) sees other light.
    pub fn region(&self, k: usize, u: f32, v: f32) -> u64 {
        let cell = (locate(k, u).0, locate(k, v).0);
        if !self.touches(k, cell) {
            return 0;
        }
        let at = [f64::from(u).clamp(0.0, 1.0), f64::from(v).clamp(0.0, 1.0)];
        self.lines.iter().enumerate().fold(1, |bits, (i, [c, d])| {
            bits | (u64::from(orient(*c, *d, at) > 0.0) << (i % 63 + 1))
        })
    }

    /// The four vertices and weights that blend (u, v) on a k×k grid: [`corners`], but in a
    /// cell a line may touch a vertex across a line from (u, v) gets no weight, and the others
    /// share its weight in proportion (all four keep theirs if every one is across).
    pub fn blend(&self, k: usize, u: f32, v: f32) -> [((usize, usize), f64); 4] {
        self.blend_finer(k, k, u, v)
    }

    /// [`Cuts::blend`] on a lattice of n×n squares over the k×k grid these cuts belong to (pass
    /// 2 relights shadows' edges on one finer than the grid): the lattice's corners across a
    /// line from (u, v) get no weight.
    pub fn blend_finer(&self, k: usize, n: usize, u: f32, v: f32) -> [((usize, usize), f64); 4] {
        let mut c = corners(n, u, v);
        if !self.touches(k, (locate(k, u).0, locate(k, v).0)) {
            return c;
        }
        let at = [f64::from(u).clamp(0.0, 1.0), f64::from(v).clamp(0.0, 1.0)];
        let seen =
            c.map(|((i, j), _)| !self.blocks(at, [i as f64 / n as f64, j as f64 / n as f64]));
        let kept: f64 = c
            .iter()
            .zip(seen)
            .filter(|(_, s)| *s)
            .map(|(c, _)| c.1)
            .sum();
        if kept > 0.0 && seen.contains(&false) {
            for (c, s) in c.iter_mut().zip(seen) {
                c.1 = if s { c.1 / kept } else { 0.0 };
            }
        }
        c
    }
}

impl Grid {
    /// Builds the vertex grid from K×K element values (v-major: index b·K + a).
    pub fn from_samples(k: usize, samples: &[[f64; 3]]) -> Grid {
        Grid::with_cuts(k, samples, &[])
    }

    /// [`Grid::from_samples`] on a patch crossed by `lines` ([`crate::contact`]): a vertex is
    /// the mean of the samples around it on its own side of them, and a point blends the
    /// vertices on its side ([`Cuts::blend`]).
    pub fn with_cuts(k: usize, samples: &[[f64; 3]], lines: &[Cut]) -> Grid {
        assert_eq!(samples.len(), k * k, "K×K samples");
        // Pad the samples by one cell on every side with linear extrapolation (one cell is
        // enough: a vertex only touches its four neighbouring cells).
        let w = k + 2;
        let mut pad = vec![[0.0f64; 3]; w * w];
        for b in 0..k {
            for a in 0..k {
                pad[(b + 1) * w + a + 1] = samples[b * k + a];
            }
        }
        // The padding cell takes the value the parabola through the three samples nearest the
        // boundary has there: the light towards a patch's edge curves (a corner's darkening, a
        // lamp's fall), and a line through the two inner samples overshot it by 2-3 % in the
        // Cornell box's ceiling corners at K = 16 (docs/ACCURACY.md, "Held-out points"). On a
        // coarse grid the three samples span much of the patch and the parabola follows its
        // whole curve, not its edge (at K = 6 it darkened the box's wall tops by up to 46/255
        // in tests/golden), so below PARABOLA_FROM cells the line stays.
        let extend = |f1: [f64; 3], f2: [f64; 3], f3: [f64; 3]| -> [f64; 3] {
            match k {
                1 => f1,
                k if k < PARABOLA_FROM => [0, 1, 2].map(|c| 2.0 * f1[c] - f2[c]),
                _ => [0, 1, 2].map(|c| 3.0 * f1[c] - 3.0 * f2[c] + f3[c]),
            }
        };
        let k3 = 3.min(k);
        for b in 1..=k {
            let r = b * w;
            pad[r] = extend(pad[r + 1], pad[r + 2.min(k)], pad[r + k3]);
            pad[r + k + 1] = extend(pad[r + k], pad[r + (k - 1).max(1)], pad[r + k + 1 - k3]);
        }
        for a in 0..w {
            pad[a] = extend(pad[w + a], pad[2.min(k) * w + a], pad[k3 * w + a]);
            pad[(k + 1) * w + a] = extend(
                pad[k * w + a],
                pad[(k - 1).max(1) * w + a],
                pad[(k + 1 - k3) * w + a],
            );
        }
        let cuts = Cuts::new(k, lines);
        let vertices = (0..=k)
            .flat_map(|j| (0..=k).map(move |i| (i, j)))
            .map(|(i, j)| {
                // vertex (i, j) is the corner shared by padded cells (i|i+1, j|j+1)
                // on a cut patch, only the samples on the vertex's side of the lines
                let around = [(i, j), (i + 1, j), (i, j + 1), (i + 1, j + 1)];
                let vertex = [i as f64 / k as f64, j as f64 / k as f64];
                let centre =
                    |a: usize, b: usize| [(a as f64 - 0.5) / k as f64, (b as f64 - 0.5) / k as f64];
                let side = around.map(|(a, b)| !cuts.blocks(centre(a, b), vertex));
                let count = side.iter().filter(|s| **s).count();
                let mut v = [0.0; 3];
                if count == 4 || count == 0 {
                    for (a, b) in around {
                        for c in 0..3 {
                            v[c] += 0.25 * pad[b * w + a][c];
                        }
                    }
                } else {
                    for ((a, b), _) in around.into_iter().zip(side).filter(|(_, s)| *s) {
                        for c in 0..3 {
                            v[c] += pad[b * w + a][c] / count as f64;
                        }
                    }
                }
                // extrapolation must not make radiosity negative
                v.map(|x| x.max(0.0))
            })
            .collect();
        Grid { k, vertices, cuts }
    }

    /// The lines this grid does not blend across.
    pub fn cuts(&self) -> &Cuts {
        &self.cuts
    }

    /// K: the grid has K×K cells, one per sample point.
    pub fn k(&self) -> usize {
        self.k
    }

    /// The value at vertex (i, j) of the (K+1)×(K+1) vertex grid (i along u).
    pub fn vertex(&self, i: usize, j: usize) -> [f64; 3] {
        self.vertices[j * (self.k + 1) + i]
    }

    /// Sets vertex (i, j) (seams are welded this way, `crate::seams`).
    pub fn set_vertex(&mut self, i: usize, j: usize, value: [f64; 3]) {
        self.vertices[j * (self.k + 1) + i] = value;
    }

    /// B at (u, v).
    pub fn at(&self, u: f32, v: f32) -> [f64; 3] {
        let k = self.k;
        let (a, fa) = locate(k, u);
        let (b, fb) = locate(k, v);
        if self.cuts.touches(k, (a, b)) {
            let mut out = [0.0; 3];
            for ((i, j), w) in self.cuts.blend(k, u, v) {
                let b = self.vertex(i, j);
                for c in 0..3 {
                    out[c] += w * b[c];
                }
            }
            return out;
        }
        let at = |i: usize, j: usize| self.vertices[j * (k + 1) + i];
        let mut out = [0.0; 3];
        for (c, o) in out.iter_mut().enumerate() {
            let lo = at(a, b)[c] * (1.0 - fa) + at(a + 1, b)[c] * fa;
            let hi = at(a, b + 1)[c] * (1.0 - fa) + at(a + 1, b + 1)[c] * fa;
            *o = lo * (1.0 - fb) + hi * fb;
        }
        out
    }
}

/// The fewest cells a side for which the samples are extended to the boundary by a parabola
/// (a line below it; see [`Grid::from_samples`]).
pub const PARABOLA_FROM: usize = 8;

/// The cell of a k-cell grid side that parameter `t` falls in, and where in it (0..1).
fn locate(k: usize, t: f32) -> (usize, f64) {
    let x = (t as f64).clamp(0.0, 1.0) * k as f64;
    // x is not negative (a NaN `as` takes to 0, as `floor` did), so truncation is its floor:
    // the same cell without the libm call baseline x86-64 makes of `floor`, on the path of
    // every ray the field's transport records
    let i = (x as usize).min(k - 1);
    (i, x - i as f64)
}

/// The four vertices (i, j) of a k×k grid that [`Grid::at`] blends at (u, v), with their
/// bilinear weights (which sum to 1): `Grid::at(u, v) = Σ w · vertex(i, j)`.
pub fn corners(k: usize, u: f32, v: f32) -> [((usize, usize), f64); 4] {
    let (a, fa) = locate(k, u);
    let (b, fb) = locate(k, v);
    [
        ((a, b), (1.0 - fa) * (1.0 - fb)),
        ((a + 1, b), fa * (1.0 - fb)),
        ((a, b + 1), (1.0 - fa) * fb),
        ((a + 1, b + 1), fa * fb),
    ]
}

/// How far `grid` misses its own k×k `samples` (v-major, as [`Grid::from_samples`] takes
/// them), per cell and channel, the largest over the cell and its eight neighbours: the grid
/// reproduces a linear field exactly and a curved one to O(h²), so a large miss marks light it
/// cannot carry — a shadow's edge, a kink — in or next to the cell, where a smooth gradient,
/// however steep, shows none.
pub fn misses(grid: &Grid, samples: &[[f64; 3]]) -> Vec<[f32; 3]> {
    let k = grid.k();
    if samples.len() != k * k {
        return vec![[0.0; 3]; k * k];
    }
    let centre = |i: usize| (i as f32 + 0.5) / k as f32;
    let own: Vec<[f64; 3]> = (0..k * k)
        .map(|q| {
            let at = grid.at(centre(q % k), centre(q / k));
            [0, 1, 2].map(|c| (samples[q][c] - at[c]).abs())
        })
        .collect();
    (0..k * k)
        .map(|q| {
            let (a, b) = (q % k, q / k);
            let mut m = [0.0f32; 3];
            for j in b.saturating_sub(1)..(b + 2).min(k) {
                for i in a.saturating_sub(1)..(a + 2).min(k) {
                    for c in 0..3 {
                        m[c] = m[c].max(own[j * k + i][c] as f32);
                    }
                }
            }
            m
        })
        .collect()
}

/// The grid of scene patch `side`, or an error naming what a backend got wrong.
pub fn grid_of(grids: &[Grid], side: usize) -> anyhow::Result<&Grid> {
    grids
        .get(side)
        .ok_or_else(|| anyhow::anyhow!("a backend reported a hit on unknown patch {side}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A wall standing across the patch at u = 0.52 (between samples): dark before it, bright
    /// behind. Blended, the dark side reads light from behind the wall up to a cell away;
    /// cut, each side reads only its own samples, and the blend's weights (what the transport
    /// records) give the same values as `at`.
    #[test]
    fn a_cut_keeps_each_side_to_its_own_light() {
        let k = 10;
        let samples: Vec<[f64; 3]> = (0..k * k)
            .map(|q| if (q % k) < 5 { [0.1; 3] } else { [2.0; 3] })
            .collect();
        let cut = [[0.52, 0.2], [0.52, 0.8]];
        let blended = Grid::from_samples(k, &samples);
        let cut_grid = Grid::with_cuts(k, &samples, &[cut]);
        let dark_side = (0.51, 0.5);
        assert!(
            blended.at(dark_side.0, dark_side.1)[0] > 0.5,
            "the leak this prevents"
        );
        let dark = cut_grid.at(dark_side.0, dark_side.1)[0];
        assert!((dark - 0.1).abs() < 1e-12, "{dark}");
        let bright = cut_grid.at(0.53, 0.5)[0];
        assert!((bright - 2.0).abs() < 1e-12, "{bright}");
        // beyond the cut's ends the grid blends as before
        assert_eq!(cut_grid.at(0.51, 0.05), blended.at(0.51, 0.05));
        for (u, v) in [(0.51, 0.5), (0.53, 0.45), (0.31, 0.77), (0.52, 0.9)] {
            let by_weights: f64 = cut_grid
                .cuts()
                .blend(k, u, v)
                .iter()
                .map(|((i, j), w)| w * cut_grid.vertex(*i, *j)[0])
                .sum();
            assert!((by_weights - cut_grid.at(u, v)[0]).abs() < 1e-12);
        }
    }

    /// Points of one cell on either side of a line are in different regions, points on one
    /// side in the same, and a cell no line touches has none.
    #[test]
    fn a_cut_splits_its_cells_into_regions() {
        let k = 10;
        let grid = Grid::with_cuts(k, &vec![[1.0; 3]; k * k], &[[[0.52, 0.2], [0.52, 0.8]]]);
        let cuts = grid.cuts();
        let (before, behind) = (cuts.region(k, 0.51, 0.5), cuts.region(k, 0.53, 0.5));
        assert_ne!(before, 0);
        assert_ne!(before, behind);
        assert_eq!(cuts.region(k, 0.505, 0.45), before);
        assert_eq!(cuts.region(k, 0.59, 0.55), behind);
        assert_eq!(cuts.region(k, 0.25, 0.5), 0);
        assert_eq!(
            Grid::from_samples(k, &vec![[1.0; 3]; k * k])
                .cuts()
                .region(k, 0.51, 0.5),
            0
        );
    }

    #[test]
    fn uniform_samples_give_a_uniform_grid() {
        let g = Grid::from_samples(4, &vec![[0.3, 0.2, 0.1]; 16]);
        for i in 0..=20 {
            for j in 0..=20 {
                let b = g.at(i as f32 / 20.0, j as f32 / 20.0);
                assert!((b[0] - 0.3).abs() < 1e-12 && (b[2] - 0.1).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn the_corners_blend_to_what_at_interpolates() {
        let samples: Vec<[f64; 3]> = (0..9).map(|i| [i as f64, (i * i) as f64, 1.0]).collect();
        let g = Grid::from_samples(3, &samples);
        for (u, v) in [(0.0, 0.0), (0.41, 0.77), (1.0, 0.5), (0.999, 1.0)] {
            let mut sum = [0.0; 3];
            for ((i, j), w) in corners(3, u, v) {
                for (s, x) in sum.iter_mut().zip(g.vertex(i, j)) {
                    *s += w * x;
                }
            }
            let at = g.at(u, v);
            assert!(
                (0..3).all(|c| (sum[c] - at[c]).abs() < 1e-12),
                "{sum:?} vs {at:?}"
            );
        }
    }

    #[test]
    fn a_grid_misses_a_step_and_not_a_slope() {
        let k = 8;
        let field = |step: bool| -> Vec<[f64; 3]> {
            (0..k * k)
                .map(|q| {
                    let a = q % k;
                    let x = if step {
                        f64::from(u8::from(a >= 4))
                    } else {
                        1.0 + a as f64
                    };
                    [x; 3]
                })
                .collect()
        };
        let slope = field(false);
        let m = misses(&Grid::from_samples(k, &slope), &slope);
        assert!(m.iter().flatten().all(|&x| x < 1e-6), "{m:?}");
        let step = field(true);
        let m = misses(&Grid::from_samples(k, &step), &step);
        // next to the step (cells 2..=5 along u) the grid misses by a quarter, far from it not
        assert!(
            m[3][0] > 0.2 && m[4][0] > 0.2 && m[0][0] < 1e-6 && m[7][0] < 1e-6,
            "{m:?}"
        );
    }

    #[test]
    fn linear_gradients_are_reproduced_exactly() {
        let k = 5;
        let f = |u: f64, v: f64| 1.0 + 2.0 * u + 0.5 * v;
        let samples: Vec<[f64; 3]> = (0..k * k)
            .map(|i| {
                let (a, b) = (i % k, i / k);
                let (u, v) = ((a as f64 + 0.5) / k as f64, (b as f64 + 0.5) / k as f64);
                [f(u, v); 3]
            })
            .collect();
        let g = Grid::from_samples(k, &samples);
        for (u, v) in [
            (0.0, 0.0),
            (1.0, 1.0),
            (0.37, 0.81),
            (0.5, 0.02),
            (0.99, 0.5),
        ] {
            let b = g.at(u as f32, v as f32)[0];
            assert!((b - f(u, v)).abs() < 1e-6, "({u},{v}): {b} vs {}", f(u, v));
        }
    }
}
