// Synthesis harness of the compact set-up unit (`setup_unit.v`: a patch's plane test, edge
// words and reach), as `syn_reach.v` is the reach's: its inputs from a register chain shifted
// in from one pin, its outputs folded into one registered pin. Figures: `cargo xtask rtl`.
module syn_setup (
    input  wire clk,
    input  wire sin,
    output reg  sout
);
    localparam integer N = 3 + 9 * 32 + 9 * 32;
    reg [N-1:0] c;
    always @(posedge clk) c <= {c[N-2:0], sin};

    wire        e_valid, p_valid, p_active;
    wire [53:0] e_words;
    wire [3:0]  e_kappa, p_kappa, band_lo, band_hi;
    wire [1:0]  kind;
    wire [5:0]  lo;
    wire [6:0]  len;
    setup_unit unit (
        .clk(clk), .in_valid(c[0]), .in_last(c[1]), .in_pass(c[2]),
        .in_cx(c[34:3]), .in_cy(c[66:35]), .in_cz(c[98:67]),
        .in_nx(c[130:99]), .in_ny(c[162:131]), .in_nz(c[194:163]),
        .in_ox(c[226:195]), .in_oy(c[258:227]), .in_oz(c[290:259]),
        .in_ux(c[322:291]), .in_uy(c[354:323]), .in_uz(c[386:355]),
        .in_vx(c[418:387]), .in_vy(c[450:419]), .in_vz(c[482:451]),
        .in_wx(c[514:483]), .in_wy(c[546:515]), .in_wz(c[578:547]),
        .out_e_valid(e_valid), .out_e_words(e_words), .out_e_kappa(e_kappa),
        .out_p_valid(p_valid), .out_p_active(p_active), .out_p_kappa(p_kappa),
        .out_p_kind(kind), .out_p_lo(lo), .out_p_len(len), .out_p_band_lo(band_lo),
        .out_p_band_hi(band_hi));
    always @(posedge clk)
        sout <= ^{e_valid, e_words, e_kappa, p_valid, p_active, p_kappa, kind, lo, len, band_lo,
                  band_hi};
endmodule
