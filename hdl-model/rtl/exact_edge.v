// The compact datapath's shared exact edge unit (hdl-model/src/intersect/exact.rs): a pair the
// lanes' coarse test left undecided has each undecided edge tested exactly, d . e_k >= 0, the
// edge normal e_k = a_k x a_(k+1) formed again from the patch's corners as the set-up pass
// forms it (negated when the origin is behind the patch, truncated towards zero by the
// origin-wide shift, kept to 64 bits), on one multiplier of 34 x 64 bits. (Two until session
// 43: eight DSP tiles more for a unit that sees 0.002 to 0.022 undecided edges a ray, while
// the set-up units' products were LUT arrays for want of tiles.)
//
// Clocks, on a grid of nine-clock windows (phase, from 0 after reset):
// - an idle unit (no edge in a window, none to start, none offered) holds phase 1, so a pair
//   offered to it is taken at once and its clocks do not depend on the clocks since reset;
// - a pair is taken on phase 1 when the last pair has no edge left to start; the corners of
//   its next edge are read on phases 2 and 3 (c_addr, a synchronous read: c_data holds the
//   word a clock later), each less the origin on phases 3 and 4; the edge enters its window on
//   phase 8;
// - an edge's window: its cross product's six products on phases 0 to 5, each component's
//   pair on consecutive clocks (the first product held until the second is out), the dot
//   product's three on phases 6 to 8 of the next window (each component of the normal two
//   clocks after its pair: the difference with the side, the truncation's bias; its shift as
//   it is taken);
// - the multiplier takes five clocks (exact_mul.v), and the dot product is summed as its
//   products come out, the last with its sign: the pair's verdict is out on the 23rd clock
//   after its last window began (out_valid for one clock, with the tag it came with).
module exact_edge #(
    parameter integer SLOT_BITS = 10,
    parameter integer TW = 10          // the tag's bits
) (
    input  wire                 clk,
    input  wire                 rst,
    input  wire                 in_valid,
    output wire                 in_ready,
    input  wire [SLOT_BITS-1:0] in_slot,
    input  wire                 in_quad,
    input  wire [3:0]           in_mask,   // the undecided edges, bit k: corner k to the next
    input  wire                 in_negate, // the origin is behind the patch
    input  wire [2:0]           in_shift,  // the origin-wide truncation, 0 to 4
    input  wire [95:0]          in_origin, // Q8.24, x in bits 31:0
    input  wire [95:0]          in_d,      // Q2.30
    input  wire [TW-1:0]        in_tag,
    // corner memory: the corner at {slot, k}, a clock after the address
    output reg  [SLOT_BITS+1:0] c_addr,
    input  wire [95:0]          c_data,
    output reg                  out_valid,
    output reg                  out_inside,
    output reg  [TW-1:0]        out_tag
);
    localparam [3:0] LAST = 4'd8;   // a window's last phase
    reg [3:0] phase;
    wire      idle;
    always @(posedge clk) phase <= rst || phase == LAST ? 4'd0 : idle ? 4'd1 : phase + 4'd1;

    // ---- the pair whose edges are being started, and the next edge's reads ----
    reg [SLOT_BITS-1:0] p_slot;
    reg                 p_quad, p_negate;
    reg [2:0]           p_shift;
    reg [95:0]          p_origin, p_d;
    reg [TW-1:0]        p_tag;
    reg [3:0]           rem;        // its edges not started yet
    reg                 x_valid, y_valid;   // an edge in a window, an edge's dot product
    assign in_ready = phase == 4'd1 && rem == 4'd0;
    assign idle = in_ready && !in_valid && !x_valid && !y_valid;
    wire take = in_valid && in_ready;
    wire [3:0] pick = take ? in_mask : rem;
    wire [1:0] k = pick[0] ? 2'd0 : pick[1] ? 2'd1 : pick[2] ? 2'd2 : 2'd3;
    wire [3:0] left = pick & ~(4'd1 << k);
    reg        st_valid, st_first, st_last;
    reg [1:0]  st_k;
    // the corner after k: a triangle's edges close at corner 2
    wire [1:0] st_next = st_k == 2'd2 && !p_quad ? 2'd0 : st_k + 2'd1;
    always @(posedge clk) begin
        if (rst) begin
            rem <= 4'd0;
            st_valid <= 1'b0;
        end else if (phase == 4'd1) begin
            st_valid <= take || rem != 4'd0;
            st_first <= take;
            st_last <= left == 4'd0;
            st_k <= k;
            rem <= take || rem != 4'd0 ? left : 4'd0;
            c_addr <= {take ? in_slot : p_slot, k};
        end else if (phase == 4'd2) begin
            c_addr <= {p_slot, st_next};
        end
        if (take) begin
            p_slot <= in_slot;
            p_quad <= in_quad;
            p_negate <= in_negate;
            p_shift <= in_shift;
            p_origin <= in_origin;
            p_d <= in_d;
            p_tag <= in_tag;
        end
    end

    // a corner less the origin, 33 bits a component
    function [98:0] less_origin(input [95:0] v, input [95:0] o);
        integer c;
        begin
            for (c = 0; c < 3; c = c + 1)
                less_origin[33 * c +: 33] = {v[32 * c + 31], v[32 * c +: 32]}
                                          - {o[32 * c + 31], o[32 * c +: 32]};
        end
    endfunction
    reg [98:0] s_au, s_av;
    // the edge in its window (x) and the edge whose dot product is formed in it (y)
    reg              x_first, x_last, x_negate, y_first, y_last;
    reg [2:0]        x_shift, y_shift;
    reg [98:0]       x_au, x_av;
    reg [95:0]       x_d, y_d;
    reg [TW-1:0]     x_tag, y_tag;
    always @(posedge clk) begin
        if (phase == 4'd3) s_au <= less_origin(c_data, p_origin);
        if (phase == 4'd4) s_av <= less_origin(c_data, p_origin);
        if (rst) begin
            x_valid <= 1'b0;
            y_valid <= 1'b0;
        end else if (phase == LAST) begin
            x_valid <= st_valid;
            y_valid <= x_valid;
        end
        if (phase == LAST) begin
            x_first <= st_first;
            x_last <= st_last;
            x_negate <= p_negate;
            x_shift <= p_shift;
            x_au <= s_au;
            x_av <= s_av;
            x_d <= p_d;
            x_tag <= p_tag;
            y_first <= x_first;
            y_shift <= x_shift;
            y_last <= x_last;
            y_d <= x_d;
            y_tag <= x_tag;
        end
    end

    // ---- the multiplier's operands by phase: cross products, then the last edge's dots ----
    function signed [33:0] a34(input [98:0] a, input integer c);
        a34 = {a[33 * c + 32], a[33 * c +: 33]};
    endfunction
    function signed [63:0] a64(input [98:0] a, input integer c);
        a64 = {{31{a[33 * c + 32]}}, a[33 * c +: 33]};
    endfunction
    function signed [33:0] d34(input [95:0] d, input integer c);
        d34 = {{2{d[32 * c + 31]}}, d[32 * c +: 32]};
    endfunction
    // the edge normal's components before the truncation's shift, and after it (64 bits)
    reg signed [67:0] e_sum [0:2];
    /* verilator lint_off UNUSEDSIGNAL */ // the 64-bit wrap drops the top
    wire signed [67:0] e_shifted [0:2];
    /* verilator lint_on UNUSEDSIGNAL */
    wire signed [63:0] e [0:2];
    genvar g;
    generate
        for (g = 0; g < 3; g = g + 1) begin : normal
            assign e_shifted[g] = e_sum[g] >>> y_shift;
            assign e[g] = e_shifted[g][63:0];
        end
    endgenerate
    // what a product is: a cross product's first (A) or second (B, then A − B), the dot's
    // first, middle or last
    localparam [2:0] NONE = 3'd0, CROSS_A = 3'd1, CROSS_B = 3'd2, DOT_FIRST = 3'd3,
                     DOT_MID = 3'd4, DOT_LAST = 3'd5;
    reg signed [33:0] m_x;
    reg signed [63:0] m_y;
    reg        [2:0]  kind;
    reg        [1:0]  comp;
    // component c of a_u x a_v is a_u[c+1] a_v[c+2] − a_u[c+2] a_v[c+1] (indices mod 3): A
    // on the even phase, B on the odd
    always @(*) begin
        kind = NONE;
        comp = 2'd0;
        m_x = d34(y_d, 0);
        m_y = e[0];
        case (phase)
            4'd0, 4'd1, 4'd2, 4'd3, 4'd4, 4'd5: kind = x_valid ? (phase[0] ? CROSS_B : CROSS_A)
                                                               : NONE;
            4'd6: kind = y_valid ? DOT_FIRST : NONE;
            4'd7: kind = y_valid ? DOT_MID : NONE;
            default: kind = y_valid ? DOT_LAST : NONE;
        endcase
        case (phase)
            4'd0: begin m_x = a34(x_au, 1); m_y = a64(x_av, 2); end
            4'd1: begin m_x = a34(x_au, 2); m_y = a64(x_av, 1); end
            4'd2: begin m_x = a34(x_au, 2); m_y = a64(x_av, 0); comp = 2'd1; end
            4'd3: begin m_x = a34(x_au, 0); m_y = a64(x_av, 2); comp = 2'd1; end
            4'd4: begin m_x = a34(x_au, 0); m_y = a64(x_av, 1); comp = 2'd2; end
            4'd5: begin m_x = a34(x_au, 1); m_y = a64(x_av, 0); comp = 2'd2; end
            4'd7: begin m_x = d34(y_d, 1); m_y = e[1]; end
            4'd8: begin m_x = d34(y_d, 2); m_y = e[2]; end
            default: ;
        endcase
    end
    // the product's description travels with it: kind, component, side, shift, and the
    // dot's edge (first and last of its pair, tag)
    localparam integer QW = 3 + 2 + 1 + 3 + 1 + 1 + TW;
    wire [QW-1:0] q_in = {kind, comp, x_negate, x_shift, y_first, y_last, y_tag};
    wire [97:0] pm;
    wire [QW-1:0] q;
    exact_mul #(.QW(QW)) mul (.clk(clk), .x(m_x), .y(m_y), .q_in(q_in), .p(pm), .q(q));
    wire [2:0]    q_kind = q[QW-1 -: 3];
    wire [1:0]    q_comp = q[QW-4 -: 2];
    wire          q_negate = q[QW-6];
    wire [2:0]    q_shift = q[QW-7 -: 3];
    wire          q_first = q[TW+1];
    wire          q_last = q[TW];
    wire [TW-1:0] q_tag = q[TW-1:0];

    // ---- the edge normal: the difference with the side, then the truncation towards zero ----
    reg signed [67:0] held;     // a component's first product, until its second is out
    reg               c_valid;
    reg        [1:0]  c_comp;
    reg        [3:0]  c_ones;   // 2^k − 1, the bias a negative x needs (k ≤ 4)
    reg signed [67:0] c_cross;
    always @(posedge clk) begin
        if (q_kind == CROSS_A) held <= $signed(pm[67:0]);
        c_valid <= !rst && q_kind == CROSS_B;
        c_comp <= q_comp;
        c_ones <= ~(4'hF << q_shift);
        c_cross <= q_negate ? $signed(pm[67:0]) - held : held - $signed(pm[67:0]);
    end
    // x / 2^k towards zero: (x + 2^k − 1) >> k for a negative x, the sum kept and shifted as the
    // dot product takes it (the bias a register beside x, not a chain after it: 2^k − 1 formed
    // after the difference placed at 76 MHz; the shift after the sum, at 97 MHz)
    wire signed [67:0] c_bias = {64'd0, c_cross[67] ? c_ones : 4'd0};
    always @(posedge clk) if (c_valid) e_sum[c_comp] <= c_cross + c_bias;

    // ---- the dot product's sum as its products come out, its sign, the pair's verdict ----
    reg               acc;
    reg signed [97:0] s;
    /* verilator lint_off UNUSEDSIGNAL */ // its sign alone
    wire signed [97:0] total = s + $signed(pm);
    /* verilator lint_on UNUSEDSIGNAL */
    wire edge_in = !total[97];
    wire pair_in = (q_first || acc) && edge_in;
    always @(posedge clk) begin
        if (q_kind == DOT_FIRST) s <= $signed(pm);
        else if (q_kind == DOT_MID) s <= total;
        out_valid <= !rst && q_kind == DOT_LAST && q_last;
        out_inside <= pair_in;
        out_tag <= q_tag;
        if (q_kind == DOT_LAST) acc <= pair_in;
    end
endmodule
