//! The memory pass 1's form factors take, known before it is taken.
//!
//! Rows are sparse (`matrix`): an element keeps what its hemisphere saw, not N columns. The
//! dense bound (every element sees every patch) is right for a box of a few walls and wrong by
//! orders of magnitude for a floor of 10⁵ tiles, which see the lamp and little else. So a scene
//! whose dense bound passes the budget is measured: a pilot of hemispheres spread evenly over
//! pass 1's shots gives the bytes per element, and pass 1 is refused (or, under `--solver
//! auto`, solved without stored rows) only when the estimate passes it. While pass 1 runs, its
//! rows are counted as they arrive and it stops at the budget, so a pilot that guessed low
//! costs time, never the memory.
//!
//! ```
//! # use hemi::footprint::Footprint;
//! // an element that saw 10 patches in a scene without coloured mirrors
//! let bytes = Footprint::new(false).element(10);
//! assert_eq!(bytes, Footprint::ROW_FIXED + 10 * (16 + 12));
//! ```

use crate::backend::{shoot_checked, Backend, Progress};
use crate::scene::Scene;
use crate::shots::{all_uniform_shots, sample_count, ElementRow, Shot};
use anyhow::{bail, Result};
use hemi_kernel::tracer::ShotStats;

/// Hemispheres the pilot shoots (fewer when pass 1 has fewer).
pub const PILOT: usize = 256;

/// Factor on the pilot's mean: its elements are a sample, and a scene's patches differ.
const PILOT_MARGIN: f64 = 1.25;

/// Pass 1 is shot in this many pieces at least, so its rows can be counted as they arrive.
const PIECES: usize = 16;

/// What one element row costs, its share of the patch matrices (4.3) included.
#[derive(Clone, Copy, Debug)]
pub struct Footprint {
    /// Patch matrices formed: the grey one, and three more when coloured mirrors tint the
    /// channels (`pass1::patch_matrix`).
    matrices: u64,
}

impl Footprint {
    /// Bytes of an element row's fixed part: the row itself and its vector's header.
    pub const ROW_FIXED: u64 = std::mem::size_of::<ElementRow>() as u64;

    /// The footprint of rows feeding one patch matrix, or four when `tinted`.
    pub fn new(tinted: bool) -> Footprint {
        Footprint {
            matrices: if tinted { 4 } else { 1 },
        }
    }

    /// The footprint of `scene`'s rows: four matrices wherever a mirror could tint them.
    pub fn of(scene: &Scene) -> Footprint {
        let coloured = |k: &crate::scene::Rgb| k[0] != k[1] || k[1] != k[2];
        let tinted = scene.materials.iter().any(|m| {
            let (r, t) = (&m.specular, &m.transmission);
            coloured(r) || coloured(t)
        });
        Footprint::new(tinted)
    }

    /// Bytes of an element that saw `seen` patches: its entries (patch index and three f32), and
    /// at most as many entries of its patch's rows (index and f64) in every matrix.
    pub fn element(self, seen: usize) -> u64 {
        let entry = (4 + 12) + self.matrices * (4 + 8);
        Footprint::ROW_FIXED + seen as u64 * entry
    }

    /// Bytes of the rows given.
    pub fn rows(self, rows: &[ElementRow]) -> u64 {
        rows.iter().map(|r| self.element(r.row.len())).sum()
    }
}

/// Pass 1's bytes by the dense bound for `shots` hemispheres: every element sees every patch.
pub fn dense_bound(scene: &Scene, shots: u64) -> u64 {
    let each = Footprint::of(scene).element(scene.patches.len());
    each.saturating_mul(shots)
}

/// Pass 1's bytes for `shots` on `backend`, estimated from a pilot of [`PILOT`] of them spread
/// evenly over the list (their rows are dropped): the pilot's mean times 1.25 (`PILOT_MARGIN`).
pub fn estimate(backend: &dyn Backend, shots: &[Shot]) -> Result<u64> {
    if shots.is_empty() {
        return Ok(0);
    }
    let n = PILOT.min(shots.len());
    let pilot: Vec<Shot> = (0..n).map(|i| shots[i * shots.len() / n]).collect();
    let (rows, _) = shoot_checked(backend, &pilot, &|_| {})?;
    let footprint = Footprint::of(backend.scene());
    let mean = footprint.rows(&rows) as f64 / n as f64;
    Ok((mean * PILOT_MARGIN * shots.len() as f64) as u64)
}

/// What pass 1's rows would take, and how it was found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Need {
    /// Bytes.
    pub bytes: u64,
    /// Hemispheres of the pilot that estimated it; 0 when it is the dense bound.
    pub pilot: usize,
}

impl Need {
    /// What pass 1 on `backend` needs, measured no further than `limit` calls for: the dense
    /// bound when it is within `limit`, else the pilot's [`estimate`].
    pub fn of(backend: &dyn Backend, limit: u64) -> Result<Need> {
        let (scene, k) = (backend.scene(), backend.settings().samples);
        // counted without placing them: the dense bound decides most scenes alone
        let count = (0..scene.patches.len()).map(|i| sample_count(scene, i, k) as u64);
        let dense = dense_bound(scene, count.sum());
        if dense <= limit {
            return Ok(Need {
                bytes: dense,
                pilot: 0,
            });
        }
        let shots = all_uniform_shots(scene, k);
        Ok(Need {
            bytes: estimate(backend, &shots)?,
            pilot: PILOT.min(shots.len()),
        })
    }

    /// The figure and where it comes from, for messages.
    pub fn describe(&self) -> String {
        match self.pilot {
            0 => format!("{:.1} MiB", mib(self.bytes)),
            n => format!(
                "about {:.1} MiB (estimated from a pilot of {n} hemispheres)",
                mib(self.bytes)
            ),
        }
    }
}

/// `shots` on `backend`, as [`shoot_checked`] does, in pieces whose rows are counted as they
/// arrive (one piece when even the dense bound fits): past `limit` bytes pass 1 stops with the
/// figure, naming `raise` (the option that raises the limit, and what else avoids it).
pub fn shoot_within(
    backend: &dyn Backend,
    shots: &[Shot],
    progress: &Progress<'_>,
    limit: u64,
    raise: &str,
) -> Result<(Vec<ElementRow>, ShotStats)> {
    let footprint = Footprint::of(backend.scene());
    // rows that cannot pass the limit need no counting: one request, as boards prefer
    if dense_bound(backend.scene(), shots.len() as u64) <= limit {
        return shoot_checked(backend, shots, progress);
    }
    let piece = shots.len().div_ceil(PIECES).max(4096);
    let (mut rows, mut stats, mut bytes) = (Vec::new(), ShotStats::default(), 0u64);
    for chunk in shots.chunks(piece) {
        let (more, s) = shoot_checked(backend, chunk, progress)?;
        bytes += footprint.rows(&more);
        rows.extend(more);
        stats += s;
        if bytes > limit {
            bail!(
                "pass 1 stopped: its form factors took {:.1} MiB after {} of {} hemispheres, past \
                 the {:.1} MiB allowed ({raise})",
                mib(bytes),
                rows.len(),
                shots.len(),
                mib(limit)
            );
        }
    }
    Ok((rows, stats))
}

/// Bytes in MiB, for messages.
pub fn mib(bytes: u64) -> f64 {
    bytes as f64 / (1u64 << 20) as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend::{InProcess, Soft};
    use crate::settings::Pass1Settings;

    use crate::adaptive::tests::SCENE;

    fn with_backend(test: impl FnOnce(&InProcess<'_, Soft>)) {
        let scene = crate::scene::parse(SCENE, "t.toml").unwrap();
        let settings = Pass1Settings {
            circles: 8,
            samples: 4,
            ..Pass1Settings::default()
        };
        test(&InProcess::new(&scene, &settings, Soft::new()).unwrap());
    }

    #[test]
    fn the_rows_stay_within_the_dense_bound_and_the_pilot_estimates_them() {
        with_backend(|backend| {
            let shots = all_uniform_shots(backend.scene(), 4);
            let (rows, _) = shoot_checked(backend, &shots, &|_| {}).unwrap();
            let measured = Footprint::of(backend.scene()).rows(&rows);
            assert!(measured <= dense_bound(backend.scene(), shots.len() as u64));
            // every shot is in the pilot here: the estimate is the measure and its margin
            let estimated = estimate(backend, &shots).unwrap();
            assert_eq!(estimated, (measured as f64 * PILOT_MARGIN) as u64);
        });
    }

    #[test]
    fn pass_1_stops_at_its_limit_with_the_figure() {
        with_backend(|backend| {
            let shots = all_uniform_shots(backend.scene(), 4);
            let err = shoot_within(backend, &shots, &|_| {}, 100, "--more raises it")
                .unwrap_err()
                .to_string();
            assert!(
                err.starts_with("pass 1 stopped: its form factors took"),
                "{err}"
            );
            assert!(
                err.contains("past the 0.0 MiB allowed (--more raises it)"),
                "{err}"
            );
            let room = shoot_within(backend, &shots, &|_| {}, u64::MAX, "").unwrap();
            assert_eq!(room.0.len(), shots.len());
        });
    }
}
