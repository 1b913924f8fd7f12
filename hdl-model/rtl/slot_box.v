// A slot's bounding box on patch memory's write path (hdl-model/src/intersect/horizon.rs,
// `SlotBox::write`): the box after word `word` of the slot is written with `value`. The header
// (word 0) starts it empty; a corner word (1 to 12: corner (word - 1) / 3, axis (word - 1)
// mod 3) widens that axis's ends by the value rounded outward to Q8.16 (the low end down, the
// high end up) and sets its written bit; a high end past 24 bits sets the unbounded bit (12)
// and is held at the largest word. The box counts once bits 11:0 are set and bit 12 is not.
// Two clocks, a write each: the value rounded and registered (as the slot's box is read), then
// the box in widened and handed back to its holder with out_we (which writes it at the end of
// that clock; in a memory, a write to the slot the clock before is forwarded as the box in).
// The model gives the write path no clock: a set-up pass begins clocks after the last write.
// Verilog-2005, accepted by Verilator and Yosys.
module slot_box (
    input  wire        clk,
    input  wire        in_we,
    input  wire [3:0]  in_word,
    input  wire [31:0] in_value,
    input  wire [71:0] lo_in,        // the box before: 24-bit signed low ends at bits 24c
    input  wire [71:0] hi_in,        // high ends
    input  wire [12:0] written_in,
    output reg         out_we,
    output reg  [71:0] lo_out,
    output reg  [71:0] hi_out,
    output reg  [12:0] written_out
);
    localparam [23:0] LO_EMPTY = 24'h7f_ffff;
    localparam [23:0] HI_EMPTY = 24'h80_0000;
    // ceil(value / 2^8) = floor + (any bit below); it passes 24 bits only from the largest
    // floor, which is told without the increment's carry chain
    wire frac = |in_value[7:0];
    wire over = frac && in_value[31:8] == LO_EMPTY;
    wire [23:0] up = in_value[31:8] + {23'd0, frac};
    wire [3:0] w1 = in_word - 4'd1;

    // 1: the value's ends, its axis and its written bit
    reg               s1_we, s1_header, s1_corner, s1_over;
    reg signed [23:0] s1_lo, s1_hi;
    reg        [1:0]  s1_axis;
    reg        [11:0] s1_bit;
    always @(posedge clk) begin
        s1_we <= in_we;
        s1_header <= in_word == 4'd0;
        s1_corner <= in_word >= 4'd1 && in_word <= 4'd12;
        s1_over <= over;
        s1_lo <= in_value[31:8];
        s1_hi <= over ? LO_EMPTY : up;
        s1_axis <= (w1 == 4'd0 || w1 == 4'd3 || w1 == 4'd6 || w1 == 4'd9) ? 2'd0
                 : (w1 == 4'd1 || w1 == 4'd4 || w1 == 4'd7 || w1 == 4'd10) ? 2'd1 : 2'd2;
        s1_bit <= 12'd1 << w1;
    end

    // 2: the box widened
    integer c;
    always @* begin
        out_we = s1_we;
        lo_out = lo_in;
        hi_out = hi_in;
        written_out = written_in;
        if (s1_header) begin
            lo_out = {3{LO_EMPTY}};
            hi_out = {3{HI_EMPTY}};
            written_out = 13'd0;
        end else if (s1_corner) begin
            for (c = 0; c < 3; c = c + 1)
                if (s1_axis == c[1:0]) begin
                    if (s1_lo < $signed(lo_in[24 * c +: 24])) lo_out[24 * c +: 24] = s1_lo;
                    if (s1_hi > $signed(hi_in[24 * c +: 24])) hi_out[24 * c +: 24] = s1_hi;
                end
            written_out = written_in | {s1_over, s1_bit};
        end
    end
endmodule
