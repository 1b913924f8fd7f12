//! What the boards of a farm can do, by the protocol features their handshakes name.

use crate::farm::Farm;
use anyhow::Result;
use hemi_kernel::link::Feature;

/// Fails, naming the first board that lacks `feature` and `what` needs it (a phrase that
/// takes "needs"), before any job.
pub fn require(farm: &Farm, feature: Feature, what: &str) -> Result<()> {
    match farm
        .hellos()
        .into_iter()
        .flatten()
        .find(|h| !h.supports(feature))
    {
        Some(old) => anyhow::bail!(
            "{what} needs protocol {}, which brought {feature}; a board speaks protocol {} ({}): \
             flash a newer firmware",
            feature.since(),
            old.protocol,
            old.build
        ),
        None => Ok(()),
    }
}

/// Whether every connected board of `farm` has `feature`.
pub fn supports(farm: &Farm, feature: Feature) -> bool {
    farm.hellos().iter().flatten().all(|h| h.supports(feature))
}
