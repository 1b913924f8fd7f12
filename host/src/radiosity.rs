//! From patch radiosities back to the elements (4.2) and the per-patch grids that pass 2 and the
//! irradiance queries interpolate.

use crate::pass1::FormFactors;
use crate::scene::Scene;
use crate::solve::Solution;

/// Radiosity over one patch: a K×K grid of element values at the element centres, interpolated
/// bilinearly in (u,v) and held constant beyond the outermost centres, so the shading is
/// continuous across the patch.
#[derive(Clone, Debug)]
pub struct Grid {
    k: usize,
    values: Vec<[f64; 3]>,
}

impl Grid {
    /// B at (u, v).
    pub fn at(&self, u: f32, v: f32) -> [f64; 3] {
        let k = self.k;
        if k == 1 {
            return self.values[0];
        }
        let coord = |t: f32| {
            let x = (t as f64 * k as f64 - 0.5).clamp(0.0, (k - 1) as f64);
            let i = (x.floor() as usize).min(k - 2);
            (i, x - i as f64)
        };
        let (a, fa) = coord(u);
        let (b, fb) = coord(v);
        let at = |a: usize, b: usize| self.values[b * k + a];
        let mut out = [0.0; 3];
        for (c, o) in out.iter_mut().enumerate() {
            let lo = at(a, b)[c] * (1.0 - fa) + at(a + 1, b)[c] * fa;
            let hi = at(a, b + 1)[c] * (1.0 - fa) + at(a + 1, b + 1)[c] * fa;
            *o = lo * (1.0 - fb) + hi * fb;
        }
        out
    }
}

/// Element radiosities (4.2) `B_iq = E_i + ρ_i Σ_j F_iq,j B_j`, gathered into one grid per patch.
pub fn grids(scene: &Scene, ff: &FormFactors, sol: &Solution) -> Vec<Grid> {
    let k = ff.samples as usize;
    let mut grids: Vec<Grid> = (0..scene.patches.len())
        .map(|_| Grid {
            k,
            values: Vec::with_capacity(k * k),
        })
        .collect();
    for e in &ff.elements {
        let m = scene.material_of(e.patch);
        let mut b = m.emission;
        for (c, bc) in b.iter_mut().enumerate() {
            let gathered: f64 = e.row.iter().map(|&(j, f)| f as f64 * sol.radiosity[j as usize][c]).sum();
            *bc += m.diffuse[c] * gathered;
        }
        grids[e.patch].values.push(b);
    }
    grids
}
