// Synthesis harness of a bank's set-up pass front (`bank_front.v`: its box and corner
// memories, the horizon filter, the FIFO and the corner reads), as `syn_horizon.v` is the
// filter's: its inputs from a register chain shifted in from one pin, its outputs folded into
// one registered pin. Figures: `cargo xtask rtl`.
module syn_bank (
    input  wire clk,
    input  wire sin,
    output reg  sout
);
    localparam integer SB = 9;
    localparam integer N = (1 + SB + 72 + 72 + 1 + 2) + (1 + SB + 2 + 96) + (1 + SB + 1 + 96 + 96)
        + (1 + SB + 96) + 1;
    reg [N-1:0] c;
    always @(posedge clk) c <= {c[N-2:0], sin};

    wire          c_valid, c_planar, c_pass, c_last, busy;
    wire [SB-1:0] c_slot;
    wire [1:0]    c_corner;
    wire [95:0]   c_data, c_normal;
    bank_front #(.SLOT_BITS(SB)) front (
        .clk(clk),
        .box_we(c[0]), .box_slot(c[SB:1]), .box_lo(c[SB+72:SB+1]), .box_hi(c[SB+144:SB+73]),
        .box_boxed(c[SB+145]), .box_clocks(c[SB+147:SB+146]),
        .corner_we(c[SB+148]), .corner_addr(c[2*SB+150:SB+149]),
        .corner_data(c[2*SB+246:2*SB+151]),
        .start(c[2*SB+247]), .count(c[3*SB+248:2*SB+248]), .o(c[3*SB+344:3*SB+249]),
        .w(c[3*SB+440:3*SB+345]), .normal_we(c[3*SB+441]), .normal_slot(c[4*SB+441:3*SB+442]),
        .normal_data(c[4*SB+537:4*SB+442]), .tag(c[4*SB+538]),
        .c_valid(c_valid), .c_planar(c_planar), .c_pass(c_pass), .c_last(c_last),
        .c_slot(c_slot), .c_corner(c_corner), .c_data(c_data), .c_normal(c_normal), .busy(busy));
    always @(posedge clk)
        sout <= ^{c_valid, c_planar, c_pass, c_last, c_slot, c_corner, c_data, c_normal, busy};
endmodule
