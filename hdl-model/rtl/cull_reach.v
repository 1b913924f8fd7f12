// The culling unit's patch side, the RTL of hdl-model/src/intersect/cull.rs's `CullUnit::reach`:
// per origin and frame, where a planar patch can be met by a hemisphere ray — below the horizon,
// in every sector, or in sectors lo .. lo + len − 1 (mod SECTORS) — and its polar bands. The
// set-up writes the patch's bits in the sector and band rows by it. As the model's set-up unit
// does, it takes a corner a clock (with the edge that leaves it), so a patch of n corners takes n
// clocks; the answers come out in order, one a patch, 2 · (ITER + 4) + 27 clocks after its last
// corner (63 at ITER 14, `cull::REACH_LATENCY`; in the compact set-up unit, `setup_unit.v`, the
// corners wait for their edges' words first, and the model charges both). The culling bench
// compares its answers; the set-up unit's bench, their clocks too.
//
// Inputs a beat: the corner a = v − O (Q8.24, 33-bit), the edge's coarse word e (18-bit words of
// the lanes, bounded by 2^κ), κ, the frame's axes u, v, w (Q2.30), and `last` on the patch's
// last corner. Per corner (cull.rs's module doc, "Narrow arithmetic"):
// 1. ã, a scaled to 18-bit words by a power of two of its own (`coarse::block18`), in three
//    clocks (|a| OR, the leading one as a one-hot word, an AND-OR of constant shifts);
// 2. the corner in the frame f_k = ã · x̃_k (x̃ the axes' Q2.16 words, nine 18 × 18 products),
//    its error bound b_k = Σ(|ã_c| + |x̃_kc| + 1), and the edge's axis test (three products)
//    with its bound B = 2^κ Σ(|w̃_c| + 1) + Σ|e_c|;
// 3. whether the corner is certainly below the horizon (f_z + b_z < −(|f|∞ + |b|∞) 2^-9) or may
//    be within 2^-4 of the axis (ρ < |b|∞ + (|f|∞ + |b|∞) 2^-4), and whether +z (−z) may be
//    inside the edge (e · w̃ + B > −(|e|∞ + 2^κ) 2^6; e · w̃ − B < (|e|∞ + 2^κ) 2^6);
// 4. its azimuth and polar angle by the unit's vectorings (`cull_angles.v`).
// Per patch, once its corners' angles are in:
// 5. the wedge's ends: the corners' azimuths against the first's, wrapped into (−π, π]; the
//    polar range: below, min(θ_k, θ_k+1) − ⌈|Δφ|/2⌉ over the edges, above, the largest θ;
// 6. below the horizon if every corner is; every sector if the axis may be inside (every edge
//    allows it, or κ bounds nothing), a corner is near the axis, or the wedge with its margins
//    spans π; the ends' sectors and bands, each widened by the margin 2^-7 rad (`cull_bin.v`).
//
// SCALED = 1: the corner comes already scaled, ã in in_a's low 18 bits (the compact set-up unit's
// edge unit forms it, `coarse_edge.v`'s out_u18), and step 1's scaling is left out; the clocks
// are the same. SCALED = 0 scales it here, for a set-up without that edge unit (the wide
// datapath's, whose edges are exact) and for the culling bench, which feeds the reach alone.
module cull_reach #(
    parameter integer ITER = 14,
    parameter integer W = 20,
    parameter integer SECTORS = 32,
    parameter integer SCALED = 0
) (
    input  wire               clk,
    input  wire               in_valid,
    input  wire               in_last,
    input  wire signed [32:0] in_ax,
    input  wire signed [32:0] in_ay,
    input  wire signed [32:0] in_az,
    input  wire signed [17:0] in_ex,
    input  wire signed [17:0] in_ey,
    input  wire signed [17:0] in_ez,
    input  wire        [3:0]  in_kappa,
    // the axes' Q2.30 words, of which the unit keeps the top 18 bits
    /* verilator lint_off UNUSEDSIGNAL */
    input  wire signed [31:0] in_ux,
    input  wire signed [31:0] in_uy,
    input  wire signed [31:0] in_uz,
    input  wire signed [31:0] in_vx,
    input  wire signed [31:0] in_vy,
    input  wire signed [31:0] in_vz,
    input  wire signed [31:0] in_wx,
    input  wire signed [31:0] in_wy,
    input  wire signed [31:0] in_wz,
    /* verilator lint_on UNUSEDSIGNAL */
    output reg                out_valid,
    // 0: below the horizon, 1: every sector, 2: sectors lo .. lo + len − 1
    output reg         [1:0]  out_kind,
    output reg         [5:0]  out_lo,
    output reg         [6:0]  out_len,
    output reg         [3:0]  out_band_lo,
    output reg         [3:0]  out_band_hi
);
`include "cordic_rom.vh"
    // Angles from here on are the vectorings' words, Q3.(W-3), in AW bits (35, on Q3.29, until
    // session 45): π as those words hold it (cull.rs's PI) and the margin 2^-7 rad, so that every
    // angle and bound below is on the word's grid; κ at which the words bound nothing
    // (`coarse::KAPPA_DECLINE`)
    localparam integer AW = W + 3;
    localparam [63:0] PI_R = rom_round(2 * HALF_PI_Q62, W - 3);
    localparam signed [AW-1:0] PI = PI_R[AW-1:0];
    localparam signed [AW-1:0] MARGIN = 1 << (W - 10);
    // the wedge spans π once hi − lo reaches this
    localparam signed [AW-1:0] SPAN = PI - 2 * MARGIN;
    localparam [3:0] KAPPA_DECLINE = 4'd15;

    // ---- 1: the corner's block scaling, the axes' narrow words
    reg                v0, l0;
    reg        [32:0]  m0;
    reg signed [32:0]  a0 [0:2];
    reg signed [17:0]  e0 [0:2];
    // the corner's magnitudes, each one carry chain (magnitude.v)
    wire       [32:0]  in_mag [0:2];
    magnitude #(.W(33)) mag_ax (.x(in_ax), .m(in_mag[0]));
    magnitude #(.W(33)) mag_ay (.x(in_ay), .m(in_mag[1]));
    magnitude #(.W(33)) mag_az (.x(in_az), .m(in_mag[2]));
    reg        [3:0]   k0;
    reg signed [17:0]  x0 [0:8];
    always @(posedge clk) begin
        v0 <= in_valid;
        l0 <= in_last;
        m0 <= in_mag[0] | in_mag[1] | in_mag[2];
        a0[0] <= in_ax;
        a0[1] <= in_ay;
        a0[2] <= in_az;
        e0[0] <= in_ex;
        e0[1] <= in_ey;
        e0[2] <= in_ez;
        k0 <= in_kappa;
        // Q2.30 >> 14: Q2.16 words of 18 bits
        x0[0] <= in_ux[31:14];
        x0[1] <= in_uy[31:14];
        x0[2] <= in_uz[31:14];
        x0[3] <= in_vx[31:14];
        x0[4] <= in_vy[31:14];
        x0[5] <= in_vz[31:14];
        x0[6] <= in_wx[31:14];
        x0[7] <= in_wy[31:14];
        x0[8] <= in_wz[31:14];
    end
    // beside the leading one: the magnitudes of e's and the axes' words
    reg                v1, l1;
    reg        [32:0]  h1;
    reg signed [32:0]  a1 [0:2];
    reg signed [17:0]  e1 [0:2];
    reg        [17:0]  ea1 [0:2];
    wire       [17:0]  e0_mag [0:2];
    wire       [17:0]  x0_mag [0:8];
    genvar g;
    generate
        for (g = 0; g < 3; g = g + 1) begin : mags_e0
            magnitude #(.W(18)) mag (.x(e0[g]), .m(e0_mag[g]));
        end
        for (g = 0; g < 9; g = g + 1) begin : mags_x0
            magnitude #(.W(18)) mag (.x(x0[g]), .m(x0_mag[g]));
        end
    endgenerate
    reg        [3:0]   k1;
    reg signed [17:0]  x1 [0:8];
    reg        [17:0]  xa1 [0:8];
    integer i;
    always @(posedge clk) begin
        v1 <= v0;
        l1 <= l0;
        h1 <= lead(m0);
        for (i = 0; i < 3; i = i + 1) begin
            a1[i] <= a0[i];
            e1[i] <= e0[i];
            ea1[i] <= e0_mag[i];
        end
        k1 <= k0;
        for (i = 0; i < 9; i = i + 1) begin
            x1[i] <= x0[i];
            xa1[i] <= x0_mag[i];
        end
    end
    // |e|∞ with its three compares side by side (two in a row placed the set-up unit at 99 MHz)
    /* verilator lint_off UNUSEDSIGNAL */
    wire [37:0] em1 = max3_38({20'd0, ea1[0]}, {20'd0, ea1[1]}, {20'd0, ea1[2]});
    /* verilator lint_on UNUSEDSIGNAL */
    // beside the scaling: each axis's Σ(|x̃_kc| + 1) (b's part from the axes, and for the w
    // axis the axis test's), Σ|e_c| and |e|∞
    reg                v2, l2;
    reg signed [17:0]  w2 [0:2];
    reg signed [17:0]  e2 [0:2];
    reg        [3:0]   k2;
    reg signed [17:0]  x2 [0:8];
    reg        [20:0]  xs2 [0:2];
    reg        [19:0]  es2;
    reg        [17:0]  em2;
    always @(posedge clk) begin
        v2 <= v1;
        l2 <= l1;
        for (i = 0; i < 3; i = i + 1) begin
            w2[i] <= (SCALED != 0) ? a1[i][17:0] : block(a1[i], h1);
            e2[i] <= e1[i];
            xs2[i] <= {3'd0, xa1[3 * i]} + {3'd0, xa1[3 * i + 1]} + {3'd0, xa1[3 * i + 2]}
                + 21'd3;
        end
        es2 <= {2'd0, ea1[0]} + {2'd0, ea1[1]} + {2'd0, ea1[2]};
        em2 <= em1[17:0];
        k2 <= k1;
        for (i = 0; i < 9; i = i + 1) x2[i] <= x1[i];
    end

    // ---- 2: the products, the bounds: b_k = Σ|ã_c| + Σ(|x̃_kc| + 1), B = (Σ(|w̃_c| + 1) << κ)
    // + Σ|e_c|, the axis test's threshold (|e|∞ + 2^κ) 2^6
    reg                v3, l3;
    // each product on a tile with its output register (`mul18.v`)
    wire signed [35:0] p3 [0:8];
    wire signed [35:0] q3 [0:2];
    generate
        for (g = 0; g < 9; g = g + 1) begin : corner_products
            mul18 mul (.clk(clk), .ce(1'b1), .a(w2[g % 3]), .b(x2[g]), .p(p3[g]));
        end
        for (g = 0; g < 3; g = g + 1) begin : axis_products
            mul18 mul (.clk(clk), .ce(1'b1), .a(e2[g]), .b(x2[6 + g]), .p(q3[g]));
        end
    endgenerate
    reg        [17:0]  wa3 [0:2];
    wire       [17:0]  w2_mag [0:2];
    generate
        for (g = 0; g < 3; g = g + 1) begin : mags_w2
            magnitude #(.W(18)) mag (.x(w2[g]), .m(w2_mag[g]));
        end
    endgenerate
    reg        [20:0]  xs3 [0:2];
    reg        [33:0]  bound3;
    reg        [24:0]  mth3;
    reg                decline3;
    always @(posedge clk) begin
        v3 <= v2;
        l3 <= l2;
        for (i = 0; i < 3; i = i + 1) begin
            xs3[i] <= xs2[i];
            wa3[i] <= w2_mag[i];
        end
        bound3 <= ({13'd0, xs2[2]} << k2) + {14'd0, es2};
        mth3 <= ({7'd0, em2} + (25'd1 << k2)) << 6;
        decline3 <= k2 >= KAPPA_DECLINE;
    end
    reg                v4, l4, decline4;
    reg signed [37:0]  f4 [0:2];
    reg signed [37:0]  dot4;
    reg        [20:0]  b4 [0:2];
    // the axis test's two thresholds: +z may be inside if e · w̃ > −(|e|∞ + 2^κ) 2^6 − B, −z if
    // e · w̃ < (|e|∞ + 2^κ) 2^6 + B (formed here, so that the next clock only compares)
    reg signed [37:0]  tpos4, tneg4;
    always @(posedge clk) begin
        v4 <= v3;
        l4 <= l3;
        decline4 <= decline3;
        for (i = 0; i < 3; i = i + 1) begin
            f4[i] <= {{2{p3[3*i][35]}}, p3[3*i]} + {{2{p3[3*i+1][35]}}, p3[3*i+1]}
                + {{2{p3[3*i+2][35]}}, p3[3*i+2]};
            b4[i] <= ({3'd0, wa3[0]} + {3'd0, wa3[1]}) + ({3'd0, wa3[2]} + xs3[i]);
        end
        dot4 <= {{2{q3[0][35]}}, q3[0]} + {{2{q3[1][35]}}, q3[1]} + {{2{q3[2][35]}}, q3[2]};
        tpos4 <= -$signed({13'd0, mth3}) - $signed({4'd0, bound3});
        tneg4 <= $signed({13'd0, mth3}) + $signed({4'd0, bound3});
    end

    // ---- 3: the corner's and the edge's decisions
    /* verilator lint_off UNUSEDSIGNAL */
    wire [37:0] eb4 = max3_38({17'd0, b4[0]}, {17'd0, b4[1]}, {17'd0, b4[2]});
    /* verilator lint_on UNUSEDSIGNAL */
    reg                v5, l5, pos5, neg5, decline5;
    reg signed [37:0]  f5 [0:2];
    reg        [37:0]  mf5 [0:2];
    wire       [37:0]  f4_mag [0:2];
    generate
        for (g = 0; g < 3; g = g + 1) begin : mags_f4
            magnitude #(.W(38)) mag (.x(f4[g]), .m(f4_mag[g]));
        end
    endgenerate
    reg        [20:0]  eb5;
    reg        [20:0]  bz5;
    always @(posedge clk) begin
        v5 <= v4;
        l5 <= l4;
        decline5 <= decline4;
        pos5 <= dot4 > tpos4;
        neg5 <= dot4 < tneg4;
        for (i = 0; i < 3; i = i + 1) begin
            f5[i] <= f4[i];
            mf5[i] <= f4_mag[i];
        end
        eb5 <= eb4[20:0];
        bz5 <= b4[2];
    end
    reg                v6, l6, pos6, neg6, decline6;
    reg signed [37:0]  f6 [0:2];
    reg        [37:0]  rho6, n6;
    reg        [20:0]  eb6, bz6;
    always @(posedge clk) begin
        v6 <= v5;
        l6 <= l5;
        pos6 <= pos5;
        neg6 <= neg5;
        decline6 <= decline5;
        for (i = 0; i < 3; i = i + 1) f6[i] <= f5[i];
        rho6 <= max38(mf5[0], mf5[1]);
        n6 <= max3_38(mf5[0], mf5[1], mf5[2]);
        eb6 <= eb5;
        bz6 <= bz5;
    end
    // |f|∞ + |b|∞ and f_z + b_z, then the two decisions (the mutant check flips NEAR_AXIS's
    // shift below)
    reg                v7, l7, pos7, neg7;
    reg signed [37:0]  f7 [0:2];
    reg signed [39:0]  slack7;
    /* verilator lint_off UNUSEDSIGNAL */
    reg        [38:0]  nb7;
    /* verilator lint_on UNUSEDSIGNAL */
    reg signed [38:0]  fz7;
    always @(posedge clk) begin
        v7 <= v6;
        l7 <= l6;
        pos7 <= pos6 || decline6;
        neg7 <= neg6 || decline6;
        for (i = 0; i < 3; i = i + 1) f7[i] <= f6[i];
        // ρ − e_b beside |f|∞ + |b|∞, so that NEAR is one compare after the register
        slack7 <= $signed({2'd0, rho6}) - $signed({19'd0, eb6});
        nb7 <= {1'b0, n6} + {18'd0, eb6};
        fz7 <= {f6[2][37], f6[2]} + $signed({18'd0, bz6});
    end
    // each decision one carry chain after the register (a negation then a compare, or a sum
    // then a compare, was two in series: the set-up family's critical path):
    // f_z + b_z < −m as the sign of f_z + b_z + m, ρ < e_b + m' as ρ − e_b < m'
    /* verilator lint_off UNUSEDSIGNAL */
    wire signed [39:0] lift7 = {fz7[38], fz7} + $signed({10'd0, nb7[38:9]});
    /* verilator lint_on UNUSEDSIGNAL */
    wire below7 = lift7[39];
    wire near7 = slack7 < $signed({5'd0, nb7[38:4]});
    // a corner's decisions, beside its angles: last, below, near, +z and −z allowed
    wire [4:0] flags7 = {l7, below7, near7, pos7, neg7};

    // ---- 4: the corner's angles
    wire                cv;
    wire signed [W-1:0] cphi, ctheta;
    wire [4:0]          cflags;
    cull_angles #(.ITER(ITER), .W(W), .IW(38), .LO1(0), .HI1(37), .ZW(66), .LO2(0), .HI2(65),
        .PW(5)) angles (
        .clk(clk), .in_valid(v7), .in_x(f7[0]), .in_y(f7[1]), .in_z(f7[2]),
        .in_payload(flags7), .out_valid(cv), .out_phi(cphi), .out_theta(ctheta),
        .out_payload(cflags));

    // ---- 5: the patch's corners gathered, then its wedge and polar range
    wire signed [AW-1:0] cphi_w = {{3{cphi[W-1]}}, cphi};
    wire signed [AW-1:0] ctheta_w = {{3{ctheta[W-1]}}, ctheta};
    reg        [1:0]   cnt;
    reg signed [AW-1:0] gphi [0:2];
    reg signed [AW-1:0] gtheta [0:2];
    // the patch's decisions so far, {below, near, +z, −z}: every corner below, any near,
    // every edge allowing +z, every edge allowing −z
    localparam [3:0] NONE_YET = 4'b1011;
    reg        [3:0]   gf;
    // the patch: its corners' angles (a triangle's fourth the first's again, so that its last
    // edge is from corner 0 to itself: no bulge, no turn, θ_0 again, which changes no minimum
    // or maximum below and lets every edge be k to k + 1 mod 4), its decisions
    reg                rv;
    reg signed [AW-1:0] rphi [0:3];
    reg signed [AW-1:0] rtheta [0:3];
    reg        [3:0]   rf;
    always @(posedge clk) begin
        rv <= cv && cflags[4];
        if (cv) begin
            if (cflags[4]) begin
                for (i = 0; i < 3; i = i + 1) begin
                    rphi[i] <= {30'd0, cnt} == i ? cphi_w : gphi[i];
                    rtheta[i] <= {30'd0, cnt} == i ? ctheta_w : gtheta[i];
                end
                rphi[3] <= cnt == 2'd3 ? cphi_w : gphi[0];
                rtheta[3] <= cnt == 2'd3 ? ctheta_w : gtheta[0];
                rf <= merge(gf, cflags[3:0]);
                cnt <= 2'd0;
                gf <= NONE_YET;
            end else begin
                if (cnt != 2'd3) begin
                    gphi[cnt] <= cphi_w;
                    gtheta[cnt] <= ctheta_w;
                    cnt <= cnt + 2'd1;
                end
                gf <= merge(gf, cflags[3:0]);
            end
        end
    end
    initial begin
        cnt = 2'd0;
        gf = NONE_YET;
    end

    // Then seven clocks, each at most two carry chains deep (as three, the unit placed at
    // 57 MHz): g1 the differences, g2 wrapped, g3 and g4 the ends' and the bulges' mins and
    // maxes, g5 and g6 the polar range, the wedge's ends and the kind, g7 the bands' ends.
    reg                g1v;
    reg        [3:0]   g1f;
    reg signed [AW-1:0] g1phi0;
    reg signed [AW-1:0] g1d [1:3];
    reg signed [AW-1:0] g1e [0:3];
    reg signed [AW-1:0] g1tmin [0:3];
    reg signed [AW-1:0] g1tmax [0:3];
    integer k;
    always @(posedge clk) begin
        g1v <= rv;
        g1f <= rf;
        g1phi0 <= rphi[0];
        for (k = 1; k < 4; k = k + 1) g1d[k] <= rphi[k] - rphi[0];
        for (k = 0; k < 4; k = k + 1) begin
            g1e[k] <= rphi[(k + 1) % 4] - rphi[k];
            g1tmin[k] <= min_a(rtheta[k], rtheta[(k + 1) % 4]);
            g1tmax[k] <= rtheta[k];
        end
    end
    reg                g2v;
    reg        [3:0]   g2f;
    reg signed [AW-1:0] g2phi0;
    reg signed [AW-1:0] g2d [1:3];
    reg signed [AW-1:0] g2e [0:3];
    reg signed [AW-1:0] g2tmin [0:3];
    reg signed [AW-1:0] g2tmax [0:1];
    always @(posedge clk) begin
        g2v <= g1v;
        g2f <= g1f;
        g2phi0 <= g1phi0;
        for (k = 1; k < 4; k = k + 1) g2d[k] <= wrap(g1d[k]);
        for (k = 0; k < 4; k = k + 1) begin
            g2e[k] <= wrap(g1e[k]);
            g2tmin[k] <= g1tmin[k];
        end
        g2tmax[0] <= max_a(g1tmax[0], g1tmax[1]);
        g2tmax[1] <= max_a(g1tmax[2], g1tmax[3]);
    end
    reg                g3v;
    reg        [3:0]   g3f;
    reg signed [AW-1:0] g3phi0, g3hit;
    reg signed [AW-1:0] g3lo [0:1];
    reg signed [AW-1:0] g3hi [0:1];
    reg signed [AW-1:0] g3loc [0:1];
    reg signed [AW-1:0] g3bulge [0:3];
    // |e| / 2 of the four ends, rounded up (`cull::half_up`: the bulge at least half the turn,
    // on the words' grid; the magnitude as a signed word, which a wrapped turn, within ±π, never
    // makes the most negative)
    wire       [AW-1:0] g2e_mag [0:3];
    generate
        for (g = 0; g < 4; g = g + 1) begin : mags_g2e
            magnitude #(.W(AW)) mag (.x(g2e[g]), .m(g2e_mag[g]));
        end
    endgenerate
    reg signed [AW-1:0] g3tmin [0:3];
    always @(posedge clk) begin
        g3v <= g2v;
        g3f <= g2f;
        g3phi0 <= g2phi0;
        g3hit <= max_a(g2tmax[0], g2tmax[1]);
        // against 0 by the sign bit alone (as min_a and max_a, Yosys compared with a carry
        // chain, and that chain was the set-up unit's critical path, at 99.5 MHz)
        g3lo[0] <= g2d[1][AW-1] ? g2d[1] : {AW{1'b0}};
        g3lo[1] <= min_a(g2d[2], g2d[3]);
        g3hi[0] <= g2d[1][AW-1] ? {AW{1'b0}} : g2d[1];
        g3hi[1] <= max_a(g2d[2], g2d[3]);
        // the same two ends plus SPAN, each sum beside its compare: the span test below is then
        // one compare of registers (hi − lo as a register compared with SPAN placed at 88 MHz)
        g3loc[0] <= g2d[1][AW-1] ? g2d[1] + SPAN : SPAN;
        g3loc[1] <= g2d[2] < g2d[3] ? g2d[2] + SPAN : g2d[3] + SPAN;
        for (k = 0; k < 4; k = k + 1) begin
            g3bulge[k] <= ($signed(g2e_mag[k]) + 1) >>> 1;
            g3tmin[k] <= g2tmin[k];
        end
    end
    reg                g4v;
    reg        [3:0]   g4f;
    reg signed [AW-1:0] g4phi0, g4hit, g4lo, g4hi, g4loc;
    reg signed [AW-1:0] g4lt [0:3];
    always @(posedge clk) begin
        g4v <= g3v;
        g4f <= g3f;
        g4phi0 <= g3phi0;
        g4hit <= g3hit;
        g4lo <= min_a(g3lo[0], g3lo[1]);
        g4loc <= g3lo[0] < g3lo[1] ? g3loc[0] : g3loc[1];
        g4hi <= max_a(g3hi[0], g3hi[1]);
        for (k = 0; k < 4; k = k + 1)
            g4lt[k] <= g3tmin[k] - g3bulge[k];
    end
    reg                g5v;
    reg        [3:0]   g5f;
    reg signed [AW-1:0] g5hit, g5alo, g5ahi;
    // hi − lo >= SPAN as hi >= lo + SPAN, one compare of registers (on 35-bit words it took
    // two halves of the carry chain side by side)
    reg                g5spans;
    reg signed [AW-1:0] g5lt [0:1];
    always @(posedge clk) begin
        g5v <= g4v;
        g5f <= g4f;
        g5hit <= g4hit;
        g5spans <= g4hi >= g4loc;
        g5alo <= g4phi0 + g4lo;
        g5ahi <= g4phi0 + g4hi;
        g5lt[0] <= min_a(g4lt[0], g4lt[1]);
        g5lt[1] <= min_a(g4lt[2], g4lt[3]);
    end
    // hi − lo + 2·MARGIN >= π
    wire spans = g5spans;
    reg                g6v, g6pos_near;
    reg        [1:0]   g6kind;
    reg signed [AW-1:0] g6hit, g6lot, g6alo, g6ahi;
    always @(posedge clk) begin
        g6v <= g5v;
        g6pos_near <= g5f[1] || g5f[2];
        g6kind <= g5f[3] ? 2'd0 : g5f[2] || g5f[1] || g5f[0] || spans ? 2'd1 : 2'd2;
        g6hit <= g5hit;
        g6lot <= min_a(g5lt[0], g5lt[1]);
        g6alo <= g5alo - MARGIN;
        g6ahi <= g5ahi + MARGIN;
    end
    // g7 puts the low end (the wedge's, and the polar range's less the margin) in the registers
    // the bin unit reads, and holds the high end (the range's plus the margin), which the same
    // registers take on the next clock: one cull_bin.v for both ends. A patch has at least
    // three corners, so its ends come at least three clocks after the last patch's and the unit
    // is free on the second clock.
    reg                g7v, g7second;
    reg        [1:0]   g7kind;
    reg signed [AW-1:0] g7a, g7t, g7ahi, g7thi;
    always @(posedge clk) begin
        g7v <= g6v;
        g7second <= g7v;
        g7kind <= g6kind;
        g7a <= g6v ? g6alo : g7ahi;
        g7t <= g6v ? (g6pos_near ? {AW{1'b0}} : g6lot) - MARGIN : g7thi;
        g7ahi <= g6ahi;
        g7thi <= g6hit + MARGIN;
    end
    wire       bv;
    wire [2:0] bpay;
    wire [5:0] s_end;
    wire [3:0] b_end;
    cull_bin #(.W(W), .SECTORS(SECTORS), .PW(3)) ends (
        .clk(clk), .in_valid(g7v || g7second), .in_a(g7a), .in_t(g7t),
        .in_payload({g7second, g7kind}),
        .out_valid(bv), .out_sector(s_end), .out_band(b_end), .out_payload(bpay));
    // the low end's bins wait a clock for the high end's
    reg        [1:0]   lo_kind;
    reg        [5:0]   s_lo;
    reg        [3:0]   b_lo;
    always @(posedge clk) begin
        if (bv && !bpay[2]) begin
            lo_kind <= bpay[1:0];
            s_lo <= s_end;
            b_lo <= b_end;
        end
    end
    // len = (s_hi − s_lo mod SECTORS) + 1, both candidates beside the compare that picks one
    wire [6:0] len_same = {1'b0, s_end} - {1'b0, s_lo} + 7'd1;
    wire [6:0] len_wrap = {1'b0, s_end} + (SECTORS[6:0] + 7'd1) - {1'b0, s_lo};
    always @(posedge clk) begin
        out_valid <= bv && bpay[2];
        out_kind <= lo_kind;
        out_lo <= s_lo;
        out_len <= s_end >= s_lo ? len_same : len_wrap;
        // below the horizon: every band (`Reach::ALL`)
        out_band_lo <= lo_kind == 2'd0 ? 4'd0 : b_lo;
        out_band_hi <= lo_kind == 2'd0 ? 4'd15 : b_end;
    end

    // ---- helpers
    // a corner's decisions {below, near, +z, −z} into the patch's so far
    function [3:0] merge(input [3:0] acc, input [3:0] f);
        merge = {acc[3] && f[3], acc[2] || f[2], acc[1] && f[1], acc[0] && f[0]};
    endfunction
    function [37:0] max38(input [37:0] s, input [37:0] t);
        max38 = s > t ? s : t;
    endfunction
    // the largest of three, its three compares side by side (two in a row placed at 101 MHz)
    function [37:0] max3_38(input [37:0] s, input [37:0] t, input [37:0] u);
        reg st, su, tu;
        begin
            st = s >= t;
            su = s >= u;
            tu = t >= u;
            max3_38 = st && su ? s : !st && tu ? t : u;
        end
    endfunction
    function signed [AW-1:0] min_a(input signed [AW-1:0] s, input signed [AW-1:0] t);
        min_a = s < t ? s : t;
    endfunction
    function signed [AW-1:0] max_a(input signed [AW-1:0] s, input signed [AW-1:0] t);
        max_a = s > t ? s : t;
    endfunction
    // an angle difference into (−π, π]
    function signed [AW-1:0] wrap(input signed [AW-1:0] d);
        wrap = d > PI ? d - 2 * PI : d <= -PI ? d + 2 * PI : d;
    endfunction
    // the leading one of m as a one-hot word (bit 0 if none)
    function [32:0] lead(input [32:0] m);
        integer b;
        reg above;
        begin
            above = 1'b0;
            for (b = 32; b > 0; b = b - 1) begin
                lead[b] = m[b] && !above;
                above = above || m[b];
            end
            lead[0] = !above;
        end
    endfunction
    // `coarse::block18`: the shift that brings a leading one at bit b to bit 16, as an AND-OR
    // of constant shifts chosen by the one-hot word h (floor when shifting down)
    /* verilator lint_off UNUSEDSIGNAL */
    function signed [17:0] block(input signed [32:0] v, input [32:0] h);
        integer b;
        reg signed [32:0] s;
        begin
            block = 18'sd0;
            for (b = 0; b <= 32; b = b + 1) begin
                s = b >= 16 ? v >>> (b - 16) : v <<< (16 - b);
                block = block | (s[17:0] & {18{h[b]}});
            end
        end
    endfunction
    /* verilator lint_on UNUSEDSIGNAL */
endmodule
