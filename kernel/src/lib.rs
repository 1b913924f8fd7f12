//! The hemi ray kernel: everything of the generalized two-pass radiosity method that runs on the
//! co-processor, written once and run unchanged on the host and in the firmware.
#![no_std]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

#[cfg(feature = "std")]
extern crate std;

pub mod link;
