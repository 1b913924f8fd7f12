//! The settings every pass shares: the hemisphere (R, the δD rule), the initial lattice K, the
//! specular frustums' bounds and the pass-1 method. A backend is made for one scene and one
//! `Pass1Settings` ([`crate::backend`]), and every pass over it reads them from there.

use crate::method::Method;
use crate::optics::SpecularSettings;
use hemi_kernel::hemisphere::DeltaRule;

/// Settings of pass 1 (and of the hemispheres and frustums of pass 2 and the queries).
#[derive(Clone, Copy, Debug)]
pub struct Pass1Settings {
    /// R, hemisphere circles (M = 4R rays on the horizon).
    pub circles: u32,
    /// K: K×K initial sample points per polygon patch.
    pub samples: u32,
    /// How delta form factors are assigned to rings.
    pub rule: DeltaRule,
    /// Frustums through specular surfaces.
    pub specular: SpecularSettings,
    /// The hemisphere, or a peer method at the same ray budget (`--method`).
    pub method: Method,
}

impl Default for Pass1Settings {
    fn default() -> Self {
        Pass1Settings {
            circles: 64,
            // K = 16, not 8: the K×K midpoint rule, not the hemisphere, dominates the error of
            // patch-to-patch form factors (docs/ACCURACY.md: 1.26 % at K = 8, 0.25 % at 16 on
            // perpendicular rectangles with a common edge).
            samples: 16,
            rule: DeltaRule::Band,
            specular: SpecularSettings::default(),
            method: Method::Hemisphere,
        }
    }
}
