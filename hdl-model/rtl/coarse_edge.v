// The compact set-up unit's coarse edge word (hdl-model/src/intersect/coarse.rs, `narrow_edge`):
// for the edge from corner u to corner v (a_k = v_k - O, 33-bit signed components), the 18-bit
// words of the top bits of +-(u x v) and the exponent kappa that bounds their error, from six
// 18 x 18 products of u and the edge's vector v - u, each in 18 bits by a power of two of its
// own. A new edge every clock, LATENCY clocks each; the stages:
//    1. delta = v - u, and the six magnitudes |u_c|, |delta_c|;
//    2. the OR of each vector's magnitudes (its leading one is the largest one's);
//  3-4. that leading one, in two clocks (the exponents p, q are bits - 17 = its place - 16);
//    5. u and delta into 18 bits (floor when shifted down, exact when shifted up), and
//       p + q - shift;
//    6. the six products u~_j delta~_k, and the words' magnitudes;
//    7. X = u~ x delta~ (three differences), and each component's sum of the four magnitudes
//       it takes, + 1;
//    8. +-X, the OR of |X|'s components, and the error bound E (the largest sum);
// 9-10. its leading one, in two clocks: m, the bits the words drop;
//   11. the words X >>> m, S = p + q + m - shift, 16 E / 2^m's floor and whether it dropped
//       bits, and the truncation term's exponent 4 - S (clamped to 0..20);
//   12. eta = ceil(16 E / 2^m) and the truncation term 2^(4 - S);
//   13. need - 1 = 15 + eta + 2^(4 - S);
// 14-15. kappa = bits(need - 1) - 4, at most 15 ("no bound"), in two clocks (its leading one).
//
// The side's sign is taken with the edge (LATE_NEGATE = 0) or, for a set-up unit that learns it
// from h while the edge is in the pipe (`setup_unit.v`), seven clocks after it, as stage 8 uses
// it (LATE_NEGATE = 1).
module coarse_edge #(
    parameter integer LATE_NEGATE = 0
) (
    input  wire         clk,
    input  wire         in_valid,
    input  wire [98:0]  in_u,      // u_c (33 bits each) at bits 33c
    input  wire [98:0]  in_v,
    input  wire [2:0]   in_shift,  // the set-up pass's origin-wide truncation
    input  wire         in_negate, // the side's sign (h < 0): see LATE_NEGATE
    output reg          out_valid,
    output reg  [53:0]  out_words, // e'_c (18-bit signed) at bits 18c
    output reg  [3:0]   out_kappa,
    // u~, u scaled to 18 bits (`coarse::block18`), 5 clocks after the edge: a set-up unit's
    // reach takes the corner in these words rather than scaling it again
    output wire [53:0]  out_u18
);
    // The leading one's place of a nonzero value, by halving, in two clocks (one level of
    // halving a bit of the place; as one loop over the bits it was a chain of 36 multiplexers):
    // lead36_hi gives the place's three upper bits and the byte below them, lead8 the rest.
    function [10:0] lead36_hi(input [35:0] m);
        reg [63:0] x;
        reg [2:0]  n;
        begin
            x = {28'b0, m};
            n[2] = |x[63:32];
            if (n[2]) x = x >> 32;
            n[1] = |x[31:16];
            if (n[1]) x = x >> 16;
            n[0] = |x[15:8];
            if (n[0]) x = x >> 8;
            lead36_hi = {n, x[7:0]};
        end
    endfunction
    // the leading one's place in a byte (0 also for a byte of 0 or 1)
    function [2:0] lead8(input [7:1] b);
        lead8 = b[7] ? 3'd7 : b[6] ? 3'd6 : b[5] ? 3'd5 : b[4] ? 3'd4 :
                b[3] ? 3'd3 : b[2] ? 3'd2 : b[1] ? 3'd1 : 3'd0;
    endfunction
    function [33:0] mag34(input signed [33:0] x);
        mag34 = x[33] ? -x : x;
    endfunction
    function [35:0] max3(input [35:0] a, input [35:0] b, input [35:0] c);
        max3 = (a > b) ? ((a > c) ? a : c) : ((b > c) ? b : c);
    endfunction
    // x (|x| < 2^34, its leading one at `lead`) into 18 bits by 2^(lead - 16), floor when shifted
    // down, exact when shifted up: (x 2^33) >>> lead, an exact shift, then its bits 34:17 (a
    // shift each way and the sign of lead - 16 choosing, before, were the longest path)
    /* verilator lint_off UNUSEDSIGNAL */ // the shifted value's other bits
    function [17:0] narrow(input signed [33:0] x, input [5:0] lead);
        reg signed [66:0] y;
        begin
            y = {x, 33'b0} >>> lead;
            narrow = y[34:17];
        end
    endfunction
    /* verilator lint_on UNUSEDSIGNAL */
    // the exponent that brings a vector whose largest magnitude has its leading one at `lead`
    // into 17 bits: lead - 16, 0 for a zero vector
    function signed [6:0] expo(input zero, input [5:0] lead);
        expo = zero ? 7'sd0 : $signed({1'b0, lead}) - 7'sd16;
    endfunction
    function [19:0] mag18(input signed [17:0] x);
        mag18 = {2'b0, x[17] ? -x : x};
    endfunction

    localparam integer LATENCY = 15;
    // valid (into the output register) and the side's sign (into stage 8) along the pipe
    reg [LATENCY-2:0] valid;
    reg [6:0]         negate;
    always @(posedge clk) begin
        valid <= {valid[LATENCY-3:0], in_valid};
        negate <= {negate[5:0], in_negate};
    end

    // 1: delta and the magnitudes
    reg signed [33:0] s1_u [0:2];
    reg signed [33:0] s1_d [0:2];
    reg [33:0]        s1_mu [0:2];
    reg [33:0]        s1_md [0:2];
    reg [2:0]         s1_shift;
    integer i;
    always @(posedge clk) begin
        s1_shift <= in_shift;
        for (i = 0; i < 3; i = i + 1) begin
            s1_u[i] <= {in_u[33 * i + 32], in_u[33 * i +: 33]};
            s1_d[i] <= {in_v[33 * i + 32], in_v[33 * i +: 33]} - {in_u[33 * i + 32], in_u[33 * i +: 33]};
            s1_mu[i] <= mag34({in_u[33 * i + 32], in_u[33 * i +: 33]});
            s1_md[i] <= mag34({in_v[33 * i + 32], in_v[33 * i +: 33]} -
                              {in_u[33 * i + 32], in_u[33 * i +: 33]});
        end
    end

    // 2: the magnitudes' ORs
    reg signed [33:0] s2_u [0:2];
    reg signed [33:0] s2_d [0:2];
    reg [35:0]        s2_mu, s2_md;
    reg [2:0]         s2_shift;
    always @(posedge clk) begin
        s2_shift <= s1_shift;
        s2_mu <= {2'b0, s1_mu[0] | s1_mu[1] | s1_mu[2]};
        s2_md <= {2'b0, s1_md[0] | s1_md[1] | s1_md[2]};
        for (i = 0; i < 3; i = i + 1) begin
            s2_u[i] <= s1_u[i];
            s2_d[i] <= s1_d[i];
        end
    end

    // 3-4: the leading ones, in two clocks
    /* verilator lint_off UNUSEDSIGNAL */ // the bytes' bit 0 places nothing
    reg [10:0]        s3_hu, s3_hd;
    /* verilator lint_on UNUSEDSIGNAL */
    reg signed [33:0] s3_u [0:2];
    reg signed [33:0] s3_d [0:2];
    reg               s3_zu, s3_zd;
    reg [2:0]         s3_shift;
    always @(posedge clk) begin
        s3_hu <= lead36_hi(s2_mu);
        s3_hd <= lead36_hi(s2_md);
        s3_zu <= s2_mu == 36'd0;
        s3_zd <= s2_md == 36'd0;
        s3_shift <= s2_shift;
        for (i = 0; i < 3; i = i + 1) begin
            s3_u[i] <= s2_u[i];
            s3_d[i] <= s2_d[i];
        end
    end
    reg signed [33:0] s4_u [0:2];
    reg signed [33:0] s4_d [0:2];
    reg [5:0]         s4_lu, s4_ld;
    reg               s4_zu, s4_zd;
    reg [2:0]         s4_shift;
    always @(posedge clk) begin
        s4_lu <= {s3_hu[10:8], lead8(s3_hu[7:1])};
        s4_ld <= {s3_hd[10:8], lead8(s3_hd[7:1])};
        s4_zu <= s3_zu;
        s4_zd <= s3_zd;
        s4_shift <= s3_shift;
        for (i = 0; i < 3; i = i + 1) begin
            s4_u[i] <= s3_u[i];
            s4_d[i] <= s3_d[i];
        end
    end

    // 5: both vectors into 18 bits, and p + q - shift
    wire signed [6:0] p = expo(s4_zu, s4_lu);
    wire signed [6:0] q = expo(s4_zd, s4_ld);
    reg signed [17:0] s5_u [0:2];
    reg signed [17:0] s5_d [0:2];
    reg signed [7:0]  s5_pq;
    always @(posedge clk) begin
        s5_pq <= {p[6], p} + {q[6], q} - {5'b0, s4_shift};
        for (i = 0; i < 3; i = i + 1) begin
            s5_u[i] <= narrow(s4_u[i], s4_lu);
            s5_d[i] <= narrow(s4_d[i], s4_ld);
        end
    end

    assign out_u18 = {s5_u[2], s5_u[1], s5_u[0]};

    // 6: the six products u~_j delta~_k, (j, k) = (1, 2), (2, 1), (2, 0), (0, 2), (0, 1),
    // (1, 0), each on a tile with its output register (`mul18.v`), and the words' magnitudes
    wire signed [35:0] s6_p [0:5];
    mul18 mul0 (.clk(clk), .ce(1'b1), .a(s5_u[1]), .b(s5_d[2]), .p(s6_p[0]));
    mul18 mul1 (.clk(clk), .ce(1'b1), .a(s5_u[2]), .b(s5_d[1]), .p(s6_p[1]));
    mul18 mul2 (.clk(clk), .ce(1'b1), .a(s5_u[2]), .b(s5_d[0]), .p(s6_p[2]));
    mul18 mul3 (.clk(clk), .ce(1'b1), .a(s5_u[0]), .b(s5_d[2]), .p(s6_p[3]));
    mul18 mul4 (.clk(clk), .ce(1'b1), .a(s5_u[0]), .b(s5_d[1]), .p(s6_p[4]));
    mul18 mul5 (.clk(clk), .ce(1'b1), .a(s5_u[1]), .b(s5_d[0]), .p(s6_p[5]));
    reg [19:0]        s6_mu [0:2];
    reg [19:0]        s6_md [0:2];
    reg signed [7:0]  s6_pq;
    always @(posedge clk) begin
        s6_pq <= s5_pq;
        for (i = 0; i < 3; i = i + 1) begin
            s6_mu[i] <= mag18(s5_u[i]);
            s6_md[i] <= mag18(s5_d[i]);
        end
    end

    // 7: X, and each component's bound (the sum of the four magnitudes it takes, + 1)
    reg signed [36:0] s7_x [0:2];
    reg [19:0]        s7_b [0:2];
    reg signed [7:0]  s7_pq;
    always @(posedge clk) begin
        s7_pq <= s6_pq;
        for (i = 0; i < 3; i = i + 1) begin
            s7_x[i] <= {s6_p[2 * i][35], s6_p[2 * i]} - {s6_p[2 * i + 1][35], s6_p[2 * i + 1]};
            s7_b[i] <= s6_mu[(i + 1) % 3] + s6_mu[(i + 2) % 3] + s6_md[(i + 1) % 3] +
                       s6_md[(i + 2) % 3] + 20'd1;
        end
    end

    // 8: the side's sign, |X|'s OR, and E (the largest bound)
    /* verilator lint_off UNUSEDSIGNAL */ // four 18-bit magnitudes and 1 need 20 bits
    wire [35:0] e_max = max3({16'b0, s7_b[0]}, {16'b0, s7_b[1]}, {16'b0, s7_b[2]});
    /* verilator lint_on UNUSEDSIGNAL */
    /* verilator lint_off UNUSEDSIGNAL */ // |X| <= 2^35
    function [35:0] mag37(input signed [36:0] x);
        reg signed [36:0] a;
        begin
            a = x[36] ? -x : x;
            mag37 = a[35:0];
        end
    endfunction
    /* verilator lint_on UNUSEDSIGNAL */
    wire side = (LATE_NEGATE != 0) ? in_negate : negate[6];
    reg signed [36:0] s8_x [0:2];
    reg [35:0]        s8_or;
    reg [19:0]        s8_e;
    reg signed [7:0]  s8_pq;
    always @(posedge clk) begin
        s8_or <= mag37(s7_x[0]) | mag37(s7_x[1]) | mag37(s7_x[2]);
        s8_e <= e_max[19:0];
        s8_pq <= s7_pq;
        for (i = 0; i < 3; i = i + 1) s8_x[i] <= side ? -s7_x[i] : s7_x[i];
    end

    // 9: the top of |X|'s leading one (its place's three upper bits and the byte below them)
    /* verilator lint_off UNUSEDSIGNAL */ // the byte's bit 0 places nothing
    reg [10:0]        s9_hi;
    /* verilator lint_on UNUSEDSIGNAL */
    reg signed [36:0] s9_x [0:2];
    reg [19:0]        s9_e;
    reg signed [7:0]  s9_t;
    always @(posedge clk) begin
        s9_hi <= lead36_hi(s8_or);
        s9_e <= s8_e;
        s9_t <= 8'sd4 - s8_pq;
        for (i = 0; i < 3; i = i + 1) s9_x[i] <= s8_x[i];
    end

    // 10: the bits the words drop: bits(|X|) - 17 when above 17 (the place - 16 when above 16)
    wire [5:0] top = {s9_hi[10:8], lead8(s9_hi[7:1])};
    reg signed [36:0] s10_x [0:2];
    reg [4:0]         s10_m;
    reg [19:0]        s10_e;
    reg signed [7:0]  s10_t;
    always @(posedge clk) begin
        s10_m <= (top > 6'd16) ? top[4:0] - 5'd16 : 5'd0;
        s10_e <= s9_e;
        // the truncation term's exponent 4 - S = (4 - (p + q - shift)) - m
        s10_t <= (top > 6'd16) ? s9_t + 8'sd16 - $signed({2'b0, top}) : s9_t;
        for (i = 0; i < 3; i = i + 1) s10_x[i] <= s9_x[i];
    end

    // 11: the words, 16 E / 2^m (its floor, and whether it dropped bits) and the truncation
    // term's exponent
    wire signed [36:0] ws [0:2];
    genvar c;
    generate
        for (c = 0; c < 3; c = c + 1) begin : words
            assign ws[c] = s10_x[c] >>> s10_m;
        end
    endgenerate
    wire signed [7:0] texp = s10_t;
    wire [23:0] e16 = {s10_e, 4'b0};
    reg [53:0]  s11_words;
    reg [23:0]  s11_eta;
    reg         s11_rem;
    reg [4:0]   s11_texp;
    always @(posedge clk) begin
        s11_words <= {ws[2][17:0], ws[1][17:0], ws[0][17:0]};
        s11_eta <= e16 >> s10_m;
        // the bits below 2^m as a thermometer of ones, not 2^m − 1 (a carry chain after the
        // shift: the set-up family's critical path)
        s11_rem <= (e16 & ~(24'hFFFFFF << s10_m)) != 24'd0;
        s11_texp <= (texp < 0) ? 5'd0 : ((texp > 8'sd20) ? 5'd20 : texp[4:0]);
    end

    // 12: eta = ceil(16 E / 2^m), and the truncation term 2^(4 - S)
    reg [53:0]  s12_words;
    reg [24:0]  s12_eta;
    reg [20:0]  s12_trunc;
    always @(posedge clk) begin
        s12_words <= s11_words;
        s12_eta <= {1'b0, s11_eta} + {24'b0, s11_rem};
        s12_trunc <= 21'd1 << s11_texp;
    end

    // 13: need - 1, in sixteenths (need >= 18: eta and the truncation term are at least 1)
    reg [53:0]  s13_words;
    reg [26:0]  s13_need1;
    always @(posedge clk) begin
        s13_words <= s12_words;
        s13_need1 <= 27'd15 + {2'b0, s12_eta} + {6'b0, s12_trunc};
    end

    // 14: the top of need - 1's leading one
    /* verilator lint_off UNUSEDSIGNAL */ // the byte's bit 0 places nothing
    reg [10:0]  s14_hi;
    /* verilator lint_on UNUSEDSIGNAL */
    reg [53:0]  s14_words;
    always @(posedge clk) begin
        s14_hi <= lead36_hi({9'b0, s13_need1});
        s14_words <= s13_words;
    end

    // 15: kappa = bits(need - 1) - 4 = its leading one's place - 3
    wire [5:0] k = {s14_hi[10:8], lead8(s14_hi[7:1])} - 6'd3;
    always @(posedge clk) begin
        out_valid <= valid[LATENCY-2];
        out_words <= s14_words;
        out_kappa <= (k > 6'd15) ? 4'd15 : k[3:0];
    end
endmodule
