//! Co-simulation vectors for the accelerator's RTL (`hdl-model/rtl/`): the model's units driven
//! clock by clock, every input and output written with its clock, for the Verilator testbenches
//! (`hdl-model/rtl/tb/`) to drive the RTL with the same inputs at the same clocks and compare
//! its outputs bit for bit and clock for clock (`cargo xtask rtl`); for units the model gives
//! no clocks of their own (the coarse edge units), the inputs and outputs in order.
//!
//! - [`coarse`]: the compact datapath's coarse edge units (the set-up unit's edge words, a
//!   lane's test on them);
//! - [`cordic`]: the rotator and the angle unit's vectoring pipe;
//! - [`cull`]: the culling unit's ray side (a ray's sector and band);
//! - [`reach`]: the culling unit's patch side (a patch's sectors and bands);
//! - [`setup`]: the compact set-up unit (a patch's plane test, edge words and reach, per origin);
//! - [`horizon`]: the horizon filter and the slot boxes it reads;
//! - [`bank`]: a bank's set-up pass ahead of its set-up unit (boxes, filter, FIFO, corner reads);
//! - [`plane`]: the planar intersection unit with (u,v) (one lane, no culling);
//! - [`regs`]: the register file and its AHB-Lite bus interface;
//! - [`writer`]: a bank's bitmap writer (the set-up answers into the candidate bitmaps);
//! - [`walk`]: a lane's bitmap walk (a ray's candidates out of those bitmaps, in slot order);
//! - [`exact`]: the compact datapath's shared exact edge unit (the pairs the lanes' coarse test
//!   leaves undecided);
//! - [`group_plane`]: a compact build's plane unit (a ray group's pairs found inside, each
//!   ray's nearest hit);
//! - [`accel`]: the whole accelerator of the one-lane build, through its bus (the register
//!   driver's accesses, every read compared).

pub mod accel;
pub mod bank;
pub mod coarse;
pub mod cordic;
pub mod cull;
pub mod exact;
pub mod group_plane;
pub mod horizon;
pub mod plane;
pub mod reach;
pub mod regs;
pub mod setup;
pub mod walk;
pub mod writer;

/// A vector file being written for a bench of the culling unit or the set-up unit: the model's
/// unit that answers, the text, and what the file holds so far (each file's own `Counts`).
struct UnitVectors<C> {
    unit: hemi_hdl_model::intersect::cull::CullUnit,
    text: String,
    counts: C,
}
