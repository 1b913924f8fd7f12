// The culling unit's ray side, the RTL of hdl-model/src/intersect/cull.rs's `CullUnit::ray_bin`:
// the azimuth sector and polar band of a hemisphere ray's reference direction, which choose the
// sector and band rows of the candidate bitmaps its lanes walk. The model gives it no clocks of
// its own (it runs beside the rotator, on the reference direction the rotator turns), so the
// co-simulation compares its answers in order. Its latency, 2 · ITER + 15 = 43 clocks, is
// within the rotator's 3(n + 4) + 2 for CONFIG.ITER n >= 10 (86 at the reset n = 24); below
// that the model does not charge the difference.
//
// A ray (x, y, z: Q2.30 words) is culled when z >= 0 and rho = max(|x|, |y|) >= 2^25 (sin θ at
// least 2^-5); the outputs of any other ray are don't-care. Then, clock by clock:
// 1. (x, y) scaled by the power of two 2^s that brings rho into [2^28, 2^29) (`cull::NORM_TOP`,
//    s in -3..3 for a culled ray), z by the same (two clocks);
// 2. the azimuth φ = atan2(y, x) and the magnitude r by a vectoring CORDIC pipe (ITER + 4
//    clocks), on the top W bits of the 32-bit words as the model's pipe keeps them;
// 3. (z, r) scaled by a power of two of their own, the larger into [2^28, 2^29) (two clocks);
// 4. the polar angle θ = atan2(r, z) by a second vectoring pipe;
// 5. the sector floor(((φ + π) mod 2π) · SECTORS / 2π) and the band min(floor(θ · 32 / π), 15),
//    each as the count of constant thresholds at or below the angle (the model's integer
//    divisions exactly: floor(a · S / D) >= k exactly when a >= ceil(k · D / S)), in three
//    clocks.
module cull_ray #(
    parameter integer ITER = 14,
    parameter integer W = 20,
    parameter integer SECTORS = 32
) (
    input  wire               clk,
    input  wire               in_valid,
    input  wire signed [31:0] in_x,
    input  wire signed [31:0] in_y,
    input  wire signed [31:0] in_z,
    output reg                out_valid,
    output reg                out_culled,
    output reg  [5:0]         out_sector,
    output reg  [3:0]         out_band
);
    localparam integer BANDS = 16;
    localparam integer NORM_TOP = 29;
    // π in Q3.29, as cull.rs has it
    localparam [63:0] PI = 64'd1686629713;

    // ---- 1: culled or not, and the first normalisation, in two clocks: |x| OR |y| (whose
    // leading one is max(|x|, |y|)'s, without the compare), then the shift
    wire [32:0] ax = in_x[31] ? -{in_x[31], in_x} : {1'b0, in_x};
    wire [32:0] ay = in_y[31] ? -{in_y[31], in_y} : {1'b0, in_y};
    reg                v0, c0;
    reg        [32:0]  rho;
    reg signed [31:0]  x0, y0, z0;
    always @(posedge clk) begin
        v0 <= in_valid;
        c0 <= !in_z[31] && (ax[32:25] != 8'd0 || ay[32:25] != 8'd0);
        rho <= ax | ay;
        x0 <= in_x;
        y0 <= in_y;
        z0 <= in_z;
    end
    // Both normalisations: 2^s · v for the s that brings m's leading one to bit NORM_TOP - 1,
    // the leading one looked for among bits lo..hi only (at lo if none: the bits a culled ray's
    // words can have), each place choosing its constant shift (a shift by a computed amount put
    // a subtraction and a barrel shifter in the path: 98.9 MHz). Only the top W bits of a word
    // below 2^31 go on (hence the lint pragmas on the words' other bits).
    localparam integer LEAD = NORM_TOP - 1;
    function signed [34:0] shifted(input signed [34:0] v, input integer place);
        shifted = place >= LEAD ? v >>> (place - LEAD) : v <<< (LEAD - place);
    endfunction
    /* verilator lint_off UNUSEDSIGNAL */
    function signed [34:0] norm(input signed [34:0] v, input [34:0] m, input integer lo,
        input integer hi);
        integer b;
        begin
            norm = shifted(v, lo);
            for (b = lo + 1; b <= hi; b = b + 1) if (m[b]) norm = shifted(v, b);
        end
    endfunction
    // rho's leading one at bits 25..31 for a culled ray (any other ray is scaled as if at 25)
    wire signed [34:0] nx = norm({{3{x0[31]}}, x0}, {2'b0, rho}, 25, 31),
        ny = norm({{3{y0[31]}}, y0}, {2'b0, rho}, 25, 31),
        nz = norm({{3{z0[31]}}, z0}, {2'b0, rho}, 25, 31);
    /* verilator lint_on UNUSEDSIGNAL */

    reg                v1, c1;
    reg signed [W-1:0] x1, y1;
    reg signed [34:0]  z1;
    always @(posedge clk) begin
        v1 <= v0;
        c1 <= c0;
        // the top W bits of the 32-bit word (|nx|, |ny| < 2^29 for a culled ray)
        x1 <= nx[31:32-W];
        y1 <= ny[31:32-W];
        z1 <= nz;
    end

    // ---- 2: the azimuth, z and the culled bit alongside
    wire                v2;
    wire signed [W-1:0] r2, phi2, unused_y2;
    wire [35:0]         pay2;
    /* verilator lint_off UNUSEDSIGNAL */
    wire [35:0]         early2a, early2b;
    /* verilator lint_on UNUSEDSIGNAL */
    cordic_pipe #(.MODE(1), .ITER(ITER), .W(W), .PW(36)) azimuth (
        .clk(clk), .rst(1'b0), .in_valid(v1), .in_x(x1), .in_y(y1), .in_z({W{1'b0}}),
        .in_payload({c1, z1}), .out_valid(v2), .out_x(r2), .out_y(unused_y2), .out_z(phi2),
        .out_payload(pay2), .early_payload(early2a), .early2_payload(early2b));

    // ---- 3: the second normalisation, of (z, r) with r = the magnitude's 32-bit word, in two
    // clocks: |z| OR |r|, then the shift. The leading one is at bits 27..34 for a culled ray (r
    // is at least about 2^28, the normalised (x, y)'s length; z < 2^34), so only those are
    // looked at (as a search over all 35 bits, the unit placed at 34 MHz)
    wire signed [34:0] z2 = pay2[34:0];
    wire signed [34:0] rw = {{(35 - W){r2[W-1]}}, r2} <<< (32 - W);
    wire [34:0] az2 = z2[34] ? -z2 : z2;
    wire [34:0] ar2 = rw[34] ? -rw : rw;
    reg                vm, cm;
    reg        [34:0]  m2;
    reg signed [34:0]  zm, rm;
    reg signed [W-1:0] phim;
    always @(posedge clk) begin
        vm <= v2;
        cm <= pay2[35];
        m2 <= az2 | ar2;
        zm <= z2;
        rm <= rw;
        phim <= phi2;
    end
    /* verilator lint_off UNUSEDSIGNAL */
    wire signed [34:0] zn = norm(zm, m2, 27, 34), rn = norm(rm, m2, 27, 34);
    /* verilator lint_on UNUSEDSIGNAL */

    reg                v3, c3;
    reg signed [W-1:0] z3, r3, phi3;
    always @(posedge clk) begin
        v3 <= vm;
        c3 <= cm;
        z3 <= zn[31:32-W];
        r3 <= rn[31:32-W];
        phi3 <= phim;
    end

    // ---- 4: the polar angle, φ and the culled bit alongside
    wire                v4;
    /* verilator lint_off UNUSEDSIGNAL */
    wire signed [W-1:0] unused_x4, unused_y4;
    wire [W:0]          early4a, early4b;
    /* verilator lint_on UNUSEDSIGNAL */
    wire signed [W-1:0] theta4;
    wire [W:0]          pay4;
    cordic_pipe #(.MODE(1), .ITER(ITER), .W(W), .PW(W + 1)) polar (
        .clk(clk), .rst(1'b0), .in_valid(v3), .in_x(z3), .in_y(r3), .in_z({W{1'b0}}),
        .in_payload({c3, phi3}), .out_valid(v4), .out_x(unused_x4), .out_y(unused_y4),
        .out_z(theta4), .out_payload(pay4), .early_payload(early4a), .early2_payload(early4b));

    // ---- 5: sector and band against their thresholds (Q3.29 words), in three clocks: the
    // angles as words, the thresholds compared (each a thermometer: the thresholds increase),
    // the thermometers counted. (As one clock of 64-bit compares counted by a chain of
    // incrementers, the unit placed at 10 MHz.)
    wire signed [31:0] phi_c = {pay4[W-1:0], {(32 - W){1'b0}}};
    wire signed [31:0] theta_c = {theta4, {(32 - W){1'b0}}};
    // (φ + π) mod 2π, in [0, 2π) < 2^32 (φ's word is within (-4, 4) rad): φ + 3π, φ + π or
    // φ - π, chosen by φ's compares with ±π beside the adds rather than after them
    wire signed [33:0] phi_w = {{2{phi_c[31]}}, phi_c};
    localparam [33:0] PI34 = {2'b0, PI[31:0]};
    /* verilator lint_off UNUSEDSIGNAL */
    wire signed [33:0] a_mod = phi_w < -$signed(PI34) ? phi_w + $signed(3 * PI34)
        : phi_w >= $signed(PI34) ? phi_w - $signed(PI34) : phi_w + $signed(PI34);
    /* verilator lint_on UNUSEDSIGNAL */
    reg               v5, c5;
    reg        [31:0] a5;
    reg signed [31:0] t5;
    always @(posedge clk) begin
        v5 <= v4;
        c5 <= pay4[W];
        a5 <= a_mod[31:0];
        t5 <= theta_c;
    end

    // threshold k of the sectors, ceil(k · 2π / SECTORS), and of the bands, ceil(k · π / 32)
    // (below 2^32: the 64-bit quotients' top bits are zero)
    /* verilator lint_off UNUSEDSIGNAL */
    function [63:0] wide(input [31:0] v);
        wide = {32'd0, v};
    endfunction
    localparam [63:0] S64 = wide(SECTORS), B64 = wide(2 * BANDS);
    function [31:0] sector_at(input [63:0] k);
        reg [63:0] t;
        begin
            t = (k * 2 * PI + S64 - 1) / S64;
            sector_at = t[31:0];
        end
    endfunction
    function [31:0] band_at(input [63:0] k);
        reg [63:0] t;
        begin
            t = (k * PI + B64 - 1) / B64;
            band_at = t[31:0];
        end
    endfunction
    /* verilator lint_on UNUSEDSIGNAL */
    // thermometers: bit k - 1 set when the angle is at or past threshold k
    wire [63:0] ts;
    wire [15:0] tb;
    genvar gk;
    generate
        for (gk = 1; gk <= 64; gk = gk + 1) begin : sector_threshold
            if (gk < SECTORS) assign ts[gk-1] = a5 >= sector_at(gk);
            else assign ts[gk-1] = 1'b0;
        end
        for (gk = 1; gk <= BANDS; gk = gk + 1) begin : band_threshold
            if (gk < BANDS) assign tb[gk-1] = t5 >= $signed(band_at(gk));
            else assign tb[gk-1] = 1'b0;
        end
    endgenerate
    reg        v6, c6;
    reg [63:0] ts6;
    reg [15:0] tb6;
    always @(posedge clk) begin
        v6 <= v5;
        c6 <= c5;
        ts6 <= ts;
        tb6 <= tb;
    end

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
    wire [5:0] sector_n = ones(ts6), band_n = ones({48'd0, tb6});
    /* verilator lint_on UNUSEDSIGNAL */
    always @(posedge clk) begin
        out_valid <= v6;
        out_culled <= c6;
        out_sector <= sector_n[5:0];
        out_band <= band_n[3:0];
    end
endmodule
