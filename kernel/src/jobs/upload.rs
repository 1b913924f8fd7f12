//! The scene upload: `SceneBegin`, then patches in any order (`ScenePatch`) and the optics table
//! (`SceneSurface`, `SceneLobes`), every message acknowledged with how much has arrived. The
//! accelerator loads the scene once the last patch is in; jobs wait until then.

use super::capacity::{ENGINE_MAX_LOBES, ENGINE_MAX_PATCHES};
use super::engine::Engine;
use super::platform::Platform;
use super::provider::AccelProvider;
use crate::link::message::{ErrorCode, Response};
use crate::optics::Surface;
use crate::patch::Patch;

/// Where the scene upload stands.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum SceneState {
    Empty,
    Loading { total: u16 },
    Ready,
}

impl<P: AccelProvider, T: Platform> Engine<P, T> {
    pub(super) fn scene_begin(&mut self, patches: u16) -> Result<Response, ErrorCode> {
        if usize::from(patches) > ENGINE_MAX_PATCHES || patches == 0 {
            return Err(ErrorCode::TooLong);
        }
        // Every patch diffuse with its own column until the host says otherwise.
        self.surfaces.clear();
        for c in 0..u32::from(patches) {
            self.surfaces
                .push(Surface::diffuse(c))
                .map_err(|_| ErrorCode::TooLong)?;
        }
        self.weights.clear();
        self.patches.clear();
        self.areas.clear();
        self.received = 0;
        self.scene = SceneState::Loading { total: patches };
        Ok(Response::SceneAck {
            loaded: 0,
            total: patches,
        })
    }

    pub(super) fn scene_patch(
        &mut self,
        index: u16,
        area: f32,
        patch: &Patch,
    ) -> Result<Response, ErrorCode> {
        let total = match self.scene {
            SceneState::Loading { total } => total,
            // A repeat of a patch that completed the scene: acknowledge it again.
            SceneState::Ready if usize::from(index) < self.patches.len() => {
                let n = self.patches.len() as u16;
                return Ok(Response::SceneAck {
                    loaded: n,
                    total: n,
                });
            }
            _ => return Err(ErrorCode::NoScene),
        };
        if index >= total {
            return Err(ErrorCode::OutOfRange);
        }
        let finite = patch.hull().iter().all(|v| v.is_finite()) && area.is_finite();
        if !finite {
            return Err(ErrorCode::BadScene);
        }
        let i = usize::from(index);
        // Slots fill in any order: grow with placeholders up to the index.
        while self.patches.len() <= i {
            self.patches.push(*patch).map_err(|_| ErrorCode::TooLong)?;
            self.areas.push(area).map_err(|_| ErrorCode::TooLong)?;
        }
        if let (Some(p), Some(a)) = (self.patches.get_mut(i), self.areas.get_mut(i)) {
            *p = *patch;
            *a = area;
        }
        self.received |= 1u64 << i;
        let loaded = self.received.count_ones() as u16;
        if loaded == total {
            self.provider.load(&self.patches).inspect_err(|_| {
                self.scene = SceneState::Empty;
            })?;
            self.scene = SceneState::Ready;
        }
        Ok(Response::SceneAck { loaded, total })
    }

    pub(super) fn scene_surface(
        &mut self,
        index: u16,
        surface: &Surface,
    ) -> Result<Response, ErrorCode> {
        let total = self.scene_total()?;
        if index >= total || surface.column.is_some_and(|c| c >= u32::from(total)) {
            return Err(ErrorCode::OutOfRange);
        }
        // Diffuse transmission: a back side's column lies past the patches'
        // (`Feature::BackSides`); it must still fit the row.
        if surface
            .back_column
            .is_some_and(|c| c as usize >= ENGINE_MAX_PATCHES)
        {
            return Err(ErrorCode::TooLong);
        }
        let bad_k = [surface.reflect, surface.transmit]
            .into_iter()
            .flatten()
            .any(|s| s.k.iter().any(|k| !(k.is_finite() && *k >= 0.0)));
        if bad_k {
            return Err(ErrorCode::BadScene);
        }
        let slot = self
            .surfaces
            .get_mut(usize::from(index))
            .ok_or(ErrorCode::OutOfRange)?;
        *slot = *surface;
        Ok(self.scene_ack(total))
    }

    pub(super) fn scene_lobes(
        &mut self,
        first: u16,
        weights: &[f32],
    ) -> Result<Response, ErrorCode> {
        let total = self.scene_total()?;
        let start = usize::from(first);
        let end = start + weights.len();
        if end > ENGINE_MAX_LOBES {
            return Err(ErrorCode::TooLong);
        }
        if weights.iter().any(|w| !(w.is_finite() && *w >= 0.0)) {
            return Err(ErrorCode::BadScene);
        }
        if self.weights.len() < end {
            self.weights
                .resize(end, 0.0)
                .map_err(|_| ErrorCode::TooLong)?;
        }
        if let Some(dst) = self.weights.get_mut(start..end) {
            dst.copy_from_slice(weights);
        }
        Ok(self.scene_ack(total))
    }

    /// The scene being uploaded (or the loaded one): its patch count.
    fn scene_total(&self) -> Result<u16, ErrorCode> {
        match self.scene {
            SceneState::Loading { total } => Ok(total),
            SceneState::Ready => Ok(self.patches.len() as u16),
            SceneState::Empty => Err(ErrorCode::NoScene),
        }
    }

    fn scene_ack(&self, total: u16) -> Response {
        let loaded = match self.scene {
            SceneState::Ready => total,
            _ => self.received.count_ones() as u16,
        };
        Response::SceneAck { loaded, total }
    }
}
