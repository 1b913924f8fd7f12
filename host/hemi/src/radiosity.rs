//! From patch radiosities back to the elements (4.2), gathered into the vertex grids of paper
//! §4.3 ([`Grid`]) that pass 2 and the irradiance queries interpolate.

use crate::contact::Cut;
pub use crate::grid::{grid_of, Grid};
use crate::pass1::FormFactors;
use crate::scene::{Material, Scene};
use crate::shots::ElementRow;
use crate::solve::Solution;
use std::sync::OnceLock;

/// The value of one element (4.2) from what it gathered, `B_iq = E_i + ρ_i H_iq` per channel,
/// plus `τ_i H_tq` on a side of a translucent sheet (`through`, what its twin's element at the
/// same point gathered): the one place the element's material meets its light, whether H comes
/// from the patch solution ([`element_value`]) or from the field's sweeps (`crate::field`).
pub fn combine(m: &Material, gathered: [f64; 3], through: Option<[f64; 3]>) -> [f64; 3] {
    let mut b = m.emission;
    for (c, bc) in b.iter_mut().enumerate() {
        *bc += m.diffuse[c] * gathered[c];
        if let Some(t) = through {
            *bc += m.translucency[c] * t[c];
        }
    }
    b
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
    let gathered = |row: &[(u32, [f32; 3])]| patch_gather(row, radiosity, &[]);
    let m = scene.material_of(e.patch);
    combine(m, gathered(&e.row), twin.map(|t| gathered(&t.row)))
}

/// What an element row gathers from the patch radiosities, `Σ_j F_iq,j B_j` per channel, the
/// patches j whose `skip` entry is true left out (the lamps whose light
/// [`crate::direct`] computes exactly).
pub fn patch_gather(row: &[(u32, [f32; 3])], radiosity: &[[f64; 3]], skip: &[bool]) -> [f64; 3] {
    let mut h = [0.0f64; 3];
    for &(j, f) in row {
        if !skip.get(j as usize).copied().unwrap_or(false) {
            for c in 0..3 {
                h[c] += f[c] as f64 * radiosity[j as usize][c];
            }
        }
    }
    h
}

/// The grid of patch `i` from its element values (k×k, v-major; K = √count: K×K on a polygon,
/// 4×4 on a Bezier patch, or the last level of adaptive sampling); a pure specular patch has
/// no elements and no diffuse radiosity but its emission (a constant grid). The grid does not
/// blend across `cuts`, the lines where other surfaces stand on the patch
/// ([`crate::contact::cuts`]).
pub fn patch_grid(scene: &Scene, i: usize, values: &[[f64; 3]], cuts: &[Cut]) -> Grid {
    if values.is_empty() {
        Grid::from_samples(1, &[scene.material_of(i).emission])
    } else {
        Grid::with_cuts((values.len() as f64).sqrt().round() as usize, values, cuts)
    }
}

/// Where each patch's elements lie in an element list grouped by patch (pass 1's, adaptive
/// sampling's), and which element is the twin of which on a translucent sheet.
#[derive(Clone, Debug)]
pub struct ElementIndex {
    /// First element of each patch (`usize::MAX` if it has none).
    first: Vec<usize>,
    /// Elements per patch.
    count: Vec<usize>,
    /// The lines across each patch its grid does not blend across ([`crate::contact`]),
    /// found when the first grids are made (an index used only for its ranges never looks).
    cuts: OnceLock<Vec<Vec<Cut>>>,
}

impl ElementIndex {
    /// The index of `elements` (grouped by patch) for `scene`'s patches.
    pub fn of(scene: &Scene, elements: &[ElementRow]) -> ElementIndex {
        let n = scene.patches.len();
        let (mut first, mut count) = (vec![usize::MAX; n], vec![0; n]);
        for (k, e) in elements.iter().enumerate() {
            first[e.patch] = first[e.patch].min(k);
            count[e.patch] += 1;
        }
        ElementIndex {
            first,
            count,
            cuts: OnceLock::new(),
        }
    }

    /// The elements of patch `i`, as a range of the list.
    pub fn range(&self, i: usize) -> std::ops::Range<usize> {
        match self.count[i] {
            0 => 0..0,
            n => self.first[i]..self.first[i] + n,
        }
    }

    /// Element `k`'s index within its patch `i`'s lattice.
    pub fn within(&self, i: usize, k: usize) -> usize {
        k - self.first[i]
    }

    /// The twin of element `k` (of patch `i`): the element at the same index on the other side
    /// of a translucent sheet, if it has one there.
    pub fn twin(&self, scene: &Scene, i: usize, k: usize) -> Option<usize> {
        let t = scene.twin(i)?;
        let q = self.within(i, k);
        (q < self.count[t]).then(|| self.first[t] + q)
    }

    /// Every element's value (4.2) from the patch radiosities of a solve.
    pub fn values(
        &self,
        scene: &Scene,
        elements: &[ElementRow],
        radiosity: &[[f64; 3]],
    ) -> Vec<[f64; 3]> {
        elements
            .iter()
            .enumerate()
            .map(|(k, e)| {
                let twin = self.twin(scene, e.patch, k).map(|t| &elements[t]);
                element_value(scene, e, twin, radiosity)
            })
            .collect()
    }

    /// The grid of every scene patch from element values in the list's order.
    pub fn grids(&self, scene: &Scene, values: &[[f64; 3]]) -> Vec<Grid> {
        let cuts = self.cuts.get_or_init(|| crate::contact::cuts(scene));
        (0..scene.patches.len())
            .map(|i| patch_grid(scene, i, &values[self.range(i)], &cuts[i]))
            .collect()
    }
}

/// Element radiosities (4.2) `B_iq = E_i + ρ_i Σ_j F_iq,j B_j`, gathered into one grid per patch.
/// A side of a translucent sheet adds what comes through it, `τ_i Σ_j F_tq,j B_j` over its
/// twin's element at the same point (`scene::translucent`).
pub fn grids(scene: &Scene, ff: &FormFactors, sol: &Solution) -> Vec<Grid> {
    let index = ElementIndex::of(scene, &ff.elements);
    index.grids(scene, &index.values(scene, &ff.elements, &sol.radiosity))
}
