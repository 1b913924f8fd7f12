//! The boards' counters on stderr: engine (jobs, rays, CPU ticks per ray, stack, link bytes)
//! and, in specular scenes, frustums (what `docs/PERFORMANCE.md`'s firmware section is
//! measured with).

use crate::farm::Farm;
use hemi_kernel::link::AccelKind;

/// Prints each board's engine counters to stderr (jobs, rays, CPU ticks per ray, stack, link
/// bytes): what `docs/PERFORMANCE.md`'s firmware section is measured with.
pub fn report(farm: &Farm, what: &str) {
    for (i, s) in farm.engine_stats().into_iter().enumerate() {
        match s {
            Ok(s) => eprintln!(
                "board {i}: {what}: {:?} engine, {} jobs ({} repeated, {} refused), {} rays, \
                 {} SysTick ticks = {:.1} ticks/ray, {} accelerator cycles, stack {} of {} bytes, \
                 link {} bytes in / {} bytes out, {} damaged frames",
                s.accel.unwrap_or(AccelKind::None),
                s.jobs,
                s.repeats,
                s.refused,
                s.rays,
                s.cpu_ticks,
                s.cpu_ticks as f64 / s.rays.max(1) as f64,
                s.accel_cycles,
                s.stack_high_water,
                s.stack_size,
                s.link.bytes_rx,
                s.link.bytes_tx,
                s.link.bad_crc + s.link.bad_framing + s.link.too_long
            ),
            Err(e) => eprintln!("board {i}: no counters: {e:#}"),
        }
    }
    if !farm.specular() {
        return;
    }
    for (i, t) in farm.trace_stats().into_iter().enumerate() {
        if let Ok(t) = t {
            eprintln!(
                "board {i}: {what}: {} frustums, {} frustum rays; stack high-water {}/{} frames \
                 (capacity {}); cut: {} below Δ, {} too deep, {} overflows, weight {:.2e}; {} \
                 extra hemisphere casts (park of {})",
                t.frustums,
                t.frustum_rays,
                t.stack_high_water,
                t.stack_frames,
                t.stack_capacity,
                t.below_threshold,
                t.too_deep,
                t.overflows,
                t.cut_weight,
                t.recasts,
                t.pending_capacity
            );
        }
    }
}
