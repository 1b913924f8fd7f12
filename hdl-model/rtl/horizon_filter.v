// The horizon filter of one bank (hdl-model/src/intersect/horizon.rs, `below`): whether a slot's
// bounding box is certainly below the horizon of the frame's axis w at origin o, by more than
// 2^-7 of its reach, so that the set-up unit may pass the patch over. With l = L - o and
// h = H - o (the box's ends, Q8.24), q_c = h_c where w_c >= 0 and l_c otherwise,
// U = max_c max(|l_c|, |h_c|) and k = max(bits(U) - 17, 0): z = sum (q_c >> k)(w_c >> 14),
// E = sum(|q_c >> k| + |w_c >> 14| + 1), and the box is below iff z + E + ((U >> k) + 1) 2^9
// <= 0. A box a clock, seven stages: the subtractions (both ways, so that a magnitude is a
// choice, not a negation); the picks, each axis's larger end and |w'|; U, k and E's w part;
// the shifts; the three 18 x 18 products and E's q part; their sums; the sign. (The box read
// before it, two clocks in `bank_front.v`, completes the model's HORIZON_LATENCY.) With en low
// every stage holds: the bank's front stops the filter while its oldest verdict, a patch kept,
// waits for room in the set-up unit's FIFO.
// Verilog-2005, accepted by Verilator and Yosys.
module horizon_filter (
    input  wire        clk,
    input  wire        en,         // the stages advance
    input  wire        in_valid,
    input  wire        in_boxed,   // a planar slot whose box is complete and bounded
    input  wire [71:0] in_lo,      // the box's low ends, 24-bit signed (Q8.16) at bits 24c
    input  wire [71:0] in_hi,      // its high ends
    input  wire [95:0] in_o,       // the origin, Q8.24 at bits 32c
    input  wire [95:0] in_w,       // the frame's axis w, Q2.30 at bits 32c
    output reg         out_valid,
    output reg         out_below
);
    // |x| from x and -x, both registered (a multiplexer, not a negation's carry chain)
    function [32:0] mag34(input signed [33:0] x, input [32:0] neg);
        mag34 = x[33] ? neg : x[32:0];
    endfunction
    function [17:0] mag18(input signed [17:0] x);
        mag18 = x[17] ? -x : x;
    endfunction
    // bits(x) - 17, at least 0, of a 33-bit magnitude: the place of the leading one among bits
    // 32:17 found by halves (a tree, not a chain of priorities), plus one
    function [4:0] drop(input [32:0] x);
        /* verilator lint_off UNUSEDSIGNAL */ // bits 16:0 stay within 17 bits
        reg [32:0] all;
        /* verilator lint_on UNUSEDSIGNAL */
        reg [15:0] y;
        reg [7:0] y8;
        /* verilator lint_off UNUSEDSIGNAL */ // bit 0: the leading one when no other is
        reg [3:0] y4;
        /* verilator lint_on UNUSEDSIGNAL */
        reg h8, h4, h2, h1;
        begin
            all = x;
            y = all[32:17];
            h8 = |y[15:8];
            y8 = h8 ? y[15:8] : y[7:0];
            h4 = |y8[7:4];
            y4 = h4 ? y8[7:4] : y8[3:0];
            h2 = |y4[3:2];
            h1 = h2 ? y4[3] : y4[1];
            // its place + 1, the increment written out: one LUT after the encoder, where
            // `+ 5'd1` became a carry chain (the bank front's critical path)
            drop = (|y) ? {h8 & h4 & h2 & h1, h8 ^ (h4 & h2 & h1), h4 ^ (h2 & h1), h2 ^ h1, ~h1}
                : 5'd0;
        end
    endfunction
    // x >> k in 18 bits (|x| <= U, so |x >> k| <= 2^17)
    function [17:0] narrow(input signed [33:0] x, input [4:0] k);
        /* verilator lint_off UNUSEDSIGNAL */ // the shifted value's top bits repeat its sign
        reg signed [33:0] t;
        /* verilator lint_on UNUSEDSIGNAL */
        begin
            t = x >>> k;
            narrow = t[17:0];
        end
    endfunction
    // U >> k in 17 bits (U < 2^(k + 17))
    function [16:0] narrow_u(input [32:0] x, input [4:0] k);
        /* verilator lint_off UNUSEDSIGNAL */ // zero above bit 16
        reg [32:0] t;
        /* verilator lint_on UNUSEDSIGNAL */
        begin
            t = x >> k;
            narrow_u = t[16:0];
        end
    endfunction

    // 1: the box's ends relative to the origin, and their negations
    reg               s1_valid, s1_boxed;
    reg signed [33:0] s1_l [0:2];
    reg signed [33:0] s1_h [0:2];
    reg signed [33:0] s1_nl [0:2];
    reg signed [33:0] s1_nh [0:2];
    reg        [53:0] s1_w;        // w >> 14 (Q2.16), 18 bits at 18c
    /* verilator lint_off UNUSEDSIGNAL */ // the axis's bits below Q2.16
    wire       [95:0] w_all = in_w;
    /* verilator lint_on UNUSEDSIGNAL */
    integer c;
    genvar gc;
    always @(posedge clk) if (en) begin
        s1_valid <= in_valid;
        s1_boxed <= in_boxed;
        for (c = 0; c < 3; c = c + 1) begin
            s1_w[18 * c +: 18] <= w_all[32 * c + 14 +: 18];
            s1_l[c] <= {{2{in_lo[24 * c + 23]}}, in_lo[24 * c +: 24], 8'd0}
                - {{2{in_o[32 * c + 31]}}, in_o[32 * c +: 32]};
            s1_h[c] <= {{2{in_hi[24 * c + 23]}}, in_hi[24 * c +: 24], 8'd0}
                - {{2{in_o[32 * c + 31]}}, in_o[32 * c +: 32]};
            s1_nl[c] <= {{2{in_o[32 * c + 31]}}, in_o[32 * c +: 32]}
                - {{2{in_lo[24 * c + 23]}}, in_lo[24 * c +: 24], 8'd0};
            s1_nh[c] <= {{2{in_o[32 * c + 31]}}, in_o[32 * c +: 32]}
                - {{2{in_hi[24 * c + 23]}}, in_hi[24 * c +: 24], 8'd0};
        end
    end

    // 2: the corner w picks, and each axis's larger reach
    reg               s2_valid, s2_boxed;
    reg signed [33:0] s2_q [0:2];
    reg        [32:0] s2_m [0:2];
    reg        [53:0] s2_w;
    reg        [17:0] s2_wm [0:2];
    always @(posedge clk) if (en) begin
        s2_valid <= s1_valid;
        s2_boxed <= s1_boxed;
        s2_w <= s1_w;
        for (c = 0; c < 3; c = c + 1) begin
            s2_wm[c] <= mag18(s1_w[18 * c +: 18]);
            s2_q[c] <= s1_w[18 * c + 17] ? s1_l[c] : s1_h[c];
            s2_m[c] <= (mag34(s1_l[c], s1_nl[c][32:0]) > mag34(s1_h[c], s1_nh[c][32:0]))
                ? mag34(s1_l[c], s1_nl[c][32:0]) : mag34(s1_h[c], s1_nh[c][32:0]);
        end
    end

    // 3: U, the largest reach (its three compares side by side), k, and W = sum |w'_c| + 3
    reg               s3_valid, s3_boxed;
    reg signed [33:0] s3_q [0:2];
    reg        [32:0] s3_u;
    reg        [4:0]  s3_k;
    reg        [53:0] s3_w;
    reg        [19:0] s3_wsum;
    wire ge01 = s2_m[0] >= s2_m[1];
    wire ge02 = s2_m[0] >= s2_m[2];
    wire ge12 = s2_m[1] >= s2_m[2];
    // the largest's leading one is the leading one of the three ORed
    wire [4:0] k_all = drop(s2_m[0] | s2_m[1] | s2_m[2]);
    always @(posedge clk) if (en) begin
        s3_valid <= s2_valid;
        s3_boxed <= s2_boxed;
        s3_w <= s2_w;
        s3_wsum <= {2'd0, s2_wm[0]} + {2'd0, s2_wm[1]} + {2'd0, s2_wm[2]} + 20'd3;
        for (c = 0; c < 3; c = c + 1) s3_q[c] <= s2_q[c];
        s3_u <= (ge01 && ge02) ? s2_m[0] : (ge12 ? s2_m[1] : s2_m[2]);
        s3_k <= k_all;
    end

    // 4: k, and q, U and w narrowed to 18 bits
    reg               s4_valid, s4_boxed;
    reg signed [17:0] s4_q [0:2];
    reg signed [17:0] s4_w [0:2];
    reg        [16:0] s4_u;
    reg        [19:0] s4_wsum;
    wire [4:0] k = s3_k;
    always @(posedge clk) if (en) begin
        s4_valid <= s3_valid;
        s4_boxed <= s3_boxed;
        s4_wsum <= s3_wsum;
        s4_u <= narrow_u(s3_u, k);
        for (c = 0; c < 3; c = c + 1) begin
            s4_q[c] <= narrow(s3_q[c], k);
            s4_w[c] <= s3_w[18 * c +: 18];
        end
    end

    // 5: the products; sum |q'_c| as the q'_c with their bits flipped where negative (added
    // up, no negation's carry chain) and the count of the negative ones; W and the margin
    // (U' + 1) 2^9 added
    reg               s5_valid, s5_boxed;
    // each product on a tile with its output register (`mul18.v`)
    wire signed [35:0] s5_p [0:2];
    generate
        for (gc = 0; gc < 3; gc = gc + 1) begin : products
            mul18 mul (.clk(clk), .ce(en), .a(s4_q[gc]), .b(s4_w[gc]), .p(s5_p[gc]));
        end
    endgenerate
    reg        [19:0] s5_qx;
    reg        [1:0]  s5_neg;
    reg        [26:0] s5_k;
    always @(posedge clk) if (en) begin
        s5_valid <= s4_valid;
        s5_boxed <= s4_boxed;
        s5_qx <= {2'd0, s4_q[0] ^ {18{s4_q[0][17]}}} + {2'd0, s4_q[1] ^ {18{s4_q[1][17]}}}
            + {2'd0, s4_q[2] ^ {18{s4_q[2][17]}}};
        s5_neg <= {1'b0, s4_q[0][17]} + {1'b0, s4_q[1][17]} + {1'b0, s4_q[2][17]};
        s5_k <= {7'd0, s4_wsum} + {1'b0, s4_u, 9'd0} + 27'd512;
    end

    // 6: z = sum of the products, and E + margin - 1
    reg               s6_valid, s6_boxed;
    reg signed [37:0] s6_z;
    reg        [27:0] s6_e;
    always @(posedge clk) if (en) begin
        s6_valid <= s5_valid;
        s6_boxed <= s5_boxed;
        s6_z <= {{2{s5_p[0][35]}}, s5_p[0]} + {{2{s5_p[1][35]}}, s5_p[1]}
            + {{2{s5_p[2][35]}}, s5_p[2]};
        s6_e <= {8'd0, s5_qx} + {26'd0, s5_neg} + {1'b0, s5_k} - 28'd1;
    end

    // 7: below iff z + E + margin <= 0, that is z + E + margin - 1 < 0
    /* verilator lint_off UNUSEDSIGNAL */ // only its sign
    wire signed [38:0] sum = {s6_z[37], s6_z} + {11'd0, s6_e};
    /* verilator lint_on UNUSEDSIGNAL */
    always @(posedge clk) if (en) begin
        out_valid <= s6_valid;
        out_below <= s6_boxed && sum[38];
    end
endmodule
