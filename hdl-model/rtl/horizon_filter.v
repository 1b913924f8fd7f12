// The horizon filter of one bank (hdl-model/src/intersect/horizon.rs, `below`): whether a slot's
// bounding box is certainly below the horizon of the frame's axis w at origin o, by more than
// 2^-7 of its reach, so that the set-up unit may pass the patch over. With l = L - o and
// h = H - o (the box's ends, Q8.24), q_c = h_c where w_c >= 0 and l_c otherwise,
// U = max_c max(|l_c|, |h_c|) and k = max(bits(U) - 17, 0): z = sum (q_c >> k)(w_c >> 14),
// E = sum(|q_c >> k| + |w_c >> 14| + 1), and the box is below iff z + E + ((U >> k) + 1) 2^9
// <= 0. A box a clock, six stages: the subtractions; the magnitudes, the picks and each axis's
// larger end; U; k and the shifts; the three 18 x 18 products and E; the sum and its sign.
// (The box read before it is the seventh clock of the model's HORIZON_LATENCY.)
// Verilog-2005, accepted by Verilator and Yosys.
module horizon_filter (
    input  wire        clk,
    input  wire        in_valid,
    input  wire        in_boxed,   // a planar slot whose box is complete and bounded
    input  wire [71:0] in_lo,      // the box's low ends, 24-bit signed (Q8.16) at bits 24c
    input  wire [71:0] in_hi,      // its high ends
    input  wire [95:0] in_o,       // the origin, Q8.24 at bits 32c
    input  wire [95:0] in_w,       // the frame's axis w, Q2.30 at bits 32c
    output reg         out_valid,
    output reg         out_below
);
    function [32:0] mag34(input signed [33:0] x);
        mag34 = x[33] ? -x[32:0] : x[32:0];
    endfunction
    function [17:0] mag18(input signed [17:0] x);
        mag18 = x[17] ? -x : x;
    endfunction
    // bits(x) - 17, at least 0, of a 33-bit magnitude
    function [4:0] drop(input [32:0] x);
        integer b;
        begin
            drop = 0;
            for (b = 17; b <= 32; b = b + 1) if (x[b]) drop = b[4:0] - 5'd16;
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

    // 1: the box's ends relative to the origin
    reg               s1_valid, s1_boxed;
    reg signed [33:0] s1_l [0:2];
    reg signed [33:0] s1_h [0:2];
    reg        [53:0] s1_w;        // w >> 14 (Q2.16), 18 bits at 18c
    /* verilator lint_off UNUSEDSIGNAL */ // the axis's bits below Q2.16
    wire       [95:0] w_all = in_w;
    /* verilator lint_on UNUSEDSIGNAL */
    integer c;
    always @(posedge clk) begin
        s1_valid <= in_valid;
        s1_boxed <= in_boxed;
        for (c = 0; c < 3; c = c + 1) begin
            s1_w[18 * c +: 18] <= w_all[32 * c + 14 +: 18];
            s1_l[c] <= {{2{in_lo[24 * c + 23]}}, in_lo[24 * c +: 24], 8'd0}
                - {{2{in_o[32 * c + 31]}}, in_o[32 * c +: 32]};
            s1_h[c] <= {{2{in_hi[24 * c + 23]}}, in_hi[24 * c +: 24], 8'd0}
                - {{2{in_o[32 * c + 31]}}, in_o[32 * c +: 32]};
        end
    end

    // 2: the corner w picks, and each axis's larger reach
    reg               s2_valid, s2_boxed;
    reg signed [33:0] s2_q [0:2];
    reg        [32:0] s2_m [0:2];
    reg        [53:0] s2_w;
    always @(posedge clk) begin
        s2_valid <= s1_valid;
        s2_boxed <= s1_boxed;
        s2_w <= s1_w;
        for (c = 0; c < 3; c = c + 1) begin
            s2_q[c] <= s1_w[18 * c + 17] ? s1_l[c] : s1_h[c];
            s2_m[c] <= (mag34(s1_l[c]) > mag34(s1_h[c])) ? mag34(s1_l[c]) : mag34(s1_h[c]);
        end
    end

    // 3: U, the largest reach (its three compares side by side)
    reg               s3_valid, s3_boxed;
    reg signed [33:0] s3_q [0:2];
    reg        [32:0] s3_u;
    reg        [53:0] s3_w;
    wire ge01 = s2_m[0] >= s2_m[1];
    wire ge02 = s2_m[0] >= s2_m[2];
    wire ge12 = s2_m[1] >= s2_m[2];
    always @(posedge clk) begin
        s3_valid <= s2_valid;
        s3_boxed <= s2_boxed;
        s3_w <= s2_w;
        for (c = 0; c < 3; c = c + 1) s3_q[c] <= s2_q[c];
        s3_u <= (ge01 && ge02) ? s2_m[0] : (ge12 ? s2_m[1] : s2_m[2]);
    end

    // 4: k, and q, U and w narrowed to 18 bits
    reg               s4_valid, s4_boxed;
    reg signed [17:0] s4_q [0:2];
    reg signed [17:0] s4_w [0:2];
    reg        [16:0] s4_u;
    wire [4:0] k = drop(s3_u);
    always @(posedge clk) begin
        s4_valid <= s3_valid;
        s4_boxed <= s3_boxed;
        s4_u <= narrow_u(s3_u, k);
        for (c = 0; c < 3; c = c + 1) begin
            s4_q[c] <= narrow(s3_q[c], k);
            s4_w[c] <= s3_w[18 * c +: 18];
        end
    end

    // 5: the products, E and the margin (U' + 1) 2^9
    reg               s5_valid, s5_boxed;
    reg signed [35:0] s5_p [0:2];
    reg        [20:0] s5_e;
    reg        [26:0] s5_margin;
    always @(posedge clk) begin
        s5_valid <= s4_valid;
        s5_boxed <= s4_boxed;
        for (c = 0; c < 3; c = c + 1) s5_p[c] <= s4_q[c] * s4_w[c];
        s5_e <= {3'd0, mag18(s4_q[0])} + {3'd0, mag18(s4_w[0])}
            + {3'd0, mag18(s4_q[1])} + {3'd0, mag18(s4_w[1])}
            + {3'd0, mag18(s4_q[2])} + {3'd0, mag18(s4_w[2])} + 21'd3;
        s5_margin <= {{1'b0, s4_u} + 18'd1, 9'd0};
    end

    // 6: z + E + margin, below iff it is not positive
    wire signed [38:0] sum = {{3{s5_p[0][35]}}, s5_p[0]} + {{3{s5_p[1][35]}}, s5_p[1]}
        + {{3{s5_p[2][35]}}, s5_p[2]} + {18'd0, s5_e} + {12'd0, s5_margin};
    always @(posedge clk) begin
        out_valid <= s5_valid;
        out_below <= s5_boxed && (sum[38] || sum == 39'sd0);
    end
endmodule
