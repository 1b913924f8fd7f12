// A compact lane's coarse edge test of one (ray, patch) pair (hdl-model/src/intersect/coarse.rs,
// `coarse_inside`): per edge A = d' . e' (three 18 x 18 products) against the bound
// B = 2^kappa * sum(|d'_c| + 1) + sum |e'_c|; an edge is certainly positive if A >= B, certainly
// negative if A <= -B. The pair is decided outside if an edge is certainly negative, inside if
// every edge is certainly positive, and otherwise handed to the shared exact unit with its
// undecided edges. kappa = 15 bounds nothing: every edge is undecided. A pair a clock, five
// stages: the products and magnitudes, A and the sums, B, A - B and A + B, the signs and the
// verdict. (In a lane the ray's
// sum(|d'_c| + 1) is formed once a ray; here once a pair. The model charges a lane a clock a
// candidate and does not yet count these stages' latency: the lane is not built.)
module coarse_test (
    input  wire         clk,
    input  wire         in_valid,
    input  wire [53:0]  in_d,        // d'_c (18-bit signed) at bits 18c
    input  wire [215:0] in_words,    // e'_{k,c} at bits 18 (3k + c)
    input  wire [3:0]   in_kappa,
    input  wire         in_quad,     // four edges (else three)
    output reg          out_valid,
    output reg          out_decided,
    output reg          out_inside,
    output reg  [2:0]   out_undecided // edges left to the exact unit
);
    function [19:0] mag(input signed [17:0] x);
        mag = {2'b0, x[17] ? -x : x};
    endfunction
    wire signed [17:0] d0 = in_d[0 +: 18];
    wire signed [17:0] d1 = in_d[18 +: 18];
    wire signed [17:0] d2 = in_d[36 +: 18];

    // 1: the twelve products, and the words' magnitudes
    reg               s1_valid, s1_quad;
    reg [3:0]         s1_kappa;
    reg [19:0]        s1_md [0:2];
    reg signed [35:0] s1_p [0:3][0:2];
    reg [19:0]        s1_me [0:3][0:2];
    integer k, c;
    always @(posedge clk) begin
        s1_valid <= in_valid;
        s1_quad <= in_quad;
        s1_kappa <= in_kappa;
        s1_md[0] <= mag(d0);
        s1_md[1] <= mag(d1);
        s1_md[2] <= mag(d2);
        for (k = 0; k < 4; k = k + 1) begin
            s1_p[k][0] <= d0 * $signed(in_words[54 * k +: 18]);
            s1_p[k][1] <= d1 * $signed(in_words[54 * k + 18 +: 18]);
            s1_p[k][2] <= d2 * $signed(in_words[54 * k + 36 +: 18]);
            for (c = 0; c < 3; c = c + 1) s1_me[k][c] <= mag(in_words[54 * k + 18 * c +: 18]);
        end
    end

    // 2: A, sum(|d'_c| + 1) and each edge's sum |e'_c|
    reg               s2_valid, s2_quad;
    reg [3:0]         s2_kappa;
    reg [19:0]        s2_dsum;
    reg signed [37:0] s2_a [0:3];
    reg [19:0]        s2_esum [0:3];
    always @(posedge clk) begin
        s2_valid <= s1_valid;
        s2_quad <= s1_quad;
        s2_kappa <= s1_kappa;
        s2_dsum <= s1_md[0] + s1_md[1] + s1_md[2] + 20'd3;
        for (k = 0; k < 4; k = k + 1) begin
            s2_a[k] <= {{2{s1_p[k][0][35]}}, s1_p[k][0]} + {{2{s1_p[k][1][35]}}, s1_p[k][1]} +
                       {{2{s1_p[k][2][35]}}, s1_p[k][2]};
            s2_esum[k] <= s1_me[k][0] + s1_me[k][1] + s1_me[k][2];
        end
    end

    // 3: B
    reg               s3_valid, s3_quad, s3_decline;
    reg signed [37:0] s3_a [0:3];
    reg signed [37:0] s3_b [0:3];
    always @(posedge clk) begin
        s3_valid <= s2_valid;
        s3_quad <= s2_quad;
        s3_decline <= s2_kappa == 4'd15;
        for (k = 0; k < 4; k = k + 1) begin
            s3_a[k] <= s2_a[k];
            s3_b[k] <= ({18'b0, s2_dsum} << s2_kappa) + {18'b0, s2_esum[k]};
        end
    end

    // 4: A - B and A + B (side by side, where A <= -B after a negation was two carry chains)
    reg               s4_valid, s4_quad, s4_decline;
    reg signed [37:0] s4_lo [0:3];
    reg signed [37:0] s4_hi [0:3];
    always @(posedge clk) begin
        s4_valid <= s3_valid;
        s4_quad <= s3_quad;
        s4_decline <= s3_decline;
        for (k = 0; k < 4; k = k + 1) begin
            s4_lo[k] <= s3_a[k] - s3_b[k];
            s4_hi[k] <= s3_a[k] + s3_b[k];
        end
    end

    // 5: each edge certainly positive (A - B >= 0) or negative (A + B <= 0), and the verdict
    wire [3:0] pos, neg, used;
    genvar e;
    generate
        for (e = 0; e < 4; e = e + 1) begin : edge_test
            assign pos[e] = !s4_decline && !s4_lo[e][37];
            assign neg[e] = !s4_decline && (s4_hi[e][37] || s4_hi[e] == 38'sd0);
            assign used[e] = e < 3 || s4_quad;
        end
    endgenerate
    wire [3:0] open_edges = used & ~pos & ~neg;
    wire outside = |(used & neg);
    always @(posedge clk) begin
        out_valid <= s4_valid;
        out_decided <= outside || open_edges == 4'd0;
        out_inside <= !outside && open_edges == 4'd0;
        out_undecided <= outside ? 3'd0 : {2'b0, open_edges[0]} + {2'b0, open_edges[1]} +
                         {2'b0, open_edges[2]} + {2'b0, open_edges[3]};
    end
endmodule
