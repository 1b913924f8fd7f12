//! The system (2.6) itself, `B = E + ρ F B` per channel: its parts for a scene, assembled in
//! one place ([`SceneParts`]), and the coupled form `B = E + K B` of a scene with translucent
//! sheets, `K_s· = ρ_s F_s· + τ_s F_t·` with t the twin of side s (`scene::translucent`).

use crate::matrix::{FormMatrix, Row};
use crate::scene::{Material, Scene};
use anyhow::Result;

/// Form factors per channel: `f[c][i][j]`, sparse rows ([`FormMatrix`]). Without coloured
/// mirrors the three are one matrix ([`grey`]); with them, indirect form factors S_ij differ
/// per channel (paper §3.3).
pub type Channels<'a> = [&'a FormMatrix; 3];

/// The same matrix for every channel.
pub fn grey(f: &FormMatrix) -> Channels<'_> {
    [f, f, f]
}

/// The parts of (2.6) for a scene, owned, that a [`System`] borrows: ρ (k_d ρ_d) and E per
/// patch and, when the scene has translucent sheets, the coupled matrices of [`coupled`], which
/// carry ρ and τ themselves (so ρ is then 1). This is the one place the system is assembled.
#[derive(Clone, Debug)]
pub struct SceneParts {
    rho: Vec<[f64; 3]>,
    e: Vec<[f64; 3]>,
    coupled: Option<[FormMatrix; 3]>,
}

impl SceneParts {
    /// ρ, E and (for translucent sheets) the coupled matrices of `scene` with form factors `f`.
    pub fn new(scene: &Scene, f: Channels<'_>) -> SceneParts {
        let (rho, e) = system_reflectance_and_emission(scene);
        SceneParts {
            rho,
            e,
            coupled: coupled(scene, f),
        }
    }

    /// The system `B = E + ρFB` (or `B = E + KB` with translucent sheets) over the `f` the
    /// parts were made with.
    pub fn system<'a>(&'a self, f: Channels<'a>) -> Result<System<'a>> {
        let f = match &self.coupled {
            Some([r, g, b]) => [r, g, b],
            None => f,
        };
        System::new(f, &self.rho, &self.e)
    }
}

/// The material side of (2.6) per patch of `scene`: the reflectance the system multiplies its
/// matrix by — ρ (k_d ρ_d), or 1 with translucent sheets, whose coupled K ([`coupled`]) carries
/// ρ and τ itself — and E. Progressive refinement with rows on demand, which never holds F,
/// takes these with the coupled columns of `on_demand`.
pub fn system_reflectance_and_emission(scene: &Scene) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
    let n = scene.patches.len();
    let translucent = scene.has_translucency();
    let rho = (0..n)
        .map(|i| match translucent {
            true => [1.0; 3],
            false => scene.material_of(i).diffuse,
        })
        .collect();
    let e = (0..n).map(|i| scene.material_of(i).emission).collect();
    (rho, e)
}

/// How far above 1 a row sum must be to count as "above 1". f64 rounding of the row sum is far
/// below it; pass 1's f32 accumulation of 10⁴ ray weights per element can reach 10⁻⁵ (the Cornell
/// box has rows at 1 + 7·10⁻⁶), and such rows are reported and scaled back like sampling error.
pub const ROW_SLACK: f64 = 1e-6;

/// One radiosity system (2.6): per-channel F, ρ (k_d ρ_d) and E per patch.
#[derive(Clone, Copy, Debug)]
pub struct System<'a> {
    /// F_ij per channel.
    pub f: Channels<'a>,
    /// Diffuse reflectance per patch and channel.
    pub rho: &'a [[f64; 3]],
    /// Emission per patch and channel.
    pub e: &'a [[f64; 3]],
}

impl<'a> System<'a> {
    /// Wraps the parts, checking that their sizes agree.
    pub fn new(f: Channels<'a>, rho: &'a [[f64; 3]], e: &'a [[f64; 3]]) -> Result<System<'a>> {
        let n = e.len();
        anyhow::ensure!(
            rho.len() == n
                && f.iter()
                    .all(|m| m.len() == n && m.iter().all(|r| r.len() == n)),
            "the system's sizes disagree: {n} emissions, {} reflectances, an F that is not {n}×{n}",
            rho.len()
        );
        Ok(System { f, rho, e })
    }

    /// Number of patches.
    pub fn len(&self) -> usize {
        self.e.len()
    }

    /// Whether the system has no patches.
    pub fn is_empty(&self) -> bool {
        self.e.is_empty()
    }

    /// Whether the three channels share one matrix (one LU serves all three).
    pub fn is_grey(&self) -> bool {
        std::ptr::eq(self.f[0], self.f[1]) && std::ptr::eq(self.f[1], self.f[2])
    }

    /// max |B − E − ρFB| / max |B| over patches and channels (the stopping rule of every
    /// iterative solver here, so their residuals compare).
    #[expect(
        clippy::needless_range_loop,
        reason = "B is read at the row's columns and at i"
    )]
    pub fn residual(&self, b: &[[f64; 3]]) -> f64 {
        let mut worst = 0.0f64;
        let mut scale = 0.0f64;
        for i in 0..b.len() {
            for c in 0..3 {
                let gathered: f64 = self.f[c][i].entries().map(|(j, fij)| fij * b[j][c]).sum();
                let r = b[i][c] - self.e[i][c] - self.rho[i][c] * gathered;
                worst = worst.max(r.abs());
                scale = scale.max(b[i][c].abs());
            }
        }
        if scale > 0.0 {
            worst / scale
        } else {
            worst
        }
    }

    /// A copy of F (per channel) whose rows are scaled down to sum to at most 1, with the number
    /// of rows changed. A row of F is the fraction of the hemisphere that reaches something, so
    /// a sum above 1 is sampling error (pass 1's R and K), never light.
    pub fn conserving(&self) -> ([FormMatrix; 3], usize) {
        let mut changed = 0;
        let out = self.f.map(|m| {
            FormMatrix::from_rows(
                m.iter()
                    .map(|row| {
                        let s = row.sum();
                        if s > 1.0 + ROW_SLACK {
                            changed += 1;
                            row.map(|x| x / s)
                        } else {
                            row.clone()
                        }
                    })
                    .collect(),
            )
        });
        (out, changed)
    }
}

/// The coupled matrices `K_s· = ρ_s F_s· + τ_s F_twin(s)·` per channel, to be solved with a
/// reflectance of 1 (see the module notes); `None` when no patch is translucent (the system is
/// then the plain `B = E + ρFB`).
pub fn coupled(scene: &Scene, f: Channels<'_>) -> Option<[FormMatrix; 3]> {
    if !scene.has_translucency() {
        return None;
    }
    let n = scene.patches.len();
    Some([0, 1, 2].map(|c| {
        FormMatrix::from_rows(
            (0..n)
                .map(|i| {
                    let twin = scene.twin(i).map(|t| &f[c][t]);
                    coupled_row(scene.material_of(i), c, &f[c][i], twin)
                })
                .collect(),
        )
    }))
}

/// Row s of the coupled system in channel `c`: [`coupled_entry`] over every column that the
/// side's own row or its twin's holds (elsewhere both are zero, and so is the entry).
fn coupled_row(m: &Material, c: usize, own: &Row, twin: Option<&Row>) -> Row {
    let mut cols: Vec<usize> = own.entries().map(|(j, _)| j).collect();
    if let Some(t) = twin {
        cols.extend(t.entries().map(|(j, _)| j));
        cols.sort_unstable();
        cols.dedup();
    }
    let entries = cols
        .into_iter()
        .map(|j| (j as u32, coupled_entry(m, c, own[j], twin.map(|t| t[j]))))
        .collect();
    Row::from_entries(own.len(), entries)
}

/// One entry of the coupled system in channel `c`, `K_sj = ρ_s F_sj + τ_s F_tj`, from side s's
/// own form factor `own` and its twin t's `through` (`None` for an opaque patch): the one
/// formula of the coupling, whether a whole matrix is formed ([`coupled`]) or a column from a
/// shooter's row (`on_demand`).
pub fn coupled_entry(m: &Material, c: usize, own: f64, through: Option<f64>) -> f64 {
    m.diffuse[c] * own + through.map_or(0.0, |t| m.translucency[c] * t)
}
