// An azimuth's sector and a polar angle's band, the RTL of hdl-model/src/intersect/cull.rs's
// `CullUnit::sector_of` and `CullUnit::band_of`: the sector floor(((a + π) mod 2π) · SECTORS / 2π)
// and the band min(floor(max(t, 0) · 32 / π), 15), each as the count of constant thresholds at
// or below the angle (the model's integer divisions exactly: floor(a · S / D) >= k exactly when
// a >= ceil(k · D / S)). Both sides of the culling unit use it: a ray's bin (`cull_ray.v`) and
// the ends of a patch's reach (`cull_reach.v`).
//
// Angles are the culling vectorings' words, Q3.(W-3), sign-extended to W + 3 bits: a in
// [-3π, 3π) and t of either sign. π is π rounded to those words' grid (cull.rs's PI, that word
// shifted into Q3.29), so every threshold and every angle here is on the word's grid and the
// compares are W + 3 bits wide (35, on Q3.29, until session 45). Three clocks: (a + π) mod
// 2π and t as words, the coarse thresholds compared and counted, the fine ones (below). (As one
// clock of 64-bit compares counted by a chain of incrementers, the ray side placed at 10 MHz.)
// PW bits of payload ride along.
module cull_bin #(
    parameter integer W = 20,
    parameter integer SECTORS = 32,
    parameter integer PW = 1
) (
    input  wire                clk,
    input  wire                in_valid,
    input  wire signed [W+2:0] in_a,
    input  wire signed [W+2:0] in_t,
    input  wire       [PW-1:0] in_payload,
    output reg                 out_valid,
    output reg         [5:0]   out_sector,
    output reg         [3:0]   out_band,
    output reg       [PW-1:0]  out_payload
);
`include "cordic_rom.vh"
    localparam integer BANDS = 16;
    localparam integer AW = W + 3;
    // π on the word's grid (Q3.(W-3)), and its wider copies for the compares
    localparam [63:0] PI = rom_round(2 * HALF_PI_Q62, W - 3);
    localparam [63:0] PI3 = 3 * PI;
    localparam [AW-1:0] PI_A = PI[AW-1:0], PI3_A = PI3[AW-1:0];

    // (a + π) mod 2π, in [0, 2π) < 2^W: a + 3π, a + π or a − π, chosen by a's compares with
    // ±π beside the adds rather than after them
    /* verilator lint_off UNUSEDSIGNAL */
    wire signed [AW-1:0] a_mod = in_a < -$signed(PI_A) ? in_a + $signed(PI3_A)
        : in_a >= $signed(PI_A) ? in_a - $signed(PI_A) : in_a + $signed(PI_A);
    /* verilator lint_on UNUSEDSIGNAL */
    reg                 v0;
    reg        [W-1:0]  a0;
    reg signed [AW-1:0] t0;
    reg        [PW-1:0] p0;
    always @(posedge clk) begin
        v0 <= in_valid;
        a0 <= a_mod[W-1:0];
        t0 <= in_t;
        p0 <= in_payload;
    end

    // threshold k of the sectors, ceil(k · 2π / SECTORS), and of the bands, ceil(k · π / 32)
    // (below 2^W: the 64-bit quotients' top bits are zero)
    /* verilator lint_off UNUSEDSIGNAL */
    function [63:0] wide(input [31:0] v);
        wide = {32'd0, v};
    endfunction
    localparam [63:0] S64 = wide(SECTORS), B64 = wide(2 * BANDS);
    function [W-1:0] sector_at(input [63:0] k);
        reg [63:0] t;
        begin
            t = (k * 2 * PI + S64 - 1) / S64;
            sector_at = t[W-1:0];
        end
    endfunction
    function [AW-1:0] band_at(input [63:0] k);
        reg [63:0] t;
        begin
            t = (k * PI + B64 - 1) / B64;
            band_at = t[AW-1:0];
        end
    endfunction
    /* verilator lint_on UNUSEDSIGNAL */
    // The count of thresholds at or below the angle in two steps of one clock each, rather than
    // every threshold compared at once (46 compares of 32 or 35 bits at 32 sectors, 812 carry
    // cells a unit, on Q3.29): first the coarse thresholds k = 4m (m >= 1), whose count c puts
    // the angle between thresholds 4c and 4c + 4; then the three thresholds 4c + 1 .. 4c + 3,
    // chosen by c from constant tables, whose count f gives the bin 4c + f. The thresholds
    // increase, so this is the same count. Each fine compare has its own copy of c (kept: one
    // copy fanned out to every table LUT4 was the set-up unit's critical path), and t goes in
    // clamped to W − 2 bits.
    localparam integer SC = SECTORS / 4, BC = BANDS / 4;
    wire [15:0] ts;
    wire [3:0]  tb;
    genvar gk, gj;
    generate
        for (gk = 1; gk <= 16; gk = gk + 1) begin : sector_coarse
            if (gk < SC) assign ts[gk-1] = a0 >= sector_at(4 * gk);
            else assign ts[gk-1] = 1'b0;
        end
        for (gk = 1; gk <= 4; gk = gk + 1) begin : band_coarse
            if (gk < BC) assign tb[gk-1] = t0 >= $signed(band_at(4 * gk));
            else assign tb[gk-1] = 1'b0;
        end
    endgenerate
    reg               v1;
    (* keep *) reg [3:0] cs1 [0:2];
    (* keep *) reg [1:0] cb1 [0:2];
    reg        [W-1:0] a1;
    reg        [W-3:0] t1;
    reg      [PW-1:0] p1;
    integer f;
    /* verilator lint_off UNUSEDSIGNAL */
    wire [5:0] cs = ones({48'd0, ts}), cb = ones({60'd0, tb});
    /* verilator lint_on UNUSEDSIGNAL */
    always @(posedge clk) begin
        v1 <= v0;
        for (f = 0; f < 3; f = f + 1) begin
            cs1[f] <= cs[3:0];
            cb1[f] <= cb[1:0];
        end
        a1 <= a0;
        // every band threshold is in (0, π/2] < 2^(W-2): t clamped into [0, 2^(W-2)) compares
        // the same
        t1 <= t0[AW-1] ? {(W-2){1'b0}} : |t0[AW-2:W-2] ? {(W-2){1'b1}} : t0[W-3:0];
        p1 <= p0;
    end

    // the fine thresholds 4c + j (j = 1..3) of every c, as constant tables indexed by {c, j}
    // (so that each bit of a chosen threshold is one LUT4 of c's bits)
    /* verilator lint_off UNUSEDSIGNAL */
    wire [W-1:0]  s_tab [0:63];
    wire [AW-1:0] b_tab [0:15];
    /* verilator lint_on UNUSEDSIGNAL */
    generate
        for (gk = 0; gk < 64; gk = gk + 1) begin : sector_table
            assign s_tab[gk] = gk % 4 == 0 ? {W{1'b0}} : sector_at(gk);
        end
        for (gk = 0; gk < 16; gk = gk + 1) begin : band_table
            assign b_tab[gk] = gk % 4 == 0 ? {AW{1'b0}} : band_at(gk);
        end
    endgenerate
    wire [2:0] fs, fb;
    generate
        for (gj = 1; gj < 4; gj = gj + 1) begin : fine_compare
            assign fs[gj-1] = a1 >= s_tab[{cs1[gj-1], gj[1:0]}];
            assign fb[gj-1] = t1 >= b_tab[{cb1[gj-1], gj[1:0]}][W-3:0];
        end
    endgenerate
    // a thermometer's count c (bit i set for i < c): bit j of c is the XOR of bits m·2^j - 1,
    // m >= 1 (the count of multiples of 2^j up to c, mod 2), each bit a tree of its own
    function [5:0] ones(input [63:0] t);
        integer j, m;
        begin
            ones = 6'd0;
            for (j = 0; j < 6; j = j + 1)
                for (m = 1; m * (1 << j) <= 64; m = m + 1)
                    ones[j] = ones[j] ^ t[m * (1 << j) - 1];
        end
    endfunction
    /* verilator lint_off UNUSEDSIGNAL */
    wire [5:0] sector_f = ones({61'd0, fs}), band_f = ones({61'd0, fb});
    /* verilator lint_on UNUSEDSIGNAL */
    always @(posedge clk) begin
        out_valid <= v1;
        out_sector <= {cs1[0], sector_f[1:0]};
        out_band <= {cb1[0], band_f[1:0]};
        out_payload <= p1;
    end
endmodule
