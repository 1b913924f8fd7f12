// Synthesis harness of a bank's horizon filter (`horizon_filter.v`) and the slot boxes' write
// path (`slot_box.v`), as `syn_rotator.v` is the rotator's: their inputs from a register chain
// shifted in from one pin, the box's read-modify-write through a register as its memory would
// hold it, their outputs folded into one registered pin. The filter's enable is a chain bit as
// well: tied to 1, Yosys 0.23 mapped the filter to 292 LUT4s more. Figures: `cargo xtask rtl`.
module syn_horizon (
    input  wire clk,
    input  wire sin,
    output reg  sout
);
    localparam integer N = 2 + 72 + 72 + 96 + 96 + 1 + 4 + 32 + 1;
    reg [N-1:0] c;
    always @(posedge clk) c <= {c[N-2:0], sin};

    wire f_valid, f_below;
    horizon_filter filter (
        .clk(clk), .en(c[375]), .in_valid(c[0]), .in_boxed(c[1]), .in_lo(c[73:2]),
        .in_hi(c[145:74]),
        .in_o(c[241:146]), .in_w(c[337:242]), .out_valid(f_valid), .out_below(f_below));

    reg  [71:0] lo, hi;
    reg  [12:0] written;
    wire        we_next;
    wire [71:0] lo_next, hi_next;
    wire [12:0] written_next;
    slot_box box (
        .clk(clk), .in_we(c[338]), .in_word(c[342:339]), .in_value(c[374:343]), .lo_in(lo),
        .hi_in(hi), .written_in(written), .out_we(we_next), .lo_out(lo_next), .hi_out(hi_next),
        .written_out(written_next));
    always @(posedge clk)
        if (we_next) begin
            lo <= lo_next;
            hi <= hi_next;
            written <= written_next;
        end
    always @(posedge clk) sout <= ^{f_valid, f_below, lo, hi, written};
endmodule
