//! The storage of the tracer's scratch (parked specular hits, the skeleton stack's frames) in
//! the engine's static SRAM, lent to one job at a time.

use heapless::Vec;

use super::capacity::{ENGINE_PARKED, ENGINE_PENDING, ENGINE_STACK_DEPTH};
use crate::link::message::TraceSettings;
use crate::skeleton::{Frame, Skeleton};
use crate::specular::Pending;
use crate::tracer::TraceScratch;

/// Fills a scratch Vec to its capacity (it starts empty so a static engine stays in `.bss`).
fn fill<T: Copy, const N: usize>(v: &mut Vec<T, N>, value: T) {
    while v.push(value).is_ok() {}
}

/// The storage of the tracer's scratch, in the engine's static SRAM.
pub(super) struct TraceStore {
    pending: Vec<Pending, ENGINE_PENDING>,
    parked: Vec<Pending, ENGINE_PARKED>,
    frames: Vec<Frame, ENGINE_STACK_DEPTH>,
}

impl TraceStore {
    /// Empty buffers (all zero bytes, so a `static` engine stays in `.bss`); a job's
    /// [`scratch`](Self::scratch) fills them.
    pub(super) const fn new() -> Self {
        TraceStore {
            pending: Vec::new(),
            parked: Vec::new(),
            frames: Vec::new(),
        }
    }

    /// The scratch of one job, bounded by `tracing` (its stack at most the frames there are).
    pub(super) fn scratch(&mut self, tracing: TraceSettings) -> TraceScratch<'_> {
        fill(&mut self.pending, Pending::EMPTY);
        fill(&mut self.parked, Pending::EMPTY);
        fill(&mut self.frames, Frame::EMPTY);
        let stack = usize::from(tracing.stack).min(self.frames.len());
        TraceScratch {
            pending: &mut self.pending,
            parked: &mut self.parked,
            skeleton: Skeleton::new(&mut self.frames[..stack]),
            threshold: tracing.threshold,
            max_depth: tracing.max_bounces,
        }
    }
}
