//! What this firmware says about itself in the handshake.

use hemi_kernel::jobs::ENGINE_CAPACITIES;
use hemi_kernel::link::{HelloInfo, BUILD_LEN, PROTOCOL_VERSION};

/// Name, version and git revision, as reported in the handshake.
pub const BUILD: &str = concat!(
    "hemi-firmware ",
    env!("CARGO_PKG_VERSION"),
    " (",
    env!("HEMI_GIT_REV"),
    ")"
);

/// The handshake: this build's accelerator and the engine's capacities.
pub fn hello_info() -> HelloInfo {
    let mut build = heapless::String::<BUILD_LEN>::new();
    // Truncate rather than fail: the build string is informational.
    for c in BUILD.chars() {
        if build.push(c).is_err() {
            break;
        }
    }
    HelloInfo {
        protocol: PROTOCOL_VERSION,
        build,
        accel: crate::accel::FwAccel::native(),
        caps: ENGINE_CAPACITIES,
    }
}
