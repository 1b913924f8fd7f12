//! Calibrates SysTick against instructions under QEMU's `-icount shift=0` (docs/PERFORMANCE.md,
//! "instructions per tick"): a loop of exactly two instructions per pass (`subs`, `bne`) runs
//! for N and 2N passes, and the difference of the SysTick counts gives instructions per tick
//! free of the measurement's own overhead.
//!
//! `HEMI_QEMU_ARGS="-icount shift=0" cargo run --release --target thumbv7em-none-eabihf -p
//! hemi-firmware --example icount` prints the ticks and the ratio, and exits 0.
#![no_std]
#![no_main]

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::SYST;
use hemi_firmware as _;

/// `passes` passes of a two-instruction loop.
#[inline(never)]
fn spin(passes: u32) {
    // SAFETY: a register-only countdown; touches no memory and no stack.
    unsafe {
        core::arch::asm!(
            "2:",
            "subs {0}, {0}, #1",
            "bne 2b",
            inout(reg) passes => _,
            options(nomem, nostack),
        );
    }
}

/// SysTick ticks taken by `spin(passes)` (SysTick counts down; no wrap for the sizes used).
fn ticks_of(passes: u32) -> u32 {
    let before = SYST::get_current();
    spin(passes);
    let after = SYST::get_current();
    before.wrapping_sub(after) & 0x00FF_FFFF
}

#[cortex_m_rt::entry]
fn main() -> ! {
    let Some(cp) = cortex_m::Peripherals::take() else {
        hemi_firmware::fault::fail()
    };
    let mut syst = cp.SYST;
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(0x00FF_FFFF);
    syst.clear_current();
    syst.enable_counter();
    const N: u32 = 1_000_000;
    let t1 = ticks_of(N);
    let t2 = ticks_of(2 * N);
    let dt = t2.saturating_sub(t1);
    // 2 instructions per pass, N more passes
    let milli = if dt == 0 {
        0
    } else {
        (2 * u64::from(N) * 1000) / u64::from(dt)
    };
    defmt::println!(
        "icount: {} passes: {} ticks, {} passes: {} ticks; {} instructions / {} ticks = {}.{:03} instructions per tick",
        N,
        t1,
        2 * N,
        t2,
        2 * N,
        dt,
        milli / 1000,
        milli % 1000
    );
    hemi_firmware::fault::succeed()
}
