//! Firmware entry: paint the stack, start SysTick and UART0, then serve the link and its jobs
//! forever.
//!
//! The job engine (scene, hemisphere table, scratch: tens of KiB) is a `static` built by a
//! `const fn`, so it sits in `.bss`/`.data` where the size tool sees it and is never copied
//! through the stack. Taking the one `&'static mut` to it, painting the stack and reading it back
//! for the high-water mark are the entry's only `unsafe` code.
#![no_std]
#![no_main]
#![deny(unsafe_code)]

use cortex_m_rt::{entry, exception};
use embedded_io::Read;
use hemi_firmware::job::{new_engine, FwEngine, FwPlatform, JobLoop, NO_PLATFORM};
use hemi_firmware::{board, clock, uart};

/// The job engine. Only `main` touches it, once, through the `&'static mut` it takes below.
static mut ENGINE: FwEngine = new_engine(NO_PLATFORM);

/// The pattern unused stack words hold.
const PAINT: u32 = 0x5AC4_5AC4;
/// At most this much of the stack (from its top) is painted and measured. A QEMU model build has
/// megabytes of stack (building the model moves its state through the stack several times: with
/// the lanes' FIFOs and candidate lists, ~250 KiB of it, beyond 1 MiB deep, as measured by the
/// HIL tests), painting them all would only cost time; other builds have what RAM leaves, well
/// below this.
const MEASURED: usize = 3 * 1024 * 1024;

extern "C" {
    static _stack_start: u32;
    static _stack_end: u32;
}

/// The measured stack region: (lowest address, top).
fn stack_region() -> (usize, usize) {
    // Only the addresses of the linker's symbols are taken, never their contents.
    let (top, end) = (
        core::ptr::addr_of!(_stack_start) as usize,
        core::ptr::addr_of!(_stack_end) as usize,
    );
    (end.max(top.saturating_sub(MEASURED)), top)
}

/// Fills the unused part of the measured stack with [`PAINT`].
#[expect(unsafe_code, reason = "writes the unused stack below the live frames")]
fn paint_stack() {
    let (low, _) = stack_region();
    let here = cortex_m::register::msp::read() as usize;
    // Leave a margin below the current frame: this function's own locals live there.
    let mut p = low;
    while p + 256 < here {
        // SAFETY: [low, here - 256) is stack memory below every live frame (the stack grows
        // down from `top`, and `here` is the current stack pointer); nothing else uses it.
        unsafe { core::ptr::write_volatile(p as *mut u32, PAINT) };
        p += 4;
    }
}

/// (deepest stack use, measured stack size) in bytes: the first word from the bottom that lost
/// its paint marks how deep the stack has ever been.
#[expect(unsafe_code, reason = "reads the painted stack")]
fn stack_use() -> (u32, u32) {
    let (low, top) = stack_region();
    let mut p = low;
    // SAFETY: reads of aligned words inside the stack region, which is RAM.
    while p < top && unsafe { core::ptr::read_volatile(p as *const u32) } == PAINT {
        p += 4;
    }
    ((top - p) as u32, (top - low) as u32)
}

#[entry]
fn main() -> ! {
    paint_stack();
    let Some(cp) = cortex_m::Peripherals::take() else {
        defmt::panic!("core peripherals taken twice");
    };
    clock::start(cp.SYST);
    let Some((mut tx, mut rx)) = uart::take(uart::BAUDDIV_115200) else {
        defmt::panic!("UART0 taken twice");
    };
    // SAFETY: `main` runs once and never returns, and this is the only place that names
    // `ENGINE`: the one mutable reference to it exists for the rest of the program.
    #[expect(unsafe_code, reason = "the one `&'static mut` to the static engine")]
    let engine: &'static mut FwEngine = unsafe { &mut *core::ptr::addr_of_mut!(ENGINE) };
    engine.platform = FwPlatform {
        stack: Some(stack_use),
        clock: true,
    };
    defmt::info!(
        "{=str} up: UART0 at {=usize:#x}, accelerator {=str}",
        board::BUILD,
        uart::UART0_BASE,
        match hemi_firmware::accel::FwAccel::native() {
            hemi_kernel::link::AccelKind::Model => "model",
            hemi_kernel::link::AccelKind::Mmio => "registers (if they answer)",
            _ => "soft",
        }
    );
    if let Some(slots) = engine.provider.attach_mmio() {
        defmt::info!(
            "accelerator found by its ID register: {=u32} patch slots",
            slots
        );
    }
    let mut job = JobLoop::new(board::hello_info());
    let mut chunk = [0u8; 64];
    loop {
        let Ok(n) = rx.read(&mut chunk);
        job.note_rx_overrun(rx.take_overruns());
        let Ok(()) = job.feed_with(chunk.get(..n).unwrap_or_default(), &mut tx, engine);
    }
}

/// SysTick wrapped: extends the tick count.
#[exception]
fn SysTick() {
    clock::on_systick();
}

/// Device interrupts. Without a PAC, cortex-m-rt routes every device interrupt here; UART0's
/// receive interrupt is the only one enabled.
// `allow`, not `expect`: `#[exception]` copies the attribute onto the items it generates, and
// on one of them the lint does not fire, so an expectation there would be unfulfilled.
#[allow(
    unsafe_code,
    reason = "cortex-m-rt requires DefaultHandler to be `unsafe fn`"
)]
#[exception]
unsafe fn DefaultHandler(irqn: i16) {
    if irqn == uart::UART0_RX_IRQ as i16 {
        uart::on_rx_interrupt();
    }
}
