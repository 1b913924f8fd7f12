// The culling unit's two chained vectorings, the RTL of hdl-model/src/intersect/cull.rs's
// `CullUnit::azimuth` then `CullUnit::polar`: of a vector (x, y, z) in the frame, the azimuth
// φ = atan2(y, x) and the polar angle θ = atan2(ρ, z), ρ the azimuth vectoring's magnitude. Both
// sides of the unit use it: a ray's reference direction (`cull_ray.v`) and a patch's corners in
// the frame (`cull_reach.v`).
//
// Clock by clock (latency 2 · ITER + 14):
// 1. (x, y) scaled by the power of two 2^s that brings max(|x|, |y|) into [2^28, 2^29)
//    (`cull::NORM_TOP`), z by the same, in three clocks: |x| OR |y| (whose leading one is the
//    max's, without a compare), the leading one as a one-hot word, then an AND-OR of constant
//    shifts;
// 2. the azimuth φ and the magnitude r by a vectoring CORDIC pipe (ITER + 4 clocks), on the
//    top W bits of the 32-bit words as the model's pipe keeps them;
// 3. (z·2^s, r) scaled by a power of two of their own, the larger into [2^28, 2^29), the same
//    way (three clocks);
// 4. θ by a second vectoring pipe.
//
// The leading one is looked for among bits LO..HI only (at LO if none), the bits the caller's
// words can have: a ray's only a few (its culled directions have ρ near 1), a corner's all.
// For a zero (x, y) the model takes s = 0 where this takes s = 28 − LO; the polar angle is the
// same (z·2^s is shifted left exactly, and the second normalisation takes out either shift).
module cull_angles #(
    parameter integer ITER = 14,
    parameter integer W = 20,
    // the input words' width, and where the leading one of |x| OR |y| can be
    parameter integer IW = 32,
    parameter integer LO1 = 25,
    parameter integer HI1 = 31,
    // z·2^s's width, and where the leading one of |z·2^s| OR |r| can be
    parameter integer ZW = 35,
    parameter integer LO2 = 27,
    parameter integer HI2 = 34,
    parameter integer PW = 1
) (
    input  wire                 clk,
    input  wire                 in_valid,
    input  wire signed [IW-1:0] in_x,
    input  wire signed [IW-1:0] in_y,
    input  wire signed [IW-1:0] in_z,
    input  wire        [PW-1:0] in_payload,
    output wire                 out_valid,
    output wire signed [W-1:0]  out_phi,
    output wire signed [W-1:0]  out_theta,
    output wire        [PW-1:0] out_payload
);
    localparam integer NORM_TOP = 29;
    localparam integer LEAD = NORM_TOP - 1;

    // ---- 1: the first normalisation
    wire [IW:0] ax = in_x[IW-1] ? -{in_x[IW-1], in_x} : {1'b0, in_x};
    wire [IW:0] ay = in_y[IW-1] ? -{in_y[IW-1], in_y} : {1'b0, in_y};
    reg                 v0;
    reg        [IW:0]   m0;
    reg signed [IW-1:0] x0, y0, z0;
    reg        [PW-1:0] p0;
    always @(posedge clk) begin
        v0 <= in_valid;
        m0 <= ax | ay;
        x0 <= in_x;
        y0 <= in_y;
        z0 <= in_z;
        p0 <= in_payload;
    end
    reg                 va;
    reg        [ZW-1:0] h1;
    reg signed [IW-1:0] xa, ya, za;
    reg        [PW-1:0] pa;
    always @(posedge clk) begin
        va <= v0;
        h1 <= lead({{(ZW - IW - 1){1'b0}}, m0}, LO1, HI1);
        xa <= x0;
        ya <= y0;
        za <= z0;
        pa <= p0;
    end
    /* verilator lint_off UNUSEDSIGNAL */
    wire signed [ZW-1:0] nx = pick({{(ZW - IW){xa[IW-1]}}, xa}, h1, LO1, HI1),
        ny = pick({{(ZW - IW){ya[IW-1]}}, ya}, h1, LO1, HI1),
        nz = pick({{(ZW - IW){za[IW-1]}}, za}, h1, LO1, HI1);
    /* verilator lint_on UNUSEDSIGNAL */
    reg                 v1;
    reg signed [W-1:0]  x1, y1;
    reg signed [ZW-1:0] z1;
    reg        [PW-1:0] p1;
    always @(posedge clk) begin
        v1 <= va;
        // the top W bits of the 32-bit word (|nx|, |ny| < 2^29 after the shift)
        x1 <= nx[31:32-W];
        y1 <= ny[31:32-W];
        z1 <= nz;
        p1 <= pa;
    end

    // ---- 2: the azimuth, z·2^s and the payload alongside
    wire                v2;
    wire signed [W-1:0] r2, phi2;
    wire [ZW+PW-1:0]    pay2;
    /* verilator lint_off UNUSEDSIGNAL */
    wire signed [W-1:0] unused_y2;
    wire [ZW+PW-1:0]    early2a, early2b;
    /* verilator lint_on UNUSEDSIGNAL */
    cordic_pipe #(.MODE(1), .ITER(ITER), .W(W), .PW(ZW + PW)) azimuth (
        .clk(clk), .rst(1'b0), .in_valid(v1), .in_x(x1), .in_y(y1), .in_z({W{1'b0}}),
        .in_payload({p1, z1}), .out_valid(v2), .out_x(r2), .out_y(unused_y2), .out_z(phi2),
        .out_payload(pay2), .early_payload(early2a), .early2_payload(early2b));

    // ---- 3: the second normalisation, of (z·2^s, r) with r the magnitude's 32-bit word
    wire signed [ZW-1:0] z2 = pay2[ZW-1:0];
    wire signed [ZW-1:0] rw = {{(ZW - W){r2[W-1]}}, r2} <<< (32 - W);
    wire [ZW-1:0] az2 = z2[ZW-1] ? -z2 : z2;
    wire [ZW-1:0] ar2 = rw[ZW-1] ? -rw : rw;
    reg                 vm;
    reg        [ZW-1:0] m2;
    reg signed [ZW-1:0] zm, rm;
    reg signed [W-1:0]  phim;
    reg        [PW-1:0] pm;
    always @(posedge clk) begin
        vm <= v2;
        m2 <= az2 | ar2;
        zm <= z2;
        rm <= rw;
        phim <= phi2;
        pm <= pay2[ZW+PW-1:ZW];
    end
    reg                 vb;
    reg        [ZW-1:0] h2;
    reg signed [ZW-1:0] zb, rb;
    reg signed [W-1:0]  phib;
    reg        [PW-1:0] pb;
    always @(posedge clk) begin
        vb <= vm;
        h2 <= lead(m2, LO2, HI2);
        zb <= zm;
        rb <= rm;
        phib <= phim;
        pb <= pm;
    end
    /* verilator lint_off UNUSEDSIGNAL */
    wire signed [ZW-1:0] zn = pick(zb, h2, LO2, HI2), rn = pick(rb, h2, LO2, HI2);
    /* verilator lint_on UNUSEDSIGNAL */
    reg                 v3;
    reg signed [W-1:0]  z3, r3, phi3;
    reg        [PW-1:0] p3;
    always @(posedge clk) begin
        v3 <= vb;
        z3 <= zn[31:32-W];
        r3 <= rn[31:32-W];
        phi3 <= phib;
        p3 <= pb;
    end

    // ---- 4: the polar angle, φ and the payload alongside
    /* verilator lint_off UNUSEDSIGNAL */
    wire signed [W-1:0] unused_x4, unused_y4;
    wire [W+PW-1:0]     early4a, early4b;
    /* verilator lint_on UNUSEDSIGNAL */
    wire [W+PW-1:0]     pay4;
    cordic_pipe #(.MODE(1), .ITER(ITER), .W(W), .PW(W + PW)) polar (
        .clk(clk), .rst(1'b0), .in_valid(v3), .in_x(z3), .in_y(r3), .in_z({W{1'b0}}),
        .in_payload({p3, phi3}), .out_valid(out_valid), .out_x(unused_x4), .out_y(unused_y4),
        .out_z(out_theta), .out_payload(pay4), .early_payload(early4a),
        .early2_payload(early4b));
    assign out_phi = pay4[W-1:0];
    assign out_payload = pay4[W+PW-1:W];

    // The leading one of m among bits lo..hi as a one-hot word (bit lo if none above it; the
    // other bits zero). "A one above bit b" is written as OR trees, by groups of four bits
    // (a group's own bits above b, any group above b's): as one running OR from the top, Yosys
    // built a chain through every bit, the unit's critical path at 66 bits (76 MHz).
    localparam integer GROUPS = (ZW + 3) / 4;
    /* verilator lint_off UNUSEDSIGNAL */
    function [ZW-1:0] lead(input [ZW-1:0] m, input integer lo, input integer hi);
        integer b, j;
        reg [4*GROUPS-1:0] mm;
        reg [GROUPS-1:0] g;
        reg [3:0] own;
        begin
            mm = {(4 * GROUPS){1'b0}};
            for (b = lo + 1; b <= hi; b = b + 1) mm[b] = m[b];
            for (j = 0; j < GROUPS; j = j + 1) g[j] = |mm[4*j +: 4];
            lead = {ZW{1'b0}};
            for (b = lo + 1; b <= hi; b = b + 1) begin
                j = b / 4;
                own = mm[4*j +: 4] >> (b % 4 + 1);
                lead[b] = mm[b] && !(|own) && !(|(g >> (j + 1)));
            end
            lead[lo] = !(|mm);
        end
    endfunction
    /* verilator lint_on UNUSEDSIGNAL */
    // v · 2^(LEAD − place): the shift that brings a leading one at `place` to bit LEAD
    function signed [ZW-1:0] shifted(input signed [ZW-1:0] v, input integer place);
        shifted = place >= LEAD ? v >>> (place - LEAD) : v <<< (LEAD - place);
    endfunction
    // the shift the one-hot word h chooses among places lo..hi, as an AND-OR of constant shifts
    function signed [ZW-1:0] pick(input signed [ZW-1:0] v, input [ZW-1:0] h, input integer lo,
        input integer hi);
        integer b;
        begin
            pick = {ZW{1'b0}};
            for (b = lo; b <= hi; b = b + 1) pick = pick | (shifted(v, b) & {ZW{h[b]}});
        end
    endfunction
endmodule
