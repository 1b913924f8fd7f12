//! What this firmware says about itself in the handshake.

use hemi_kernel::link::{AccelKind, HelloInfo, BUILD_LEN, KERNEL_CAPACITIES, PROTOCOL_VERSION};

/// Name, version and git revision, as reported in the handshake.
pub const BUILD: &str = concat!(
    "hemi-firmware ",
    env!("CARGO_PKG_VERSION"),
    " (",
    env!("HEMI_GIT_REV"),
    ")"
);

/// The handshake: the kernel runs on the CPU (the accelerator model and MMIO come later).
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
        accel: AccelKind::Soft,
        caps: KERNEL_CAPACITIES,
    }
}
