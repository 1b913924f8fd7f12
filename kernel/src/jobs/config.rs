//! The settings a host sends before jobs: the configuration (hemisphere, K, spp, camera,
//! engine), the specular settings (Δ, bounces, stack) and the accelerator's CORDIC. Each is
//! checked against the board's limits before anything changes.

use super::capacity::{ENGINE_DEFAULT_TRACING, ENGINE_MAX_CIRCLES, ENGINE_STACK_DEPTH};
use super::engine::Engine;
use super::platform::Platform;
use super::provider::AccelProvider;
use super::upload::SceneState;
use crate::hemisphere::build_into;
use crate::link::message::{ErrorCode, JobConfig, Response, TraceSettings, MAX_HITS};

impl<P: AccelProvider, T: Platform> Engine<P, T> {
    /// Takes a configuration. Settings outside the board's limits are refused before anything
    /// changes; the hemisphere table is built again only when R or the rule changed, so a
    /// repeated `Configure` (a host reconnecting) costs nothing.
    pub(super) fn configure(&mut self, c: &JobConfig) -> Result<(), ErrorCode> {
        let circles = usize::from(c.circles);
        if !(2..=ENGINE_MAX_CIRCLES).contains(&circles) || c.samples == 0 || c.spp == 0 {
            return Err(ErrorCode::OutOfRange);
        }
        if usize::from(c.spp) > MAX_HITS || c.samples > 256 {
            return Err(ErrorCode::OutOfRange);
        }
        if let Some(cam) = &c.camera {
            let finite = [cam.eye, cam.forward, cam.right, cam.up]
                .iter()
                .all(|v| v.is_finite())
                && cam.tan_half_fov.is_finite();
            if !finite || cam.width == 0 || cam.height == 0 {
                return Err(ErrorCode::OutOfRange);
            }
        }
        self.provider.select(c.accel)?;
        let old = self.config;
        let same_table = self.configured
            && old.circles == c.circles
            && old.rule == c.rule
            && !self.rings.is_empty();
        if !same_table {
            self.rings.clear();
            self.quarter.clear();
            self.rings
                .resize_default(circles)
                .map_err(|_| ErrorCode::TooLong)?;
            let q = crate::hemisphere::quarter_len(u32::from(c.circles));
            self.quarter
                .resize(q, [0.0; 2])
                .map_err(|_| ErrorCode::TooLong)?;
            if build_into(
                u32::from(c.circles),
                c.rule,
                &mut self.rings,
                &mut self.quarter,
            )
            .is_err()
            {
                self.rings.clear();
                self.quarter.clear();
                self.configured = false;
                return Err(ErrorCode::OutOfRange);
            }
        }
        self.config = *c;
        self.configured = true;
        Ok(())
    }

    /// Takes the specular settings; a stack deeper than the board's frames is `TooLong`, so the
    /// host learns to ask for fewer rather than being cut silently.
    pub(super) fn set_tracing(&mut self, t: &TraceSettings) -> Result<(), ErrorCode> {
        if !(t.threshold.is_finite() && t.threshold > 0.0 && t.threshold < 1.0) {
            return Err(ErrorCode::OutOfRange);
        }
        if t.stack == 0 || t.max_bounces == 0 {
            return Err(ErrorCode::OutOfRange);
        }
        if usize::from(t.stack) > ENGINE_STACK_DEPTH {
            return Err(ErrorCode::TooLong);
        }
        self.tracing = *t;
        Ok(())
    }

    /// Sets the accelerator's CORDIC. It applies to scenes loaded from then on
    /// ([`AccelProvider::set_cordic`]), so a loaded scene is loaded again under it.
    pub(super) fn set_cordic(&mut self, iterations: u8, width: u8) -> Result<Response, ErrorCode> {
        if self.provider.set_cordic(iterations, width)? && self.scene == SceneState::Ready {
            // the loaded scene goes into the accelerator again, under the new CORDIC
            self.provider.load(&self.patches).inspect_err(|_| {
                self.scene = SceneState::Empty;
            })?;
        }
        Ok(Response::Configured)
    }

    /// Δ, bounces and stack frames in use.
    pub(super) fn tracing(&self) -> TraceSettings {
        if self.tracing.stack == 0 {
            ENGINE_DEFAULT_TRACING
        } else {
            self.tracing
        }
    }
}
