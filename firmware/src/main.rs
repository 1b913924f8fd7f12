//! Firmware entry: set up UART0, then serve the link forever.
#![no_std]
#![no_main]
#![deny(unsafe_code)]

use cortex_m_rt::{entry, exception};
use embedded_io::Read;
use hemi_firmware::{board, job::JobLoop, uart};

#[entry]
fn main() -> ! {
    let Some((mut tx, mut rx)) = uart::take(uart::BAUDDIV_115200) else {
        defmt::panic!("UART0 taken twice");
    };
    defmt::println!(
        "{=str} up: UART0 at {=usize:#x}",
        board::BUILD,
        uart::UART0_BASE
    );
    let mut job = JobLoop::new(board::hello_info());
    let mut chunk = [0u8; 64];
    loop {
        let Ok(n) = rx.read(&mut chunk);
        job.note_rx_overrun(rx.take_overruns());
        let Ok(()) = job.feed(chunk.get(..n).unwrap_or_default(), &mut tx);
    }
}

/// Device interrupts. Without a PAC, cortex-m-rt routes every device interrupt here; UART0's
/// receive interrupt is the only one enabled.
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
