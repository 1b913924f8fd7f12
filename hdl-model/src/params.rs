//! The accelerator's build parameters: what is fixed when the hardware is synthesised (unlike
//! CONFIG, which software changes at run time), reported by the CAPS and CAPS_LANES registers.
//!
//! - `lanes`: planar intersection lanes. Patch memory and the per-origin set-up are banked by
//!   patch index modulo the banks (`lanes / ray_groups`), each bank with its own set-up unit and
//!   each lane with its own edge unit and divider, so a ray's candidates in different banks are
//!   tested in the same clock.
//! - `sectors`: the azimuth sectors of the hemisphere culling unit (0 turns culling off). Per
//!   origin and frame, every planar patch gets the range of sectors in which its pyramid can be
//!   met; a hemisphere ray in sector s is only handed the patches of that sector.
//! - `bank_slots`: patch slots per bank, so the on-chip patch memory holds `banks × bank_slots`
//!   patches (a model without an allocator holds at most 256 whatever the build says).
//! - `rays_per_clock`: the width of the front end (ray FIFO, rotators, ray queue, result FIFO
//!   and the stream port): how many rays enter and leave per clock.
//! - `ray_groups`: lanes in groups of banks, each group taking every `ray_groups`-th ray over
//!   its own copy of the local memory (patch memory has `lanes / ray_groups` banks).
//! - `compact`: the datapath sized for an ECP5-85k (docs/PERFORMANCE.md, "Area proxy against
//!   lanes"): local memory and candidate bitmaps double-buffered, so the next origin's set-up pass
//!   runs while the lanes still scan the last one's rays. Without it (the wide datapath, whose
//!   one-lane build `hdl-model/rtl/plane_unit.v` mirrors) a set-up pass waits for every lane to
//!   be idle.

/// Most lanes a configuration may have.
pub const MAX_LANES: u32 = 16;
/// Most azimuth sectors.
pub const MAX_SECTORS: u32 = 64;
/// Widest front end.
pub const MAX_RAYS_PER_CLOCK: u32 = 4;
/// Most patch slots on chip: the slots of the PATCH_DATA window below control-point memory
/// (`CP_BASE / PATCH_WORDS`). Until the streaming of larger scenes this said 32,768 (what
/// CAPS's 16 bits hold), and a build of more than 4,096 slots failed to load its scene.
pub const MAX_CAPACITY: u32 =
    crate::intersect::patch_mem::CP_BASE / crate::intersect::patch_mem::PATCH_WORDS as u32;

/// The build parameters.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Params {
    /// Intersection lanes (1..=16).
    pub lanes: u32,
    /// Azimuth sectors of the culling unit: 0 (off) or a power of two in 8..=64.
    pub sectors: u32,
    /// Rays entering and leaving per clock (1..=4).
    pub rays_per_clock: u32,
    /// Patch slots per bank (banks × bank_slots ≤ [`MAX_CAPACITY`]).
    pub bank_slots: u32,
    /// The compact datapath (CAPS_LANES bit 25): double-buffered set-up, coarse edge tests
    /// with a shared exact unit.
    pub compact: bool,
    /// Ray groups (1..=lanes, dividing it; CAPS_LANES bits 31:28 hold groups − 1): the lanes
    /// form this many groups of `lanes / ray_groups` banks, each group holding a copy of the
    /// local memory and taking every `ray_groups`-th ray, so a patch every ray tests costs a
    /// lane 1 / `ray_groups` clocks a ray instead of one.
    pub ray_groups: u32,
}

impl Params {
    /// The default build: 4 lanes in 2 ray groups of 2 banks of 512 slots (1,024 patches; a
    /// larger scene streams through them in blocks), 32 sectors (and the culling unit's 16
    /// polar bands), 2 rays per clock, the compact datapath: the fewest lanes in a power-of-two
    /// number of banks that cast the Cornell box at under 1 cycle a ray and its 1,216-patch
    /// subdivision at under 4 (docs/PERFORMANCE.md, "Builds that fit": 0.99 and 3.86 since
    /// session 39 charged the exact edge unit's latency, 0.98 and 3.85 since session 34
    /// charged the bitmap writer's, 0.96 and 3.77 before session 33 charged its writes; 8
    /// lanes, the default before session 31, give 0.76 and 2.11). Its
    /// area proxy does not fit an ECP5-85k (`area`, session 35: 159,446 LUT4s, 116,591
    /// flip-flops, 270 block RAMs, where 8 lanes take 286,411, 182,923 and 432); of the builds
    /// docs/PERFORMANCE.md lists, two do: one lane at a ray a clock (2.91 and 11.09 cycles a
    /// ray), and two lanes in two groups at a ray a clock (1.53 and 7.39).
    pub const DEFAULT: Params = Params {
        lanes: 4,
        sectors: 32,
        rays_per_clock: 2,
        bank_slots: 512,
        compact: true,
        ray_groups: 2,
    };

    /// The accelerator before this datapath: one lane of 256 slots, no culling, one ray per
    /// clock.
    pub const SINGLE: Params = Params {
        lanes: 1,
        sectors: 0,
        rays_per_clock: 1,
        bank_slots: 256,
        compact: false,
        ray_groups: 1,
    };

    /// Banks of patch memory (and lanes in a group).
    pub fn banks(&self) -> u32 {
        self.lanes / self.ray_groups.max(1)
    }

    /// Rays the intersection unit holds at once, and the device's credits (rays between the ray
    /// FIFO and the result FIFO): 1,023 on the compact datapath, whose set-up pass for the next
    /// origin runs ahead of the last origin's rays only as far as these (`intersect::RAY_SLOTS`);
    /// 255, the result FIFO's depth, on the wide one, as `rtl/plane_unit.v` holds them.
    pub fn ray_slots(&self) -> usize {
        if self.compact {
            crate::intersect::RAY_SLOTS
        } else {
            crate::device::RESULT_FIFO_DEPTH
        }
    }

    /// Patch slots on chip.
    pub fn capacity(&self) -> u32 {
        self.banks() * self.bank_slots
    }

    /// Whether the hardware can be built this way.
    pub fn is_valid(&self) -> bool {
        (1..=MAX_LANES).contains(&self.lanes)
            && (self.sectors == 0
                || (self.sectors.is_power_of_two() && (8..=MAX_SECTORS).contains(&self.sectors)))
            && (1..=MAX_RAYS_PER_CLOCK).contains(&self.rays_per_clock)
            && (1..=self.lanes).contains(&self.ray_groups)
            && self.lanes.is_multiple_of(self.ray_groups)
            && self.ray_groups <= 16
            && self.bank_slots >= 1
            && self.bank_slots <= MAX_CAPACITY / self.banks().max(1)
    }

    /// The CAPS_LANES word: lanes 7:0, rays per clock 15:8, sectors 23:16, bit 24 the stream
    /// port, bit 25 the compact datapath, bits 31:28 ray groups − 1.
    pub fn caps_word(&self) -> u32 {
        self.lanes
            | self.rays_per_clock << 8
            | self.sectors << 16
            | 1 << 24
            | (self.compact as u32) << 25
            | (self.ray_groups.saturating_sub(1) & 0xF) << 28
    }

    /// Decodes a CAPS_LANES word with the patch capacity from CAPS (a CAPS_LANES of 0, from a
    /// device before register map 1.3, is one lane without culling or stream port).
    pub fn from_caps(w: u32, capacity: u32) -> Params {
        if w == 0 {
            return Params {
                bank_slots: capacity,
                ..Params::SINGLE
            };
        }
        let lanes = (w & 0xFF).max(1);
        let ray_groups = (w >> 28) + 1;
        Params {
            lanes,
            rays_per_clock: (w >> 8) & 0xFF,
            sectors: (w >> 16) & 0xFF,
            bank_slots: capacity / (lanes / ray_groups).max(1),
            compact: w & 1 << 25 != 0,
            ray_groups,
        }
    }
}

impl Default for Params {
    fn default() -> Self {
        Params::DEFAULT
    }
}
