// One level of the (u,v) bisection (hdl-model/src/intersect/uv.rs, `UvStage`), combinational:
// the cell's four projected corners are halved in u by the segment between its edge midpoints
// and in v likewise, the sides of the point against the two segments pick the sub-cell, and
// one index bit of u and of v is shifted in. Corners are QW bits, the point PW bits (the
// model's i64 registers hold no more than that: vertices are 32-bit words, the point is
// O + t d); each 2D cross product takes the segment's direction in 18 bits scaled by a power of
// two of its own (SEG bits) by the point's offset (PW + 1), and their difference is exact in
// SEG + PW + 2 bits.
module uv_level #(
    parameter integer QW = 34,
    parameter integer PW = 36,
    parameter integer DEPTH = 16
) (
    input  wire [4*2*QW-1:0] in_q,    // corner k, axis a at bits QW (2k + a)
    input  wire [2*PW-1:0]   in_p,
    /* verilator lint_off UNUSEDSIGNAL */ // the top index bits are shifted out
    input  wire [DEPTH-1:0]  in_iu,
    input  wire [DEPTH-1:0]  in_iv,
    /* verilator lint_on UNUSEDSIGNAL */
    output wire [4*2*QW-1:0] out_q,
    output wire [DEPTH-1:0]  out_iu,
    output wire [DEPTH-1:0]  out_iv
);
    function signed [QW-1:0] qc(input integer k, input integer a);
        qc = in_q[QW * (2 * k + a) +: QW];
    endfunction
    function signed [QW-1:0] mid(input signed [QW-1:0] x, input signed [QW-1:0] y);
        /* verilator lint_off UNUSEDSIGNAL */ // the halved sum drops its low bit
        reg signed [QW:0] s;
        /* verilator lint_on UNUSEDSIGNAL */
        begin
            s = {x[QW-1], x} + {y[QW-1], y};
            mid = s[QW:1];
        end
    endfunction
    // the segment's direction in SEG signed bits, as the model's `coarse::top_words` scales
    // it: both components shifted right (floored) by how far the bit length of |e_x| OR |e_y|
    // reaches beyond SEG - 1, so each product of the side test is SEG x (PW + 1) bits
    localparam integer SEG = 18;
    function [PW:0] mag(input signed [PW:0] x);
        mag = x[PW] ? -x : x;
    endfunction
    function [5:0] shift_of(input [PW:0] m);
        integer k;
        /* verilator lint_off UNUSEDSIGNAL */ // a shift is under 2^6
        reg [31:0] s;
        /* verilator lint_on UNUSEDSIGNAL */
        begin
            s = 32'd0;
            for (k = SEG - 1; k <= PW; k = k + 1)
                if (m[k]) s = k - (SEG - 2);
            shift_of = s[5:0];
        end
    endfunction
    function signed [SEG-1:0] scaled(input signed [PW:0] e, input [5:0] sh);
        /* verilator lint_off UNUSEDSIGNAL */ // the shifted word's sign copies above SEG
        reg signed [PW:0] x;
        /* verilator lint_on UNUSEDSIGNAL */
        begin
            x = e >>> sh;
            scaled = x[SEG-1:0];
        end
    endfunction
    // ẽ x (p - a), the side of p relative to a -> b
    function signed [2*PW+2:0] side(input signed [QW-1:0] ax, input signed [QW-1:0] ay,
                                  input signed [QW-1:0] bx, input signed [QW-1:0] by);
        reg signed [PW:0] px, py, bax, bay;
        reg        [5:0]  sh;
        reg signed [SEG-1:0] ex, ey;
        begin
            bax = $signed({{(PW + 1 - QW){bx[QW-1]}}, bx}) - $signed({{(PW + 1 - QW){ax[QW-1]}}, ax});
            bay = $signed({{(PW + 1 - QW){by[QW-1]}}, by}) - $signed({{(PW + 1 - QW){ay[QW-1]}}, ay});
            px = $signed({in_p[PW-1], in_p[PW-1:0]}) - $signed({{(PW + 1 - QW){ax[QW-1]}}, ax});
            py = $signed({in_p[2*PW-1], in_p[2*PW-1:PW]}) - $signed({{(PW + 1 - QW){ay[QW-1]}}, ay});
            sh = shift_of(mag(bax) | mag(bay));
            ex = scaled(bax, sh);
            ey = scaled(bay, sh);
            side = ex * py - ey * px;
        end
    endfunction

    // the 3 x 3 grid: corners, edge midpoints, centre (per axis)
    wire signed [QW-1:0] bottom [0:1], top [0:1], left [0:1], right [0:1], centre [0:1];
    genvar a;
    generate
        for (a = 0; a < 2; a = a + 1) begin : axis
            assign bottom[a] = mid(qc(0, a), qc(1, a));
            assign top[a] = mid(qc(3, a), qc(2, a));
            assign left[a] = mid(qc(0, a), qc(3, a));
            assign right[a] = mid(qc(1, a), qc(2, a));
            assign centre[a] = mid(bottom[a], top[a]);
        end
    endgenerate
    wire signed [2*PW+2:0] su = side(bottom[0], bottom[1], top[0], top[1]);
    wire signed [2*PW+2:0] sv = side(left[0], left[1], right[0], right[1]);
    wire upper_u = su < 0;
    wire upper_v = sv > 0;

    // each corner of the sub-cell is one of four grid points, picked by (upper_v, upper_u)
    function [2*QW-1:0] pick(input [2*QW-1:0] p00, input [2*QW-1:0] p01,
                             input [2*QW-1:0] p10, input [2*QW-1:0] p11);
        pick = upper_v ? (upper_u ? p11 : p10) : (upper_u ? p01 : p00);
    endfunction
    wire [2*QW-1:0] g_q0 = in_q[0 +: 2*QW], g_q1 = in_q[2*QW +: 2*QW];
    wire [2*QW-1:0] g_q2 = in_q[4*QW +: 2*QW], g_q3 = in_q[6*QW +: 2*QW];
    wire [2*QW-1:0] g_b = {bottom[1], bottom[0]}, g_t = {top[1], top[0]};
    wire [2*QW-1:0] g_l = {left[1], left[0]}, g_r = {right[1], right[0]};
    wire [2*QW-1:0] g_c = {centre[1], centre[0]};
    // uv.rs: pick([a, b, c, d]) = v ? (u ? d : c) : (u ? b : a)
    assign out_q[0 +: 2*QW] = pick(g_q0, g_b, g_l, g_c);
    assign out_q[2*QW +: 2*QW] = pick(g_b, g_q1, g_c, g_r);
    assign out_q[4*QW +: 2*QW] = pick(g_c, g_r, g_t, g_q2);
    assign out_q[6*QW +: 2*QW] = pick(g_l, g_c, g_q3, g_t);
    assign out_iu = {in_iu[DEPTH-2:0], upper_u};
    assign out_iv = {in_iv[DEPTH-2:0], upper_v};
endmodule
