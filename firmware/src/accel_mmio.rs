//! The board side of the accelerator driver: [`AccelMmio`] implements
//! [`hemi_hdl_model::driver::RegisterAccess`] by volatile 32-bit reads and writes at the
//! accelerator's base address, so the driver logic (`hemi_hdl_model::driver::Driver`, which is
//! `#![forbid(unsafe_code)]`) runs unchanged against the FPGA. The register map is
//! `docs/register-map.md`.
//!
//! This is the only `unsafe` of the accelerator's software. It stays sound for any offset the
//! trait is called with: offsets outside the register window or not word-aligned never reach the
//! bus (they read 0 and ignore writes, as the device itself treats unmapped offsets), so only
//! addresses inside the accelerator's own decode are ever dereferenced.
#![expect(unsafe_code, reason = "the accelerator's registers are volatile MMIO")]

use core::sync::atomic::{AtomicBool, Ordering};
use hemi_hdl_model::driver::RegisterAccess;

/// Where hemi's FPGA image decodes the accelerator: the start of the MPS2+ AHB expansion
/// region, after the CMSDK APB peripherals (UART0 is at 0x4000_4000). Under QEMU's
/// `mps2-an386` nothing is implemented there: reads return 0 without a fault (field notes), so
/// `Driver::new` reports `WrongDevice { id: 0, .. }` instead of hanging or faulting.
pub const ACCEL_BASE: usize = 0x4010_0000;

/// Bytes of the accelerator's register decode (the registers end at 0x0AC; the FPGA decodes a
/// 4 KiB page and reads 0 from the rest).
pub const ACCEL_WINDOW: u32 = 0x1000;

/// Guards against a second owner: the driver's FIFO and patch-window sequences assume nobody
/// else touches the registers in between.
static TAKEN: AtomicBool = AtomicBool::new(false);

/// Exclusive access to the accelerator's registers on the board.
#[derive(Debug)]
pub struct AccelMmio {
    base: usize,
}

impl AccelMmio {
    /// The accelerator at [`ACCEL_BASE`], once: `None` if it was taken already.
    pub fn take() -> Option<Self> {
        if TAKEN.swap(true, Ordering::AcqRel) {
            return None;
        }
        Some(AccelMmio { base: ACCEL_BASE })
    }

    /// The address of the register at `offset`, if it is a word inside the window.
    fn register(&self, offset: u32) -> Option<usize> {
        (offset < ACCEL_WINDOW && offset.is_multiple_of(4)).then(|| self.base + offset as usize)
    }
}

impl RegisterAccess for AccelMmio {
    fn read(&mut self, offset: u32) -> u32 {
        match self.register(offset) {
            // SAFETY: `addr` is a word-aligned address inside the accelerator's 4 KiB register
            // decode at ACCEL_BASE, a device region (not memory Rust owns) that is mapped for
            // 32-bit reads on the board and reads as 0 in QEMU. The read must be volatile: reads
            // of RESULT_OUT, CYCLE_LO and BUSY_LO have side effects and must happen exactly once
            // each, in program order.
            Some(addr) => unsafe { core::ptr::read_volatile(addr as *const u32) },
            None => 0,
        }
    }

    fn write(&mut self, offset: u32, value: u32) {
        if let Some(addr) = self.register(offset) {
            // SAFETY: as in `read`: a word-aligned device register inside the accelerator's
            // decode. Volatile, because every write is a command (FIFO pushes, self-clearing
            // control bits, write-1-to-clear flags) that must reach the device once, in order.
            unsafe { core::ptr::write_volatile(addr as *mut u32, value) }
        }
    }
}
