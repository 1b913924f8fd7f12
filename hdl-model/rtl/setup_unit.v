// The compact datapath's set-up unit for planar patches (hdl-model/src/intersect/mod.rs,
// `setup`): per origin, a corner a clock as patch memory gives them, it forms what a lane needs
// of each patch — whether the origin is off its plane (|h| > PLANE_EPS, h = n · (v_0 − O)), its
// edges' coarse words with their κ (`coarse_edge.v`) — and where culled rays can meet it
// (`cull_reach.v`). Its three parts, and how they are sequenced:
// - a = v − O, a corner a clock; h from one multiplier over the patch's first three clocks
//   (n_x a_x, n_y a_y, n_z a_z), so the side's sign is known 9 clocks after the first corner,
//   as the first edge reaches the edge unit's stage 8;
// - the edge from corner k to k + 1 enters the edge unit with corner k + 1, the closing edge
//   (last to first) on the clock after the last corner, when the next patch's first corner
//   forms no edge: an edge a clock. The side's sign reaches the edge unit 7 clocks after its
//   edge, where its stage 8 negates (LATE_NEGATE);
// - the reach takes a corner with its edge's words and the patch's κ, the largest of its
//   edges': the corners wait DELAY clocks (21: a quad's closing edge is out of the edge unit 17
//   clocks after its last corner, and its κ is registered), so the patch's answer comes
//   LATENCY = DELAY + the reach's 2 · (ITER + 4) + 27 clocks (84 at ITER 14) after its last
//   corner, which the model charges as the set-up pipe's latency (`intersect::setup_latency`).
//
// A patch's corners come on consecutive clocks (the fixed delays count on it); patches may have
// idle clocks between them. Two passes may be in the unit at once (the next origin's pass
// follows the last corner of the previous one, as the model's double-buffered set-up does):
// each corner carries its pass's tag, and the pass's origin-wide shift and frame axes are kept
// in the tag's registers, written by the pass's corners and read up to DELAY clocks after a
// pass's last corner. So a pass may start DELAY clocks after the last corner of the pass two
// before it; the model starts one only once the pass two before it is out (its buffer
// released, after its set-up). Per patch, the side's sign, whether it is off its plane and κ are
// kept by the patch's parity: the next patch of the same parity writes κ 3 clocks after the
// last read, so DELAY may grow by 2 at most.
module setup_unit #(
    parameter integer ITER = 14,
    parameter integer W = 20,
    parameter integer SECTORS = 32
) (
    input  wire               clk,
    input  wire               in_valid,
    input  wire               in_last,
    input  wire               in_pass,   // the pass's tag
    input  wire signed [31:0] in_cx,     // the corner (Q8.24 words)
    input  wire signed [31:0] in_cy,
    input  wire signed [31:0] in_cz,
    input  wire signed [31:0] in_nx,     // the patch's normal (Q2.30), read with its first corner
    input  wire signed [31:0] in_ny,
    input  wire signed [31:0] in_nz,
    input  wire signed [31:0] in_ox,     // the pass's origin (Q8.24), and so its truncation
    input  wire signed [31:0] in_oy,
    input  wire signed [31:0] in_oz,
    input  wire signed [31:0] in_ux,     // the pass's frame axes (Q2.30)
    input  wire signed [31:0] in_uy,
    input  wire signed [31:0] in_uz,
    input  wire signed [31:0] in_vx,
    input  wire signed [31:0] in_vy,
    input  wire signed [31:0] in_vz,
    input  wire signed [31:0] in_wx,
    input  wire signed [31:0] in_wy,
    input  wire signed [31:0] in_wz,
    // an edge's coarse words and κ, in order (the lanes' word memory)
    output wire               out_e_valid,
    output wire        [53:0] out_e_words,
    output wire        [3:0]  out_e_kappa,
    // a patch's answer, in order (the bitmap writes)
    output wire               out_p_valid,
    output wire               out_p_active,
    output wire        [3:0]  out_p_kappa,
    output wire        [1:0]  out_p_kind,
    output wire        [5:0]  out_p_lo,
    output wire        [6:0]  out_p_len,
    output wire        [3:0]  out_p_band_lo,
    output wire        [3:0]  out_p_band_hi
);
    localparam integer DELAY = 21;
    localparam integer REACH = 2 * (ITER + 4) + 27;
    // PLANE_EPS: an origin within 2^34 of h's scale of the plane sets nothing up
    localparam integer EPS_SHIFT = 34;

    // ---- the pass's registers, by tag
    // The origin-wide truncation of the edge normals (`intersect::origin_shift`): 2·b − 60, at
    // least 0, for b the bit length of max |o| + 2^25; with |o| ≤ 2^31 that is 4 once a
    // component's |o| reaches 2^31 − 2^25, else 2 once one reaches 2^30 − 2^25, else 0 (from the
    // components' bits: `far`)
    wire [2:0] shift = far(in_ox, 1'b1) || far(in_oy, 1'b1) || far(in_oz, 1'b1) ? 3'd4
        : far(in_ox, 1'b0) || far(in_oy, 1'b0) || far(in_oz, 1'b0) ? 3'd2 : 3'd0;
    reg [2:0]   pass_shift [0:1];
    reg [287:0] pass_axes [0:1];
    always @(posedge clk) begin
        if (in_valid) begin
            pass_shift[in_pass] <= shift;
            pass_axes[in_pass] <= {in_wz, in_wy, in_wx, in_vz, in_vy, in_vx, in_uz, in_uy, in_ux};
        end
    end

    // ---- 1: a = v − O, the corner's place in its patch
    reg               r_valid, r_last, r_first, r_tag, r_par;
    reg signed [32:0] r_a [0:2];
    reg signed [31:0] r_n [0:2];
    reg               expect_first = 1'b1;
    reg               parity = 1'b0;
    always @(posedge clk) begin
        r_valid <= in_valid;
        r_last <= in_last;
        r_first <= in_valid & expect_first;
        r_tag <= in_pass;
        r_par <= expect_first ? ~parity : parity;
        r_a[0] <= {in_cx[31], in_cx} - {in_ox[31], in_ox};
        r_a[1] <= {in_cy[31], in_cy} - {in_oy[31], in_oy};
        r_a[2] <= {in_cz[31], in_cz} - {in_oz[31], in_oz};
        r_n[0] <= in_nx;
        r_n[1] <= in_ny;
        r_n[2] <= in_nz;
        if (in_valid) begin
            expect_first <= in_last;
            if (expect_first) parity <= ~parity;
        end
    end

    // ---- h: one product a clock over the patch's first three, then summed
    reg signed [32:0] held_a [1:2];
    reg signed [31:0] held_n [1:2];
    reg [2:1]         h_step = 2'd0;  // the product of component 1 (2) is due
    reg               h_par;
    always @(posedge clk) begin
        if (r_valid & r_first) begin
            held_a[1] <= r_a[1];
            held_a[2] <= r_a[2];
            held_n[1] <= r_n[1];
            held_n[2] <= r_n[2];
            h_par <= r_par;
        end
        h_step <= {h_step[1], r_valid & r_first};
    end
    wire signed [32:0] mul_a = h_step[1] ? held_a[1] : h_step[2] ? held_a[2] : r_a[0];
    wire signed [31:0] mul_n = h_step[1] ? held_n[1] : h_step[2] ? held_n[2] : r_n[0];
    // along the multiplier: the operands, four partial products of at most 18 × 18 bits (a DSP
    // tile each), the outer two side by side and the inner two summed, the product; beside it,
    // which is the x product and which the z product (as one product and an adder tree in a
    // clock the multiplier placed at 82 MHz)
    reg signed [32:0] m_a;
    reg signed [31:0] m_n;
    reg signed [30:0] m_hh;
    reg signed [34:0] m_hl, m_lh;
    reg        [33:0] m_ll;
    reg        [64:0] m_outer;
    reg signed [35:0] m_inner;
    reg signed [64:0] m_p;
    reg [3:0]         m_x, m_z, m_par;
    always @(posedge clk) begin
        m_a <= mul_a;
        m_n <= mul_n;
        // a = ah 2^17 + al, n = nh 2^17 + nl (al, nl unsigned 17 bits)
        m_hh <= $signed(m_a[32:17]) * $signed(m_n[31:17]);
        m_hl <= $signed(m_a[32:17]) * $signed({1'b0, m_n[16:0]});
        m_lh <= $signed({1'b0, m_a[16:0]}) * $signed(m_n[31:17]);
        m_ll <= m_a[16:0] * m_n[16:0];
        m_outer <= {m_hh, m_ll};
        m_inner <= {m_hl[34], m_hl} + {m_lh[34], m_lh};
        m_p <= m_outer + {{12{m_inner[35]}}, m_inner, 17'd0};
        m_x <= {m_x[2:0], r_valid & r_first};
        m_z <= {m_z[2:0], h_step[2]};
        m_par <= {m_par[2:0], h_par};
    end
    // the sum, restarted by each patch's x product (the three come in a row)
    reg signed [66:0] h_acc;
    reg               h_done = 1'b0;
    reg               h_done_par;
    always @(posedge clk) begin
        h_acc <= (m_x[3] ? 67'sd0 : h_acc) + {{2{m_p[64]}}, m_p};
        h_done <= m_z[3];
        h_done_par <= m_par[3];
    end
    // off the plane: |h| > PLANE_EPS = 2^EPS_SHIFT, from h's bits rather than as two compares
    // (two carry chains of 67 bits placed at 101 MHz): a negative h is at least −2^S when its
    // bits from S up are all ones; a positive h above 2^S has a one above bit S, or bit S and
    // one below it
    wire off_plane = h_acc[66] ? !(&h_acc[65:EPS_SHIFT])
        : (|h_acc[65:EPS_SHIFT+1]) || (h_acc[EPS_SHIFT] && (|h_acc[EPS_SHIFT-1:0]));
    reg side [0:1];
    reg active [0:1];
    always @(posedge clk) begin
        if (h_done) begin
            side[h_done_par] <= h_acc[66];
            active[h_done_par] <= off_plane;
        end
    end

    // ---- the edges: k to k + 1 with corner k + 1, the closing one on the clock after the last
    reg signed [32:0] prev_a [0:2];
    reg signed [32:0] first_a [0:2];
    reg               closing = 1'b0;
    reg               prev_tag, prev_par;
    always @(posedge clk) begin
        if (r_valid) begin
            prev_a[0] <= r_a[0];
            prev_a[1] <= r_a[1];
            prev_a[2] <= r_a[2];
            prev_tag <= r_tag;
            prev_par <= r_par;
        end
        if (r_valid & r_first) begin
            first_a[0] <= r_a[0];
            first_a[1] <= r_a[1];
            first_a[2] <= r_a[2];
        end
        closing <= r_valid & r_last;
    end
    wire        inner = r_valid & ~r_first;
    wire        e_in = inner | closing;
    wire [98:0] e_u = {prev_a[2], prev_a[1], prev_a[0]};
    wire [98:0] e_v = closing ? {first_a[2], first_a[1], first_a[0]} : {r_a[2], r_a[1], r_a[0]};
    wire        e_tag = closing ? prev_tag : r_tag;
    wire        e_par = closing ? prev_par : r_par;
    // the patch's first edge is the one formed with its second corner
    reg second = 1'b0;
    always @(posedge clk) if (r_valid) second <= r_first;
    // beside the edge unit: the edge's patch parity (its sign read at stage 8, 7 clocks on),
    // and whether it is its patch's first or last (for κ, 15 clocks on)
    reg [6:0]  neg_par;
    reg [14:0] e_first, e_last, e_parity;
    always @(posedge clk) begin
        neg_par <= {neg_par[5:0], e_par};
        e_first <= {e_first[13:0], inner & second};
        e_last <= {e_last[13:0], closing};
        e_parity <= {e_parity[13:0], e_par};
    end
    wire [53:0] u18;
    coarse_edge #(.LATE_NEGATE(1)) edges (
        .clk(clk), .in_valid(e_in), .in_u(e_u), .in_v(e_v), .in_shift(pass_shift[e_tag]),
        .in_negate(side[neg_par[6]]), .out_valid(out_e_valid), .out_words(out_e_words),
        .out_kappa(out_e_kappa), .out_u18(u18));

    // the patch's κ: the largest of its edges', kept by parity once its last edge is out
    reg [3:0] k_run;
    reg [3:0] kappa [0:1];
    wire [3:0] k_now = e_first[14] ? out_e_kappa
                     : (out_e_kappa > k_run ? out_e_kappa : k_run);
    always @(posedge clk) begin
        if (out_e_valid) begin
            k_run <= k_now;
            if (e_last[14]) kappa[e_parity[14]] <= k_now;
        end
    end
    // each edge's words wait for the corner they go with (DELAY − 17 clocks)
    reg [53:0] e_wait [0:DELAY-18];
    integer j;
    always @(posedge clk) begin
        e_wait[0] <= out_e_words;
        for (j = 1; j <= DELAY - 18; j = j + 1) e_wait[j] <= e_wait[j-1];
    end

    // ---- the corners wait DELAY − 1 clocks for their edges' words and the patch's κ; at the
    // 8th the patch's sign and plane test are in, and its active bit is taken. The corner itself
    // waits as the edge unit scaled it to 18 bits (ã, 5 clocks after its edge, which enters 2
    // after the corner): the reach does not scale it again (SCALED)
    reg [DELAY-2:0] d_valid, d_last, d_tag, d_par, d_active;
    always @(posedge clk) begin
        d_valid <= {d_valid[DELAY-3:0], r_valid};
        d_last <= {d_last[DELAY-3:0], r_last};
        d_tag <= {d_tag[DELAY-3:0], r_tag};
        d_par <= {d_par[DELAY-3:0], r_par};
        d_active <= {d_active[DELAY-3:0], 1'b0};
        d_active[8] <= active[d_par[7]];
    end
    wire [53:0] c_u;
    delay_line #(.W(54), .N(DELAY - 7)) u_wait (.clk(clk), .in(u18), .out(c_u));
    wire        c_valid = d_valid[DELAY-2];
    wire        c_last = d_last[DELAY-2];
    wire [98:0] c_a = {{15{c_u[53]}}, c_u[53:36], {15{c_u[35]}}, c_u[35:18], {15{c_u[17]}},
                       c_u[17:0]};
    wire [53:0] c_e = e_wait[DELAY-18];
    wire [3:0]  c_kappa = kappa[d_par[DELAY-2]];
    wire [287:0] c_axes = pass_axes[d_tag[DELAY-2]];
    cull_reach #(.ITER(ITER), .W(W), .SECTORS(SECTORS), .SCALED(1)) reach (
        .clk(clk), .in_valid(c_valid), .in_last(c_last),
        .in_ax(c_a[32:0]), .in_ay(c_a[65:33]), .in_az(c_a[98:66]),
        .in_ex(c_e[17:0]), .in_ey(c_e[35:18]), .in_ez(c_e[53:36]), .in_kappa(c_kappa),
        .in_ux(c_axes[31:0]), .in_uy(c_axes[63:32]), .in_uz(c_axes[95:64]),
        .in_vx(c_axes[127:96]), .in_vy(c_axes[159:128]), .in_vz(c_axes[191:160]),
        .in_wx(c_axes[223:192]), .in_wy(c_axes[255:224]), .in_wz(c_axes[287:256]),
        .out_valid(out_p_valid), .out_kind(out_p_kind), .out_lo(out_p_lo), .out_len(out_p_len),
        .out_band_lo(out_p_band_lo), .out_band_hi(out_p_band_hi));
    // the patch's active bit and κ beside the reach
    delay_line #(.W(5), .N(REACH)) beside (
        .clk(clk), .in({d_active[DELAY-2], c_kappa}), .out({out_p_active, out_p_kappa}));
    // |x| ≥ 2^31 − 2^25 (`top`) or ≥ 2^30 − 2^25, from x's bits: a positive x needs bits 30:25
    // all ones (or bit 30, or bits 29:25 all ones); a negative x at most −2^31 + 2^25 (−2^30 +
    // 2^25) has bits 30:25 clear (bit 30 or bits 29:25 clear), or is that bound itself
    function far(input signed [31:0] x, input top);
        if (!x[31])
            far = top ? &x[30:25] : x[30] || &x[29:25];
        else if (top)
            far = x[30:25] == 6'd0 || x[30:25] == 6'd1 && x[24:0] == 25'd0;
        else
            far = !x[30] || x[29:25] == 5'd0 || x[29:25] == 5'd1 && x[24:0] == 25'd0;
    endfunction
endmodule
