// The culling unit's two chained vectorings, the RTL of hdl-model/src/intersect/cull.rs's
// `CullUnit::azimuth` then `CullUnit::polar`: of a vector (x, y, z) in the frame, the azimuth
// φ = atan2(y, x) and the polar angle θ = atan2(ρ, z), ρ the azimuth vectoring's magnitude. Both
// sides of the unit use it: a ray's reference direction (`cull_ray.v`) and a patch's corners in
// the frame (`cull_reach.v`).
//
// Clock by clock (latency 2 · ITER + 14):
// 1. (x, y) scaled by the power of two 2^s that brings max(|x|, |y|) into [2^28, 2^29)
//    (`cull::NORM_TOP`), z by the same, in three clocks: |x| OR |y| (whose leading one is the
//    max's, without a compare), the leading one (`leading_one.v`) as its step of eight places
//    and its place in the step, then the shift as two AND-ORs of constant shifts (`pick`);
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
    // the fine shift's word (v shifted left by up to LEAD, nothing lost) and the coarse steps
    localparam integer UW = ZW + LEAD + 1;
    localparam integer CW = (ZW + 7) / 8;

    // ---- 1: the first normalisation
    wire [IW:0] ax, ay;
    magnitude #(.W(IW + 1)) mag_x (.x({in_x[IW-1], in_x}), .m(ax));
    magnitude #(.W(IW + 1)) mag_y (.x({in_y[IW-1], in_y}), .m(ay));
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
    wire [ZW-1:0] lead1;
    leading_one #(.W(ZW), .LO(LO1), .HI(HI1)) first_lead (
        .m({{(ZW - IW - 1){1'b0}}, m0}), .lead(lead1));
    reg                 va;
    reg        [7:0]    f1;
    reg        [CW-1:0] c1;
    reg signed [IW-1:0] xa, ya, za;
    reg        [PW-1:0] pa;
    always @(posedge clk) begin
        va <= v0;
        f1 <= fine(lead1, LO1, HI1);
        c1 <= coarse(lead1, LO1, HI1);
        xa <= x0;
        ya <= y0;
        za <= z0;
        pa <= p0;
    end
    /* verilator lint_off UNUSEDSIGNAL */
    wire signed [ZW-1:0] nx = pick({{(ZW - IW){xa[IW-1]}}, xa}, f1, c1, LO1),
        ny = pick({{(ZW - IW){ya[IW-1]}}, ya}, f1, c1, LO1),
        nz = pick({{(ZW - IW){za[IW-1]}}, za}, f1, c1, LO1);
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
    wire [ZW-1:0] az2, ar2;
    magnitude #(.W(ZW)) mag_z (.x(z2), .m(az2));
    magnitude #(.W(ZW)) mag_r (.x(rw), .m(ar2));
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
    wire [ZW-1:0] lead2;
    leading_one #(.W(ZW), .LO(LO2), .HI(HI2)) second_lead (.m(m2), .lead(lead2));
    reg                 vb;
    reg        [7:0]    f2;
    reg        [CW-1:0] c2;
    reg signed [ZW-1:0] zb, rb;
    reg signed [W-1:0]  phib;
    reg        [PW-1:0] pb;
    always @(posedge clk) begin
        vb <= vm;
        f2 <= fine(lead2, LO2, HI2);
        c2 <= coarse(lead2, LO2, HI2);
        zb <= zm;
        rb <= rm;
        phib <= phim;
        pb <= pm;
    end
    /* verilator lint_off UNUSEDSIGNAL */
    wire signed [ZW-1:0] zn = pick(zb, f2, c2, LO2), rn = pick(rb, f2, c2, LO2);
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

    // A one-hot place among lo..hi as its step of eight places (coarse) and its place in the step
    // (fine), registered in place of the one-hot word: the shift is then two small AND-ORs in
    // turn, 8 then ⌈(hi − lo + 1)/8⌉ ways, where one AND-OR of every place took four in ten of
    // the patch side's LUT4s (session 33).
    function [7:0] fine(input [ZW-1:0] h, input integer lo, input integer hi);
        integer b;
        begin
            fine = 8'd0;
            for (b = lo; b <= hi; b = b + 1) fine[(b - lo) % 8] = fine[(b - lo) % 8] | h[b];
        end
    endfunction
    function [CW-1:0] coarse(input [ZW-1:0] h, input integer lo, input integer hi);
        integer b;
        begin
            coarse = {CW{1'b0}};
            for (b = lo; b <= hi; b = b + 1) coarse[(b - lo) / 8] = coarse[(b - lo) / 8] | h[b];
        end
    endfunction
    // v · 2^(LEAD − place) for the place lo + 8·c + f that the two words choose: the fine shift
    // in a word wide enough that a left shift loses nothing, then the coarse one right by 8·c,
    // the same bits as the one shift (each step in signed registers of its own: inside a wider
    // expression with unsigned masks, >>> would shift in zeros).
    function signed [ZW-1:0] pick(input signed [ZW-1:0] v, input [7:0] f, input [CW-1:0] c,
        input integer lo);
        integer k, a;
        reg signed [UW-1:0] vw, u, s;
        begin
            vw = {{(UW - ZW){v[ZW-1]}}, v};
            u = {UW{1'b0}};
            for (k = 0; k < 8; k = k + 1) begin
                s = lo + k >= LEAD ? vw >>> (lo + k - LEAD) : vw <<< (LEAD - lo - k);
                u = u | (s & {UW{f[k]}});
            end
            pick = {ZW{1'b0}};
            for (a = 0; a < CW; a = a + 1) begin
                s = u >>> (8 * a);
                pick = pick | (s[ZW-1:0] & {ZW{c[a]}});
            end
        end
    endfunction
endmodule
