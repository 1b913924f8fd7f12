//! hemi on the host: scenes, sample points, backends, the radiosity solve and image assembly.
#![forbid(unsafe_code)]

pub mod board;
