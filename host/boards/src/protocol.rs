//! What the boards of a farm can do, by the protocol features their handshakes name.

use crate::farm::Farm;
use anyhow::Result;
use hemi_kernel::link::HelloInfo;
use std::fmt;

/// What a protocol version added that the host relies on (provisional, until the kernel
/// names them).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Feature {
    /// Specular tracing: tracing settings, CORDIC settings, lobe tables, trace counters (3).
    Specular,
    /// Optics tables with the back sides' columns of translucent sheets (4).
    Optics,
    /// `ShootLevel` jobs: adaptive sampling's lattice levels (4).
    ShootLevel,
    /// `Query` jobs: irradiance through specular surfaces (4).
    Query,
}

impl Feature {
    /// The protocol version that added it.
    pub fn since(self) -> u16 {
        match self {
            Feature::Specular => 3,
            Feature::Optics | Feature::ShootLevel | Feature::Query => 4,
        }
    }
}

impl fmt::Display for Feature {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Feature::Specular => "specular tracing",
            Feature::Optics => "optics tables with back sides",
            Feature::ShootLevel => "ShootLevel jobs",
            Feature::Query => "Query jobs",
        })
    }
}

/// Whether a board that answered `hello` has `feature`.
pub fn supports(hello: &HelloInfo, feature: Feature) -> bool {
    hello.protocol >= feature.since()
}

/// Fails, naming the first board that lacks `feature` and what needs it, before any job.
pub fn require(farm: &Farm, feature: Feature, what: &str) -> Result<()> {
    match farm
        .hellos()
        .into_iter()
        .flatten()
        .find(|h| !supports(h, feature))
    {
        Some(old) => anyhow::bail!(
            "{what} need{} protocol {} ({feature}); a board speaks protocol {} ({}): flash a \
             newer firmware",
            if what.ends_with('s') { "" } else { "s" },
            feature.since(),
            old.protocol,
            old.build
        ),
        None => Ok(()),
    }
}
