//! What a backend is asked to shoot: hemispheres at sample points, each named by its patch and
//! its cell of a lattice, and the element rows F_iq,· that come back (paper §4.1).
//!
//! The lattice rule is the kernel's (`hemi_kernel::sampling::uniform_side`, shared with the
//! boards' job engine): a polygon patch gets K×K points, a Bezier patch the 4×4 of paper §7
//! whatever K, a pure mirror none (it has no column and gathers nothing); the back side of a
//! translucent sheet has its front's points facing the other way.

use crate::scene::{Scene, Sides};
use hemi_kernel::sampling::{
    lattice_sample, uniform_count, uniform_sample, uniform_side, SamplePoint,
};

/// Where a shot's point lies, which decides how a board is asked for it and which spin ψ its
/// hemisphere gets (the cell index q picks the spin, `spin_for_sample`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cell {
    /// Point q of the patch's uniform K×K (or §7 4×4) points, [`sample_points`].
    Uniform {
        /// Index, v-major.
        q: u32,
    },
    /// Cell q = b·k + a of a k×k level of adaptive sampling, [`cell_point`].
    Level {
        /// Cells per side.
        k: u32,
        /// Index, v-major.
        q: u32,
    },
}

impl Cell {
    /// The cell index, which picks the hemisphere's spin.
    pub fn q(self) -> u32 {
        match self {
            Cell::Uniform { q } | Cell::Level { q, .. } => q,
        }
    }
}

/// One hemisphere to shoot: scene patch `patch`, its cell, and the sample point there.
#[derive(Clone, Copy, Debug)]
pub struct Shot {
    /// Scene patch.
    pub patch: usize,
    /// The lattice cell.
    pub cell: Cell,
    /// The sample point.
    pub point: SamplePoint,
}

/// One element's row: F_iq,j for every patch j (sparse, ascending j).
#[derive(Clone, Debug)]
pub struct ElementRow {
    /// Patch i the element belongs to.
    pub patch: usize,
    /// The sample point (centre of element q).
    pub point: SamplePoint,
    /// (j, F_iq,j per channel) for the patches j (scene indices) the hemisphere saw, directly
    /// or through specular surfaces.
    pub row: Vec<(u32, [f32; 3])>,
}

/// The side of patch `i` of the uniform lattice at K = `k`: the kernel's rule
/// (`sampling::uniform_side`, which the boards' job engine uses too) for the patch's shape
/// and material.
pub fn lattice_side(scene: &Scene, i: usize, k: u32) -> u32 {
    let diffuse = scene.material_of(i).is_diffuse();
    uniform_side(&scene.patches[i].shape, diffuse, k)
}

/// How many sample points patch `i` gets (see [`sample_points`]), without placing them.
pub fn sample_count(scene: &Scene, i: usize, k: u32) -> usize {
    let diffuse = scene.material_of(i).is_diffuse();
    uniform_count(&scene.patches[i].shape, diffuse, k) as usize
}

/// The sample points of patch `i`: K×K for a polygon, the 16 points of paper §7 for a Bezier
/// patch (4×4 whatever K); none for a pure specular patch. The back side of a translucent sheet
/// has its front's points, facing the other way.
pub fn sample_points(scene: &Scene, i: usize, k: u32) -> Vec<SamplePoint> {
    let (at, flip) = match scene.patches[i].sides {
        Sides::Back { front } => (front, true),
        _ => (i, false),
    };
    let patch = &scene.patches[at];
    (0..sample_count(scene, i, k) as u32)
        .map(|q| uniform_sample(&patch.shape, patch.area, k, q))
        .map(|p| if flip { p.flipped() } else { p })
        .collect()
}

/// The uniform shots of patch `i` at K = `k`, in the order of [`sample_points`].
pub fn uniform_shots(scene: &Scene, i: usize, k: u32) -> impl Iterator<Item = Shot> {
    sample_points(scene, i, k)
        .into_iter()
        .enumerate()
        .map(move |(q, point)| Shot {
            patch: i,
            cell: Cell::Uniform { q: q as u32 },
            point,
        })
}

/// Every hemisphere of uniform pass 1 at K = `k`, patch by patch.
pub fn all_uniform_shots(scene: &Scene, k: u32) -> Vec<Shot> {
    (0..scene.patches.len())
        .flat_map(|i| uniform_shots(scene, i, k))
        .collect()
}

/// Sample point (a, b) of the k×k lattice on patch `i` (the cell's centre, its area share):
/// the kernel's `lattice_sample`, which a board's `ShootLevel` job uses too. The back side of
/// a translucent sheet has its front's points, facing the other way (as in uniform sampling).
pub fn cell_point(scene: &Scene, i: usize, k: u32, a: u32, b: u32) -> SamplePoint {
    let patch = &scene.patches[i];
    if let Sides::Back { front } = patch.sides {
        return cell_point(scene, front, k, a, b).flipped();
    }
    lattice_sample(&patch.shape, patch.area, k, a, b)
}

/// The shot of cell (a, b) of the k×k level on patch `i`.
pub fn level_shot(scene: &Scene, i: usize, k: u32, (a, b): (u32, u32)) -> Shot {
    Shot {
        patch: i,
        cell: Cell::Level { k, q: b * k + a },
        point: cell_point(scene, i, k, a, b),
    }
}
