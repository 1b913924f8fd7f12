// Synthesis harness of a compact build's plane unit (`group_plane.v`), as `syn_exact.v` is the
// exact edge unit's: its inputs from a register chain shifted in from one pin, its outputs
// folded into one registered pin. The normal memory is the unit's (one a ray group). Figures:
// `cargo xtask rtl`.
module syn_group_plane (
    input  wire clk,
    input  wire sin,
    output reg  sout
);
    localparam integer SB = 10, TW = 10;
    localparam integer N = 2 + SB + 96 + 1 + SB + 68 + 96 + TW + 1 + TW;
    reg [N-1:0] c;
    always @(posedge clk) c <= {c[N-2:0], sin};

    wire          ready, out_valid, out_hit, out_front;
    wire [30:0]   out_t;
    wire [SB-1:0] out_slot;
    wire [TW-1:0] out_tag;
    group_plane #(.SLOT_BITS(SB), .TW(TW)) unit (
        .clk(clk), .rst(c[0]), .nm_we(c[1]), .nm_addr(c[2 +: SB]), .nm_data(c[SB+2 +: 96]),
        .in_valid(c[SB+98]), .in_slot(c[SB+99 +: SB]), .in_h(c[2*SB+99 +: 68]),
        .in_d(c[2*SB+167 +: 96]), .in_tag(c[2*SB+263 +: TW]), .rd_valid(c[2*SB+TW+263]),
        .rd_tag(c[2*SB+TW+264 +: TW]), .ready(ready), .out_valid(out_valid), .out_hit(out_hit),
        .out_t(out_t), .out_slot(out_slot), .out_front(out_front), .out_tag(out_tag));
    always @(posedge clk) sout <= ^{ready, out_valid, out_hit, out_t, out_slot, out_front, out_tag};
endmodule
