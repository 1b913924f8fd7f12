// A slot's bounding box on patch memory's write path (hdl-model/src/intersect/horizon.rs,
// `SlotBox::write`): the box after word `word` of the slot is written with `value`, from the box
// before (read beside the word's write; written back the next clock). The header (word 0)
// starts it empty; a corner word (1 to 12: corner (word - 1) / 3, axis (word - 1) mod 3) widens
// that axis's ends by the value rounded outward to Q8.16 (the low end down, the high end up)
// and sets its written bit; a high end past 24 bits sets the unbounded bit (12) and is held at
// the largest word. The box counts once bits 11:0 are set and bit 12 is not. Combinational.
// Verilog-2005, accepted by Verilator and Yosys.
module slot_box (
    input  wire [3:0]  word,
    input  wire [31:0] value,
    input  wire [71:0] lo_in,        // 24-bit signed low ends at bits 24c
    input  wire [71:0] hi_in,        // high ends
    input  wire [12:0] written_in,
    output reg  [71:0] lo_out,
    output reg  [71:0] hi_out,
    output reg  [12:0] written_out
);
    localparam [23:0] LO_EMPTY = 24'h7f_ffff;
    localparam [23:0] HI_EMPTY = 24'h80_0000;
    // ceil(value / 2^8): 25 bits, past 24 when it reaches 2^23
    /* verilator lint_off UNUSEDSIGNAL */ // the rounded-away bits
    wire [32:0] up = {value[31], value} + 33'd255;
    /* verilator lint_on UNUSEDSIGNAL */
    wire signed [23:0] lo_new = value[31:8];
    wire over = !up[32] && up[31];
    wire signed [23:0] hi_new = over ? LO_EMPTY : up[31:8];
    wire corner = word >= 4'd1 && word <= 4'd12;
    // the axis: (word - 1) mod 3
    wire [3:0] w1 = word - 4'd1;
    wire [1:0] axis = (w1 == 4'd0 || w1 == 4'd3 || w1 == 4'd6 || w1 == 4'd9) ? 2'd0
                    : (w1 == 4'd1 || w1 == 4'd4 || w1 == 4'd7 || w1 == 4'd10) ? 2'd1 : 2'd2;
    integer c;
    always @* begin
        lo_out = lo_in;
        hi_out = hi_in;
        written_out = written_in;
        if (word == 4'd0) begin
            lo_out = {3{LO_EMPTY}};
            hi_out = {3{HI_EMPTY}};
            written_out = 13'd0;
        end else if (corner) begin
            for (c = 0; c < 3; c = c + 1)
                if (axis == c[1:0]) begin
                    if (lo_new < $signed(lo_in[24 * c +: 24])) lo_out[24 * c +: 24] = lo_new;
                    if (hi_new > $signed(hi_in[24 * c +: 24])) hi_out[24 * c +: 24] = hi_new;
                end
            written_out = written_in | (13'd1 << w1) | {over, 12'd0};
        end
    end
endmodule
