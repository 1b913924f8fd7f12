//! Boards: the co-processor running hemi's firmware, reached over a serial line, as a backend
//! of the hemi library.
//!
//! - [`link`]: request/response client of the wire protocol of `hemi_kernel::link`, with
//!   timeouts and the handshake's retries;
//! - [`qemu`]: boots the firmware in QEMU with UART0 on a pty and never leaves QEMU behind;
//!   [`firmware_log`]: its defmt log, decoded with the ELF's table when asked for;
//! - [`farm`]: a farm of boards taking jobs, several in flight per link, re-issued when a link
//!   fails;
//! - [`backend`]: the passes' requests cut into jobs for the farm ([`Boards`]);
//! - [`index`]: patch indices as boards name them; [`protocol`]: what a farm's boards can do;
//! - [`error`]: which failures are final ([`error::Refused`]) and which are retried;
//! - [`mod@info`]: the handshake of a backend, for `hemi board info`; [`report`]: their counters.
#![forbid(unsafe_code)]

pub mod backend;
pub mod error;
pub mod farm;
pub mod firmware_log;
pub mod index;
pub mod info;
pub mod link;
pub mod protocol;
pub mod qemu;
pub mod report;

pub use backend::Boards;
pub use farm::{BoardSpec, Farm, FarmOptions};
pub use firmware_log::FirmwareLog;
pub use info::{info, BoardInfo};
pub use link::{Handshake, Link, Retry};
pub use qemu::{firmware_elf, qemu_available, Qemu, QemuBoard, QemuOptions};
