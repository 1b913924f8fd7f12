//! What happens when the firmware fails: a panic or a HardFault ends QEMU with a failing
//! status (feature `qemu`, the default) so a test run can never hang; on a board (feature off,
//! where a semihosting call without a debugger would itself fault) the chip resets.
//!
//! The panic handler is this module's under QEMU, and panic-probe's on a board (feature `rtt`):
//! it logs the panic and raises a HardFault, where `probe-rs run` stops and shows the backtrace;
//! without a probe, the HardFault handler below resets the chip.

use cortex_m_rt::{exception, ExceptionFrame};

/// Ends the run with a failure: QEMU exits with status 1.
#[cfg(feature = "qemu")]
pub fn fail() -> ! {
    loop {
        cortex_m_semihosting::debug::exit(cortex_m_semihosting::debug::EXIT_FAILURE);
    }
}

/// Ends the run with a failure: the board resets (and the host's handshake retry reconnects).
#[cfg(not(feature = "qemu"))]
pub fn fail() -> ! {
    cortex_m::peripheral::SCB::sys_reset()
}

/// Ends the run successfully: QEMU exits with status 0 (used by examples and tests).
#[cfg(feature = "qemu")]
pub fn succeed() -> ! {
    loop {
        cortex_m_semihosting::debug::exit(cortex_m_semihosting::debug::EXIT_SUCCESS);
    }
}

#[cfg(feature = "qemu")]
#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    defmt::error!("panic: {}", defmt::Display2Format(info));
    fail()
}

// `allow`, not `expect`: `#[exception]` copies the attribute onto the items it generates, and
// on one of them the lint does not fire, so an expectation there would be unfulfilled.
#[allow(
    unsafe_code,
    reason = "cortex-m-rt requires HardFault handlers to be `unsafe fn`"
)]
#[exception]
unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
    defmt::error!(
        "HardFault: pc={=u32:#010x} lr={=u32:#010x}",
        frame.pc(),
        frame.lr()
    );
    fail()
}
