//! hemi on the host: scenes, sample points, backends, the radiosity solve and image assembly.
#![forbid(unsafe_code)]

pub mod adaptive;
pub mod analytic;
pub mod bench;
pub mod board;
pub mod chart;
pub mod engine;
pub mod irradiance;
pub mod method;
pub mod optics;
pub mod overlay;
pub mod pass1;
pub mod quality;
pub mod radiosity;
pub mod render;
pub mod scene;
pub mod solve;
pub mod translucent;
