// A bank's set-up pass, whole: its front (`bank_front.v`: the box read, the horizon filter, the
// FIFO and the corner reads) feeding its compact set-up unit (`setup_unit.v`) a corner a clock,
// as the model's set-up pass (hdl-model/src/intersect/mod.rs, `setup_pass`) has them. Each pass
// gets the next tag (its parity); the pass's origin and frame axes are kept in the tag's
// registers and given with each of its corners, which is when the set-up unit takes them. A
// pass two after this one may begin only once this one's answers are out (in the model, once
// the lanes have released its buffer), so two sets of registers are enough. Slots other than
// triangles and quads have their one clock in the front and go nowhere: the Bezier lane's root
// boxes have no RTL yet. Each answer comes with its slot (`out_p_slot`), the place the bank's
// bitmap writer sets (`bank_pass.v`).
// Verilog-2005, accepted by Verilator and Yosys.
module bank_setup #(
    parameter integer SLOT_BITS = 9,
    parameter integer ITER = 14,
    parameter integer W = 20,
    parameter integer SECTORS = 32
) (
    input  wire                   clk,
    input  wire                   box_we,
    input  wire [SLOT_BITS-1:0]   box_slot,
    input  wire [71:0]            box_lo,
    input  wire [71:0]            box_hi,
    input  wire                   box_boxed,
    input  wire [1:0]             box_clocks,
    input  wire                   corner_we,
    input  wire [SLOT_BITS+1:0]   corner_addr,
    input  wire [95:0]            corner_data,
    input  wire                   normal_we,
    input  wire [SLOT_BITS-1:0]   normal_slot,
    input  wire [95:0]            normal_data,
    // a pass over the bank's first `count` slots from `origin` in the frame with axes u, v, w
    input  wire                   start,
    input  wire [SLOT_BITS:0]     count,
    input  wire [95:0]            origin,
    input  wire [95:0]            axis_u,
    input  wire [95:0]            axis_v,
    input  wire [95:0]            axis_w,
    // the set-up unit's answers: an edge's coarse words, a patch's plane test and reach
    output wire                   out_e_valid,
    output wire [53:0]            out_e_words,
    output wire [3:0]             out_e_kappa,
    output wire                   out_p_valid,
    output wire                   out_p_active,
    output wire [3:0]             out_p_kappa,
    output wire [1:0]             out_p_kind,
    output wire [5:0]             out_p_lo,
    output wire [6:0]             out_p_len,
    output wire [3:0]             out_p_band_lo,
    output wire [3:0]             out_p_band_hi,
    // the answer's slot (its place in the bank's bitmaps)
    output wire [SLOT_BITS-1:0]   out_p_slot
);
    // the passes' registers, by tag
    reg         tag;
    reg [383:0] frame [0:1];
    initial tag = 1'b0;
    always @(posedge clk) if (start) begin
        tag <= !tag;
        frame[!tag] <= {axis_w, axis_v, axis_u, origin};
    end

    wire                 c_valid, c_planar, c_pass, c_last;
    wire [SLOT_BITS-1:0] c_slot;
    /* verilator lint_off UNUSEDSIGNAL */ // which corner: the set-up unit does not need it
    wire [1:0]           c_corner;
    wire                 busy;
    /* verilator lint_on UNUSEDSIGNAL */
    wire [95:0]          c_data, c_normal;
    bank_front #(.SLOT_BITS(SLOT_BITS)) front (
        .clk(clk), .box_we(box_we), .box_slot(box_slot), .box_lo(box_lo), .box_hi(box_hi),
        .box_boxed(box_boxed), .box_clocks(box_clocks), .corner_we(corner_we),
        .corner_addr(corner_addr), .corner_data(corner_data), .normal_we(normal_we),
        .normal_slot(normal_slot), .normal_data(normal_data), .start(start), .count(count),
        .o(origin), .w(axis_w), .tag(!tag), .c_valid(c_valid), .c_planar(c_planar), .c_pass(c_pass),
        .c_last(c_last), .c_slot(c_slot), .c_corner(c_corner), .c_data(c_data),
        .c_normal(c_normal), .busy(busy));

    wire [383:0] f = frame[c_pass];
    setup_unit #(.ITER(ITER), .W(W), .SECTORS(SECTORS)) unit (
        .clk(clk), .in_valid(c_valid && c_planar), .in_last(c_last), .in_pass(c_pass),
        .in_cx(c_data[31:0]), .in_cy(c_data[63:32]), .in_cz(c_data[95:64]),
        .in_nx(c_normal[31:0]), .in_ny(c_normal[63:32]), .in_nz(c_normal[95:64]),
        .in_ox(f[31:0]), .in_oy(f[63:32]), .in_oz(f[95:64]),
        .in_ux(f[127:96]), .in_uy(f[159:128]), .in_uz(f[191:160]),
        .in_vx(f[223:192]), .in_vy(f[255:224]), .in_vz(f[287:256]),
        .in_wx(f[319:288]), .in_wy(f[351:320]), .in_wz(f[383:352]),
        .out_e_valid(out_e_valid), .out_e_words(out_e_words), .out_e_kappa(out_e_kappa),
        .out_p_valid(out_p_valid), .out_p_active(out_p_active), .out_p_kappa(out_p_kappa),
        .out_p_kind(out_p_kind), .out_p_lo(out_p_lo), .out_p_len(out_p_len),
        .out_p_band_lo(out_p_band_lo), .out_p_band_hi(out_p_band_hi));

    // The slots of the planar patches in the set-up unit, in order, for their answers, which
    // leave it in the order their last corners entered: at most its answer latency (84 clocks)
    // over three corners a patch, 28, are in flight, so 32 entries of distributed RAM.
    localparam integer FLIGHT_BITS = 5;
    reg [SLOT_BITS-1:0]   flight [0:(1<<FLIGHT_BITS)-1];
    reg [FLIGHT_BITS-1:0] f_wr, f_rd;
    initial begin
        f_wr = 0;
        f_rd = 0;
    end
    always @(posedge clk) begin
        if (c_valid && c_planar && c_last) begin
            flight[f_wr] <= c_slot;
            f_wr <= f_wr + 1'b1;
        end
        if (out_p_valid) f_rd <= f_rd + 1'b1;
    end
    assign out_p_slot = flight[f_rd];
endmodule
