//! An area proxy per build: adders, multipliers, register bits and RAM bits counted unit by unit
//! from the widths the model uses, and their mapping onto a Lattice ECP5 (LUT4s, 18×18 DSP
//! tiles, 18 kbit block RAMs). A proxy, not synthesis: issue 20 (the RTL) replaces it with
//! Yosys/nextpnr figures.
//!
//! The mapping, stated once:
//! - an adder, subtractor or comparator of w bits is w LUT4s (ECP5's carry chain: two bits per
//!   slice of two LUTs); an adder-subtractor whose direction is data (a CORDIC stage's) 2w, a
//!   LUT4 a bit inverting the operand beside the chain (calibrated against Yosys in session 21);
//! - an a×b multiplier takes ⌈a/18⌉·⌈b/18⌉ DSP tiles while the part has tiles left: first the
//!   fixed units' (the (u,v) units' and the Bezier engine's, whose products sit in a loop that
//!   waits for them), then the ray datapath's in the order listed (until session 24 the ray
//!   datapath's first). Without a tile it is an array of rows as `rtl/array_mul.v` builds it,
//!   registered every three rows (`lut_multiplier`, `array_flip_flops`): about 2·a·b LUT4s,
//!   where Yosys 0.23 maps `a * b` to about 6.1·a·b (the rule of sessions 22 and 23; a·b, an
//!   ideal array of full adders, before);
//! - a multiplier by a constant fixed at build time (the gain compensation of the culling
//!   unit's vectorings, whose CORDIC is not the CONFIG register's) is a shift-and-add tree: one
//!   w-bit adder per nonzero digit of the constant's canonical signed-digit form but one;
//! - the rotators' and the angle unit's gain stages, whose constant 1/K_n follows CONFIG's ITER
//!   and WIDTH, are tables of the word's hex digits times the constant and a tree of adders
//!   (`Proxy::const_products`, as `rtl/const_mul.v`; multipliers until session 24);
//! - a register bit is a flip-flop;
//! - a memory of depth d and width w is ⌈w/W⌉·⌈d/D⌉ block RAMs in the EBR's cheapest shape
//!   D × W (512 × 36, 1,024 × 18, 2,048 × 9, … 16,384 × 1, as Yosys picks among them; 512 × 36
//!   alone until session 44), or ⌈d·w/16⌉ LUT4s of distributed RAM when it holds under 2 kbit;
//! - 10 % of the LUTs again for control and multiplexers;
//! - a unit whose RTL has been placed (the compact set-up unit and the culling unit's ray side,
//!   since session 28) is counted by its place and route instead: its LUT4s and flip-flops as
//!   nextpnr-ecp5 packed them (its own control included, so no 10 % on them), its multipliers
//!   still listed, mapped to tiles or arrays as the part allows.
//!
//! Two parts are counted: the **ray datapath** this crate's [`Params`] change (front end,
//! culling, set-up units, lanes, min tree and their memories) and the **fixed units** every
//! build has (the register file and its bus, the angle unit, the (u,v) units, the Bezier
//! subdivision engine), so that what does not fit is named. (Hosts only: the `alloc`
//! feature.)

extern crate alloc;

use crate::cordic::CordicConfig;
use crate::intersect::bezier::{RECIP_BITS, STACK_ENTRIES, STACK_WORDS};
#[cfg(doc)]
use crate::intersect::bezier::{SERIAL_LEAF_CLOCKS, SERIAL_SLAB_CLOCKS};
use crate::intersect::bitmap_walk::{row_words, BITMAP_WORD};
use crate::intersect::cull::{BANDS, CULL_CORDIC};
use crate::intersect::uv::SEG_BITS;
use crate::intersect::{PLANE_UNITS, UV_UNITS};
use crate::params::Params;
use alloc::vec::Vec;

/// Resources of one ECP5-85k (LFE5U-85F).
pub const ECP5_85K: Fpga = Fpga {
    luts: 83_640,
    ffs: 83_640,
    dsps: 156,
    brams: 208,
};

/// An FPGA's resources, or what a design needs of them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Fpga {
    /// LUT4s.
    pub luts: u64,
    /// Flip-flops.
    pub ffs: u64,
    /// 18×18 multiplier tiles.
    pub dsps: u64,
    /// 18 kbit block RAMs.
    pub brams: u64,
}

impl Fpga {
    /// Whether `self` (a need) fits `part`.
    pub fn fits(&self, part: &Fpga) -> bool {
        self.luts <= part.luts
            && self.ffs <= part.ffs
            && self.dsps <= part.dsps
            && self.brams <= part.brams
    }
}

/// The counted resources of a design.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Proxy {
    /// Adders, subtractors and comparators, and their bits in all.
    pub adders: u64,
    /// Adder bits.
    pub adder_bits: u64,
    /// Multipliers (a, b widths), in mapping order.
    pub multipliers: Vec<(u32, u32)>,
    /// Register bits.
    pub register_bits: u64,
    /// Memories (depth, width).
    pub memories: Vec<(u64, u64)>,
    /// LUT4s and flip-flops of placed units ([`Placed`]), besides their multipliers.
    pub placed: Fpga,
}

/// A unit counted by its place and route (`cargo xtask rtl`, seed 1, nextpnr-ecp5 at 100
/// MHz): its packed LUT4s, and its flip-flops less its harness's input chain. Its DSP tiles are
/// the multipliers the proxy lists beside it.
#[derive(Clone, Copy, Debug)]
pub struct Placed {
    /// LUT4s (logic, carry chains and distributed RAM).
    pub luts: u64,
    /// Flip-flops.
    pub ffs: u64,
}

/// The compact set-up unit with culling, `rtl/setup_unit.v` (session 46: 15,580 LUT4s and
/// 11,389 flip-flops placed, 580 of them its harness's input chain and output register, 22 DSP
/// tiles for its 6 edge products, h's four and the reach's 12; 107.1 MHz in `cargo xtask rtl`,
/// 110.1 placed by hand. Session 45, before
/// the edge products and the reach's took their registers in their tiles (`rtl/mul18.v`):
/// 15,621 LUT4s, 12,037 flip-flops, 109.3 MHz. Session 43, before
/// the reach binned both ends of a patch in one `rtl/cull_bin.v` and took its angles in the
/// vectorings' 23 bits: 17,210 LUT4s, 12,406 flip-flops, 105.2 MHz. Session 38, before
/// its words that only wait did so in distributed RAM (`rtl/delay_line.v`): 19,029 LUT4s and
/// 14,771 flip-flops, 105.3 MHz. Session 37: 17,248
/// LUT4s at 100.7 MHz, before its decisions took one carry chain each: each of those changes
/// alone mapped smaller, together Yosys's LUT mapping took 1,839 LUT4s more, 1,781 as placed
/// (docs/PERFORMANCE.md, "Session 38"). Session 33: 19,029 LUT4s at 107.2 MHz, before the
/// culling's CORDIC and magnitudes took their inversions into the carry cells, `rtl/add_sub.v`;
/// session 30: 19,602 LUT4s and 14,865 flip-flops, before the culling's leading one in windows
/// and its shift in two steps; session 29: 19,683, before the reach's ends were compared with 0
/// by their sign; session 28: 21,372, before the culling bins' two-step count).
pub const SETUP_UNIT: Placed = Placed {
    luts: 15_580,
    ffs: 11_389 - 580,
};

/// A compact lane's coarse edge test, `rtl/coarse_test.v` (session 30: 1,939 LUT4s and 1,702
/// flip-flops placed, 277 of them its harness's, 12 DSP tiles for its twelve 18 × 18 products;
/// 120.0 MHz). The rules it replaces gave 1,566 LUT4s and 426 flip-flops: the RTL's five
/// stages register every sum and bound.
pub const COARSE_TEST: Placed = Placed {
    luts: 1_939,
    ffs: 1_702 - 277,
};

/// The culling unit's ray side for one ray a clock, `rtl/cull_ray.v` (session 45: 3,919 LUT4s
/// and 2,571 flip-flops placed, 98 of them its harness's, no DSP tile; 116.6 MHz. Session 43,
/// its bins on the angles' Q3.29 containers, whose constant low bits Yosys had already left
/// out: 3,868 LUT4s, 2,580 flip-flops, 124.7 MHz. Session 37, its CORDIC payloads in
/// registers: 3,761 LUT4s, 3,427 flip-flops, 125.9 MHz. Session 33:
/// 4,597 LUT4s at 122.9 MHz, before `rtl/add_sub.v`; session 29: 4,510 LUT4s and 3,425
/// flip-flops, before the leading one in windows, which on the ray side's few places costs more
/// than the two-step shift saves; session 27: 5,250 LUT4s).
pub const RAY_SIDE: Placed = Placed {
    luts: 3_919,
    ffs: 2_571 - 98,
};

/// The compact datapath's shared exact edge unit, `rtl/exact_edge.v` (session 43: 2,401 LUT4s and
/// 2,596 flip-flops placed, 416 of them its harness's input chain, corner word and output register;
/// 8 DSP tiles for its one 34 × 64 multiplier; 119.3 and 115.8 MHz at seeds 1 and 2. Session 40's,
/// on two multipliers: 2,756 LUT4s, 3,270 flip-flops, 16 tiles, 110.1 MHz; session 39's, before an
/// idle unit held its grid: 2,754 LUT4s, 108.9 and 111.3 MHz). The rules it replaces (two 34 × 62
/// multipliers, the cross product's subtraction, the shift, the side, the dot product's sums) gave
/// 919 LUT4s and 846 flip-flops: the RTL's multiplier takes five clocks, its tiles' sums in carry
/// chains, and the operands, corners and edge normals of two edges are registered.
pub const EXACT_UNIT: Placed = Placed {
    luts: 2_401,
    ffs: 2_596 - 416,
};

/// A compact build's plane unit, one a ray group, `rtl/group_plane.v` (session 43, its divider's
/// payload in `rtl/delay_line.v`: 5,907 LUT4s and 6,756 flip-flops placed, 305 of them its
/// harness's input chain and output register, 116.8 MHz; session 42's run, the payload in a chain
/// written in `rtl/plane_divider.v`: 5,773 LUT4s, 6,658 flip-flops, 123.8 MHz. Session
/// 40: 6,049 LUT4s and 6,658 flip-flops; 12 DSP tiles for n · d, 14 block RAMs for its normal
/// memory, its minima and their generation bits, counted as memories; 114.1 MHz at seed 1.
/// Before its minimum dropped the pairs in flight across a reset, one term more, Yosys mapped it
/// into 5,798 LUT4s: 108.6 and 113.7 MHz at seeds 1 and 2). Its divider is most of it (2,245
/// LUT4s and 1,217 carry cells in synthesis, its remainders and divisors 5,478 flip-flops). The
/// rules it replaces (the wide datapath's lane's) gave the default build's two units, with the
/// lanes' hand-off registers and 10 % for control, 5,552 LUT4s and 13,120 flip-flops, now 12,133
/// and 13,062: they counted a divider stage's subtract, not the select of the remainder after it.
pub const GROUP_PLANE_UNIT: Placed = Placed {
    luts: 5_907,
    ffs: 6_756 - 305,
};

/// The rotator at the reset CORDIC configuration (20 iterations, 24-bit words), `rtl/rotator.v`
/// (session 44's place and route, by hand as `cargo xtask rtl` runs it: 7,941 LUT4s and 6,006
/// flip-flops, 195 of them its harness's input chain and output register; 5 block RAMs, its
/// side table, counted as a memory; 116.6 MHz). At 24 iterations on 32-bit words, the reset
/// configuration until session 44: 12,901 LUT4s and 9,226 flip-flops at 118.9 MHz (session 43;
/// session 37's, its pipes' payloads in registers rather than `rtl/delay_line.v`: 12,517 LUT4s,
/// 11,055 flip-flops; session 33's: 15,904 LUT4s, before the micro-rotations'
/// adder-subtractors took their inversion into the carry cells, `rtl/add_sub.v`). Until session
/// 34 counted by the CORDIC rules, which gave 20,750 LUT4s for its three pipes at 24/32 with
/// their 10 % for control at session 33's two LUT4s an adder-subtractor bit.
pub const ROTATOR: Placed = Placed {
    luts: 7_941,
    ffs: 6_006 - 195,
};

/// The angle unit at the reset CORDIC configuration, `rtl/frame_unit.v` (session 44's place and
/// route, mapped with ABC9: 2,309 LUT4s and 2,031 flip-flops, 195 of them its harness's;
/// 130.3 MHz): the vectoring pipe with its gain stage, and its sequencing. At 24 iterations on
/// 32-bit words (until session 44): 3,657 LUT4s and 3,115 flip-flops at 117.6 MHz (session 43;
/// session 35's, before `rtl/add_sub.v`, 4,729 LUT4s; session 33's default mapping gave 4,936
/// LUT4s at 104.7 MHz). Session 33's rules gave 6,098 LUT4s with their 10 % for control.
pub const ANGLE_UNIT: Placed = Placed {
    luts: 2_309,
    ffs: 2_031 - 195,
};

/// A bank's bitmap writer, `rtl/bitmap_writer.v` (session 34: 2,350 LUT4s and 812 flip-flops
/// placed, 212 of them its harness's input chain and output registers, and 2 block RAMs, its
/// answers' FIFO, counted as a memory; 104.4 to 113.2 MHz at three seeds, mapped with ABC9):
/// the FIFO's queue, the gatherer, the two copies of the open column in distributed RAM
/// (7,168 bits) and their read-modify-writes, the copy engine, the valid bits and the passes'
/// ends.
pub const BITMAP_WRITER: Placed = Placed {
    luts: 2_350,
    ffs: 812 - 212,
};

/// A lane's bitmap walk with its bank's bitmaps, `rtl/bitmap_walk.v` (session 42, with its
/// end port for a ray without a candidate, held low in reset, and the word held back for its
/// last mark: 2,910 LUT4s and 1,130 flip-flops placed, 233 of them its harness's input chain
/// and output register, 978 of the LUT4s the mask words' and the word queue's distributed RAM;
/// its 4 block RAMs, the sector and band words of two buffers, counted as memories; 105.7 and
/// 102.1 MHz at seeds 1 and 2; before the end port was held low in reset 2,836 LUT4s, and the
/// first version, which ended such a ray on a token, 2,707). At 32 sectors, 16 bands and banks
/// of 512 slots, the default build's; other builds are counted with the same figure. The rules
/// it replaces (the band bit picked from each mask word, the next word and the
/// next slot found and cleared, the AND, a few registers; the mask words in block RAM) gave 273
/// LUT4s and 152 flip-flops a lane and 4 block RAMs for the mask words: the placed walk keeps
/// its word and the word less its first candidate, queues eight words, and reads every mask
/// word of a row at once from distributed RAM.
pub const BITMAP_WALK: Placed = Placed {
    luts: 2_910,
    ffs: 1_130 - 233,
};

/// The register file and its bus, `rtl/ahb_regs.v` at the default build's 1,024 patch slots
/// (session 45's `cargo xtask rtl`: 7,140 LUT4s and 3,346 flip-flops placed, 871 of them its
/// harness's input chain and output register; 106.2 MHz): the AHB-Lite slave, the registers of
/// docs/register-map.md, the ray FIFO (two halves of 16 entries of 256 bits in distributed RAM,
/// 128 of the LUT4s' RAM cells), the stream port, the counters and the interrupt logic. Its
/// block RAMs are patch memory's and control-point memory's, counted as memories. The proxy
/// left it out until session 46, and counted the ray FIFO alone, as 7 block RAMs. Its ray FIFO
/// gives one entry a clock, as the one-lane build takes them: a front end of two rays a clock
/// would read two, which neither this nor the proxy counts.
pub const REGISTER_FILE: Placed = Placed {
    luts: 7_140,
    ffs: 3_346 - 871,
};

/// A bank's set-up pass front, `rtl/bank_front.v` (session 46: 3,628 LUT4s and 2,928 flip-flops
/// placed, 576 of them its harness's input chain and output register; 3 DSP tiles for the horizon
/// filter's three 18 × 18 products, each with its register in the tile, `rtl/mul18.v`; 110.9 MHz.
/// Session 32: 3,911 LUT4s, 3,035 flip-flops, 105.0 MHz): the box read, the horizon filter
/// (`rtl/horizon_filter.v`), the FIFO of slot numbers (in LUT RAM), the corner and normal reads and
/// the pass's tag. Its block RAMs are counted as memories. Session 31 counted the filter alone as
/// placed with the write path below (3,009 LUT4s, 1,126 flip-flops), and the FIFO as a memory.
pub const BANK_FRONT: Placed = Placed {
    luts: 3_628,
    ffs: 2_928 - 576,
};

/// The slot boxes' write path, `rtl/slot_box.v`, one a build (session 32, placed in a harness
/// of its own not kept: 516 LUT4s and 238 flip-flops, 195 of them the harness's input chain,
/// output register and the one box it holds in registers where a build holds boxes in block
/// RAM; 117.8 MHz).
pub const SLOT_BOX_WRITE: Placed = Placed {
    luts: 516,
    ffs: 238 - 195,
};

impl Proxy {
    fn add(&mut self, count: u64, bits: u64) {
        self.adders += count;
        self.adder_bits += count * bits;
    }

    fn mul(&mut self, count: u32, a: u32, b: u32) {
        self.multipliers
            .extend(core::iter::repeat_n((a, b), count as usize));
    }

    fn reg(&mut self, bits: u64) {
        self.register_bits += bits;
    }

    fn mem(&mut self, depth: u64, width: u64) {
        self.memories.push((depth, width));
    }

    /// `count` placed units.
    fn placed(&mut self, count: u64, unit: Placed) {
        self.placed.luts += count * unit.luts;
        self.placed.ffs += count * unit.ffs;
    }

    /// A pipelined CORDIC of `cfg` (quadrant stage, micro-rotations, gain stage). Its
    /// adder-subtractors, whose direction is data, count as plain adders: one carry chain each,
    /// the operand's inversion in the carry cells' own LUT4s (`rtl/add_sub.v`, since session
    /// 37). From session 21 to 36 they counted two LUT4s a bit, as Yosys then mapped the
    /// written form, an XOR a bit in front of the chain.
    fn cordic(&mut self, cfg: CordicConfig, count: u64) {
        let (n, w) = (cfg.iterations as u64, cfg.width as u64);
        self.add(count * 3 * (n + 1), w);
        self.const_products(2 * count, w);
        // n + 3 stages of x, y and z (the quadrant stage's decision and turn since session 25,
        // the micro-rotations, the gain), and z beside the gain stage's partial sums
        self.reg(count * ((n + 3) * 3 * w + w));
    }

    /// `count` products of a w-bit word by a constant in tables of its hex digits, as
    /// `rtl/const_mul.v` builds the CORDIC gain stages: ⌈w/4⌉ tables of digit × C, each a LUT4
    /// per bit of its (w + 5)-bit word, and a tree of ⌈w/4⌉ − 1 adders of up to 2w bits,
    /// registered after its second level. Until session 24 a w × w multiplier each (four DSP
    /// tiles at 32 bits, or 6.1·w² LUT4s).
    fn const_products(&mut self, count: u64, w: u64) {
        let digits = w.div_ceil(4);
        self.add(count * digits, w + 5);
        self.add(count * (digits - 1), 2 * w);
        // the tree registered after its second level (two sums of 2w bits): the gain stage's
        // second clock (since session 24)
        self.reg(count * 4 * w);
    }

    /// A pipelined vectoring CORDIC of `cfg`, fixed at build time, whose magnitude is used
    /// (`magnitude`: the x output's gain compensation, a multiply by the constant 1/K_n) or not
    /// (the angle alone needs no gain stage).
    fn vectoring(&mut self, cfg: CordicConfig, count: u64, magnitude: bool) {
        let (n, w) = (cfg.iterations as u64, cfg.width as u64);
        self.add(count * 3 * (n + 1), w);
        if magnitude {
            self.add(count * (gain_digits(cfg) as u64 - 1), w);
        }
        self.reg(count * (n + 3) * 3 * w);
    }

    /// Adds `other`'s counts to these (its multipliers after these in mapping order).
    fn merge(&mut self, other: Proxy) {
        self.adders += other.adders;
        self.adder_bits += other.adder_bits;
        self.multipliers.extend(other.multipliers);
        self.register_bits += other.register_bits;
        self.memories.extend(other.memories);
        self.placed.luts += other.placed.luts;
        self.placed.ffs += other.placed.ffs;
    }

    /// Multiplier bits: Σ a·b.
    pub fn multiplier_bits(&self) -> u64 {
        self.multipliers
            .iter()
            .map(|&(a, b)| a as u64 * b as u64)
            .sum()
    }

    /// RAM bits of its memories, block and distributed (a placed unit's own distributed RAM,
    /// the bitmap writers', is in its LUT4s).
    pub fn ram_bits(&self) -> u64 {
        self.memories.iter().map(|&(d, w)| d * w).sum()
    }

    /// Its mapping onto a part with `dsps_free` DSP tiles left (see the module doc).
    pub fn ecp5(&self, dsps_free: u64) -> Fpga {
        let mut out = Fpga::default();
        let mut luts = self.adder_bits;
        let mut array_ffs = 0;
        for &(a, b) in &self.multipliers {
            let tiles = (a as u64).div_ceil(18) * (b as u64).div_ceil(18);
            if out.dsps + tiles <= dsps_free {
                out.dsps += tiles;
            } else {
                luts += lut_multiplier(a, b);
                array_ffs += array_flip_flops(a, b);
            }
        }
        for &(d, w) in &self.memories {
            if d * w < 2048 {
                luts += (d * w).div_ceil(16);
            } else {
                out.brams += block_rams(d, w);
            }
        }
        out.luts = luts + luts / 10 + self.placed.luts;
        out.ffs = self.register_bits + array_ffs + self.placed.ffs;
        out
    }
}

/// Block RAMs of a memory of depth `d` and width `w` in the ECP5 EBR's cheapest shape (18 kbit:
/// 512 × 36 with one read and one write port, 1,024 × 18 … 16,384 × 1 with two of either). A
/// 1,023-deep queue of 16-bit tags is one EBR as 1,024 × 18, where 512 × 36 took two.
fn block_rams(d: u64, w: u64) -> u64 {
    EBR_SHAPES
        .iter()
        .map(|&(depth, width)| w.div_ceil(width) * d.div_ceil(depth))
        .min()
        .unwrap_or(0)
}

/// The shapes (depth, width) of an ECP5 EBR.
const EBR_SHAPES: [(u64, u64); 6] = [
    (512, 36),
    (1024, 18),
    (2048, 9),
    (4096, 4),
    (8192, 2),
    (16384, 1),
];

/// LUT4s of an a × b multiplier without DSP tiles, as `rtl/array_mul.v` builds it with r rows
/// (the narrower operand) of c + 2 bits (the wider): a carry chain of c + 2 bits a row (two bits
/// a carry cell, each counted two LUT4s as nextpnr counts them) and an AND a bit, 2·r·c + 2·r,
/// and c more for the last row's sign. Yosys 0.23 (session 24), as this rule: 18 × 18 702
/// LUT4s, 34 × 34 2,414 (2,380 placed by nextpnr-ecp5, at 107 MHz), 26 × 64 3,444. Yosys
/// maps `a * b` without DSP tiles to about 6.1·a·b LUT4s (18 × 18: 2,078), the rule until this
/// session: it builds the partial products as one logic network, not as rows of carry chains.
fn lut_multiplier(a: u32, b: u32) -> u64 {
    let (r, c) = (a.min(b) as u64, a.max(b) as u64);
    2 * r * c + 2 * r + c
}

/// Flip-flops of [`lut_multiplier`]'s array registered every three rows (`STAGE = 3`, which
/// placed 34 × 34 at 107 MHz; unregistered, 62.7 MHz at six rows a stage): ⌈r/3⌉ − 1 stages of
/// the running sum (c + 1 bits), its final low bits and the operand bits still to come (r in
/// all) and the wide operand (c). 34 × 34: 1,133, as placed.
fn array_flip_flops(a: u32, b: u32) -> u64 {
    let (r, c) = (a.min(b) as u64, a.max(b) as u64);
    (r.div_ceil(3) - 1) * (r + 2 * c + 1)
}

/// Nonzero digits of the canonical signed-digit (non-adjacent) form of `c`.
fn csd_digits(mut c: u64) -> u32 {
    let mut digits = 0;
    while c != 0 {
        if c & 1 == 1 {
            digits += 1;
            // a run of ones ends in −1 (the form's digit is 2 − (c mod 4))
            if c & 2 == 2 {
                c += 1;
            } else {
                c -= 1;
            }
        }
        c >>= 1;
    }
    digits
}

/// Nonzero signed digits of a CORDIC's gain constant 1/K_n as its gain stage holds it (Q2.(W−2),
/// rounded).
fn gain_digits(cfg: CordicConfig) -> u32 {
    let drop = 62 - (cfg.width - 2);
    let q62 = crate::cordic::rom::INV_GAIN_Q62[cfg.iterations as usize];
    csd_digits((q62 + (1 << (drop - 1))) >> drop).max(1)
}

/// Bits of h in a lane's word: |h| = |n · a| ≤ |n| |a| < 1.01 · √3 · 2^62 < 2^63 (n a unit
/// normal in Q2.30, a = v − O of two Q8.24 words), a 64-bit signed integer (the model's 128-bit
/// container is only that).
const H_BITS: u64 = 64;

/// Bits of the plane divider's subtractors, divisor and partial remainders: the divisor is n · d
/// with |n · d| ≤ |n||d| < 1.01 · 2^60 (two unit vectors in Q2.30), every remainder is below it,
/// so 64 bits hold them (the model's 128-bit containers are only that; counted as 98 before
/// issue 19's fourth round).
const DIV_BITS: u64 = 64;

/// Register bits of a divider stage: remainder and divisor ([`DIV_BITS`] each), the dividend's
/// bits still to come down (h · 2^30 for a 32-bit t) and the quotient's bits so far, which
/// share 32 bits (one shifts in as the other shifts out), and the pair's 16-bit tag.
const DIV_STAGE_BITS: u64 = 2 * DIV_BITS + 32 + 16;

/// Width of a lane's local-memory word: four edge normals (3 × 62 bits), the normal (3 × 32),
/// h and the flags.
const LOCAL_WORD: u64 = 4 * 3 * 62 + 3 * 32 + H_BITS + 4;

/// Width of a compact lane's local-memory word: four coarse edge normals (3 × 18 bits), h that
/// the lane hands its group's plane unit with a pair found inside, and the flags. Since issue
/// 19's fourth round the lane forms each edge's Σ|e'_c| itself and the plane unit reads n from
/// its group's normal memory ([`crate::intersect::NORMAL_READ`]): before, the word held both
/// (4 × 20 + 3 × 32 bits more, 460 instead of 284). Since session 22 the words' error
/// exponent κ (four bits, [`crate::intersect::coarse`]) too: 288 bits, eight block RAMs wide.
const COARSE_WORD: u64 = 4 * 3 * 18 + H_BITS + 4 + 4;

/// The ray datapath of `params` at CORDIC `cfg` (the part the build parameters change).
pub fn ray_datapath(params: &Params, cfg: CordicConfig) -> Proxy {
    if params.compact {
        return compact_datapath(params, cfg);
    }
    wide_datapath(params, cfg)
}

/// The compact datapath: per lane the coarse edge test (twelve 18 × 18 products, one DSP tile
/// each, and the bound's adders and compares); per ray group [`PLANE_UNITS`] plane units
/// (n · d, divider, running minimum) fed with the pairs its lanes find inside; one shared
/// exact edge unit (one 34 × 64 multiplier, a product a clock: the six products that
/// recompute an edge's normal from the corners, then the three of its dot product with d;
/// [`EXACT_UNIT`] as placed); one set-up
/// unit per bank (the wide datapath's); local memory, candidate bitmaps and
/// exact words double-buffered, each lane's words for its bank (so once per ray group).
fn compact_datapath(params: &Params, cfg: CordicConfig) -> Proxy {
    let mut p = Proxy::default();
    for (_, part) in compact_parts(params, cfg) {
        p.merge(part);
    }
    p
}

/// The compact datapath of `params` unit by unit, in mapping order (its multipliers take the
/// DSP tiles in this order): what [`ray_datapath`] sums, so that what does not fit is named.
pub fn compact_parts(params: &Params, cfg: CordicConfig) -> Vec<(&'static str, Proxy)> {
    let (l, b) = (params.lanes as u64, params.banks() as u64);
    // the lanes' coarse tests as placed ([`COARSE_TEST`], twelve products each); the placed
    // unit forms the ray's Σ(|d'| + 1) itself, where a lane would take it from the front end
    let mut coarse = Proxy::default();
    coarse.mul(12 * l as u32, 18, 18);
    coarse.placed(l, COARSE_TEST);
    // the plane units, PLANE_UNITS a ray group, as placed ([`GROUP_PLANE_UNIT`]: n · d on
    // twelve tiles, the divider, each ray's minimum); each lane's hand-off register (its
    // pair's slot and h from its word) and the oldest-first arbiter's compares of ray tags
    let units = params.ray_groups as u64 * PLANE_UNITS as u64;
    let mut plane = Proxy::default();
    plane.mul(3 * units as u32, 32, 32);
    plane.placed(units, GROUP_PLANE_UNIT);
    plane.reg(l * (16 + H_BITS + 8 + 1));
    plane.add(l, 8);
    // the shared exact edge unit as placed ([`EXACT_UNIT`]), its 34 × 64 multiplier of eight
    // tiles (two until session 43); the queue of undecided pairs before it (with their mask of
    // undecided edges), which the sequencing holds
    let mut exact = Proxy::default();
    exact.mul(1, 34, 64);
    exact.placed(1, EXACT_UNIT);
    exact.mem(params.ray_slots() as u64, tag_bits(params) + 16 + 4 + 4);
    let mut setup = Proxy::default();
    setup_units(&mut setup, params, b);
    let mut horizon = Proxy::default();
    horizon_filters(&mut horizon, params, b);
    walks(&mut coarse, params, l);
    let mut writers = Proxy::default();
    bitmap_writers(&mut writers, params, b);
    let mut front = Proxy::default();
    front_end(&mut front, params, cfg);
    queues(&mut front, params);
    alloc::vec![
        ("coarse edge tests and bitmap walks", coarse),
        ("plane units (n · d, dividers, minima)", plane),
        ("exact edge unit", exact),
        ("set-up units", setup),
        (
            "bank fronts (horizon filters, FIFOs, corner reads), slot boxes",
            horizon
        ),
        ("bitmap writers", writers),
        ("front end and queues", front),
        ("memories", compact_memories(params)),
    ]
}

/// The horizon filters (`intersect/horizon.rs`), one a bank ahead of its set-up unit, each in
/// its bank's set-up pass front as placed ([`BANK_FRONT`]: three 18 × 18 products each, the
/// FIFO of slot numbers and the corner reads), the slot boxes' write path ([`SLOT_BOX_WRITE`])
/// and the slot boxes the filters read: a memory a bank of its slots' boxes (six 24-bit ends,
/// twelve written bits and the unbounded bit).
fn horizon_filters(p: &mut Proxy, params: &Params, banks: u64) {
    p.placed(banks, BANK_FRONT);
    p.placed(1, SLOT_BOX_WRITE);
    p.mul(3 * banks as u32, 18, 18);
    for _ in 0..banks {
        p.mem(params.bank_slots as u64, 6 * 24 + 13);
    }
}

/// The compact datapath's memories, double-buffered where the set-up pass writes them (the
/// next origin's pass fills the other half): each lane's coarse words for its bank, the sector
/// and band bitmaps per bank and group (a lane walks its ray's sector row ANDed with its band
/// row word by word, [`bitmaps`], so a patch outside the ray's band costs it no clock), patch
/// memory (the exact unit recomputes the exact edge normals from it) and each ray group's
/// normal memory (single: n does not depend on the origin).
fn compact_memories(params: &Params) -> Proxy {
    let mut p = Proxy::default();
    let slots = params.capacity() as u64;
    for _ in 0..params.lanes {
        p.mem(2 * params.bank_slots as u64, COARSE_WORD);
    }
    p.mem(slots * 16, 32);
    // each ray group's normal memory (n of every slot, written with patch memory), and its
    // plane units' minima, an entry {t, slot, side, g} a ray tag, a copy for the minimum and
    // one for the readout, and each copy's generation bits
    let slot_bits = 64 - (slots - 1).max(1).leading_zeros() as u64;
    for _ in 0..params.ray_groups {
        p.mem(slots, 3 * 32);
    }
    for _ in 0..2 * params.ray_groups as usize * PLANE_UNITS {
        p.mem(params.ray_slots() as u64, 31 + slot_bits + 2);
        p.mem(params.ray_slots() as u64, 1);
    }
    if params.sectors > 0 {
        for _ in 0..params.banks() * params.ray_groups {
            bitmaps(&mut p, params, 2);
        }
    }
    p
}

/// The bitmap walks of `lanes` lanes ([`crate::intersect::bitmap_walk`]) as placed
/// ([`BITMAP_WALK`], with the mask words of its bank's bitmaps in distributed RAM; since
/// session 42, counted by rules before).
fn walks(p: &mut Proxy, params: &Params, lanes: u64) {
    if params.sectors == 0 {
        return;
    }
    p.placed(lanes, BITMAP_WALK);
}

/// The set-up's bitmap writers, one a bank ([`crate::intersect::bitmap_write`]), as placed
/// ([`BITMAP_WRITER`]) with their answers' FIFOs (two entries a slot of 36 bits: the slot's
/// place, the wedge, the bands and the answer's row writes) counted as memories (a LUT4 a word
/// a lane more until session 42, the walk's read of a column not written this pass as zero by
/// its valid bit, which is the placed walk's now). Until session 34 counted by rules, as the
/// writer had no RTL: 1,707 LUT4s for the default build's two banks, where the placed writers
/// take 4,700.
fn bitmap_writers(p: &mut Proxy, params: &Params, banks: u64) {
    if params.sectors == 0 {
        return;
    }
    for _ in 0..banks {
        p.mem(2 * params.bank_slots as u64, 36);
    }
    p.placed(banks, BITMAP_WRITER);
}

/// One bank's candidate bitmaps, `copies` of them (double-buffered or not), as the lane walks
/// them ([`crate::intersect::bitmap_walk`]): the sector rows and the band rows in words of
/// [`BITMAP_WORD`] bits. The mask row beside each sector row ([`BANDS`] bits a word) is the
/// placed walk's distributed RAM ([`BITMAP_WALK`]; block RAM until session 42). Before issue
/// 19's fifth round each row was one word of the bank's width (512 bits: 15 block RAMs a
/// bitmap whatever its depth).
fn bitmaps(p: &mut Proxy, params: &Params, copies: u64) {
    let words = row_words(params.bank_slots) as u64;
    let sectors = params.sectors as u64;
    p.mem(copies * sectors * words, BITMAP_WORD as u64);
    p.mem(copies * BANDS as u64 * words, BITMAP_WORD as u64);
}

/// Set-up units, one per bank, a corner per clock (the wide datapath's a patch per clock, its
/// four edges' a × b at once: 24 products of 34 × 34; the compact one's coarse words from
/// narrow products, [`narrow_edges`]) and h (one 32 × 34 product a clock, accumulated over the
/// patch's three or four corner clocks), and with
/// culling (`intersect::cull`, on 18-bit words) the corner's block-floating-point shift into 18
/// bits, its three dot products with the axes (nine 18 × 18) and their error bounds, its edge's
/// coarse normal dotted with the frame's axis (three 18 × 18) and its bound, the normalisation
/// of each vectoring's input, the azimuth's vectoring CORDIC (the magnitude feeds the polar
/// vectoring), the arc and band bounds and the constant multiplies that turn angles into
/// sectors and bands; the rays' sector and band vectorings and constant multiplies,
/// `rays_per_clock` of each. The compact datapath's units with culling are counted as placed
/// instead ([`placed_setup_units`]); these rules count the others.
fn setup_units(p: &mut Proxy, params: &Params, banks: u64) {
    if params.compact && params.sectors > 0 {
        placed_setup_units(p, params, banks);
        return;
    }
    // the compact datapath's unit forms one edge normal a clock (a corner a clock); the wide
    // one a whole patch a clock, its four edge normals at once (until session 21 the proxy
    // counted it one edge's six products, where `plane_setup.v` has twenty-four)
    if params.compact {
        narrow_edges(p, banks);
    } else {
        for _ in 0..banks {
            p.mul(24, 34, 34);
            p.mul(1, 32, 34);
        }
        p.add(banks * 24, 68);
    }
    p.add(banks, 68);
    p.reg(banks * 1024);
    if params.compact || params.sectors > 0 {
        // the corner into 18 bits, which the narrow edge words and the culling share: its
        // leading one (as a 34-bit adder) and three shifters of six levels of 2:1 multiplexers
        // on 34 bits (a LUT4 a bit a level, counted as adders). Until session 23 counted with
        // the culling only, so a compact build without culling went without it.
        p.add(banks, 34);
        p.add(banks * 3 * 6, 34);
    }
    if params.sectors > 0 {
        for _ in 0..banks {
            p.mul(9, 18, 18);
            p.mul(3, 18, 18);
        }
        // f = ã · x̃: two adds of 36 bits a component; the bounds Σ(|ã| + |x̃| + 1): three
        // negations and two adds for Σ|ã|, three adds of the frame's Σ|x̃| + 3
        p.add(banks * 3 * 2, 36);
        p.add(banks * 8, 20);
        // |f|∞ and the largest bound, the horizon and near-axis compares (twelve of 36 bits)
        p.add(banks * 12, 36);
        // each vectoring's input normalised (`cull::NORM_TOP`): ρ's leading one and x, y
        // shifted (six levels either way on 36 bits), then max(|z|, r)'s and z, r shifted (z by
        // both shifts at once); until session 26 one leading one and x, y, z shifted four
        // levels into 27 bits
        p.add(banks * 2, 36);
        p.add(banks * 4 * 6, 36);
        // ce · w̃ (two adds of 36 bits), its bound (five of 20), ±bound and the two compares
        p.add(banks * 2, 36);
        p.add(banks * 5, 20);
        p.add(banks * 4, 37);
        // a corner's azimuth (its magnitude kept for the polar angle) and its polar angle: two
        // chained pipes, as `cull_angles.v` has them (until session 27 the proxy counted one)
        p.vectoring(CULL_CORDIC, banks, true);
        p.vectoring(CULL_CORDIC, banks, false);
        // the arc's and the bands' bounds (angle compares and halvings)
        p.add(banks * 8, 32);
        // sector and band of the arc's two ends and the band range's two: four multiplies by a
        // constant (S / 2π, 32 / π) of 16 significant bits, six adders of 32 bits each
        p.add(banks * 4 * 6, 32);
        let rays = params.rays_per_clock as u64;
        // a ray's two normalisations (since session 26): leading ones of 32 bits, and x, y,
        // then z, r shifted five levels
        p.add(rays * 2, 32);
        p.add(rays * 4 * 5, 32);
        p.vectoring(CULL_CORDIC, rays, true);
        p.vectoring(CULL_CORDIC, rays, false);
        p.add(rays * 2 * 6, 32);
    }
}

/// The compact datapath's set-up units with culling and the culling unit's ray sides, counted
/// by their place and route since session 28 ([`SETUP_UNIT`] a bank, [`RAY_SIDE`] a ray a
/// clock) where the rules of [`setup_units`] had counted them: for one set-up unit and one ray
/// side the rules gave 18,334 LUT4s and 6,124 flip-flops (16,354 and 5,104 without the polar
/// vectoring they counted twice), the placed units 26,622 and 17,506. Their multipliers, in the
/// rules' order: each bank's six edge products and h's (listed 32 × 34 as the rules had it; the
/// RTL's 33 × 32 takes the same four tiles), then each bank's twelve of the reach.
fn placed_setup_units(p: &mut Proxy, params: &Params, banks: u64) {
    for _ in 0..banks {
        p.mul(6, 18, 18);
        p.mul(1, 32, 34);
    }
    for _ in 0..banks {
        p.mul(9, 18, 18);
        p.mul(3, 18, 18);
    }
    p.placed(banks, SETUP_UNIT);
    p.placed(params.rays_per_clock as u64, RAY_SIDE);
}

/// The compact set-up unit's coarse edge words, an edge a clock
/// ([`crate::intersect::coarse::narrow_edge`]): the edge's vector Δ = v − u (three subtractors
/// of 35 bits), Δ into 18 bits (its leading one, three shifters of six levels on 67 bits, as
/// `rtl/coarse_edge.v` shifts Δ·2^33; the corner's own 18 bits are the culling's, below),
/// X = ũ × Δ̃ (six 18 × 18 products, three subtractions of 36 bits), X's top bits into the
/// words (a leading one, three shifters of five levels on 36 bits), and κ: the bound E (four
/// negations of 18 bits, three sums of four 18-bit magnitudes and two compares, 20 bits), its
/// shift by m, the exponent sum S and the sum of the three terms (24 bits each), and κ's
/// leading one. Each bank's h product (32 × 34) is listed after its six, as before, so that
/// the DSP tiles go to the banks in the same order. Since session 22: six 34 × 34 products
/// before.
fn narrow_edges(p: &mut Proxy, banks: u64) {
    for _ in 0..banks {
        p.mul(6, 18, 18);
        p.mul(1, 32, 34);
    }
    p.add(banks * 3, 35);
    p.add(banks, 35);
    p.add(banks * 3 * 6, 67);
    p.add(banks * 3, 36);
    p.add(banks, 36);
    p.add(banks * 3 * 5, 36);
    p.add(banks * 4, 18);
    p.add(banks * (3 * 3 + 2), 20);
    p.add(banks * 5, 24);
    p.add(banks * 4, 24);
}

/// The front end: rotators (three pipes each; at the reset CORDIC configuration as placed,
/// [`ROTATOR`], since session 34), reciprocal units (radix-2 dividers of 33 stages on 64 bits:
/// three a ray a clock, or the compact datapath's one for the Bezier lane).
fn front_end(p: &mut Proxy, params: &Params, cfg: CordicConfig) {
    let g = params.rays_per_clock as u64;
    if cfg == CordicConfig::DEFAULT {
        // as placed, with each one's side table of 128 slots (two angles, the direction and
        // the bypass bit)
        p.placed(g, ROTATOR);
        for _ in 0..g {
            p.mem(128, 32 + 32 + 96 + 1);
        }
    } else {
        p.cordic(cfg, 3 * g);
    }
    // the compact datapath's one divider, a component a clock, and its results for the rays
    // waiting for the Bezier lane: each reciprocal as the slab tests take it, its leading
    // `bezier::RECIP_BITS` and the shift below them (six bits; the whole 64-bit quotient until
    // session 44)
    let dividers = if params.compact { 1 } else { 3 * g };
    p.add(dividers * 33, 64);
    p.reg(dividers * 33 * 128);
    if params.compact {
        p.mem(params.ray_slots() as u64, 3 * (RECIP_BITS as u64 + 6));
    }
}

/// The descriptor FIFOs, the ray table, ray queue and result FIFO (the ray FIFO is the register
/// file's, [`REGISTER_FILE`]).
fn queues(p: &mut Proxy, params: &Params) {
    let (lanes, slots_in_flight) = (params.lanes as u64, params.ray_slots() as u64);
    let tag = tag_bits(params);
    for _ in 0..lanes {
        p.mem(slots_in_flight, tag + 6);
    }
    p.mem(slots_in_flight, 3 * 32 + 3 * 32 + 32);
    p.mem(slots_in_flight, 3 * 32 + 3 * 32 + 3 * 32);
    p.mem(crate::device::RESULT_FIFO_DEPTH as u64, 4 * 32);
}

/// Bits of a ray's tag, its place among the rays in flight (8 while they were 255 in every
/// build, until session 24).
fn tag_bits(params: &Params) -> u64 {
    (params.ray_slots() as u64 + 1).ilog2() as u64
}

/// The wide datapath: every lane with the exact edge products.
fn wide_datapath(params: &Params, cfg: CordicConfig) -> Proxy {
    let mut p = Proxy::default();
    let l = params.lanes as u64;
    let slots = params.capacity() as u64;
    // lanes: edge stage (4 edges · 3 products of 32 × 62, n · d), divider, running minimum
    for _ in 0..l {
        p.mul(12, 32, 62);
        p.mul(3, 32, 32);
    }
    p.add(l * (4 * 2 + 2), 94);
    p.add(l * crate::intersect::DIV_LATENCY as u64, DIV_BITS);
    p.reg(l * crate::intersect::DIV_LATENCY as u64 * DIV_STAGE_BITS);
    p.add(l, 64);
    p.reg(l * (4 * 94 + 64 + 64));
    setup_units(&mut p, params, l);
    // a slot a clock: h's three products at once
    for _ in 0..l {
        p.mul(2, 32, 34);
    }
    front_end(&mut p, params, cfg);
    // min tree
    p.add(l, 64 + 16);
    p.reg(l * 80);
    // memories: local memory (one bank per lane, a whole word per clock), patch memory, sector
    // bitmaps, descriptor FIFOs, the ray table, ray queue and result FIFO
    for _ in 0..l {
        p.mem(params.bank_slots as u64, LOCAL_WORD);
    }
    p.mem(slots * 16, 32);
    if params.sectors > 0 {
        for _ in 0..l {
            bitmaps(&mut p, params, 1);
        }
    }
    walks(&mut p, params, l);
    queues(&mut p, params);
    p
}

/// The angle unit as `frame.rs` models it: one vectoring pipe of `cfg` (x, y and the angle
/// each iteration) whose x output, the magnitude ρ that the θ pass takes, is gain-compensated
/// (a product by the constant 1/K_n in digit tables); at the reset CORDIC configuration, the
/// whole unit as placed ([`ANGLE_UNIT`], since session 34). Until issue 19's fifth round the
/// proxy counted two rotation pipes here (four gain multipliers), a unit the model never had.
fn angle_unit(p: &mut Proxy, cfg: CordicConfig) {
    if cfg == CordicConfig::DEFAULT {
        p.placed(1, ANGLE_UNIT);
        return;
    }
    let (n, w) = (cfg.iterations as u64, cfg.width as u64);
    p.add(3 * (n + 1), w);
    p.const_products(1, w);
    p.reg((n + 3) * 3 * w + w);
}

/// The units every build has: the register file and its bus as placed ([`REGISTER_FILE`], since
/// session 46), the angle unit (one vectoring CORDIC pipe, `frame.rs`), the (u,v) unit and the
/// Bezier subdivision engine (the de Casteljau network on 26-bit control points,
/// child boxes and slab tests, the leaf's products and six dividers, the node stack and
/// control-point memory). The wide datapath (`compact` false) unrolls the (u,v) pipe into
/// `uv_depth` levels (two 2D side tests of two 36 × 18 products each, midpoints) and slab-tests a
/// step's four children at once; the compact one has [`UV_UNITS`] iterative (u,v) units (one
/// level a clock), one slab tester of two multipliers (an axis a clock, three clocks a child)
/// and a leaf of two multipliers instead of eighteen (six each until session 24; the clocks:
/// [`SERIAL_SLAB_CLOCKS`], [`SERIAL_LEAF_CLOCKS`]).
pub fn fixed_units(cfg: CordicConfig, uv_depth: u32, compact: bool) -> Proxy {
    let mut p = Proxy::default();
    p.placed(1, REGISTER_FILE);
    angle_unit(&mut p, cfg);
    let d = uv_depth as u64;
    let (levels, children) = if compact {
        (UV_UNITS as u64, 1)
    } else {
        (d, 4)
    };
    // each level's two side tests, two products each of the segment's 18-bit direction by
    // the point's 36-bit offset (34 × 34 until session 44), and the direction's scaling: two
    // magnitudes, their leading one and two shifters of five levels on 37 bits a test
    p.mul(4 * levels as u32, 36, SEG_BITS);
    p.add(levels * 2 * (2 + 1 + 2 * 5), 37);
    p.add(levels * 12, 34);
    p.reg(levels * (4 * 2 * 34 + 2 * 34 + 48));
    if compact {
        // each unit's level counter and cell registers
        p.add(levels, 5);
        p.reg(levels * 8);
    }
    // Bezier engine
    p.add(3 * 66, 26);
    p.add(children * 3 * 2 * 15, 26);
    // the slab products take the reciprocal's leading 18 bits (`bezier::RECIP_BITS`: 26 × 18,
    // two tiles, where the whole Q32.32 word took eight until session 44), and each bound its
    // own relative margin (a magnitude and an adder more); the reciprocal's rounding (a leading
    // one and a mask on 64 bits) is at the serial divider's output, one for the engine
    p.add(2, 64);
    if compact {
        // an axis's two bounds a clock, folded into the child's running entry and exit
        p.mul(2, 26, RECIP_BITS);
        p.add(4 + 2 * 2, 64);
        p.reg(2 * 64);
    } else {
        p.mul(children as u32 * 6, 26, RECIP_BITS);
        p.add(children * 6 * 3, 64);
    }
    // the leaf's products: both triangles' at once, or two a clock (compact)
    p.mul(if compact { 2 } else { 18 }, 34, 34);
    // its dividers as the model times them (`bezier::LEAF_CLOCKS`: t, s and r of both triangles at
    // once, radix-2 restoring, a quotient bit a clock while the engine waits): six, each a
    // 64-bit subtract, the 64-bit choice of what remains (counted as an adder) and its
    // remainder, divisor and quotient registers. Until session 43 three dividers of 32
    // pipelined stages (6,144 adder bits, 12,288 flip-flops), as if a leaf could enter each clock
    p.add(6 * 2, 64);
    p.reg(6 * (64 + 64 + 32) + 2 * 1300);
    // the node stack, a node in two words (`bezier::STACK_WORDS`)
    let words = STACK_WORDS as u64;
    p.mem(STACK_ENTRIES as u64 * words, 1300 / words);
    p.mem(64 * 48, 32);
    p
}

/// The whole build on an ECP5-85k: the fixed units mapped first (the (u,v) units and the
/// Bezier engine wait for their products in a loop, where an array multiplier's latency would
/// be paid at every level and step), then the ray datapath with the tiles left, whose
/// multipliers feed pipelines. Returns (ray datapath, fixed units).
pub fn on_ecp5(params: &Params, cfg: CordicConfig, uv_depth: u32) -> (Fpga, Fpga) {
    let fixed = fixed_units(cfg, uv_depth, params.compact).ecp5(ECP5_85K.dsps);
    let ray = ray_datapath(params, cfg).ecp5(ECP5_85K.dsps - fixed.dsps);
    (ray, fixed)
}

/// A compact build on an ECP5-85k unit by unit, mapped as [`on_ecp5`] maps the whole (the
/// fixed units first, listed last), each with its own 10 % for control: what does not fit,
/// named.
pub fn compact_parts_on_ecp5(
    params: &Params,
    cfg: CordicConfig,
    uv_depth: u32,
) -> Vec<(&'static str, Fpga)> {
    let fixed = fixed_units(cfg, uv_depth, params.compact).ecp5(ECP5_85K.dsps);
    let mut dsps = ECP5_85K.dsps - fixed.dsps;
    let mut out: Vec<(&'static str, Fpga)> = compact_parts(params, cfg)
        .into_iter()
        .map(|(name, part)| {
            let f = part.ecp5(dsps);
            dsps -= f.dsps;
            (name, f)
        })
        .collect();
    out.push((
        "fixed units (register file, angle unit, (u,v) units, Bezier engine)",
        fixed,
    ));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn block_rams_in_their_cheapest_shape() {
        // the rotator's side table, 128 × 161: five as 512 × 36 (as placed)
        assert_eq!(block_rams(128, 161), 5);
        // a queue of 1,023 tags of 16 bits: one as 1,024 × 18
        assert_eq!(block_rams(1023, 16), 1);
        // patch memory, 16,384 words of 32 bits: 32 in any shape
        assert_eq!(block_rams(16_384, 32), 32);
        // 1,023 × 224: thirteen as 1,024 × 18, fourteen as 512 × 36
        assert_eq!(block_rams(1023, 224), 13);
    }

    #[test]
    fn signed_digits() {
        // 7 = 8 − 1, 0b1011 = 16 − 4 − 1, 0b101 = 4 + 1
        assert_eq!(csd_digits(7), 2);
        assert_eq!(csd_digits(0b1011), 3);
        assert_eq!(csd_digits(0b101), 2);
        assert_eq!(csd_digits(0), 0);
        assert_eq!(csd_digits(u32::MAX as u64), 2);
        // the culling unit's gain constant has far fewer digits than its width
        assert!(gain_digits(CULL_CORDIC) < CULL_CORDIC.width / 2);
    }

    /// The array multiplier's rule against what Yosys 0.23 and nextpnr-ecp5 made of
    /// `rtl/array_mul.v` (session 24; LUT4s with each carry cell as two, before packing).
    #[test]
    fn array_multipliers_as_synthesised() {
        assert_eq!(lut_multiplier(18, 18), 702);
        assert_eq!(lut_multiplier(34, 34), 2_414);
        assert_eq!(lut_multiplier(64, 26), 3_444);
        // the placed 34 × 34 held 1,133 flip-flops of its own (1,269 with its harness's 136)
        assert_eq!(array_flip_flops(34, 34), 1_133);
        assert_eq!(array_flip_flops(2, 18), 0);
    }
}
