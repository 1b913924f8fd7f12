//! hemi's host library: scenes, sample points, the backend trait and its in-process engines,
//! pass 1, the radiosity solve, radiosity fields, pass 2 and irradiance queries.
//!
//! From the bottom up (no module imports one further down this list, and `cargo xtask layout`
//! checks that the imports have no cycle): `scene`, `analytic`, `grid`, `transport`; `optics`, `method`,
//! `settings`, `shots`, `matrix`; `backend`; `pass1`; `solve`; `radiosity`, `seams`; then the passes built on
//! them: `direct`, `field`, `adaptive`, `on_demand`, `render`, `irradiance`, `quality`, `overlay`, and
//! `export`, the solution as meshes for viewers (docs/ARCHITECTURE.md).
#![forbid(unsafe_code)]

pub mod adaptive;
pub mod analytic;
pub mod backend;
pub mod contact;
pub mod direct;
pub mod export;
pub mod field;
pub mod footprint;
pub mod grid;
pub mod irradiance;
pub mod matrix;
pub mod method;
pub mod on_demand;
pub mod optics;
pub mod overlay;
pub mod pass1;
pub mod quality;
pub mod radiosity;
pub mod render;
pub mod scene;
pub mod seams;
pub mod settings;
pub mod shots;
pub mod solve;
pub mod transport;
