// The planar intersection unit with (u,v) (paper §6.1, fig. 7), the RTL of
// hdl-model/src/intersect/mod.rs for a build of one lane without culling (Params { lanes: 1,
// sectors: 0 }) and planar slots only: nearest hit over patch memory, in the model's clocks.
//
//   ray -> descriptor FIFO -> sequencer: set-up pass (per origin) | scan (one candidate a clock)
//          scan -> local memory -> edge stage -> divider (32) -> running minimum
//          -> (u,v): hit point, projection, DEPTH bisection levels -> in-order retirement
//
// Clocks, as the model counts them (a ray entering on clock `now`):
// - a new origin starts a set-up pass on max(now, lane free): one slot a clock for `count`
//   clocks, two more for its pipe (plane_setup.v), then the lane is free;
// - the scan starts on max(lane free, now + 1) and hands the lane one candidate (an active slot,
//   the skipped one left out) a clock;
// - the result leaves 37 + DEPTH clocks after the clock following the last candidate, in order,
//   one a clock; a bypassed entry leaves 38 + DEPTH clocks after it entered;
// - a ray without any candidate (no active slot but the skipped one) takes one clock of the
//   scan, as a ray with one candidate that misses would (since session 42 the model charges it
//   so too: before, it let such a ray leave before its origin's set-up pass had ended).
module plane_unit #(
    parameter integer IW = 8,       // log2 of the patch slots
    parameter integer DEPTH = 16    // (u,v) levels (CONFIG.DEPTH)
) (
    input  wire          clk,
    input  wire          rst,
    // patch memory, a 32-bit word at a time (slot << 4 | word), as PATCH_ADDR/PATCH_DATA
    input  wire          pm_we,
    input  wire [IW+3:0] pm_addr,
    input  wire [31:0]   pm_data,
    input  wire [IW:0]   count,     // PATCH_COUNT
    input  wire          invalidate, // the set-up forgotten (patch memory or PATCH_COUNT written)
    // rays
    input  wire          in_valid,
    output wire          in_ready,
    input  wire [95:0]   in_origin, // Q8.24, x in bits 31:0
    input  wire [95:0]   in_dir,    // Q2.30
    input  wire          in_uv,
    input  wire          in_skip_en,
    input  wire [IW-1:0] in_skip,
    input  wire          in_bypass,
    // results, in the order the rays came
    output reg           out_valid,
    output reg           out_hit,
    output reg  [IW-1:0] out_patch,
    output reg  [31:0]   out_t,
    output reg  [31:0]   out_u,
    output reg  [31:0]   out_v,
    output reg           out_front
);
    localparam integer CAP = 1 << IW;
    localparam integer BYPASS_DELAY = 36 + DEPTH;
    localparam [1:0] IDLE = 2'd0, SETUP = 2'd1, SCAN = 2'd2;

    // ---- patch memory: 16 word planes, one write port, two slot-wide read ports ----
    reg  [511:0] su_words, uv_words;
    wire [IW-1:0] su_addr;
    wire [IW-1:0] uv_addr;  // the result's slot (r_patch), read for its (u,v)
    genvar w;
    generate
        for (w = 0; w < 16; w = w + 1) begin : plane
            reg [31:0] mem [0:CAP-1];
            always @(posedge clk) begin
                if (pm_we && pm_addr[3:0] == w) mem[pm_addr[IW+3:4]] <= pm_data;
                su_words[32 * w +: 32] <= mem[su_addr];
                uv_words[32 * w +: 32] <= mem[uv_addr];
            end
        end
    endgenerate

    // ---- entry: the set-up key, the ray table, sequence numbers ----
    reg  [8:0]  in_flight;
    assign in_ready = (in_flight - {8'd0, out_valid}) < 9'd255;
    wire in_fire = in_valid && in_ready;
    wire lane_ray = in_fire && !in_bypass;
    reg  [95:0] key_o;
    reg         key_valid;
    wire stale = !key_valid || key_o != in_origin;
    reg  [7:0]  in_seq;
    reg  [95:0] rt_o [0:255];
    reg  [95:0] rt_d [0:255];
    reg         rt_uv [0:255];
    always @(posedge clk) begin
        if (rst) begin
            key_valid <= 1'b0;
            in_seq <= 8'd0;
            in_flight <= 9'd0;
        end else begin
            in_flight <= in_flight + {8'd0, in_fire} - {8'd0, out_valid};
            if (in_fire) in_seq <= in_seq + 8'd1;
            if (pm_we || invalidate) key_valid <= 1'b0;
            else if (lane_ray && stale) begin
                key_valid <= 1'b1;
                key_o <= in_origin;
            end
        end
        if (in_fire) begin
            rt_o[in_seq] <= in_origin;
            rt_d[in_seq] <= in_dir;
            rt_uv[in_seq] <= in_uv;
        end
    end

    // ---- descriptor FIFO of lane rays ----
    reg  [7:0]    f_seq [0:255];
    reg           f_setup [0:255];
    reg           f_skip_en [0:255];
    reg  [IW-1:0] f_skip [0:255];
    reg  [7:0]    f_wp, f_rp;
    reg  [8:0]    f_n;
    wire head_v = f_n != 0;
    wire [7:0] h_seq = f_seq[f_rp];
    wire h_setup = f_setup[f_rp];
    wire h_skip_en = f_skip_en[f_rp];
    wire [IW-1:0] h_skip = f_skip[f_rp];

    // ---- the sequencer: one job at a time, the next starting on the clock after the last ----
    reg  [1:0]    st;
    reg  [IW+1:0] k;
    reg  [IW:0]   p;
    reg  [IW:0]   n_cur;
    reg  [IW:0]   active_len;
    reg  [IW-1:0] list [0:CAP-1];
    reg           act_bit [0:CAP-1];
    wire go_setup_head = st == IDLE && head_v && h_setup;
    wire go_scan_head = st == IDLE && head_v && !h_setup;
    wire go_setup_in = st == IDLE && !head_v && lane_ray && stale;
    wire in_setup = go_setup_head || go_setup_in || st == SETUP;
    wire [IW+1:0] step = st == IDLE ? {(IW + 2){1'b0}} : k;
    wire [IW+1:0] count2 = {1'b0, count};
    wire su_read = in_setup && step < count2;
    wire su_last = in_setup && step == count2 + 1;
    assign su_addr = step[IW-1:0];

    wire skip_in = h_skip_en && {1'b0, h_skip} < count && act_bit[h_skip];
    wire [IW:0] n_new = active_len - {{IW{1'b0}}, skip_in};
    wire in_scan = go_scan_head || st == SCAN;
    wire [IW:0] n_now = st == SCAN ? n_cur : n_new;
    wire empty_scan = n_now == 0;
    wire [IW:0] p_now = st == SCAN ? p : {(IW + 1){1'b0}};
    wire [IW-1:0] cand0 = list[p_now[IW-1:0]];
    wire [IW-1:0] cand1 = list[p_now[IW-1:0] + 1'b1];
    wire skip_hit = h_skip_en && cand0 == h_skip;
    wire [IW-1:0] cand = skip_hit ? cand1 : cand0;
    wire scan_last = in_scan && (empty_scan || step[IW:0] == n_now - 1'b1);

    // the set-up pass's origin and truncation, latched when it starts
    reg  [95:0] su_o;
    reg  [2:0]  su_shift;
    wire [95:0] start_o = go_setup_in ? in_origin : rt_o[h_seq];
    function [31:0] mag(input [31:0] c);
        mag = c[31] ? -c : c;
    endfunction
    function [2:0] trunc_shift(input [95:0] o);
        /* verilator lint_off UNUSEDSIGNAL */ // only the bit length matters
        reg [32:0] amax;
        /* verilator lint_on UNUSEDSIGNAL */
        reg [31:0] m0, m1, m2;
        begin
            m0 = mag(o[31:0]);
            m1 = mag(o[63:32]);
            m2 = mag(o[95:64]);
            amax = {1'b0, (m0 > m1 ? (m0 > m2 ? m0 : m2) : (m1 > m2 ? m1 : m2))} + 33'h2000000;
            // bits = bit length of amax; shift = max(2 bits + 2 - 62, 0)
            trunc_shift = amax[31] ? 3'd4 : (amax[30] ? 3'd2 : 3'd0);
        end
    endfunction

    always @(posedge clk) begin
        if (rst) begin
            st <= IDLE;
            f_wp <= 8'd0;
            f_rp <= 8'd0;
            f_n <= 9'd0;
        end else begin
            if (in_setup) begin
                st <= su_last ? IDLE : SETUP;
                k <= step + 1'b1;
            end else if (in_scan) begin
                st <= scan_last ? IDLE : SCAN;
                k <= step + 1'b1;
                p <= p_now + (skip_hit ? {{(IW - 1){1'b0}}, 2'd2} : {{IW{1'b0}}, 1'b1});
                if (go_scan_head) n_cur <= n_new;
            end
            if (go_setup_head || go_setup_in) begin
                su_o <= start_o;
                su_shift <= trunc_shift(start_o);
            end
            if (go_setup_head) f_setup[f_rp] <= 1'b0;
            if (lane_ray) begin
                f_seq[f_wp] <= in_seq;
                f_setup[f_wp] <= stale && !go_setup_in;
                f_skip_en[f_wp] <= in_skip_en;
                f_skip[f_wp] <= in_skip;
                f_wp <= f_wp + 8'd1;
            end
            if (scan_last) f_rp <= f_rp + 8'd1;
            f_n <= f_n + {8'd0, lane_ray} - {8'd0, scan_last};
        end
    end

    // ---- set-up pipe: read, plane_setup's two stages, local memory write ----
    reg          r1_v, r2_v;
    reg [IW-1:0] r1_i, r2_i;
    wire         s_valid, s_active, s_quad;
    wire [767:0] s_e;
    wire [95:0]  s_n;
    wire [67:0]  s_h;
    plane_setup setup (
        .clk(clk), .in_valid(r1_v), .in_words(su_words), .in_shift(su_shift), .origin(su_o),
        .out_valid(s_valid), .out_active(s_active), .out_quad(s_quad), .out_e(s_e),
        .out_n(s_n), .out_h(s_h));
    reg [767:0] lm_e [0:CAP-1];
    reg [95:0]  lm_n [0:CAP-1];
    reg [67:0]  lm_h [0:CAP-1];
    reg         lm_quad [0:CAP-1];
    always @(posedge clk) begin
        r1_v <= !rst && su_read;
        r1_i <= su_addr;
        r2_v <= r1_v;
        r2_i <= r1_i;
        if (go_setup_head || go_setup_in) active_len <= {(IW + 1){1'b0}};
        if (s_valid && r2_v) begin
            lm_e[r2_i] <= s_e;
            lm_n[r2_i] <= s_n;
            lm_h[r2_i] <= s_h;
            lm_quad[r2_i] <= s_quad;
            act_bit[r2_i] <= s_active;
            if (s_active) begin
                list[active_len[IW-1:0]] <= r2_i;
                active_len <= active_len + 1'b1;
            end
        end
    end

    // ---- the lane: C0 local memory read, C1 edge stage, divider, running minimum ----
    reg          c0_v, c0_first, c0_last, c0_empty;
    reg [7:0]    c0_seq;
    reg [IW-1:0] c0_patch;
    reg [767:0]  c0_e;
    reg [95:0]   c0_n;
    reg [67:0]   c0_h;
    reg          c0_quad;
    always @(posedge clk) begin
        c0_v <= !rst && in_scan;
        c0_first <= step == 0;
        c0_last <= scan_last;
        c0_empty <= empty_scan;
        c0_seq <= h_seq;
        c0_patch <= cand;
        c0_e <= lm_e[cand];
        c0_n <= lm_n[cand];
        c0_h <= lm_h[cand];
        c0_quad <= lm_quad[cand];
    end

    wire [95:0] dir = rt_d[c0_seq];
    function signed [97:0] dot_e(input [191:0] e, input [95:0] d);
        dot_e = $signed(d[31:0]) * $signed(e[63:0]) + $signed(d[63:32]) * $signed(e[127:64])
              + $signed(d[95:64]) * $signed(e[191:128]);
    endfunction
    /* verilator lint_off UNUSEDSIGNAL */ // only the signs of d . e_k are used
    wire signed [97:0] de0 = dot_e(c0_e[0 +: 192], dir);
    wire signed [97:0] de1 = dot_e(c0_e[192 +: 192], dir);
    wire signed [97:0] de2 = dot_e(c0_e[384 +: 192], dir);
    wire signed [97:0] de3 = dot_e(c0_e[576 +: 192], dir);
    /* verilator lint_on UNUSEDSIGNAL */
    wire in_pyr = !c0_empty && !de0[97] && !de1[97] && !de2[97] && (!c0_quad || !de3[97]);
    wire signed [67:0] den = $signed(dir[31:0]) * $signed(c0_n[31:0])
                           + $signed(dir[63:32]) * $signed(c0_n[63:32])
                           + $signed(dir[95:64]) * $signed(c0_n[95:64]);
    localparam integer DPW = IW + 11;
    reg              c1_v, c1_inside;
    reg signed [67:0] c1_h, c1_den;
    reg [DPW-1:0]    c1_pay;
    always @(posedge clk) begin
        c1_v <= !rst && c0_v;
        c1_inside <= in_pyr;
        c1_h <= c0_h;
        c1_den <= in_pyr ? den : 68'sd0;
        c1_pay <= {c0_patch, c0_h[67], c0_seq, c0_first, c0_last};
    end
    wire          dv_v, dv_hit;
    wire [30:0]   dv_t;
    wire [DPW-1:0] dv_pay;
    plane_divider #(.PW(DPW)) divider (
        .clk(clk), .rst(rst), .in_valid(c1_v), .in_inside(c1_inside), .in_h(c1_h), .in_den(c1_den),
        .in_payload(c1_pay), .out_valid(dv_v), .out_hit(dv_hit), .out_t(dv_t),
        .out_payload(dv_pay));
    wire [IW-1:0] dv_patch = dv_pay[DPW-1 -: IW];
    wire          dv_front = dv_pay[10];
    wire [7:0]    dv_seq = dv_pay[9:2];
    wire          dv_first = dv_pay[1];
    wire          dv_last = dv_pay[0];

    // the running minimum: nearest t, of equal t the first candidate (the lowest index)
    reg          acc_hit, acc_front;
    reg [IW-1:0] acc_patch;
    reg [30:0]   acc_t;
    wire take = dv_hit && (dv_first || !acc_hit || dv_t < acc_t);
    wire          nx_hit = take || (!dv_first && acc_hit);
    wire [IW-1:0] nx_patch = take ? dv_patch : acc_patch;
    wire [30:0]   nx_t = take ? dv_t : acc_t;
    wire          nx_front = take ? dv_front : acc_front;
    reg          r_v, r_hit, r_front;
    reg [IW-1:0] r_patch;
    reg [30:0]   r_t;
    reg [7:0]    r_seq;
    always @(posedge clk) begin
        if (dv_v) begin
            acc_hit <= nx_hit;
            acc_patch <= nx_patch;
            acc_t <= nx_t;
            acc_front <= nx_front;
        end
        r_v <= !rst && dv_v && dv_last;
        r_hit <= nx_hit;
        r_patch <= nx_patch;
        r_t <= nx_t;
        r_front <= nx_front;
        r_seq <= dv_seq;
    end

    // ---- (u,v): U0 hit point and slot read, U1 projection and level 1, levels 2..DEPTH ----
    localparam integer QW = 34, PW = 36;
    assign uv_addr = r_patch;
    wire [95:0] ro = rt_o[r_seq];
    wire [95:0] rd = rt_d[r_seq];
    function [PW-1:0] hit_point(input [31:0] o, input [31:0] d, input [30:0] t);
        /* verilator lint_off UNUSEDSIGNAL */ // the point is PW bits wide
        reg signed [63:0] td, sum;
        /* verilator lint_on UNUSEDSIGNAL */
        begin
            td = $signed({1'b0, t}) * $signed(d);
            sum = $signed({{32{o[31]}}, o}) + (td >>> 30);
            hit_point = sum[PW-1:0];
        end
    endfunction
    reg            u0_v, u0_hit, u0_front, u0_uv;
    reg [IW-1:0]   u0_patch;
    reg [30:0]     u0_t;
    reg [3*PW-1:0] u0_hp;
    always @(posedge clk) begin
        u0_v <= !rst && r_v;
        u0_hit <= r_hit;
        u0_front <= r_front;
        u0_uv <= rt_uv[r_seq];
        u0_patch <= r_patch;
        u0_t <= r_t;
        u0_hp <= {hit_point(ro[95:64], rd[95:64], r_t), hit_point(ro[63:32], rd[63:32], r_t),
                  hit_point(ro[31:0], rd[31:0], r_t)};
    end

    // projection: drop the normal's largest component (ties to the lower axis), keep the other
    // two in cyclic order, swapped when that component is negative
    wire signed [31:0] nn0 = uv_words[32 * 13 +: 32];
    wire signed [31:0] nn1 = uv_words[32 * 14 +: 32];
    wire signed [31:0] nn2 = uv_words[32 * 15 +: 32];
    wire [31:0] m0 = mag(nn0), m1 = mag(nn1), m2 = mag(nn2);
    wire [1:0] ax = (m0 >= m1 && m0 >= m2) ? 2'd0 : (m1 >= m2 ? 2'd1 : 2'd2);
    wire ax_neg = ax == 2'd0 ? nn0[31] : (ax == 2'd1 ? nn1[31] : nn2[31]);
    wire [1:0] pi = ax == 2'd0 ? 2'd1 : (ax == 2'd1 ? 2'd2 : 2'd0);
    wire [1:0] pj = ax == 2'd0 ? 2'd2 : (ax == 2'd1 ? 2'd0 : 2'd1);
    wire [1:0] ai = ax_neg ? pj : pi;
    wire [1:0] aj = ax_neg ? pi : pj;
    function [QW-1:0] vtx(input [511:0] words, input integer corner, input [1:0] c);
        reg [31:0] x;
        integer ci;
        begin
            ci = {30'd0, c};
            x = words[32 * (1 + 3 * corner + ci) +: 32];
            vtx = {{(QW - 32){x[31]}}, x};
        end
    endfunction
    wire [8*QW-1:0] q_proj = {vtx(uv_words, 3, aj), vtx(uv_words, 3, ai),
                              vtx(uv_words, 2, aj), vtx(uv_words, 2, ai),
                              vtx(uv_words, 1, aj), vtx(uv_words, 1, ai),
                              vtx(uv_words, 0, aj), vtx(uv_words, 0, ai)};
    wire [2*PW-1:0] p_proj = {u0_hp[PW * aj +: PW], u0_hp[PW * ai +: PW]};

    reg [8*QW-1:0]  lq [1:DEPTH];
    reg [2*PW-1:0]  lp [1:DEPTH];
    reg [DEPTH-1:0] liu [1:DEPTH];
    reg [DEPTH-1:0] liv [1:DEPTH];
    reg             lv [1:DEPTH];
    reg [IW+33:0]   lres [1:DEPTH];  // hit, uv, front, patch, t
    genvar l;
    generate
        for (l = 1; l <= DEPTH; l = l + 1) begin : level
            wire [8*QW-1:0]  iq = l == 1 ? q_proj : lq[l == 1 ? 1 : l - 1];
            wire [2*PW-1:0]  ip = l == 1 ? p_proj : lp[l == 1 ? 1 : l - 1];
            wire [DEPTH-1:0] iiu = l == 1 ? {DEPTH{1'b0}} : liu[l == 1 ? 1 : l - 1];
            wire [DEPTH-1:0] iiv = l == 1 ? {DEPTH{1'b0}} : liv[l == 1 ? 1 : l - 1];
            wire [8*QW-1:0]  oq;
            wire [DEPTH-1:0] oiu, oiv;
            uv_level #(.QW(QW), .PW(PW), .DEPTH(DEPTH)) lvl (
                .in_q(iq), .in_p(ip), .in_iu(iiu), .in_iv(iiv),
                .out_q(oq), .out_iu(oiu), .out_iv(oiv));
            always @(posedge clk) begin
                lq[l] <= oq;
                lp[l] <= ip;
                liu[l] <= oiu;
                liv[l] <= oiv;
                lv[l] <= !rst && (l == 1 ? u0_v : lv[l == 1 ? 1 : l - 1]);
                lres[l] <= l == 1 ? {u0_hit, u0_uv, u0_front, u0_patch, u0_t}
                                  : lres[l == 1 ? 1 : l - 1];
            end
        end
    endgenerate

    // ---- retirement: lane results and bypassed entries, merged back into entry order ----
    wire [IW+33:0] fin = lres[DEPTH];
    wire fin_hit = fin[IW+33];
    wire fin_uv = fin[IW+32];
    function [31:0] centre(input [DEPTH-1:0] index);
        centre = {{(31 - DEPTH){1'b0}}, index, 1'b1} << (29 - DEPTH);
    endfunction
    reg [IW+96:0] lf [0:255];  // hit, front, patch, t, u, v
    reg [7:0]     lf_seq [0:255];
    reg [7:0]     lf_wp, lf_rp;
    reg [7:0]     bf_seq [0:255];
    reg [7:0]     bf_wp, bf_rp;
    reg [7:0]     bp_seq [0:BYPASS_DELAY-1];
    reg           bp_v [0:BYPASS_DELAY-1];
    reg [7:0]     l_seq [1:DEPTH];  // the result's sequence number, beside the levels
    reg [7:0]     r_seq_d;
    reg [7:0]     next_seq;
    integer j;
    always @(posedge clk) begin
        l_seq[1] <= r_seq_d;
        for (j = 2; j <= DEPTH; j = j + 1) l_seq[j] <= l_seq[j-1];
        bp_v[0] <= !rst && in_fire && in_bypass;
        bp_seq[0] <= in_seq;
        for (j = 1; j < BYPASS_DELAY; j = j + 1) begin
            bp_v[j] <= !rst && bp_v[j-1];
            bp_seq[j] <= bp_seq[j-1];
        end
        if (rst) begin
            lf_wp <= 8'd0;
            lf_rp <= 8'd0;
            bf_wp <= 8'd0;
            bf_rp <= 8'd0;
            next_seq <= 8'd0;
            out_valid <= 1'b0;
        end else begin
            if (lv[DEPTH]) begin
                // a miss reads as zeros, as the model's HitOut::default()
                lf[lf_wp] <= fin_hit ? {1'b1, fin[IW+31], fin[IW+30:31], fin[30:0],
                                        fin_uv ? centre(liu[DEPTH]) : 32'd0,
                                        fin_uv ? centre(liv[DEPTH]) : 32'd0}
                                     : {(IW + 97){1'b0}};
                lf_seq[lf_wp] <= l_seq[DEPTH];
                lf_wp <= lf_wp + 8'd1;
            end
            if (bp_v[BYPASS_DELAY-1]) begin
                bf_seq[bf_wp] <= bp_seq[BYPASS_DELAY-1];
                bf_wp <= bf_wp + 8'd1;
            end
            out_valid <= 1'b0;
            if (lf_wp != lf_rp && lf_seq[lf_rp] == next_seq) begin
                {out_hit, out_front, out_patch, out_t[30:0], out_u, out_v} <= lf[lf_rp];
                out_t[31] <= 1'b0;
                out_valid <= 1'b1;
                lf_rp <= lf_rp + 8'd1;
                next_seq <= next_seq + 8'd1;
            end else if (bf_wp != bf_rp && bf_seq[bf_rp] == next_seq) begin
                {out_hit, out_front, out_patch, out_t, out_u, out_v} <= {(IW + 98){1'b0}};
                out_valid <= 1'b1;
                bf_rp <= bf_rp + 8'd1;
                next_seq <= next_seq + 8'd1;
            end
        end
    end
    always @(posedge clk) r_seq_d <= r_seq;
endmodule
