//! Proves the failure path: a HardFault must end QEMU with a failing status, never spin.
//! `cargo run --target thumbv7em-none-eabihf -p hemi-firmware --example hardfault` exits 1.
#![no_std]
#![no_main]

use hemi_firmware as _;

/// Unmapped on mps2-an386: a read raises a BusFault, escalated to HardFault (field notes).
const UNMAPPED: usize = 0x5000_0000;

#[cortex_m_rt::entry]
fn main() -> ! {
    defmt::println!("reading {=usize:#x} on purpose", UNMAPPED);
    // SAFETY: not safe at all, deliberately: the bus error is the point of this example. Nothing
    // Rust owns is at this address, so no Rust-visible memory is corrupted before the fault.
    #[expect(unsafe_code, reason = "the faulting read is the point of the example")]
    let v = unsafe { core::ptr::read_volatile(UNMAPPED as *const u32) };
    defmt::println!("unreachable {}", v);
    hemi_firmware::fault::succeed()
}
