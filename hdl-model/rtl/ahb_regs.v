// The accelerator's register file behind an AHB-Lite slave (docs/register-map.md; the model is
// hdl-model/src/device.rs, whose `read`, `write` and `tick` this mirrors clock for clock).
//
// The bus: AHB-Lite, HRESP OKAY, word transfers (HSIZE is not decoded: a narrower write acts as
// a word write), zero wait states but for a PATCH_DATA read, which takes four
// (PATCH_DATA_READ_WAITS in hdl-model/src/regs.rs). An access's address phase is latched; its
// read data is driven combinationally in its data phase's last clock from the registers as they
// are then, and its effects (a write's, and a read's side effects: RESULT_OUT's pop,
// PATCH_DATA's increment, the latching of CYCLE_HI and BUSY_HI, RESULT_UNDERFLOW and
// PATCH_RANGE) take place on the clock edge that ends the data phase, together with that clock's
// counting. So back-to-back accesses see each other in order, as the model's accesses do (the
// model's clock n is the data phase of the access it makes then; a wait state is a clock of
// counting, as the model's idle ticks). Patch memory is synchronous block RAM, read every clock
// at PATCH_ADDR, its word registered three times (below): a PATCH_DATA read waits for the read
// and the registers. Until session 25 the read was issued in the address phase from the
// PATCH_ADDR the access in its data phase leaves behind, and its word went to the bus
// unregistered: no wait state, but the address's logic before the 64 block RAMs' spread-out
// address pins, and their slow output after them, held the file to 54–70 MHz.
//
// What lies behind the registers (the angle unit, the rotators, the intersection unit, the
// result FIFO) is not here: its state comes in on the dp_*, frame_* and result_* ports and the
// ray FIFO's head goes out on entry_*. An entry is packed in eight words as the model's
// `Device::queued_entries` packs it: word 0 the kind (17:16: 0 a ray, 1 a frame from NORMAL and
// SPIN, 2 a frame from PHI, THETA and SPIN) and a ray's MODE (8:0); a ray's ORIGIN x, y, z, its
// SKIP_PATCH (bit 31 set when it skips) and its direction; a frame's inputs in register order.
// Verilog-2005, accepted by Verilator and Yosys.
module ahb_regs #(
    // log2 of the patch slots (CAPS 31:16): 1,024 in the default build
    parameter SLOT_BITS = 10,
    // CAPS_LANES of the build (the default build's)
    parameter [31:0] CAPS_LANES_VALUE = 32'h1320_0204,
    // the CONFIG (ITER 4:0, WIDTH 13:8, DEPTH 20:16) the units behind were synthesised with,
    // the only one APPLY_CONFIG then takes; 0 (never a valid CONFIG) for units that follow it
    parameter [31:0] BUILD_CONFIG = 32'd0
) (
    input  wire         hclk,
    input  wire         hresetn,
    // AHB-Lite slave
    input  wire         hsel,
    input  wire [11:0]  haddr,
    input  wire [1:0]   htrans,
    input  wire         hwrite,
    input  wire [2:0]   hsize,
    input  wire [31:0]  hwdata,
    input  wire         hready,
    output wire [31:0]  hrdata,
    output wire         hreadyout,
    output wire         hresp,
    output wire         irq,
    // the ray FIFO's head, for the datapath (popped by it)
    output wire         entry_valid,
    output wire [255:0] entry,
    input  wire         entry_pop,
    // the datapath's state
    input  wire         dp_busy,
    input  wire         frame_busy,
    input  wire         frame_done,
    input  wire [95:0]  frame_angles,
    input  wire [7:0]   stack_high,
    input  wire         result_push,
    input  wire [7:0]   result_level,
    input  wire         result_valid,
    input  wire [127:0] result_words,
    output reg          result_pop,
    // errors the datapath raises on this clock (ERROR bits: NO_FRAME when a ray that rotates
    // finds no frame)
    input  wire [31:0]  dp_raise,
    // the stream port (a DMA pair beside the bus, CAPS_LANES bit 24), on clocks without an
    // access: a ray entry in (its direction; MODE, ORIGIN and SKIP_PATCH as RAY_IN latches
    // them; dropped if the FIFO is full, which `sp_full` said) and a whole result out (when
    // `sp_valid`: none is being read through RESULT_OUT)
    input  wire         sp_push,
    input  wire [95:0]  sp_dir,
    input  wire         sp_pop,
    output wire         sp_full,
    output wire         sp_valid,
    // what the datapath is told: ENABLE and FRAME_VALID as the access in its data phase
    // leaves them (the model's tick, which issues entries, runs after its access)
    output wire         enable,
    output wire         frame_ok,
    // a slot word written through PATCH_DATA, for the datapath's own copy of patch memory
    output wire          pm_we,
    output wire [SLOT_BITS+3:0] pm_addr,
    output wire [31:0]   pm_data,
    output wire [31:0]  config_active,
    output wire [31:0]  bz_config_active,
    output wire [31:0]  patch_count,
    output reg          apply,
    output reg          soft_reset,
    output reg          invalidate
);
    localparam [31:0] ID_VALUE = 32'h4845_4D49, VERSION_VALUE = 32'h0001_0004;
    localparam [31:0] CAPS_BEZIER_VALUE = 32'h1028_0040;
    // CONFIG at power-on: the build's, for units synthesised for one (BUILD_CONFIG)
    localparam [31:0] CONFIG_RESET = BUILD_CONFIG != 32'd0 ? BUILD_CONFIG : 32'h0010_1814,
        BZ_CONFIG_RESET = 32'h0000_1A0A;
    localparam [31:0] SPIN_C_RESET = 32'h3FFF_FFFF;
    localparam [31:0] SLOTS = 32'd1 << SLOT_BITS;
    localparam WORD_BITS = SLOT_BITS + 4;
    localparam RAY_DEPTH = 32;
    // word offsets (byte offset / 4)
    localparam [9:0] A_ID = 10'h000, A_VERSION = 10'h001, A_CAPS = 10'h002, A_CTRL = 10'h003,
        A_STATUS = 10'h004, A_ERROR = 10'h005, A_IRQ_STATUS = 10'h006, A_IRQ_ENABLE = 10'h007,
        A_CONFIG = 10'h008, A_CONFIG_ACTIVE = 10'h009, A_CYCLE_LO = 10'h00A,
        A_CYCLE_HI = 10'h00B, A_BUSY_LO = 10'h00C, A_BUSY_HI = 10'h00D,
        A_RESULTS_DONE = 10'h00E, A_MODE = 10'h010, A_ORIGIN = 10'h011, A_NORMAL = 10'h014,
        A_SPIN = 10'h017, A_PHI = 10'h019, A_THETA = 10'h01B, A_FRAME = 10'h01D,
        A_RAY_IN = 10'h020, A_RESULT_OUT = 10'h021, A_PATCH_ADDR = 10'h024,
        A_PATCH_DATA = 10'h025, A_PATCH_COUNT = 10'h026, A_SKIP_PATCH = 10'h027,
        A_BZ_CONFIG = 10'h028, A_BZ_CONFIG_ACTIVE = 10'h029, A_CAPS_BEZIER = 10'h02A,
        A_STACK_HIGH = 10'h02B, A_CAPS_LANES = 10'h02C;
    // ERROR bits
    localparam [31:0] E_RAY_OVERFLOW = 32'h001, E_RESULT_UNDERFLOW = 32'h002,
        E_BAD_CONFIG = 32'h004, E_CONFIG_BUSY = 32'h008, E_PATCH_RANGE = 32'h020,
        E_PATCH_BUSY = 32'h080;
    // IRQ_STATUS bits
    localparam [3:0] I_RESULT = 4'h1, I_IDLE = 4'h2, I_ERROR = 4'h4, I_FRAME = 4'h8;

    assign hresp = 1'b0;

    // ---- the access in its data phase (a PATCH_DATA read waits four clocks, `waits`, before
    // its last: the slave holds HREADYOUT low and the master holds the next address phase)
    reg       d_valid, d_write;
    reg [9:0] d_addr;
    reg [2:0] waits;
    // the writes decoded in the address phase (CTRL, RAY_IN and PATCH_DATA: from the data
    // phase's address, their decoding was the start of the critical paths into the FIFO and
    // the patch RAMs)
    reg       d_patch_write, d_ctrl_write, d_ray_in_write, d_config_write, d_bz_write;
    wire      a_valid = hsel && htrans[1] && hready;
    wire      stall = d_valid && !d_write && d_addr == A_PATCH_DATA && waits != 3'd4;
    wire      d_wr = d_valid && d_write;
    wire      d_rd = d_valid && !d_write && !stall;
    assign hreadyout = !stall;

    // ---- registers
    reg [31:0] config_reg, config_act, bz_reg, bz_act, error, mode, skip_reg, patch_addr, pcount;
    reg [3:0]  irq_status, irq_enable;
    reg        enable_reg, frame_valid, was_busy;
    // (CYCLE readable by a simulation harness without a bus access: accel_sim.cpp)
    reg [63:0] cycles /* verilator public_flat_rd */;
    reg [63:0] busy_cycles;
    reg [31:0] cycle_hi, busy_hi, results_done;
    reg [31:0] origin [0:2];
    reg [31:0] normal [0:2];
    reg [31:0] spin [0:1];
    reg [31:0] phi [0:1];
    reg [31:0] theta [0:1];
    reg [31:0] staging [0:1];
    reg [1:0]  staged, result_word;
    // the ray FIFO
    // in two banks of one write port each, even places and odd places, so that the two entries
    // one CTRL write can queue go to different banks (held in flip-flops with two write ports,
    // the FIFO was 8,192 of them and most of the register file's LUTs)
    reg [255:0] fifo_even [0:RAY_DEPTH/2-1];
    reg [255:0] fifo_odd [0:RAY_DEPTH/2-1];
    reg [4:0]   head, tail;
    reg [5:0]   count;

    assign irq = |(irq_status & irq_enable);
    // (APPLY_CONFIG clears FRAME_VALID; it is refused while anything is busy, so no frame
    // completes on its clock)
    assign frame_ok = frame_valid && !apply;
    assign config_active = config_act;
    assign bz_config_active = bz_act;
    assign patch_count = pcount;
    // a push is written into its bank a clock after its access, from registers (pend_*), so
    // that the LUT RAMs' write enables are a register's fanout and not the access's decoding;
    // the head is read past a write still pending
    reg         pend_even_we, pend_odd_we;
    reg [3:0]   pend_even_at, pend_odd_at;
    reg [255:0] pend_even, pend_odd;
    wire [255:0] head_even = pend_even_we && pend_even_at == head[4:1] ? pend_even
        : fifo_even[head[4:1]];
    wire [255:0] head_odd = pend_odd_we && pend_odd_at == head[4:1] ? pend_odd
        : fifo_odd[head[4:1]];
    // busy as the model's accesses see it, before their clock's tick: as the last clock left
    // it (the ray FIFO not empty, or the datapath busy at the end of its clock, `dp_busy`)
    wire busy = was_busy;
    // the data phase's word within the register groups
    wire [9:0] origin_ix = d_addr - A_ORIGIN, normal_ix = d_addr - A_NORMAL;
    wire [9:0] spin_ix = d_addr - A_SPIN, phi_ix = d_addr - A_PHI, theta_ix = d_addr - A_THETA;

    // ---- patch memory: the slots and the control-point rows (64 × 48 words at 0x1_0000)

    function in_slots(input [31:0] a);
        in_slots = (a >> WORD_BITS) == 32'd0;
    endfunction
    function in_cp(input [31:0] a);
        in_cp = a[31:16] == 16'd1 && a[15:0] < 16'd3072;
    endfunction

    wire d_ctrl_reset = d_ctrl_write && hwdata[31];
    wire d_patch_step = (d_wr || d_rd) && d_addr == A_PATCH_DATA;
    // PATCH_ADDR as the access in its data phase leaves it
    wire [31:0] patch_addr_next = d_ctrl_reset ? 32'd0
        : (d_wr && d_addr == A_PATCH_ADDR) ? hwdata
        : d_patch_step ? patch_addr + 32'd1 : patch_addr;
    wire [31:0] cp_here = patch_addr - 32'h0001_0000;
    // where PATCH_ADDR points: a slot word, a control-point word, or neither (PATCH_RANGE)
    // (registered with PATCH_ADDR, as is whether the access in its data phase writes
    // PATCH_DATA, above: decoded in the data phase, both were the logic before the write
    // enables' fanout to 64 block RAMs, the critical path at 74.6 MHz)
    // (at_slot is |at_group and at_cp |at_cp_group, below: kept as flip-flops of their own so
    // that the read's choice and PATCH_RANGE do not wait for an OR over the groups)
    reg at_slot, at_cp;
    // which group's memory PATCH_ADDR points into, one-hot, registered with it (decoded from
    // PATCH_ADDR, the group was the logic before its RAMs' write enables, the critical
    // path at 87–91 MHz)
    localparam integer GROUP_BITS = 10;
    localparam integer GROUPS = 1 << (WORD_BITS - GROUP_BITS);
    reg [GROUPS-1:0] at_group;
    reg [5:0]        at_cp_group;
    function [GROUPS-1:0] group_of(input [31:0] a);
        group_of = in_slots(a) ? {{(GROUPS - 1){1'b0}}, 1'b1} << a[WORD_BITS-1:GROUP_BITS]
            : {GROUPS{1'b0}};
    endfunction
    // where PATCH_ADDR + 1 points, from where PATCH_ADDR points rather than through the 32-bit
    // increment (through it, the ranges and groups of an auto-increment were the critical path
    // at 88–91 MHz): it leaves the slots past their last word and enters them past 2^32 − 1,
    // leaves the control points past their last and enters them past 0xFFFF, and moves a group
    // on past a group's last word
    wire slot_end = patch_addr[WORD_BITS-1:0] == {WORD_BITS{1'b1}};
    wire step_slot = at_slot ? !slot_end : patch_addr == 32'hFFFF_FFFF;
    wire [GROUPS-1:0] step_group = !step_slot ? {GROUPS{1'b0}}
        : !at_slot ? {{(GROUPS - 1){1'b0}}, 1'b1}
        : &patch_addr[GROUP_BITS-1:0] ? at_group << 1 : at_group;
    wire cp_end = patch_addr[15:0] == 16'd3071;
    wire step_cp = at_cp ? !cp_end : patch_addr == 32'h0000_FFFF;
    wire [5:0] step_cp_group = !step_cp ? 6'd0 : !at_cp ? 6'd1
        : &patch_addr[8:0] ? at_cp_group << 1 : at_cp_group;
    // (a control-point word's group from its index a − 0x1_0000, bits 11:9: the subtraction
    // leaves a[11:9] as they are, since 0x1_0000 has no bit below 16)
    function [5:0] cp_group_of(input [31:0] a);
        cp_group_of = in_cp(a) ? 6'd1 << a[11:9] : 6'd0;
    endfunction
    // read every clock at PATCH_ADDR (a write at the edge before is seen: read after write): the
    // slots in groups of 1,024 words (two block RAMs each) and the control points in groups of
    // 512 (one), each group's word registered the clock after its read, then the word of each
    // four groups' at PATCH_ADDR (and the control points' group's) the clock after that, then
    // the word at PATCH_ADDR: a PATCH_DATA read's four waits. (As one memory each, the RAMs'
    // slow output went through a 64-way (6-way) multiplexer into one register, the critical
    // path at 85–86 MHz (83 MHz); in groups of 2,048 words, through a 4-way one, at 92–94 MHz;
    // in groups of one RAM, the 64-way choice of their words took its place, at twice the
    // LUT4s; with the groups' words chosen among all 32 in one clock, their registers sat by
    // that choice, up to 45 columns from their RAMs, whose output takes 5.8 ns: 99.9 MHz.)
    integer i;
    wire [31:0] group_word [0:GROUPS-1];
    wire [31:0] cp_group_word [0:5];
    // a PATCH_DATA write reaches its RAM a clock after its access, from registers (in
    // `patch_group.v`, with `pend_word`): decided in its data phase, BUSY's logic was in one
    // clock with the write enables' routing to a group's RAMs, the critical path at 89–95 MHz.
    // A read cannot miss it: the next access is at least a clock, and PATCH_ADDR has moved on
    // past the word unless that access wrote PATCH_ADDR, after which the read's RAM read is a
    // clock later.
    reg [31:0] pend_word;
    always @(posedge hclk) pend_word <= hwdata;
    genvar g;
    generate
        for (g = 0; g < 6; g = g + 1) begin : cp_group
            patch_group #(.AW(9)) ram (
                .clk(hclk), .at(cp_here[8:0]),
                .write(hresetn && d_patch_write && !busy && at_cp_group[g]), .data(pend_word),
                .word(cp_group_word[g]));
        end
        for (g = 0; g < GROUPS; g = g + 1) begin : slot_group
            patch_group #(.AW(GROUP_BITS)) ram (
                .clk(hclk), .at(patch_addr[GROUP_BITS-1:0]),
                .write(hresetn && d_patch_write && !busy && at_group[g]), .data(pend_word),
                .word(group_word[g]));
        end
    endgenerate
    localparam integer QUADS = GROUPS >= 4 ? GROUPS / 4 : 1;
    reg [31:0] quad_word [0:QUADS-1];
    reg [31:0] cp_word, patch_word;
    generate
        for (g = 0; g < QUADS; g = g + 1) begin : slot_quad
            wire [31:0] at = 4 * g + {30'd0, patch_addr[GROUP_BITS+1:GROUP_BITS]};
            always @(posedge hclk) quad_word[g] <= at < GROUPS ? group_word[at] : 32'd0;
        end
    endgenerate
    always @(posedge hclk) begin
        cp_word <= cp_group_word[cp_here[11:9]];
        patch_word <= at_slot ? quad_word[(patch_addr >> (GROUP_BITS + 2)) % QUADS]
            : at_cp ? cp_word : 32'd0;
    end

    // ---- CONFIG and BZ_CONFIG as APPLY_CONFIG validates them, `configs_ok`: registered with
    // them from the words they take (checked from the registers, the checks' adders were in one
    // clock with APPLY_CONFIG's decision and its fanout to CONFIG's and BZ_CONFIG's copies in
    // force, the critical path at 95.7 MHz once patch memory's paths were shorter)
    // (the words' other bits are not the checks')
    /* verilator lint_off UNUSEDSIGNAL */
    function configs_ok_of(input [31:0] c, input [31:0] b);
        reg [4:0] c_iter, c_depth, b_depth;
        reg [5:0] c_width, b_width;
        begin
            {c_iter, c_width, c_depth} = {c[4:0], c[13:8], c[20:16]};
            {b_depth, b_width} = {b[4:0], b[13:8]};
            // BZ_CONFIG: depth 1..=16 and 3·depth ≤ the stack's 40 entries
            configs_ok_of = c_iter >= 5'd4 && c_iter <= 5'd30 && c_width >= 6'd12 &&
                c_width <= 6'd32 && {1'b0, c_iter} + 6'd2 <= c_width && c_depth >= 5'd1 &&
                c_depth <= 5'd24 && b_depth >= 5'd1 && b_depth <= 5'd13 && b_width >= 6'd12 &&
                b_width <= 6'd26 && (BUILD_CONFIG == 32'd0 ||
                {c_depth, c_width, c_iter} == {BUILD_CONFIG[20:16], BUILD_CONFIG[13:8],
                BUILD_CONFIG[4:0]});
        end
    endfunction
    /* verilator lint_on UNUSEDSIGNAL */
    reg configs_ok;

    // ---- read data, in the data phase
    reg [31:0] rdata;
    always @* begin
        rdata = 32'd0;
        case (d_addr)
            A_ID: rdata = ID_VALUE;
            A_VERSION: rdata = VERSION_VALUE;
            A_CAPS: rdata = {SLOTS[15:0], 8'd255, 8'd32};
            A_CTRL: rdata = {31'd0, enable_reg};
            A_STATUS: rdata = {8'd0, result_level, 2'd0, count, 3'd0, result_valid,
                count == RAY_DEPTH[5:0], frame_valid, frame_busy, busy};
            A_ERROR: rdata = error;
            A_IRQ_STATUS: rdata = {28'd0, irq_status};
            A_IRQ_ENABLE: rdata = {28'd0, irq_enable};
            A_CONFIG: rdata = config_reg;
            A_CONFIG_ACTIVE: rdata = config_act;
            A_CYCLE_LO: rdata = cycles[31:0];
            A_CYCLE_HI: rdata = cycle_hi;
            A_BUSY_LO: rdata = busy_cycles[31:0];
            A_BUSY_HI: rdata = busy_hi;
            A_RESULTS_DONE: rdata = results_done;
            A_MODE: rdata = mode;
            A_ORIGIN, A_ORIGIN + 10'd1, A_ORIGIN + 10'd2: rdata = origin[origin_ix[1:0]];
            A_NORMAL, A_NORMAL + 10'd1, A_NORMAL + 10'd2: rdata = normal[normal_ix[1:0]];
            A_SPIN, A_SPIN + 10'd1: rdata = spin[spin_ix[0]];
            A_PHI, A_PHI + 10'd1: rdata = phi[phi_ix[0]];
            A_THETA, A_THETA + 10'd1: rdata = theta[theta_ix[0]];
            A_FRAME: rdata = frame_angles[31:0];
            A_FRAME + 10'd1: rdata = frame_angles[63:32];
            A_FRAME + 10'd2: rdata = frame_angles[95:64];
            A_RESULT_OUT: rdata = result_valid ? result_words[32*result_word +: 32] : 32'd0;
            A_PATCH_ADDR: rdata = patch_addr;
            A_PATCH_DATA: rdata = patch_word;
            A_PATCH_COUNT: rdata = pcount;
            A_SKIP_PATCH: rdata = skip_reg;
            A_BZ_CONFIG: rdata = bz_reg;
            A_BZ_CONFIG_ACTIVE: rdata = bz_act;
            A_CAPS_BEZIER: rdata = CAPS_BEZIER_VALUE;
            A_STACK_HIGH: rdata = {24'd0, stack_high};
            A_CAPS_LANES: rdata = CAPS_LANES_VALUE;
            default: rdata = 32'd0;
        endcase
    end
    assign hrdata = d_rd ? rdata : 32'd0;

    // ---- the next state: the data phase's access, then the clock's own counting, in the
    // model's order (`Device::write` / `read`, then `Device::tick`)
    reg [31:0] n_error, n_mode, n_skip, n_config, n_bz, n_config_act, n_bz_act, n_pcount;
    reg [3:0]  n_irq_status, n_irq_enable;
    reg        n_enable, n_frame_valid, n_busy;
    reg [1:0]  n_staged, n_word;
    reg [5:0]  n_count, n_step;
    reg [4:0]  n_tail, tail_b;
    reg        push_a, push_b, overflow;
    // the entries a CTRL write or RAY_IN's third write queues, first (a) and second (b), chosen
    // by the access alone: which of them a bank takes follows from the tail, whether it takes
    // one from the pushes (chosen by the pushes, the 512 multiplexers were their fanout, and
    // the pushes' logic sat far from the count it feeds)
    wire [255:0] frame_normal = {32'd0, 32'd0, spin[1], spin[0], normal[2], normal[1],
        normal[0], 32'h0001_0000};
    wire [255:0] frame_pairs = {32'd0, spin[1], spin[0], theta[1], theta[0], phi[1], phi[0],
        32'h0002_0000};
    // a ray's direction: RAY_IN's three words, or the stream port's (never on the same clock)
    wire [95:0]  ray_dir = sp_push ? sp_dir : {hwdata, staging[1], staging[0]};
    wire [255:0] ray_entry = {ray_dir, skip_reg[31] ? skip_reg : 32'd0, origin[2], origin[1],
        origin[0], mode};
    wire [255:0] entry_a = sp_push || d_ray_in_write ? ray_entry
        : hwdata[1] ? frame_normal : frame_pairs;
    wire [255:0] entry_b = frame_pairs;
    // an entry queued by this clock's access (or the stream port) into an empty FIFO is the
    // head already: the model's access comes before its tick, which may issue it on the same
    // clock
    assign entry_valid = count != 6'd0 || push_a;
    assign sp_full = count == RAY_DEPTH[5:0];
    assign sp_valid = result_valid && result_word == 2'd0;
    assign entry = count == 6'd0 ? entry_a : head[0] ? head_odd : head_even;
    assign enable = n_enable && !d_ctrl_reset;
    assign pm_we = hresetn && d_patch_write && !busy && at_slot;
    assign pm_addr = patch_addr[SLOT_BITS+3:0];
    assign pm_data = hwdata;
    reg [31:0] n_cycle_hi, n_busy_hi;

    task raise(input [31:0] bits);
        begin
            n_error = n_error | bits;
            n_irq_status = n_irq_status | I_ERROR;
        end
    endtask

    // (full from count and the first push, not from a running count's adders)
    task queue;
        begin
            if (push_a ? count == RAY_DEPTH[5:0] - 6'd1 : count == RAY_DEPTH[5:0])
                overflow = 1'b1;
            else if (!push_a) push_a = 1'b1;
            else push_b = 1'b1;
        end
    endtask

    // the ray FIFO's pushes, from the access decoded in its address phase or from the stream
    // port, in a block of their own: the datapath's issue reads the head they make and its pop
    // comes back into the next state below (in one block, a loop to Verilator)
    always @* begin
        push_a = 1'b0;
        push_b = 1'b0;
        overflow = 1'b0;
        if (d_ctrl_write && !d_ctrl_reset) begin
            if (hwdata[1]) queue;
            if (hwdata[2]) queue;
        end
        if (d_ray_in_write && staged == 2'd2) queue;
        if (sp_push && !sp_full) push_a = 1'b1;
    end

    always @* begin
        n_error = error;
        n_irq_status = irq_status;
        n_irq_enable = irq_enable;
        n_mode = mode;
        n_skip = skip_reg;
        n_config = config_reg;
        n_bz = bz_reg;
        n_config_act = config_act;
        n_bz_act = bz_act;
        n_pcount = pcount;
        n_enable = enable_reg;
        n_frame_valid = frame_valid;
        n_staged = staged;
        n_word = result_word;
        n_count = count;
        n_step = 6'd0;
        n_cycle_hi = cycle_hi;
        n_busy_hi = busy_hi;
        apply = 1'b0;
        invalidate = 1'b0;
        result_pop = 1'b0;
        soft_reset = d_ctrl_reset;
        if (d_wr && !d_ctrl_reset) begin
            case (d_addr)
                A_CTRL: begin
                    n_enable = hwdata[0];
                    if (hwdata[3]) begin
                        if (busy) raise(E_CONFIG_BUSY);
                        else if (configs_ok) begin
                            n_config_act = config_reg;
                            n_bz_act = bz_reg;
                            n_frame_valid = 1'b0;
                            apply = 1'b1;
                        end else raise(E_BAD_CONFIG);
                    end
                end
                A_ERROR: n_error = error & ~hwdata;
                A_IRQ_STATUS: n_irq_status = irq_status & ~hwdata[3:0];
                A_IRQ_ENABLE: n_irq_enable = hwdata[3:0];
                A_CONFIG: n_config = hwdata;
                A_BZ_CONFIG: n_bz = hwdata;
                A_SKIP_PATCH: n_skip = hwdata & 32'h80FF_FFFF;
                A_MODE:
                    if ((hwdata & ~32'h0000_0103) == 32'd0 && hwdata[1:0] != 2'd3) n_mode = hwdata;
                    else raise(E_BAD_CONFIG);
                A_RAY_IN: n_staged = staged == 2'd2 ? 2'd0 : staged + 2'd1;
                A_PATCH_DATA:
                    if (busy) raise(E_PATCH_BUSY);
                    else if (at_slot || at_cp) invalidate = 1'b1;
                    else raise(E_PATCH_RANGE);
                A_PATCH_COUNT:
                    if (busy) raise(E_PATCH_BUSY);
                    else if (hwdata > SLOTS) raise(E_PATCH_RANGE);
                    else begin
                        n_pcount = hwdata;
                        invalidate = 1'b1;
                    end
                default: ;
            endcase
        end
        if (overflow) raise(E_RAY_OVERFLOW);
        if (sp_pop && sp_valid) result_pop = 1'b1;
        if (d_rd) begin
            case (d_addr)
                A_CYCLE_LO: n_cycle_hi = cycles[63:32];
                A_BUSY_LO: n_busy_hi = busy_cycles[63:32];
                A_RESULT_OUT:
                    if (!result_valid) raise(E_RESULT_UNDERFLOW);
                    else if (n_word == (result_words[27] ? 2'd1 : 2'd3)) begin
                        n_word = 2'd0;
                        result_pop = 1'b1;
                    end else n_word = n_word + 2'd1;
                A_PATCH_DATA:
                    if (!at_slot && !at_cp) raise(E_PATCH_RANGE);
                default: ;
            endcase
        end
        // the clock: the datapath takes the head, a frame completes, a result comes
        // the count's step (the pushes less a pop) into one adder: as two adders and a
        // decrement after them, chained behind the pushes, it was the critical path (97 MHz);
        // a second push comes only with a first, and a pop takes one of count + pushes
        if (push_b) n_step = entry_pop ? 6'd1 : 6'd2;
        else if (push_a) n_step = entry_pop ? 6'd0 : 6'd1;
        else n_step = entry_pop && count != 6'd0 ? 6'h3F : 6'd0;
        n_count = count + n_step;
        if (dp_raise != 32'd0) raise(dp_raise);
        if (frame_done) begin
            n_frame_valid = 1'b1;
            n_irq_status = n_irq_status | I_FRAME;
        end
        if (result_push) n_irq_status = n_irq_status | I_RESULT;
        // n_count != 0 from the pushes and the pop rather than from n_count's adders (through
        // them, the busy counter's enable was the critical path, 70 MHz): a pop takes one of
        // count + pushes when there is one
        n_busy = dp_busy || count > 6'd1
            || (count == 6'd1 && (push_a || !entry_pop))
            || (count == 6'd0 && (push_b || (push_a && !entry_pop)));
        tail_b = tail + {4'd0, push_a};
        n_tail = tail_b + {4'd0, push_b};
        if (!n_busy && was_busy) n_irq_status = n_irq_status | I_IDLE;
    end

    // one write port a bank: two pushes go to tail and tail + 1, one even place and one odd
    wire a_even = push_a && !tail[0], a_odd = push_a && tail[0];
    wire even_we = a_even || (push_b && !tail_b[0]), odd_we = a_odd || (push_b && tail_b[0]);
    // each bank's place from tail alone, whatever is pushed (the odd place is at tail[4:1]
    // whether the first push or the second takes it, the even one a row on when tail is odd):
    // chosen by the pushes, the LUT RAMs' write address waited for the access's decoding, the
    // critical path at 78.2 MHz
    wire [3:0] even_at = tail[4:1] + {3'd0, tail[0]};
    wire [3:0] odd_at = tail[4:1];
    wire [255:0] even_entry = tail[0] ? entry_b : entry_a;
    wire [255:0] odd_entry = tail[0] ? entry_a : entry_b;

    always @(posedge hclk) begin
        if (pend_even_we) fifo_even[pend_even_at] <= pend_even;
        if (pend_odd_we) fifo_odd[pend_odd_at] <= pend_odd;
    end

    always @(posedge hclk) begin
        if (!hresetn || d_ctrl_reset) begin
            // power-on reset, or SOFT_RESET: patch memory, PATCH_COUNT and the configuration in
            // force survive a soft reset (CONFIG and BZ_CONFIG read back the ones in force)
            if (!hresetn) begin
                config_act <= CONFIG_RESET;
                bz_act <= BZ_CONFIG_RESET;
                config_reg <= CONFIG_RESET;
                bz_reg <= BZ_CONFIG_RESET;
                configs_ok <= configs_ok_of(CONFIG_RESET, BZ_CONFIG_RESET);
                pcount <= 32'd0;
                d_valid <= 1'b0;
            end else begin
                config_reg <= config_act;
                bz_reg <= bz_act;
                configs_ok <= configs_ok_of(config_act, bz_act);
                if (hready) d_valid <= a_valid;
            end
            error <= 32'd0;
            irq_status <= 4'd0;
            irq_enable <= 4'd0;
            enable_reg <= 1'b0;
            frame_valid <= 1'b0;
            was_busy <= 1'b0;
            // the soft reset's clock still counts (the model resets, then ticks)
            cycles <= hresetn ? 64'd1 : 64'd0;
            busy_cycles <= 64'd0;
            cycle_hi <= 32'd0;
            busy_hi <= 32'd0;
            results_done <= 32'd0;
            mode <= 32'd0;
            skip_reg <= 32'd0;
            patch_addr <= 32'd0;
            at_slot <= 1'b1;
            at_cp <= 1'b0;
            at_group <= group_of(32'd0);
            at_cp_group <= 6'd0;
            staged <= 2'd0;
            result_word <= 2'd0;
            head <= 5'd0;
            tail <= 5'd0;
            pend_even_we <= 1'b0;
            pend_odd_we <= 1'b0;
            count <= 6'd0;
            for (i = 0; i < 3; i = i + 1) begin
                origin[i] <= 32'd0;
                normal[i] <= 32'd0;
            end
            spin[0] <= SPIN_C_RESET;
            spin[1] <= 32'd0;
            phi[0] <= 32'd0;
            phi[1] <= 32'd0;
            theta[0] <= 32'd0;
            theta[1] <= 32'd0;
        end else begin
            // the next access only when the bus is ready (not while a read waits)
            if (hready) d_valid <= a_valid;
            error <= n_error;
            irq_status <= n_irq_status;
            irq_enable <= n_irq_enable;
            enable_reg <= n_enable;
            frame_valid <= n_frame_valid;
            was_busy <= n_busy;
            cycles <= cycles + 64'd1;
            // (the increment does not wait for n_busy, which only selects it: as a carry into
            // the 64-bit adder it was the critical path, 55 MHz)
            if (n_busy) busy_cycles <= busy_cycles + 64'd1;
            cycle_hi <= n_cycle_hi;
            busy_hi <= n_busy_hi;
            if (result_push) results_done <= results_done + 32'd1;
            mode <= n_mode;
            skip_reg <= n_skip;
            config_reg <= n_config;
            bz_reg <= n_bz;
            // (the words CONFIG and BZ_CONFIG take, from the writes decoded in the address
            // phase: through n_config's decoding the check was the critical path, 91 MHz)
            configs_ok <= configs_ok_of(d_config_write ? hwdata : config_reg,
                d_bz_write ? hwdata : bz_reg);
            config_act <= n_config_act;
            bz_act <= n_bz_act;
            pcount <= n_pcount;
            patch_addr <= patch_addr_next;
            if (d_wr && d_addr == A_PATCH_ADDR) begin
                at_slot <= in_slots(hwdata);
                at_cp <= in_cp(hwdata);
                at_group <= group_of(hwdata);
                at_cp_group <= cp_group_of(hwdata);
            end else if (d_patch_step) begin
                at_slot <= step_slot;
                at_cp <= step_cp;
                at_group <= step_group;
                at_cp_group <= step_cp_group;
            end
            staged <= n_staged;
            result_word <= n_word;
            count <= n_count;
            if (entry_pop && (count != 6'd0 || push_a)) head <= head + 5'd1;
            pend_even_we <= even_we;
            pend_odd_we <= odd_we;
            pend_even_at <= even_at;
            pend_odd_at <= odd_at;
            pend_even <= even_entry;
            pend_odd <= odd_entry;
            tail <= n_tail;
            if (d_wr && d_addr == A_RAY_IN && staged != 2'd2) staging[staged[0]] <= hwdata;
            if (d_wr && d_addr >= A_ORIGIN && d_addr < A_ORIGIN + 10'd3)
                origin[origin_ix[1:0]] <= hwdata;
            if (d_wr && d_addr >= A_NORMAL && d_addr < A_NORMAL + 10'd3)
                normal[normal_ix[1:0]] <= hwdata;
            if (d_wr && d_addr >= A_SPIN && d_addr < A_SPIN + 10'd2) spin[spin_ix[0]] <= hwdata;
            if (d_wr && d_addr >= A_PHI && d_addr < A_PHI + 10'd2) phi[phi_ix[0]] <= hwdata;
            if (d_wr && d_addr >= A_THETA && d_addr < A_THETA + 10'd2)
                theta[theta_ix[0]] <= hwdata;
        end
        if (a_valid) begin
            d_write <= hwrite;
            d_addr <= haddr[11:2];
        end
        if (!hresetn) begin
            d_patch_write <= 1'b0;
            d_ctrl_write <= 1'b0;
            d_ray_in_write <= 1'b0;
            d_config_write <= 1'b0;
            d_bz_write <= 1'b0;
        end else if (hready) begin
            d_patch_write <= a_valid && hwrite && haddr[11:2] == A_PATCH_DATA;
            d_ctrl_write <= a_valid && hwrite && haddr[11:2] == A_CTRL;
            d_ray_in_write <= a_valid && hwrite && haddr[11:2] == A_RAY_IN;
            d_config_write <= a_valid && hwrite && haddr[11:2] == A_CONFIG;
            d_bz_write <= a_valid && hwrite && haddr[11:2] == A_BZ_CONFIG;
        end
        waits <= hresetn && stall ? waits + 3'd1 : 3'd0;
    end
    // (HSIZE, HTRANS's SEQ bit and the byte lane bits are not decoded, nor the index bits
    // above each register group)
    /* verilator lint_off UNUSEDSIGNAL */
    wire unused = &{1'b0, haddr[1:0], htrans[0], hsize, origin_ix[9:2], normal_ix[9:2],
        spin_ix[9:1], phi_ix[9:1], theta_ix[9:1], cp_here[31:12]};
    /* verilator lint_on UNUSEDSIGNAL */
endmodule
