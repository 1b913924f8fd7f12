// Synthesis harness of the culling unit's patch side (`cull_reach.v`, a patch's sectors and
// bands), as `syn_cull.v` is the ray side's: its inputs from a register chain shifted in from
// one pin, its outputs folded into one registered pin. Figures: `cargo xtask rtl`.
module syn_reach (
    input  wire clk,
    input  wire sin,
    output reg  sout
);
    localparam integer N = 2 + 3 * 33 + 3 * 18 + 4 + 9 * 32;
    reg [N-1:0] c;
    always @(posedge clk) c <= {c[N-2:0], sin};

    wire       valid;
    wire [1:0] kind;
    wire [5:0] lo;
    wire [6:0] len;
    wire [3:0] band_lo, band_hi;
    cull_reach unit (
        .clk(clk), .in_valid(c[0]), .in_last(c[1]), .in_ax(c[34:2]), .in_ay(c[67:35]),
        .in_az(c[100:68]), .in_ex(c[118:101]), .in_ey(c[136:119]), .in_ez(c[154:137]),
        .in_kappa(c[158:155]), .in_ux(c[190:159]), .in_uy(c[222:191]), .in_uz(c[254:223]),
        .in_vx(c[286:255]), .in_vy(c[318:287]), .in_vz(c[350:319]), .in_wx(c[382:351]),
        .in_wy(c[414:383]), .in_wz(c[446:415]), .out_valid(valid), .out_kind(kind),
        .out_lo(lo), .out_len(len), .out_band_lo(band_lo), .out_band_hi(band_hi));
    always @(posedge clk) sout <= ^{valid, kind, lo, len, band_lo, band_hi};
endmodule
