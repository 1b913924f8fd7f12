//! One module per command: its arguments (only the options it uses) and what it runs.

pub mod bench;
pub mod board;
pub mod form_factors;
pub mod irradiance;
pub mod render;
pub mod solve;
pub mod trace;
