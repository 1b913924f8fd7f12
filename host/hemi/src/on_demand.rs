//! Form-factor rows computed on demand, one patch at a time, for progressive refinement on
//! scenes whose N × N matrix does not fit (paper §9: "this restriction can be removed by using a
//! progressive refinement technique"). Memory is O(N) per row plus a bounded cache of rows.

use crate::backend::{shoot_checked, Backend};
use crate::pass1::add_element;
use crate::radiosity::{element_value, patch_grid, Grid};
use crate::scene::Scene;
use crate::shots::{uniform_shots, ElementRow};
use crate::solve::progressive::progressive;
use crate::solve::{coupled_entry, system_reflectance_and_emission, Solution, SolveSettings};
use anyhow::Result;
use std::collections::HashMap;

/// Shoots one patch's sample points on the backend and forms its row F_ij by (4.3).
pub struct RowShooter<'a> {
    backend: &'a dyn Backend,
    cache: HashMap<usize, Vec<[f64; 3]>>,
    /// Rows kept at most (the cache's bound).
    pub max_cached: usize,
    /// Rows shot so far (cache misses).
    pub shot: u64,
    /// Hemisphere rays cast so far.
    pub rays: u64,
}

impl<'a> RowShooter<'a> {
    /// A row source over the backend's scene, caching up to `max_cached` rows.
    pub fn new(backend: &'a dyn Backend, max_cached: usize) -> Result<Self> {
        anyhow::ensure!(
            backend.settings().samples >= 1,
            "--samples must be at least 1"
        );
        Ok(RowShooter {
            backend,
            cache: HashMap::new(),
            max_cached,
            shot: 0,
            rays: 0,
        })
    }

    fn scene(&self) -> &'a Scene {
        self.backend.scene()
    }

    /// The element rows of patch `i`, in the order of `shots::sample_points`.
    pub fn element_rows(&mut self, i: usize) -> Result<Vec<ElementRow>> {
        let k = self.backend.settings().samples;
        let shots: Vec<_> = uniform_shots(self.scene(), i, k).collect();
        let (rows, stats) = shoot_checked(self.backend, &shots, &|_| {})?;
        self.rays += stats.rays;
        Ok(rows)
    }

    /// Row i of F per channel, dense over the scene's patches, by (4.3).
    pub fn row(&mut self, i: usize) -> Result<Vec<[f64; 3]>> {
        if let Some(r) = self.cache.get(&i) {
            return Ok(r.clone());
        }
        let mut row = vec![[0.0f64; 3]; self.scene().patches.len()];
        for e in self.element_rows(i)? {
            add_element(&e, |j, c, x| row[j][c] += x);
        }
        self.shot += 1;
        if self.cache.len() < self.max_cached {
            self.cache.insert(i, row.clone());
        }
        Ok(row)
    }

    /// The column F_·i that shooter i needs, from its row by reciprocity: F_ji = F_ij A_i / A_j.
    pub fn column(&mut self, i: usize, out: &mut [[f64; 3]]) -> Result<()> {
        let row = self.row(i)?;
        let ai = self.scene().patches[i].area as f64;
        for (j, (o, f)) in out.iter_mut().zip(&row).enumerate() {
            let aj = self.scene().patches[j].area as f64;
            *o = if aj > 0.0 {
                f.map(|x| x * ai / aj)
            } else {
                [0.0; 3]
            };
        }
        Ok(())
    }

    /// The column K_·i of the coupled system of a scene with translucent sheets
    /// ([`crate::solve::coupled`]), K_ji = ρ_j F_ji + τ_j F_twin(j),i, from row i alone:
    /// both F's are in it by reciprocity (a sheet's sides have the same area).
    pub fn coupled_column(&mut self, i: usize, out: &mut [[f64; 3]]) -> Result<()> {
        let mut f = vec![[0.0f64; 3]; out.len()];
        self.column(i, &mut f)?;
        for (j, o) in out.iter_mut().enumerate() {
            let m = self.scene().material_of(j);
            let twin = self.scene().twin(j);
            *o = [0, 1, 2].map(|c| coupled_entry(m, c, f[j][c], twin.map(|t| f[t][c])));
        }
        Ok(())
    }
}

/// Progressive refinement with rows shot on demand: no N × N matrix is ever formed.
/// `on_shot(shots, b)` sees the radiosity after every shot.
pub fn solve_streaming(
    shooter: &mut RowShooter<'_>,
    settings: &SolveSettings,
    on_shot: &mut dyn FnMut(u32, &[[f64; 3]]),
) -> Result<Solution> {
    let scene = shooter.scene();
    // with translucent sheets B = E + KB: the coupled columns carry ρ and τ
    let (rho, e) = system_reflectance_and_emission(scene);
    let areas: Vec<f64> = scene.patches.iter().map(|p| p.area as f64).collect();
    if scene.has_translucency() {
        let column = &mut |i, out: &mut [[f64; 3]]| shooter.coupled_column(i, out);
        return progressive(&rho, &e, &areas, column, settings, on_shot);
    }
    let column = &mut |i, out: &mut [[f64; 3]]| shooter.column(i, out);
    progressive(&rho, &e, &areas, column, settings, on_shot)
}

/// The patches that reflect (ρ > 0 in some channel), emit nothing and ended with B exactly 0:
/// what shooting missed. A shot spreads a patch's energy over the patches its own hemisphere's
/// rays hit (F_ji = F_ij A_i / A_j from the shooter's row), so a receiver smaller than the
/// spacing of those rays gets nothing, and the receivers hit get more than their share; a
/// gathering solve, where every receiver casts its own hemisphere, does not miss them.
pub fn unreached(scene: &Scene, sol: &Solution) -> usize {
    (0..scene.patches.len())
        .filter(|&i| {
            let m = scene.material_of(i);
            m.diffuse.iter().any(|r| *r > 0.0)
                && m.emission.iter().all(|e| *e == 0.0)
                && sol.radiosity[i] == [0.0; 3]
        })
        .count()
}

/// The vertex grids of [`crate::radiosity::grids`] without stored element rows: every patch's
/// sample points are shot again and their element values (4.2) formed at once. A side of a
/// translucent sheet adds what comes through it, over its twin's element at the same point: the
/// two sides are shot together and both grids formed from the two sets of rows.
pub fn grids_streaming(shooter: &mut RowShooter<'_>, sol: &Solution) -> Result<Vec<Grid>> {
    let scene = shooter.scene();
    let cuts = crate::contact::cuts(scene);
    let grid = |i: usize, rows: &[ElementRow], twin_rows: &[ElementRow]| {
        let samples: Vec<[f64; 3]> = rows
            .iter()
            .enumerate()
            .map(|(q, e)| element_value(scene, e, twin_rows.get(q), &sol.radiosity))
            .collect();
        patch_grid(scene, i, &samples, &cuts[i])
    };
    let n = scene.patches.len();
    let mut grids: Vec<Option<Grid>> = vec![None; n];
    for i in 0..n {
        if grids[i].is_some() {
            continue;
        }
        let rows = shooter.element_rows(i)?;
        match scene.twin(i) {
            Some(t) => {
                let twin_rows = shooter.element_rows(t)?;
                grids[i] = Some(grid(i, &rows, &twin_rows));
                grids[t] = Some(grid(t, &twin_rows, &rows));
            }
            None => grids[i] = Some(grid(i, &rows, &[])),
        }
    }
    Ok(grids.into_iter().flatten().collect())
}
