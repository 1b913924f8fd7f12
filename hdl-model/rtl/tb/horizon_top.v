// The co-simulation top of the horizon filter and the slot boxes it reads: one slot's box
// register, written through `slot_box.v` a clock after each write, beside the filter
// (`horizon_filter.v`), each fed a vector a clock by `horizon_tb.cpp`.
module horizon_top (
    input  wire        clk,
    input  wire        b_we,
    input  wire [3:0]  b_word,
    input  wire [31:0] b_value,
    output reg  [71:0] b_lo,
    output reg  [71:0] b_hi,
    output reg  [12:0] b_written,
    input  wire        f_valid,
    input  wire        f_boxed,
    input  wire [71:0] f_lo,
    input  wire [71:0] f_hi,
    input  wire [95:0] f_o,
    input  wire [95:0] f_w,
    output wire        f_out_valid,
    output wire        f_below
);
    initial begin
        b_lo = {3{24'h7f_ffff}};
        b_hi = {3{24'h80_0000}};
        b_written = 13'd0;
    end
    wire        we_next;
    wire [71:0] lo_next, hi_next;
    wire [12:0] written_next;
    slot_box box (
        .clk(clk), .in_we(b_we), .in_word(b_word), .in_value(b_value), .lo_in(b_lo),
        .hi_in(b_hi), .written_in(b_written), .out_we(we_next), .lo_out(lo_next),
        .hi_out(hi_next), .written_out(written_next));
    always @(posedge clk)
        if (we_next) begin
            b_lo <= lo_next;
            b_hi <= hi_next;
            b_written <= written_next;
        end
    horizon_filter filter (
        .clk(clk), .en(1'b1), .in_valid(f_valid), .in_boxed(f_boxed), .in_lo(f_lo), .in_hi(f_hi),
        .in_o(f_o), .in_w(f_w), .out_valid(f_out_valid), .out_below(f_below));
endmodule
