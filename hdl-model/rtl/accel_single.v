// The whole accelerator of the one-lane build (`Params::SINGLE`: one lane of 256 slots, no
// culling, one ray a clock, planar slots), behind its AHB-Lite slave: the RTL of
// hdl-model/src/device.rs with its units joined as `Device::tick` joins them.
//
//   AHB-Lite -> ahb_regs (registers, ray FIFO, patch memory) -> issue: a frame to frame_unit,
//   a ray to rotator -> queue -> plane_unit -> result FIFO -> RESULT_OUT
//
// One clock, in the model's order: the access in its data phase (ahb_regs); a result out of the
// intersection unit into the result FIFO; a ray out of the queue into the intersection unit if
// it is ready; the ray FIFO's head issued (a frame to the angle unit when it is idle; a ray to
// the rotator while fewer than 255 rays are held between the rotator and the result FIFO, and,
// if it rotates, once the angle unit is idle); the rotator's output into the queue; the angle
// unit's clock.
//
// Rays stay in order from issue to result (the rotator is a pipe of one latency, the queue a
// FIFO, the intersection unit retires in order), so one table of 256 rows, by a ray's place in
// that order, holds what each ray carries past the units: its MODE and error bit, origin and
// skipped slot (written at issue), its direction out of the rotator (read when it starts and,
// for a rotation, into its result). Five counters walk it, issued, rotated, started, retired
// and popped (out of the result FIFO, whose rows are the table's places too), and their
// differences are the rays in each part: held (issued − popped, the credits), in the unit
// (issued − retired, BUSY), in the result FIFO (retired − popped).
//
// CONFIG is this build's: the CORDIC pipes' ITER and W and the (u,v) DEPTH are parameters, set
// to CONFIG's reset value, and the register file refuses APPLY_CONFIG of another (BAD_CONFIG),
// as the model's `Device::built_for` does (the model's own units follow any valid CONFIG).
module accel_single #(
    parameter integer ITER = 20,
    parameter integer W = 24,
    parameter integer DEPTH = 16,
    parameter integer IW = 8
) (
    input  wire        hclk,
    input  wire        hresetn,
    input  wire        hsel,
    input  wire [11:0] haddr,
    input  wire [1:0]  htrans,
    input  wire        hwrite,
    input  wire [2:0]  hsize,
    input  wire [31:0] hwdata,
    input  wire        hready,
    output wire [31:0] hrdata,
    output wire        hreadyout,
    output wire        hresp,
    output wire        irq,
    // the stream port (CAPS_LANES bit 24): on a clock without a bus access, a ray entry in
    // (its direction, z in 95:64) unless `sp_full`, and the whole result at the head out when
    // `sp_valid` (its four words, word 0 in 31:0)
    input  wire        sp_push,
    input  wire [95:0] sp_dir,
    input  wire        sp_pop,
    output wire        sp_full,
    output wire        sp_valid,
    output wire [127:0] sp_result
);
    // `Params::SINGLE.caps_word()`: one lane, one ray a clock, no culling, the stream port (bit
    // 24)
    localparam [31:0] CAPS_LANES = 32'h0100_0101;
    localparam [31:0] E_NO_FRAME = 32'h010;
    localparam [31:0] R_HIT = 32'h8000_0000, R_FRONT = 32'h4000_0000, R_ERROR = 32'h2000_0000,
        R_ROTATED = 32'h1000_0000, R_SHORT = 32'h0800_0000;
    localparam [1:0] TRACE = 2'd0, ROTATE = 2'd1;
    localparam [7:0] CREDITS = 8'd255;

    // ---- the register file
    wire         entry_valid, entry_pop, enable, frame_ok, apply, soft_reset, invalidate;
    wire [255:0] entry;
    wire         pm_we;
    wire [IW+3:0] pm_addr;
    wire [31:0]  pm_data, patch_count;
    wire         frame_busy, frame_done, dp_busy;
    wire [W-1:0] psi, theta, phi;
    // the angles in the model's 32-bit containers (the top W bits)
    wire [31:0]  psi32 = {psi, {(32 - W){1'b0}}}, theta32 = {theta, {(32 - W){1'b0}}},
        phi32 = {phi, {(32 - W){1'b0}}};
    wire         result_pop, retire;
    // the table's places (below)
    reg  [7:0]   issued, rotated, started, retired, popped;
    wire [7:0]   results = retired - popped;
    wire [127:0] rf_head;
    wire [31:0]  raised;
    /* verilator lint_off UNUSEDSIGNAL */ // the units' configuration is this build's
    wire [31:0]  config_active, bz_config_active;
    /* verilator lint_on UNUSEDSIGNAL */
    localparam [31:0] BUILD_CONFIG = (DEPTH << 16) | (W << 8) | ITER;
    ahb_regs #(.SLOT_BITS(IW), .CAPS_LANES_VALUE(CAPS_LANES), .BUILD_CONFIG(BUILD_CONFIG)) regs (
        .hclk(hclk), .hresetn(hresetn), .hsel(hsel), .haddr(haddr), .htrans(htrans),
        .hwrite(hwrite), .hsize(hsize), .hwdata(hwdata), .hready(hready), .hrdata(hrdata),
        .hreadyout(hreadyout), .hresp(hresp), .irq(irq),
        .entry_valid(entry_valid), .entry(entry), .entry_pop(entry_pop),
        .dp_busy(dp_busy), .frame_busy(frame_busy), .frame_done(frame_done),
        .frame_angles({phi32, theta32, psi32}), .stack_high(8'd0),
        .result_push(retire), .result_level(results), .result_valid(results != 8'd0),
        .result_words(rf_head), .result_pop(result_pop), .dp_raise(raised),
        .sp_push(sp_push), .sp_dir(sp_dir), .sp_pop(sp_pop), .sp_full(sp_full),
        .sp_valid(sp_valid),
        .enable(enable), .frame_ok(frame_ok), .pm_we(pm_we), .pm_addr(pm_addr),
        .pm_data(pm_data), .config_active(config_active), .bz_config_active(bz_config_active),
        .patch_count(patch_count), .apply(apply), .soft_reset(soft_reset),
        .invalidate(invalidate));
    // everything behind the registers starts again at a soft reset (patch memory survives)
    wire rst = !hresetn || soft_reset;

    // ---- issue: the ray FIFO's head (word 0 of an entry: a frame's kind in 17:16, a ray's
    // MODE in 8:0)
    wire       e_frame = entry[17:16] != 2'd0;
    wire [1:0] e_kind = entry[1:0];
    wire       e_rotates = e_kind != TRACE;
    // the rays held from the rotator to the result FIFO, less the one a read takes out now
    wire       credit = issued - popped - {7'd0, result_pop} < CREDITS;
    wire go = enable && entry_valid && !rst;
    wire issue_frame = go && e_frame && !frame_busy;
    wire issue_ray = go && !e_frame && credit && !(e_rotates && frame_busy);
    assign entry_pop = issue_frame || issue_ray;
    wire no_frame = issue_ray && e_rotates && !frame_ok;
    assign raised = no_frame ? E_NO_FRAME : 32'd0;

    // ---- the angle unit: a frame from NORMAL and SPIN (words 1..5) or from pairs (1..6)
    frame_unit #(.ITER(ITER), .W(W)) frame (
        .clk(hclk), .rst(rst), .start(issue_frame), .clear(apply), .pairs(entry[17]),
        .w1(entry[63:64-W]), .w2(entry[95:96-W]), .w3(entry[127:128-W]),
        .w4(entry[159:160-W]), .w5(entry[191:192-W]), .w6(entry[223:224-W]),
        .busy(frame_busy), .done(frame_done), .psi(psi), .theta(theta), .phi(phi));

    // ---- the rotator (a trace's direction, and a ray without a frame, pass it as written)
    wire        rot_valid;
    wire [31:0] rot_dx, rot_dy, rot_dz;
    /* verilator lint_off UNUSEDSIGNAL */ // the table follows the order, not the tag
    wire [6:0]  rot_tag;
    /* verilator lint_on UNUSEDSIGNAL */
    rotator #(.ITER(ITER), .W(W)) rot (
        .clk(hclk), .rst(rst), .in_valid(issue_ray),
        .in_dx(entry[191:160]), .in_dy(entry[223:192]), .in_dz(entry[255:224]),
        .in_psi(psi32), .in_theta(theta32), .in_phi(phi32), .in_bypass(!e_rotates || no_frame),
        .out_valid(rot_valid), .out_dx(rot_dx), .out_dy(rot_dy), .out_dz(rot_dz),
        .out_tag(rot_tag));

    // ---- the ray table and its four places
    reg  [2:0]    t_mode [0:255];  // MODE's NO_UV and kind
    reg           t_error [0:255];
    reg  [95:0]   t_origin [0:255];
    reg           t_skip_en [0:255];
    reg  [IW-1:0] t_skip [0:255];
    reg  [95:0]   t_dir [0:255];
    // a skipped slot beyond the build's slots skips nothing (the model compares the whole word)
    wire skip_en = entry[159] && entry[151:128+IW] == {(24 - IW){1'b0}};
    always @(posedge hclk) begin
        if (issue_ray) begin
            t_mode[issued] <= {entry[8], e_kind};
            t_error[issued] <= no_frame;
            t_origin[issued] <= entry[127:32];
            t_skip_en[issued] <= skip_en;
            t_skip[issued] <= entry[128+IW-1:128];
        end
        if (rot_valid) t_dir[rotated] <= {rot_dz, rot_dy, rot_dx};
    end

    // ---- the intersection unit, fed from the queue (the rays rotated and not yet started)
    wire          in_ready, out_valid, out_hit, out_front;
    wire [IW-1:0] out_patch;
    wire [31:0]   out_t, out_u, out_v;
    wire          start = rotated != started && in_ready;
    wire [2:0]    s_mode = t_mode[started];
    plane_unit #(.IW(IW), .DEPTH(DEPTH)) lane (
        .clk(hclk), .rst(rst), .pm_we(pm_we), .pm_addr(pm_addr), .pm_data(pm_data),
        .count(patch_count[IW:0]), .invalidate(invalidate || apply),
        .in_valid(start), .in_ready(in_ready), .in_origin(t_origin[started]),
        .in_dir(t_dir[started]), .in_uv(!s_mode[2]), .in_skip_en(t_skip_en[started]),
        .in_skip(t_skip[started]),
        .in_bypass(s_mode[1:0] == ROTATE || t_error[started]),
        .out_valid(out_valid), .out_hit(out_hit), .out_patch(out_patch), .out_t(out_t),
        .out_u(out_u), .out_v(out_v), .out_front(out_front));
    // the result FIFO has room for every ray held (the credits are its depth)
    assign retire = out_valid && !rst;

    // ---- the result's words (`Device::result_words`)
    wire [2:0]  r_mode = t_mode[retired];
    wire [95:0] r_dir = t_dir[retired];
    wire [31:0] short = r_mode[2] ? R_SHORT : 32'd0;
    wire [31:0] flags = (out_hit ? R_HIT : 32'd0) | (out_hit && out_front ? R_FRONT : 32'd0)
        | short | (out_hit ? {{(32 - IW){1'b0}}, out_patch} : 32'd0);
    wire [127:0] words = t_error[retired] ? {96'd0, R_ERROR}
        : r_mode[1:0] == ROTATE ? {r_dir, R_ROTATED}
        : out_hit ? {out_v, out_u, out_t, flags} : {96'd0, short};

    // ---- the result FIFO (255 results, the credits), a row a place
    reg [127:0] rf [0:255];
    assign rf_head = rf[popped];
    assign sp_result = rf_head;
    always @(posedge hclk) if (retire) rf[retired] <= words;

    // ---- the places, and BUSY (the datapath's, as the clock leaves it: rays issued and not
    // retired, or a frame)
    wire [7:0] in_unit_next = issued + {7'd0, issue_ray} - retired - {7'd0, retire};
    assign dp_busy = in_unit_next != 8'd0 || issue_frame || (frame_busy && !frame_done);
    always @(posedge hclk) begin
        if (rst) begin
            issued <= 8'd0;
            rotated <= 8'd0;
            started <= 8'd0;
            retired <= 8'd0;
            popped <= 8'd0;
        end else begin
            if (issue_ray) issued <= issued + 8'd1;
            if (rot_valid) rotated <= rotated + 8'd1;
            if (start) started <= started + 8'd1;
            if (retire) retired <= retired + 8'd1;
            if (result_pop) popped <= popped + 8'd1;
        end
    end
    // (patch_count's bits above the slots: PATCH_COUNT is at most 256; word 0's bits that
    // are neither a frame's kind nor MODE's)
    /* verilator lint_off UNUSEDSIGNAL */
    wire unused = &{1'b0, patch_count[31:IW+1], entry[31:18], entry[15:9], entry[7:2]};
    /* verilator lint_on UNUSEDSIGNAL */
endmodule
