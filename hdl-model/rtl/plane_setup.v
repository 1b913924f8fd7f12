// The per-origin set-up of one planar patch (hdl-model/src/intersect/mod.rs, `setup`), as two
// pipeline stages behind the patch memory's read: stage 1 forms a_k = v_k - O, the plane
// distance h = n . a_0 and the edge normals' cross products a_k x a_(k+1); stage 2 (combinational
// into the local memory's write) applies the origin-wide truncation and the plane test. Edge
// normals keep the model's 64-bit wrap, so every bit of d . e_k matches.
module plane_setup (
    input  wire         clk,
    input  wire         in_valid,
    /* verilator lint_off UNUSEDSIGNAL */ // the header's bits above the kind
    input  wire [511:0] in_words,   // the slot's 16 words, word 0 in bits 31:0
    /* verilator lint_on UNUSEDSIGNAL */
    input  wire [2:0]   in_shift,   // origin-wide truncation: 0, 2 or 4
    input  wire [95:0]  origin,     // O, Q8.24, x in bits 31:0
    // stage 2's result, valid the clock after in_valid
    output wire         out_valid,
    output wire         out_active,
    output wire         out_quad,
    output wire [767:0] out_e,      // e_k[c] (64 bits each) at bits 64 (3k + c)
    output wire [95:0]  out_n,
    output wire [67:0]  out_h
);
    function signed [32:0] sub(input [31:0] a, input [31:0] b);
        sub = $signed({a[31], a}) - $signed({b[31], b});
    endfunction

    wire [3:0] kind = in_words[3:0];
    wire signed [32:0] a [0:3][0:2];
    genvar k, c;
    generate
        for (k = 0; k < 4; k = k + 1) begin : corner
            for (c = 0; c < 3; c = c + 1) begin : comp
                assign a[k][c] = sub(in_words[32 * (1 + 3 * k + c) +: 32], origin[32 * c +: 32]);
            end
        end
    endgenerate
    wire signed [31:0] n0 = in_words[32 * 13 +: 32];
    wire signed [31:0] n1 = in_words[32 * 14 +: 32];
    wire signed [31:0] n2 = in_words[32 * 15 +: 32];
    wire signed [67:0] h = n0 * a[0][0] + n1 * a[0][1] + n2 * a[0][2];
    wire quad = kind == 4'd2;

    // stage 1 registers
    reg         s_valid, s_planar, s_quad;
    reg [2:0]   s_shift;
    reg signed [67:0] s_h;
    reg signed [67:0] s_cross [0:3][0:2];
    reg [95:0]  s_n;
    integer i;
    always @(posedge clk) begin
        s_valid <= in_valid;
        s_planar <= kind == 4'd1 || kind == 4'd2;
        s_quad <= quad;
        s_shift <= in_shift;
        s_h <= h;
        s_n <= in_words[32 * 13 +: 96];
        for (i = 0; i < 4; i = i + 1) begin
            // a triangle's edges close at v2 (its v3 is a copy of v2 and is not used)
            s_cross[i][0] <= a[i][1] * a[next(i, quad)][2] - a[i][2] * a[next(i, quad)][1];
            s_cross[i][1] <= a[i][2] * a[next(i, quad)][0] - a[i][0] * a[next(i, quad)][2];
            s_cross[i][2] <= a[i][0] * a[next(i, quad)][1] - a[i][1] * a[next(i, quad)][0];
        end
    end

    function integer next(input integer j, input q);
        next = q ? (j + 1) % 4 : (j + 1) % 3;
    endfunction

    // stage 2: the side the origin is on, the truncation towards zero, the 64-bit wrap
    wire neg_h = s_h[67];
    wire signed [67:0] abs_h = neg_h ? -s_h : s_h;
    assign out_valid = s_valid;
    assign out_active = s_planar && abs_h > 68'sd17179869184;  // |h| > PLANE_EPS = 2^34
    assign out_quad = s_quad;
    assign out_n = s_n;
    assign out_h = s_h;
    generate
        for (k = 0; k < 4; k = k + 1) begin : edge_n
            for (c = 0; c < 3; c = c + 1) begin : comp
                wire signed [67:0] v = neg_h ? -s_cross[k][c] : s_cross[k][c];
                wire signed [67:0] mag = v[67] ? -v : v;
                wire signed [67:0] q = mag >>> s_shift;
                /* verilator lint_off UNUSEDSIGNAL */ // the 64-bit wrap drops the top
                wire signed [67:0] t = v[67] ? -q : q;
                /* verilator lint_on UNUSEDSIGNAL */
                assign out_e[64 * (3 * k + c) +: 64] = t[63:0];
            end
        end
    endgenerate
endmodule
