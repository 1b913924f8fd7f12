//! A board's job engine: the uploaded scene and its optics table, the hemisphere table, the
//! tracer's scratch and skeleton stack, all in bounded `heapless` storage, and the jobs of the
//! link (shoot, shoot a level, trace, trace a row, query, gather, hemisphere, cast) over any
//! accelerator.
//!
//! It lives in the kernel (like the link's [`LinkServer`](crate::link::LinkServer), which hands
//! it the requests beyond the link's own through [`JobHandler`](crate::link::JobHandler)) so the
//! exact code the firmware runs is tested on the host too, and so a host can run an in-process
//! board. It depends on the link's messages; the link knows nothing of it.
//!
//! - `capacity`: the fixed budgets ([`ENGINE_CAPACITIES`] in the handshake);
//! - `provider`: the accelerators ([`AccelProvider`], [`AccelJob`], [`SoftProvider`]);
//! - `platform`: the machine's clock and stack ([`Platform`]);
//! - `engine`: the [`Engine`] and its dispatch, `upload`: the scene upload, `config`: the
//!   settings, `store`: the tracer's scratch;
//! - one file per job: `shoot` (`Shoot` and `ShootLevel`), `trace`, `trace_row`, `hemisphere`
//!   (`Query` and `Hemisphere`: one whole hemisphere, a window of its reports), `gather`,
//!   `cast`, with `reports`, how their hits are put on the wire.

mod capacity;
mod cast;
mod config;
mod engine;
mod gather;
mod hemisphere;
mod platform;
mod provider;
mod reports;
mod shoot;
mod store;
mod trace;
mod trace_row;
mod upload;

#[cfg(test)]
mod tests;

pub use capacity::{
    rows_per_job, ENGINE_CAPACITIES, ENGINE_DEFAULT_TRACING, ENGINE_MAX_CIRCLES,
    ENGINE_MAX_IN_FLIGHT, ENGINE_MAX_LOBES, ENGINE_MAX_PATCHES, ENGINE_MAX_QUARTER,
    ENGINE_MAX_RING, ENGINE_PARKED, ENGINE_PENDING, ENGINE_STACK_DEPTH, KERNEL_CAPACITIES,
    RECENT_JOBS,
};
pub use engine::Engine;
pub use platform::{NoPlatform, Platform};
pub use provider::{AccelJob, AccelProvider, SoftProvider};
