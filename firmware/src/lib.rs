//! hemi's co-processor firmware: boots on a Cortex-M4F (QEMU `mps2-an386` or an MPS2+ board),
//! serves the link protocol of `hemi_kernel::link` over UART0 and runs the kernel's jobs
//! (scene upload, hemisphere shots, pixel and gather rays) on its accelerator.
//!
//! The library holds everything the binary and the on-target tests share: the UART driver
//! ([`uart`], the only `unsafe` code besides the entry), the job loop and engine ([`job`]), the
//! accelerators ([`accel`]), the SysTick clock ([`clock`]), the handshake contents ([`board`])
//! and the failure path ([`fault`]). Nothing that arrives on the wire can panic it.
#![no_std]
#![deny(unsafe_code)]

// Linked for their side effects: the critical-section implementation, the vector table and
// runtime, and the defmt logger (field notes: without these, linking fails). The logger is
// semihosting under QEMU, which prints it on QEMU's stdout, and RTT on a board, where
// semihosting without a debugger would fault; panic-probe comes with RTT and is the board's
// panic handler.
use cortex_m as _;
use cortex_m_rt as _;
#[cfg(feature = "qemu")]
use defmt_semihosting as _;
#[cfg(feature = "rtt")]
use {defmt_rtt as _, panic_probe as _};

#[cfg(all(feature = "qemu", feature = "rtt"))]
compile_error!(
    "features `qemu` (log over semihosting) and `rtt` (log over RTT) exclude each other"
);
#[cfg(not(any(feature = "qemu", feature = "rtt")))]
compile_error!(
    "the firmware needs a log transport: feature `qemu` (the default) or `rtt` (`board` has it)"
);

pub mod accel;
pub mod accel_mmio;
pub mod board;
pub mod clock;
pub mod fault;
pub mod job;
pub mod uart;
