//! The accelerator of paper §6 as a cycle-level model, with its register map and driver.
//!
//! - [`cordic`]: the CORDIC pipes (rotation and vectoring mode, §3.4);
//! - [`frame`]: the angle unit (normal → φ, θ by vectoring);
//! - [`rotator`]: three rotation pipes that turn hemisphere rays onto the frame;
//! - [`intersect`]: nearest hit over patch memory, with t and (u,v) (§6.1);
//! - `area` (hosts): the area proxy of a build and its mapping onto an ECP5;
//! - [`params`]: the build parameters (lanes, culling sectors, front-end width);
//! - [`device`]: register file, FIFOs and control around them, one [`device::Device::tick`] per
//!   clock;
//! - [`regs`]: the register map (`docs/register-map.md`);
//! - [`driver`]: the driver, generic over [`driver::RegisterAccess`] (the model here, volatile
//!   MMIO in the firmware);
//! - [`accel`]: [`accel::RegisterAccelerator`], the kernel's `Accelerator` on top of the driver
//!   over any register access, and [`accel::ModelAccelerator`], that over the model's bus;
//!   on hosts `accel::StreamingModel`, which streams a scene larger than patch memory
//!   through it in blocks;
//!
//! The datapath is integer/fixed point only; f32 appears only in [`accel`], where the kernel's
//! values are converted to register words and back.
#![no_std]
#![forbid(unsafe_code)]

pub mod accel;
#[cfg(feature = "alloc")]
pub mod area;
pub mod cordic;
pub mod device;
pub mod driver;
pub mod fifo;
pub mod format;
pub mod frame;
pub mod intersect;
pub mod params;
pub mod pipe;
pub mod regs;
pub mod rotator;
pub mod table;

#[cfg(feature = "alloc")]
pub use accel::StreamingModel;
pub use accel::{ModelAccelerator, ModelConfig, ModelError, RegisterAccelerator};
pub use driver::{Driver, DriverError, ModelBus, RegisterAccess, StreamPort};
pub use params::Params;
