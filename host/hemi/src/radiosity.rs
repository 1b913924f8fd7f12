//! From patch radiosities back to the elements (4.2), and the vertex grids of paper §4.3 that
//! pass 2 and the irradiance queries interpolate.

use crate::pass1::FormFactors;
use crate::scene::Scene;
use crate::shots::ElementRow;
use crate::solve::Solution;

/// Radiosity over one patch as the grid of §4.3: K×K sample points sit at the centres of the
/// cells of a (K+1)×(K+1) vertex grid; vertex values are the mean of the (up to four) samples
/// around them, extended linearly to the patch boundary; inside a cell B is bilinear between its
/// four vertices. Shading is then continuous across the patch (no faceting) and a uniform
/// patch stays exactly uniform.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Grid {
    k: usize,
    vertices: Vec<[f64; 3]>,
}

impl Grid {
    /// Builds the vertex grid from K×K element values (v-major: index b·K + a).
    pub fn from_samples(k: usize, samples: &[[f64; 3]]) -> Grid {
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
        let extend = |inner: [f64; 3], next: [f64; 3]| -> [f64; 3] {
            if k == 1 {
                inner
            } else {
                [0, 1, 2].map(|c| 2.0 * inner[c] - next[c])
            }
        };
        for b in 1..=k {
            pad[b * w] = extend(pad[b * w + 1], pad[b * w + 2.min(k)]);
            pad[b * w + k + 1] = extend(pad[b * w + k], pad[b * w + (k - 1).max(1)]);
        }
        for a in 0..w {
            pad[a] = extend(pad[w + a], pad[2.min(k) * w + a]);
            pad[(k + 1) * w + a] = extend(pad[k * w + a], pad[(k - 1).max(1) * w + a]);
        }
        let vertices = (0..=k)
            .flat_map(|j| (0..=k).map(move |i| (i, j)))
            .map(|(i, j)| {
                // vertex (i, j) is the corner shared by padded cells (i|i+1, j|j+1)
                let mut v = [0.0; 3];
                for (a, b) in [(i, j), (i + 1, j), (i, j + 1), (i + 1, j + 1)] {
                    for c in 0..3 {
                        v[c] += 0.25 * pad[b * w + a][c];
                    }
                }
                // extrapolation must not make radiosity negative
                v.map(|x| x.max(0.0))
            })
            .collect();
        Grid { k, vertices }
    }

    /// K: the grid has K×K cells, one per sample point.
    pub fn k(&self) -> usize {
        self.k
    }

    /// B at (u, v).
    pub fn at(&self, u: f32, v: f32) -> [f64; 3] {
        let k = self.k;
        let cell = |t: f32| {
            let x = (t as f64).clamp(0.0, 1.0) * k as f64;
            let i = (x.floor() as usize).min(k - 1);
            (i, x - i as f64)
        };
        let (a, fa) = cell(u);
        let (b, fb) = cell(v);
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

/// The value of one element (4.2): `B_iq = E_i + ρ_i Σ_j F_iq,j B_j` per channel, from the
/// patch radiosities B_j of a solve. (The paper's (4.2) writes the gathered sum alone; the
/// element's own emission and reflectance make it a radiosity like the patches'.) A side of a
/// translucent sheet adds what comes through it, `τ_i Σ_j F_tq,j B_j` over `twin`, its twin's
/// element at the same point (`scene::translucent`).
pub fn element_value(
    scene: &Scene,
    e: &ElementRow,
    twin: Option<&ElementRow>,
    radiosity: &[[f64; 3]],
) -> [f64; 3] {
    let gathered = |row: &[(u32, [f32; 3])], c: usize| -> f64 {
        row.iter()
            .map(|&(j, f)| f[c] as f64 * radiosity[j as usize][c])
            .sum()
    };
    let m = scene.material_of(e.patch);
    let mut b = m.emission;
    for (c, bc) in b.iter_mut().enumerate() {
        *bc += m.diffuse[c] * gathered(&e.row, c);
        if let Some(t) = twin {
            *bc += m.translucency[c] * gathered(&t.row, c);
        }
    }
    b
}

/// The grid of scene patch `side`, or an error naming what a backend got wrong.
pub fn grid_of(grids: &[Grid], side: usize) -> anyhow::Result<&Grid> {
    grids
        .get(side)
        .ok_or_else(|| anyhow::anyhow!("a backend reported a hit on unknown patch {side}"))
}

/// Element radiosities (4.2) `B_iq = E_i + ρ_i Σ_j F_iq,j B_j`, gathered into one grid per patch.
/// A side of a translucent sheet adds what comes through it, `τ_i Σ_j F_tq,j B_j` over its
/// twin's element at the same point (`scene::translucent`).
pub fn grids(scene: &Scene, ff: &FormFactors, sol: &Solution) -> Vec<Grid> {
    let mut samples: Vec<Vec<[f64; 3]>> = vec![Vec::new(); scene.patches.len()];
    // where each patch's elements start in ff.elements (they are grouped by patch)
    let mut first = vec![usize::MAX; scene.patches.len()];
    for (k, e) in ff.elements.iter().enumerate().rev() {
        first[e.patch] = k;
    }
    for (k, e) in ff.elements.iter().enumerate() {
        let twin = scene.twin(e.patch).and_then(|t| {
            let q = k - first[e.patch];
            ff.elements
                .get(first[t].wrapping_add(q))
                .filter(|w| w.patch == t)
        });
        samples[e.patch].push(element_value(scene, e, twin, &sol.radiosity));
    }
    // K per patch: K×K for polygons, 4×4 for Bezier patches, or the last level of adaptive
    // sampling (K·2^depth, per patch); a pure specular patch has no samples and no diffuse
    // radiosity but its emission (a constant grid)
    samples
        .iter()
        .enumerate()
        .map(|(i, s)| {
            if s.is_empty() {
                Grid::from_samples(1, &[scene.material_of(i).emission])
            } else {
                Grid::from_samples((s.len() as f64).sqrt().round() as usize, s)
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

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
