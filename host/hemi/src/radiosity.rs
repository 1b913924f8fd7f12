//! From patch radiosities back to the elements (4.2), gathered into the vertex grids of paper
//! §4.3 ([`Grid`]) that pass 2 and the irradiance queries interpolate.

pub use crate::grid::{grid_of, Grid};
use crate::pass1::FormFactors;
use crate::scene::Scene;
use crate::shots::ElementRow;
use crate::solve::Solution;

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
