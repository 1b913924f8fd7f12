//! Proves the failure path: a panic must end QEMU with a failing status, never hang.
//! `cargo run --target thumbv7em-none-eabihf -p hemi-firmware --example panic` exits 1.
#![no_std]
#![no_main]

use hemi_firmware as _;

#[cortex_m_rt::entry]
fn main() -> ! {
    defmt::println!("panicking on purpose");
    let v: heapless::Vec<u8, 1> = heapless::Vec::new();
    // An out-of-bounds index, the kind of bug the link code must never have.
    let i = core::hint::black_box(3);
    defmt::println!("unreachable {}", v[i]);
    hemi_firmware::fault::succeed()
}
