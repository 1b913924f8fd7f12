//! Driver of the CMSDK APB UART (UART0 of the MPS2 boards, at 0x4000_4000): receive is
//! interrupt-driven into a bounded SPSC ring, transmit is polled.
//!
//! This module and the exception signatures cortex-m-rt imposes are the only `unsafe` code of the
//! firmware. Everything above it talks to the UART through `embedded_io::{Read, Write}`, so the
//! job loop can be tested with in-memory buffers.
//!
//! Why interrupts for receive: the UART holds a single received byte, so bytes arriving while
//! the job loop is busy (encoding a reply, later shooting a hemisphere) would be lost if the loop
//! polled. The ring absorbs them; if even the ring fills, lost bytes are counted (`rx_overruns`)
//! and the damaged frame is rejected by its CRC.
#![expect(unsafe_code, reason = "the UART's registers are volatile MMIO")]

use core::cell::RefCell;
use core::convert::Infallible;
use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};

use cortex_m::interrupt::InterruptNumber;
use cortex_m::peripheral::NVIC;
use critical_section::Mutex;
use heapless::spsc::{Consumer, Producer, Queue};

/// Base address of UART0 on mps2-an385/an386/an500 (QEMU and the MPS2+ FPGA board).
pub const UART0_BASE: usize = 0x4000_4000;
/// UART0's receive interrupt: IRQ 0 (its transmit interrupt, IRQ 1, is not used).
pub const UART0_RX_IRQ: u16 = 0;
/// BAUDDIV for 115200 Bd from the MPS2's 25 MHz APB clock. QEMU ignores the rate but requires
/// BAUDDIV ≥ 16.
pub const BAUDDIV_115200: u32 = 25_000_000 / 115_200;
/// Size of the receive ring: 4 KiB is ~0.3 s of QEMU's host→firmware rate, and four full frames.
pub const RX_RING: usize = 4096;

const DATA: usize = 0x00;
const STATE: usize = 0x04;
const CTRL: usize = 0x08;
const INTCLEAR: usize = 0x0C;
const BAUDDIV: usize = 0x10;

const STATE_TX_FULL: u32 = 1 << 0;
const STATE_RX_FULL: u32 = 1 << 1;
const CTRL_TX_EN: u32 = 1 << 0;
const CTRL_RX_EN: u32 = 1 << 1;
const CTRL_RX_INT_EN: u32 = 1 << 3;
const INT_RX: u32 = 1 << 1;

/// The producer half of the ring, used only by the receive interrupt.
static RX_PRODUCER: Mutex<RefCell<Option<Producer<'static, u8>>>> = Mutex::new(RefCell::new(None));
/// Bytes the interrupt had to drop because the ring was full.
static RX_OVERRUNS: AtomicU32 = AtomicU32::new(0);
/// Guards against a second owner of UART0.
static TAKEN: AtomicBool = AtomicBool::new(false);

fn read_reg(off: usize) -> u32 {
    // SAFETY: UART0_BASE + off is one of the UART's 32-bit registers (offsets above), always
    // mapped on the MPS2 machines; a volatile read has no side effect beyond the device's own
    // (reading DATA pops the received byte, which only the interrupt and `init` do).
    unsafe { core::ptr::read_volatile((UART0_BASE + off) as *const u32) }
}

fn write_reg(off: usize, value: u32) {
    // SAFETY: as in `read_reg`; the registers are plain device registers, not memory Rust owns.
    unsafe { core::ptr::write_volatile((UART0_BASE + off) as *mut u32, value) }
}

#[derive(Clone, Copy)]
struct Irq(u16);

// SAFETY: `number` returns a valid device interrupt number of the MPS2 (UART0 RX is IRQ 0).
unsafe impl InterruptNumber for Irq {
    fn number(self) -> u16 {
        self.0
    }
}

/// Sets UART0 up (8N1, receive interrupt on) and returns its two halves; `None` if taken already.
pub fn take(bauddiv: u32) -> Option<(UartTx, UartRx)> {
    if TAKEN.swap(true, Ordering::AcqRel) {
        return None;
    }
    let queue: &'static mut Queue<u8, RX_RING> =
        cortex_m::singleton!(: Queue<u8, RX_RING> = Queue::new())?;
    let (producer, consumer) = queue.split();
    critical_section::with(|cs| RX_PRODUCER.borrow_ref_mut(cs).replace(producer));

    write_reg(CTRL, 0);
    write_reg(BAUDDIV, bauddiv.max(16));
    // Drop a byte left over from before a reset, and any stale interrupt.
    let _ = read_reg(DATA);
    write_reg(INTCLEAR, INT_RX);
    write_reg(CTRL, CTRL_TX_EN | CTRL_RX_EN | CTRL_RX_INT_EN);
    // SAFETY: the handler for this interrupt (`on_rx_interrupt`, via the firmware's
    // DefaultHandler) only touches the producer behind a critical section, so unmasking cannot
    // break a critical section elsewhere.
    unsafe { NVIC::unmask(Irq(UART0_RX_IRQ)) };
    Some((UartTx { _private: () }, UartRx { consumer }))
}

/// Moves every received byte into the ring. Call it from UART0's receive interrupt.
pub fn on_rx_interrupt() {
    // Clear first: a byte arriving while we drain raises the interrupt again instead of being
    // missed.
    write_reg(INTCLEAR, INT_RX);
    critical_section::with(|cs| {
        let mut producer = RX_PRODUCER.borrow_ref_mut(cs);
        while read_reg(STATE) & STATE_RX_FULL != 0 {
            let byte = read_reg(DATA) as u8;
            let stored = producer.as_mut().is_some_and(|p| p.enqueue(byte).is_ok());
            if !stored {
                RX_OVERRUNS.fetch_add(1, Ordering::Relaxed);
            }
        }
    });
}

/// Transmit half: polled, blocks while the UART's one-byte holding register is full.
pub struct UartTx {
    _private: (),
}

impl embedded_io::ErrorType for UartTx {
    type Error = Infallible;
}

impl embedded_io::Write for UartTx {
    fn write(&mut self, buf: &[u8]) -> Result<usize, Infallible> {
        for &b in buf {
            while read_reg(STATE) & STATE_TX_FULL != 0 {}
            write_reg(DATA, u32::from(b));
        }
        Ok(buf.len())
    }

    fn flush(&mut self) -> Result<(), Infallible> {
        while read_reg(STATE) & STATE_TX_FULL != 0 {}
        Ok(())
    }
}

/// Receive half: reads from the ring the interrupt fills.
pub struct UartRx {
    consumer: Consumer<'static, u8>,
}

impl UartRx {
    /// Bytes lost to a full ring since the last call.
    pub fn take_overruns(&mut self) -> u32 {
        RX_OVERRUNS.swap(0, Ordering::Relaxed)
    }

    /// Sleeps until the ring holds at least one byte.
    fn wait(&mut self) {
        while !self.consumer.ready() {
            // Check-then-sleep with interrupts masked: a byte arriving between the check and WFI
            // leaves its interrupt pending, which wakes WFI even while masked; without the mask
            // it could run before WFI and we would sleep with a byte waiting.
            cortex_m::interrupt::disable();
            if !self.consumer.ready() {
                cortex_m::asm::wfi();
            }
            // SAFETY: re-enables the interrupts masked just above; no critical section is open
            // here (critical sections in this firmware are closures that have returned).
            unsafe { cortex_m::interrupt::enable() };
        }
    }
}

impl embedded_io::ErrorType for UartRx {
    type Error = Infallible;
}

impl embedded_io::Read for UartRx {
    /// Blocks until at least one byte arrived, then returns what is there (up to `buf.len()`).
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, Infallible> {
        if buf.is_empty() {
            return Ok(0);
        }
        self.wait();
        let mut n = 0;
        for slot in buf.iter_mut() {
            match self.consumer.dequeue() {
                Some(b) => {
                    *slot = b;
                    n += 1;
                }
                None => break,
            }
        }
        Ok(n)
    }
}
