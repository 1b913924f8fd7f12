// Synthesis harness of the compact datapath's shared exact edge unit (`exact_edge.v`), as
// `syn_rotator.v` is the rotator's: its inputs, and the corner words it reads, from a register
// chain shifted in from one pin, its outputs folded into one registered pin. Figures: `cargo
// xtask rtl`.
module syn_exact (
    input  wire clk,
    input  wire sin,
    output reg  sout
);
    localparam integer SB = 10;
    localparam integer N = 2 + SB + 1 + 4 + 1 + 3 + 96 + 96 + 10 + 96;
    reg [N-1:0] c;
    always @(posedge clk) c <= {c[N-2:0], sin};

    // the corner words from the chain, beside the address the unit reads (patch memory is the
    // build's, counted with it, not the unit's)
    wire [SB+1:0] c_addr;
    reg  [95:0]   c_data;
    always @(posedge clk) c_data <= c[N-1 -: 96] ^ {{(96 - SB - 2){1'b0}}, c_addr};

    wire          in_ready, out_valid, out_inside;
    wire [9:0]    out_tag;
    exact_edge #(.SLOT_BITS(SB), .TW(10)) unit (
        .clk(clk), .rst(c[0]), .in_valid(c[1]), .in_ready(in_ready), .in_slot(c[2 +: SB]),
        .in_quad(c[SB+2]), .in_mask(c[SB+3 +: 4]), .in_negate(c[SB+7]),
        .in_shift(c[SB+8 +: 3]), .in_origin(c[SB+11 +: 96]), .in_d(c[SB+107 +: 96]),
        .in_tag(c[SB+203 +: 10]), .c_addr(c_addr), .c_data(c_data), .out_valid(out_valid),
        .out_inside(out_inside), .out_tag(out_tag));
    always @(posedge clk) sout <= ^{in_ready, out_valid, out_inside, out_tag};
endmodule
