//! The board engine's fixed budgets: every table of the engine is a `heapless` buffer of one of
//! these sizes, so a board's RAM use is known at link time, and the handshake reports them
//! ([`ENGINE_CAPACITIES`]) so a host never sends what a board cannot hold.

use crate::hemisphere::MAX_CIRCLES;
use crate::link::message::{Capacities, TraceSettings, MAX_ROWS, MAX_ROW_ENTRIES};
use crate::link::MAX_FRAME_LEN;
use crate::specular::DEFAULT_THRESHOLD;

/// Patches a board's engine stores (the Cornell box has 19, the teapot scene 34).
pub const ENGINE_MAX_PATCHES: usize = 48;
/// Largest hemisphere (circles R) a board's engine builds. R = 64 (the host's default) would need
/// 9 KiB more for the quarter table, which a 64 KiB part cannot spare next to the stack the
/// Bezier subdivision needs (docs/PERFORMANCE.md, firmware RAM); builds with RAM to spare
/// (feature `large-engine`: QEMU's model builds) take R ≤ 256, so that a query's own
/// hemisphere at four times the host's default R fits (325 KiB of quarter table).
#[cfg(not(feature = "large-engine"))]
pub const ENGINE_MAX_CIRCLES: usize = 48;
/// Largest hemisphere (circles R) a board's engine builds (feature `large-engine`).
#[cfg(feature = "large-engine")]
pub const ENGINE_MAX_CIRCLES: usize = 256;
/// Quarter-table entries of the largest hemisphere: `hemisphere::quarter_len(48)`.
#[cfg(not(feature = "large-engine"))]
pub const ENGINE_MAX_QUARTER: usize = 1442;
/// Quarter-table entries of the largest hemisphere: `hemisphere::quarter_len(256)`.
#[cfg(feature = "large-engine")]
pub const ENGINE_MAX_QUARTER: usize = 41599;
/// Rays on the largest ring of the largest hemisphere (4R): the soft engine's per-ring scratch.
pub const ENGINE_MAX_RING: usize = 4 * ENGINE_MAX_CIRCLES;
/// Jobs a host may keep in flight: their requests (≤ 16 bytes each) sit in the board's receive
/// ring while it works.
pub const ENGINE_MAX_IN_FLIGHT: usize = 8;
/// Recent job ids remembered to recognise repeats.
pub const RECENT_JOBS: usize = 64;
/// Frames of the skeleton stack (paper §6.2) the engine keeps in SRAM.
pub const ENGINE_STACK_DEPTH: usize = 16;
/// Primary specular hits the tracer parks per hemisphere cast; more make it cast the hemisphere
/// again for the next window of them (same rows, more rays; `TraceStats::recasts`).
pub const ENGINE_PENDING: usize = 32;
/// Specular hits one frustum may park (frustum rays reaching another specular patch); beyond,
/// they are cut and counted as overflows.
pub const ENGINE_PARKED: usize = 16;
/// Entries of the lobe-weight table: k + 1 per specular material, k < R (a few materials with
/// the widest lobes of the largest hemisphere).
pub const ENGINE_MAX_LOBES: usize = 2 * ENGINE_MAX_CIRCLES + 32;
/// The specular settings until the host sends its own: the host's defaults, with the board's
/// stack.
pub const ENGINE_DEFAULT_TRACING: TraceSettings = TraceSettings {
    threshold: DEFAULT_THRESHOLD,
    max_bounces: 24,
    stack: ENGINE_STACK_DEPTH as u16,
};

/// What a board's engine reports in the handshake.
pub const ENGINE_CAPACITIES: Capacities = Capacities {
    max_patches: ENGINE_MAX_PATCHES as u16,
    max_sample_rows: MAX_ROWS as u16,
    stack_depth: ENGINE_STACK_DEPTH as u16,
    max_frame_len: MAX_FRAME_LEN as u16,
    max_circles: ENGINE_MAX_CIRCLES as u16,
    max_in_flight: ENGINE_MAX_IN_FLIGHT as u16,
};

/// How many sample points of a scene with `patches` patches fit one [`Request::Shoot`](crate::link::Request::Shoot) job
/// (every row can hold one entry per patch): what hosts ask for and boards accept.
pub fn rows_per_job(patches: usize) -> u16 {
    let per = MAX_ROW_ENTRIES / patches.max(1);
    per.clamp(1, MAX_ROWS) as u16
}

/// The kernel's fixed budgets, reported in the handshake by every backend that runs the kernel.
///
/// In-process engines (the host's soft and model backends) have no fixed tables; these are the
/// budgets they report. A board's engine reports [`ENGINE_CAPACITIES`], which it enforces.
pub const KERNEL_CAPACITIES: Capacities = Capacities {
    max_patches: 256,
    max_sample_rows: 64,
    stack_depth: 16,
    max_frame_len: MAX_FRAME_LEN as u16,
    max_circles: MAX_CIRCLES as u16,
    max_in_flight: 1,
};
