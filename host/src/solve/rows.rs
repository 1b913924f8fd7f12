//! Form-factor rows computed on demand, one patch at a time, for progressive refinement on
//! scenes whose N × N matrix does not fit (paper §9: "this restriction can be removed by using a
//! progressive refinement technique"). Memory is O(N) per row plus a bounded cache of rows.

use super::progressive::progressive;
use super::{Solution, SolveSettings};
use crate::method::Shooter;
use crate::optics::{pending_for, SceneOptics, Scratch};
use crate::pass1::{sample_points, Pass1Settings};
use crate::radiosity::Grid;
use crate::scene::Scene;
use anyhow::Result;
use hemi_kernel::accel::Accelerator;
use hemi_kernel::hemisphere::OwnedHemisphere;
use rayon::prelude::*;
use std::collections::HashMap;

/// One element's sample weight W_iq and its sparse row (column, F_iq,j per channel).
pub type SampleRow = (f32, Vec<(u32, [f32; 3])>);

/// Shoots one patch's sample points on all cores and forms its row F_ij by (4.3).
pub struct RowShooter<'a, A> {
    scene: &'a Scene,
    settings: Pass1Settings,
    make: &'a (dyn Fn() -> A + Sync),
    hemi: OwnedHemisphere,
    optics: SceneOptics,
    pending: usize,
    cache: HashMap<usize, Vec<[f64; 3]>>,
    /// Rows kept at most (the cache's bound).
    pub max_cached: usize,
    /// Rows shot so far (cache misses).
    pub shot: u64,
    /// Hemisphere rays cast so far.
    pub rays: u64,
}

impl<'a, A: Accelerator> RowShooter<'a, A> {
    /// A row source over `scene` with engines from `make`, caching up to `max_cached` rows.
    pub fn new(
        scene: &'a Scene,
        settings: &Pass1Settings,
        make: &'a (dyn Fn() -> A + Sync),
        max_cached: usize,
    ) -> Result<Self> {
        let hemi = OwnedHemisphere::new(settings.circles, settings.rule)
            .map_err(|e| anyhow::anyhow!("--circles {}: {e:?}", settings.circles))?;
        crate::optics::check(&settings.specular)?;
        let optics = SceneOptics::new(scene, &hemi.view())?;
        settings.method.check(&optics.view())?;
        let pending = if optics.view().has_specular() {
            pending_for(&hemi.view())
        } else {
            0
        };
        Ok(RowShooter {
            scene,
            settings: *settings,
            make,
            hemi,
            optics,
            pending,
            cache: HashMap::new(),
            max_cached,
            shot: 0,
            rays: 0,
        })
    }

    /// The element rows of patch `i` (sample point, sparse F_iq,j per channel), in the order of
    /// [`sample_points`].
    pub fn element_rows(&mut self, i: usize) -> Result<Vec<SampleRow>> {
        let view = self.hemi.view();
        let kernel_optics = self.optics.view();
        let cols = self.optics.columns.len();
        let points = sample_points(self.scene, i, self.settings.samples);
        let settings = &self.settings;
        let columns = &self.optics.columns;
        let pending = self.pending;
        let make = self.make;
        // a back side shoots from its front's surface, which its rays must not see
        let scene_kernel_id = self.scene.kernel_id(i);
        let out: Vec<(SampleRow, u32)> = points
            .par_iter()
            .enumerate()
            .map_init(
                || {
                    (
                        make(),
                        vec![[0.0f32; 3]; cols],
                        Scratch::new(pending, &settings.specular),
                        Shooter::new(settings.method, settings.circles),
                    )
                },
                |(engine, row, scratch, shooter), (q, point)| {
                    row.fill([0.0; 3]);
                    let stats = shooter.shoot(
                        engine,
                        &view,
                        &kernel_optics,
                        &mut scratch.view(),
                        point,
                        q as u32,
                        scene_kernel_id,
                        row,
                    )?;
                    let sparse = row
                        .iter()
                        .enumerate()
                        .filter(|(_, f)| **f != [0.0; 3])
                        .map(|(c, f)| (columns[c] as u32, *f))
                        .collect();
                    Ok(((point.weight, sparse), stats.rays))
                },
            )
            .collect::<Result<_>>()?;
        self.rays += out.iter().map(|o| o.1 as u64).sum::<u64>();
        Ok(out.into_iter().map(|(row, _)| row).collect())
    }

    /// Row i of F per channel, dense over the scene's patches, by (4.3).
    pub fn row(&mut self, i: usize) -> Result<Vec<[f64; 3]>> {
        if let Some(r) = self.cache.get(&i) {
            return Ok(r.clone());
        }
        let mut row = vec![[0.0f64; 3]; self.scene.patches.len()];
        for (w, sparse) in self.element_rows(i)? {
            for (j, f) in sparse {
                for c in 0..3 {
                    row[j as usize][c] += w as f64 * f[c] as f64;
                }
            }
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
        let ai = self.scene.patches[i].area as f64;
        for (j, (o, f)) in out.iter_mut().zip(&row).enumerate() {
            let aj = self.scene.patches[j].area as f64;
            *o = if aj > 0.0 {
                f.map(|x| x * ai / aj)
            } else {
                [0.0; 3]
            };
        }
        Ok(())
    }

    /// The column K_·i of the coupled system of a scene with translucent sheets
    /// ([`crate::translucent::coupled`]), K_ji = ρ_j F_ji + τ_j F_twin(j),i, from row i alone:
    /// both F's are in it by reciprocity (a sheet's sides have the same area).
    pub fn coupled_column(&mut self, i: usize, out: &mut [[f64; 3]]) -> Result<()> {
        let mut f = vec![[0.0f64; 3]; out.len()];
        self.column(i, &mut f)?;
        for (j, o) in out.iter_mut().enumerate() {
            let m = self.scene.material_of(j);
            let through = self.scene.twin(j).map_or([0.0; 3], |t| f[t]);
            *o = [0, 1, 2].map(|c| m.diffuse[c] * f[j][c] + m.translucency[c] * through[c]);
        }
        Ok(())
    }
}

/// Progressive refinement with rows shot on demand: no N × N matrix is ever formed.
/// `on_shot(shots, b)` sees the radiosity after every shot.
pub fn solve_streaming<A: Accelerator>(
    shooter: &mut RowShooter<'_, A>,
    settings: &SolveSettings,
    on_shot: &mut dyn FnMut(u32, &[[f64; 3]]),
) -> Result<Solution> {
    let scene = shooter.scene;
    let n = scene.patches.len();
    let rho: Vec<[f64; 3]> = (0..n).map(|i| scene.material_of(i).diffuse).collect();
    let e: Vec<[f64; 3]> = (0..n).map(|i| scene.material_of(i).emission).collect();
    let areas: Vec<f64> = scene.patches.iter().map(|p| p.area as f64).collect();
    if scene.has_translucency() {
        // B = E + KB: the coupled columns carry ρ and τ, so the reflectance is 1
        let ones = vec![[1.0; 3]; n];
        return progressive(
            &ones,
            &e,
            &areas,
            &mut |i, out| shooter.coupled_column(i, out),
            settings,
            on_shot,
        );
    }
    progressive(
        &rho,
        &e,
        &areas,
        &mut |i, out| shooter.column(i, out),
        settings,
        on_shot,
    )
}

/// The vertex grids of [`crate::radiosity::grids`] without stored element rows: every patch's
/// sample points are shot again and their element radiosities (4.2) formed at once. A side of a
/// translucent sheet adds what comes through it, over its twin's element at the same point: the
/// two sides are shot together and both grids formed from the two sets of rows.
pub fn grids_streaming<A: Accelerator>(
    shooter: &mut RowShooter<'_, A>,
    sol: &Solution,
) -> Result<Vec<Grid>> {
    let scene = shooter.scene;
    let gathered = |row: &[(u32, [f32; 3])], c: usize| -> f64 {
        row.iter()
            .map(|&(j, f)| f[c] as f64 * sol.radiosity[j as usize][c])
            .sum()
    };
    let grid = |i: usize, rows: &[SampleRow], twin_rows: &[SampleRow]| {
        let m = scene.material_of(i);
        let samples: Vec<[f64; 3]> = rows
            .iter()
            .enumerate()
            .map(|(q, (_, row))| {
                let mut b = m.emission;
                for (c, bc) in b.iter_mut().enumerate() {
                    *bc += m.diffuse[c] * gathered(row, c);
                    if let Some((_, twin)) = twin_rows.get(q) {
                        *bc += m.translucency[c] * gathered(twin, c);
                    }
                }
                b
            })
            .collect();
        if samples.is_empty() {
            Grid::from_samples(1, &[m.emission])
        } else {
            Grid::from_samples((samples.len() as f64).sqrt().round() as usize, &samples)
        }
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
