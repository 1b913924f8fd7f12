//! Patch indices as boards name them. The host names patches in scene order (translucent
//! sheets' back sides last, `hemi::scene::Sides`); a board holds the front patches only and
//! names the back side of sheet i `n + i` (n fronts, protocol 4). The two spaces meet only here.

use anyhow::{bail, Context, Result};
use hemi::scene::{Scene, Sides};
use hemi_kernel::link::RayHit;

/// A patch index in a board's space.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BoardPatch(pub u16);

impl BoardPatch {
    /// The board's name for scene patch `i`: its index among the uploaded (front) patches, or,
    /// for the back side of a translucent sheet, the front count plus its front's index.
    pub fn of(scene: &Scene, i: usize) -> Result<BoardPatch> {
        let index = match scene.patches[i].sides {
            Sides::Back { front } => scene.fronts() + front,
            _ => i,
        };
        Ok(BoardPatch(
            u16::try_from(index).context("too many patches")?,
        ))
    }

    /// The scene patch a board's weighted report names (the inverse of [`BoardPatch::of`]).
    pub fn scene_patch(self, scene: &Scene) -> Result<usize> {
        let p = usize::from(self.0);
        match p.checked_sub(scene.fronts()) {
            None => Ok(p),
            Some(front) if front < scene.fronts() => scene
                .twin(front)
                .context("a board reported the back of an opaque patch"),
            Some(_) => bail!("a board answered a hit on an unknown patch"),
        }
    }
}

/// The scene patch whose radiosity a board's ray hit shows: the front it hit, or the back side
/// of a translucent sheet hit from behind; `None` for the back of an opaque patch (as the
/// tracer's diffuse sink sees it).
pub fn seen_patch(scene: &Scene, hit: &RayHit) -> Option<usize> {
    let i = usize::from(hit.patch);
    // (an index past the patches is left to the caller's "unknown patch" error)
    let translucent = i < scene.patches.len() && scene.twin(i).is_some();
    (hit.front || translucent).then(|| scene.side_seen(u32::from(hit.patch), hit.front))
}
