//! The register map (documented with reset values and side effects in `docs/register-map.md`).
//! All registers are 32 bits wide at word-aligned byte offsets from the accelerator's base.

/// Identification, read-only: "HEMI".
pub const ID: u32 = 0x000;
/// Version, read-only: major in 31:16, minor in 15:0.
pub const VERSION: u32 = 0x004;
/// Capabilities, read-only: ray FIFO depth 7:0, result FIFO depth 15:8, patch capacity 31:16.
pub const CAPS: u32 = 0x008;
/// Control: ENABLE and the self-clearing command bits.
pub const CTRL: u32 = 0x00C;
/// Status, read-only.
pub const STATUS: u32 = 0x010;
/// Error flags, write 1 to clear.
pub const ERROR: u32 = 0x014;
/// Interrupt flags, write 1 to clear.
pub const IRQ_STATUS: u32 = 0x018;
/// Interrupt enables.
pub const IRQ_ENABLE: u32 = 0x01C;
/// Configuration to apply (CTRL.APPLY_CONFIG).
pub const CONFIG: u32 = 0x020;
/// Configuration in force, read-only.
pub const CONFIG_ACTIVE: u32 = 0x024;
/// Cycle counter low word; reading it latches the high word.
pub const CYCLE_LO: u32 = 0x028;
/// Cycle counter high word as latched by the last CYCLE_LO read.
pub const CYCLE_HI: u32 = 0x02C;
/// Busy-cycle counter low word; reading it latches the high word.
pub const BUSY_LO: u32 = 0x030;
/// Busy-cycle counter high word as latched.
pub const BUSY_HI: u32 = 0x034;
/// Results produced since reset (wraps).
pub const RESULTS_DONE: u32 = 0x038;
/// What a ray entry does (latched per entry).
pub const MODE: u32 = 0x040;
/// Ray origin x (Q8.24, latched per entry); y and z follow.
pub const ORIGIN_X: u32 = 0x044;
/// Ray origin y.
pub const ORIGIN_Y: u32 = 0x048;
/// Ray origin z.
pub const ORIGIN_Z: u32 = 0x04C;
/// Frame normal x (Q2.30) for CTRL.FRAME_NORMAL.
pub const NORMAL_X: u32 = 0x050;
/// Frame normal y.
pub const NORMAL_Y: u32 = 0x054;
/// Frame normal z.
pub const NORMAL_Z: u32 = 0x058;
/// cos ψ (Q2.30), both frame commands.
pub const SPIN_C: u32 = 0x05C;
/// sin ψ.
pub const SPIN_S: u32 = 0x060;
/// cos φ for CTRL.FRAME_PAIRS.
pub const PHI_C: u32 = 0x064;
/// sin φ.
pub const PHI_S: u32 = 0x068;
/// cos θ for CTRL.FRAME_PAIRS.
pub const THETA_C: u32 = 0x06C;
/// sin θ.
pub const THETA_S: u32 = 0x070;
/// ψ of the frame in force (Q3.29), read-only.
pub const FRAME_PSI: u32 = 0x074;
/// θ of the frame in force.
pub const FRAME_THETA: u32 = 0x078;
/// φ of the frame in force.
pub const FRAME_PHI: u32 = 0x07C;
/// Ray FIFO input: three writes (x, y, z of the direction, Q2.30) make one entry.
pub const RAY_IN: u32 = 0x080;
/// Result FIFO output: four reads make one result (two for a result flagged SHORT).
pub const RESULT_OUT: u32 = 0x084;
/// Patch memory word address (auto-increments on PATCH_DATA access).
pub const PATCH_ADDR: u32 = 0x090;
/// Patch memory data window.
pub const PATCH_DATA: u32 = 0x094;
/// Wait states of a PATCH_DATA read (writes have none): patch memory's block RAMs are read at
/// PATCH_ADDR, each group's word is registered, then the word of each four groups', then the
/// word of PATCH_ADDR's group, before it goes to the bus, so that neither the address's logic
/// nor the RAMs' slow output lies in one clock with the bus or with a wide multiplexer over the
/// RAMs (`rtl/ahb_regs.v`; since session 25, none before; three until session 26). A read's
/// clocks are these and its data phase's ([`read_waits`]).
pub const PATCH_DATA_READ_WAITS: u64 = 4;

/// Wait states of a read of the register at `offset`, which a bus master sees as clocks
/// before the read's data phase: [`PATCH_DATA_READ_WAITS`] for PATCH_DATA, none for the rest.
pub const fn read_waits(offset: u32) -> u64 {
    if offset == PATCH_DATA {
        PATCH_DATA_READ_WAITS
    } else {
        0
    }
}
/// Number of patch slots scanned per ray.
pub const PATCH_COUNT: u32 = 0x098;
/// Patch the following ray entries skip (bit 31 enables; latched per entry).
pub const SKIP_PATCH: u32 = 0x09C;
/// Subdivision configuration to apply (CTRL.APPLY_CONFIG, together with CONFIG).
pub const BZ_CONFIG: u32 = 0x0A0;
/// Subdivision configuration in force, read-only.
pub const BZ_CONFIG_ACTIVE: u32 = 0x0A4;
/// Bezier capabilities, read-only: control-point rows 15:0, stack entries 23:16, maximum depth
/// 31:24.
pub const CAPS_BEZIER: u32 = 0x0A8;
/// Most subdivision stack entries in use at once since reset or APPLY_CONFIG, read-only.
pub const STACK_HIGH: u32 = 0x0AC;
/// Build parameters, read-only (1.3): lanes 7:0, rays per clock 15:8, culling sectors 23:16
/// (0: no culling), bit 24 the stream port.
pub const CAPS_LANES: u32 = 0x0B0;

/// ID register value.
pub const ID_VALUE: u32 = 0x4845_4D49;
/// VERSION register value: 1.4 (1.1 added the Bezier unit: BZ_CONFIG, SKIP_PATCH, the
/// control-point memory; 1.2 added MODE.NO_UV and SHORT results; 1.3 added CAPS_LANES, the
/// lanes, the culling unit and the stream port; 1.4 added CAPS_LANES' compact-datapath bit and
/// ray groups. A 1.0 driver still works against it: it never sets the new bit, so it never sees
/// a short result, and it never needs the stream port).
pub const VERSION_VALUE: u32 = 0x0001_0004;

/// CTRL bits.
pub mod ctrl {
    /// Process ray entries (R/W). Entries wait in the FIFO while clear.
    pub const ENABLE: u32 = 1 << 0;
    /// Queue a frame from NORMAL_* and SPIN_* (self-clearing).
    pub const FRAME_NORMAL: u32 = 1 << 1;
    /// Queue a frame from PHI_*, THETA_*, SPIN_* (self-clearing).
    pub const FRAME_PAIRS: u32 = 1 << 2;
    /// Validate CONFIG and apply it (self-clearing; refused while busy or invalid).
    pub const APPLY_CONFIG: u32 = 1 << 3;
    /// Soft reset (self-clearing).
    pub const SOFT_RESET: u32 = 1 << 31;
}

/// STATUS bits and fields.
pub mod status {
    /// Work is queued or in flight.
    pub const BUSY: u32 = 1 << 0;
    /// The angle unit is computing a frame.
    pub const FRAME_BUSY: u32 = 1 << 1;
    /// A frame has been computed since reset.
    pub const FRAME_VALID: u32 = 1 << 2;
    /// The ray FIFO is full.
    pub const RAY_FULL: u32 = 1 << 3;
    /// At least one result can be read.
    pub const RESULT_READY: u32 = 1 << 4;
    /// Ray FIFO level (entries), bits 15:8.
    pub const RAY_LEVEL_SHIFT: u32 = 8;
    /// Result FIFO level (results), bits 23:16.
    pub const RESULT_LEVEL_SHIFT: u32 = 16;
}

/// ERROR bits (write 1 to clear).
pub mod error {
    /// An entry was written to a full ray FIFO and dropped.
    pub const RAY_OVERFLOW: u32 = 1 << 0;
    /// RESULT_OUT was read with no result ready (read returned 0).
    pub const RESULT_UNDERFLOW: u32 = 1 << 1;
    /// CONFIG or MODE held a value outside the supported range; nothing changed.
    pub const BAD_CONFIG: u32 = 1 << 2;
    /// APPLY_CONFIG while busy; nothing changed.
    pub const CONFIG_BUSY: u32 = 1 << 3;
    /// A rotate entry reached the rotator before any frame: its result has the ERROR flag.
    pub const NO_FRAME: u32 = 1 << 4;
    /// PATCH_ADDR or PATCH_COUNT outside the memory.
    pub const PATCH_RANGE: u32 = 1 << 5;
    /// A patch slot of an unsupported kind was scanned (and skipped).
    pub const UNSUPPORTED_PATCH: u32 = 1 << 6;
    /// Patch memory or PATCH_COUNT written while busy; the write was ignored.
    pub const PATCH_BUSY: u32 = 1 << 7;
    /// The subdivision stack was full at a push: a subtree was dropped, a hit may be missing.
    pub const STACK_OVERFLOW: u32 = 1 << 8;
}

/// IRQ_STATUS / IRQ_ENABLE bits.
pub mod irq {
    /// A result was pushed into the result FIFO.
    pub const RESULT: u32 = 1 << 0;
    /// BUSY fell.
    pub const IDLE: u32 = 1 << 1;
    /// An ERROR bit was set.
    pub const ERROR: u32 = 1 << 2;
    /// A frame completed.
    pub const FRAME: u32 = 1 << 3;
}

/// CONFIG fields.
pub mod config {
    /// CORDIC iterations, bits 4:0.
    pub const ITER_SHIFT: u32 = 0;
    /// CORDIC word width, bits 13:8.
    pub const WIDTH_SHIFT: u32 = 8;
    /// (u,v) subdivision depth, bits 20:16.
    pub const DEPTH_SHIFT: u32 = 16;
    /// Fewest (u,v) levels.
    pub const MIN_DEPTH: u32 = 1;
    /// Most (u,v) levels.
    pub const MAX_DEPTH: u32 = 24;
}

/// BZ_CONFIG fields.
pub mod bz_config {
    /// Maximum subdivision depth D, bits 4:0 (1..=16, and 3·D ≤ the stack entries).
    pub const DEPTH_SHIFT: u32 = 0;
    /// Control-point datapath width Wc, bits 13:8 (12..=26).
    pub const CWIDTH_SHIFT: u32 = 8;
}

/// SKIP_PATCH bits.
pub mod skip {
    /// Skip the patch in 23:0.
    pub const ENABLE: u32 = 1 << 31;
}

/// MODE values: the kind of entry in 1:0, and the NO_UV flag.
pub mod mode {
    /// The kind of entry (TRACE, ROTATE or ROTATE_TRACE).
    pub const KIND_MASK: u32 = 0x3;
    /// Trace entries only: the caller does not want (u,v). The result is SHORT (two words, so
    /// two bus reads fewer per ray) and the (u,v) unit's stages are not enabled for the entry
    /// (clock-gated: the entry still takes its place in the pipe, so no clock count changes).
    /// Pass 1 asks for patch and distance only, which is most of the rays.
    pub const NO_UV: u32 = 1 << 8;
    /// Trace the direction as given (scene space).
    pub const TRACE: u32 = 0;
    /// Rotate the direction by the frame; the result is the direction.
    pub const ROTATE: u32 = 1;
    /// Rotate by the frame, then trace.
    pub const ROTATE_TRACE: u32 = 2;
}

/// Flags of a result's word 0 (words 1–3: t, u, v for traces; x, y, z for rotations).
pub mod result {
    /// The ray hit a patch (patch index in 23:0).
    pub const HIT: u32 = 1 << 31;
    /// The hit is on the front side.
    pub const FRONT: u32 = 1 << 30;
    /// The entry failed (see ERROR); the other words are 0.
    pub const ERROR: u32 = 1 << 29;
    /// Words 1–3 are a rotated direction.
    pub const ROTATED: u32 = 1 << 28;
    /// The result is two words (flags and t; no u, v): a trace entry with MODE.NO_UV.
    pub const SHORT: u32 = 1 << 27;
    /// Patch index mask.
    pub const PATCH_MASK: u32 = 0x00FF_FFFF;
}
