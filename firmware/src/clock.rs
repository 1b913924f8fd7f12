//! CPU time by SysTick: a 24-bit down-counter at the core clock, extended to 64 bits by counting
//! its wrap-arounds in the SysTick exception. Under QEMU with `-icount shift=0` it counts
//! instructions deterministically (docs/PERFORMANCE.md has the ratio as measured); DWT CYCCNT
//! reads 0 there.

use core::sync::atomic::{AtomicU32, Ordering};

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::SYST;

/// SysTick reload: the full 24 bits.
pub const RELOAD: u32 = 0x00FF_FFFF;

static WRAPS: AtomicU32 = AtomicU32::new(0);

/// Starts SysTick free-running at the core clock with its exception enabled.
pub fn start(mut syst: SYST) {
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(RELOAD);
    syst.clear_current();
    syst.enable_interrupt();
    syst.enable_counter();
}

/// Call from the SysTick exception: one more wrap-around.
pub fn on_systick() {
    WRAPS.fetch_add(1, Ordering::Relaxed);
}

/// Ticks since [`start`] (wrapping after 2^56 ticks).
pub fn ticks() -> u64 {
    loop {
        let before = WRAPS.load(Ordering::Acquire);
        let current = SYST::get_current();
        // A wrap between the two reads shows as a changed count: read again.
        if WRAPS.load(Ordering::Acquire) == before {
            return u64::from(before) * u64::from(RELOAD + 1) + u64::from(RELOAD - current);
        }
    }
}
