//! The hemi ray kernel: everything of the generalized two-pass radiosity method that runs on the
//! co-processor, written once and run unchanged on the host and in the firmware.
//!
//! - [`hemisphere`]: the discretised hemisphere and its delta form factors (paper §3.1–3.2)
//! - [`rotation`]: turning the hemisphere onto a normal, as two CORDIC rotations (§3.4)
//! - [`geometry`], [`patch`]: the surfaces rays can hit
//! - [`accel`]: the accelerator trait and the software (f32) engine
//! - [`sampling`]: sample points and their weights (§4.2)
//! - [`optics`], [`frustum`]: which patches are diffuse or specular, and the frustums of the
//!   Phong lobe (§2, §3.3)
//! - [`specular`], [`skeleton`]: indirect transport through frustums with a bounded stack (§6.2)
//! - [`tracer`]: form-factor rows from hemisphere shots, direct and indirect (§3.1, §3.3, §3.4)
//! - [`camera`], [`pixels`]: eye rays of pass 2 (§5)
//! - [`link`]: the wire protocol between host and board, and nothing else
//! - [`jobs`]: a board's job engine, serving the link's job requests with the above
#![no_std]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

#[cfg(any(test, feature = "std"))]
extern crate std;

pub mod accel;
pub mod camera;
pub mod form_row;
pub mod frustum;
pub mod geometry;
pub mod hemisphere;
pub mod jobs;
pub mod link;
pub mod optics;
pub mod patch;
pub mod peers;
pub mod pixels;
pub mod rotation;
pub mod sampling;
pub mod skeleton;
pub mod specular;
pub mod tracer;
