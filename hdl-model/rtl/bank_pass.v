// A bank's set-up pass into its candidate bitmaps: the set-up pass (`bank_setup.v`: the front
// and the set-up unit) whose answers, each with its slot's place, go to the bank's bitmap
// writer (`bitmap_writer.v`), as the model's set-up pass (hdl-model/src/intersect/mod.rs,
// `setup_pass`) hands them to its `ColumnWriter`: the set-up unit's registered answer is the
// writer's input on the clock after the one it is registered on, the model's clock for it.
//
// A patch whose plane holds the origin answers nothing (the model sets it up as inactive);
// one below the horizon answers with its wedge's kind 0, which the writer drops. Each pass
// begun (`start`) begins the writer's pass, whose buffer is the pass's parity as the set-up
// unit's tag is. The pass's end (`pass_end`, after or with its last answer) comes from outside:
// it is the clock every bank's set-up pass of the origin is done (the model's pass clocks are
// its slowest bank's), which a bank alone does not know. The edge words go to the lanes'
// coarse-word memory, which has no RTL here: they are this module's outputs.
// Verilog-2005, accepted by Verilator and Yosys.
module bank_pass #(
    parameter integer SLOT_BITS = 9,
    parameter integer ITER = 14,
    parameter integer W = 20,
    parameter integer SECTORS = 32
) (
    input  wire                   clk,
    // the writer's reset (the set-up pass keeps no state between passes that needs one)
    input  wire                   rst,
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
    input  wire                   start,
    input  wire [SLOT_BITS:0]     count,
    input  wire [95:0]            origin,
    input  wire [95:0]            axis_u,
    input  wire [95:0]            axis_v,
    input  wire [95:0]            axis_w,
    input  wire                   pass_end,
    // an edge's coarse words and a patch's κ, for the lanes' words
    output wire                   out_e_valid,
    output wire [53:0]            out_e_words,
    output wire [3:0]             out_e_kappa,
    output wire                   out_p_valid,
    output wire [3:0]             out_p_kappa,
    // the answer the writer takes on this clock
    output wire                   a_valid,
    output wire [SLOT_BITS-1:0]   a_place,
    output wire [1:0]             a_kind,
    output wire [5:0]             a_lo,
    output wire [6:0]             a_len,
    output wire [3:0]             a_band_lo,
    output wire [3:0]             a_band_hi,
    // the writer's block RAM write port, valid bits and completions (`bitmap_writer.v`)
    output wire                   w_valid,
    output wire                   w_buf,
    output wire [6:0]             w_row,
    output wire [SLOT_BITS-7:0]   w_col,
    output wire [63:0]            w_sector,
    output wire [15:0]            w_mask,
    output wire [63:0]            w_band,
    output wire [(1<<(SLOT_BITS-6))-1:0] valid0,
    output wire [(1<<(SLOT_BITS-6))-1:0] valid1,
    output wire [2:0]             ready_n
);
    wire p_valid, p_active;
    bank_setup #(.SLOT_BITS(SLOT_BITS), .ITER(ITER), .W(W), .SECTORS(SECTORS)) setup (
        .clk(clk), .box_we(box_we), .box_slot(box_slot), .box_lo(box_lo), .box_hi(box_hi),
        .box_boxed(box_boxed), .box_clocks(box_clocks), .corner_we(corner_we),
        .corner_addr(corner_addr), .corner_data(corner_data), .normal_we(normal_we),
        .normal_slot(normal_slot), .normal_data(normal_data), .start(start), .count(count),
        .origin(origin), .axis_u(axis_u), .axis_v(axis_v), .axis_w(axis_w),
        .out_e_valid(out_e_valid), .out_e_words(out_e_words), .out_e_kappa(out_e_kappa),
        .out_p_valid(p_valid), .out_p_active(p_active), .out_p_kappa(out_p_kappa),
        .out_p_kind(a_kind), .out_p_lo(a_lo), .out_p_len(a_len), .out_p_band_lo(a_band_lo),
        .out_p_band_hi(a_band_hi), .out_p_slot(a_place));

    assign out_p_valid = p_valid;
    assign a_valid = p_valid && p_active;

    bitmap_writer #(.SECTORS(SECTORS), .SLOT_BITS(SLOT_BITS)) writer (
        .clk(clk), .rst(rst), .a_valid(a_valid), .a_place(a_place), .a_kind(a_kind),
        .a_lo(a_lo), .a_len(a_len), .a_band_lo(a_band_lo), .a_band_hi(a_band_hi),
        .e_valid(pass_end), .p_start(start), .w_valid(w_valid), .w_buf(w_buf), .w_row(w_row),
        .w_col(w_col), .w_sector(w_sector), .w_mask(w_mask), .w_band(w_band), .valid0(valid0),
        .valid1(valid1), .ready_n(ready_n));
endmodule
