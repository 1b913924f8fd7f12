// A compact build's plane unit, one a ray group (hdl-model/src/intersect/group_plane.rs): the
// lanes hand it each (ray, slot) pair they find inside, with the slot's h from the lane's word,
// the ray's direction d and its tag; it reads the slot's unit normal n from the group's normal
// memory, forms n . d, divides, t = h / (n . d) (plane_divider.v), and keeps each ray's running
// minimum by its tag: the pairs of the rays in flight arrive interleaved. A ray's answer is
// read out once, when its lanes are done: the nearest t, of equal t the lowest slot, or none.
//
// Clocks (a pair offered on clock T, taken at once: one a clock):
// - T: the normal's address; T + 1: n; T + 2: the operands; T + 3: the twelve 18 x 18 tiles;
//   T + 4: each product's two halves; T + 5: the products; T + 6: the first two summed; T + 7:
//   n . d at the divider's input; T + 39: t out of the divider (group_plane::T_LATENCY);
// - the minimum reads the tag's entry and generation bit as t comes out, registers them a
//   clock later, and writes the entry the clock after (the entries written on the two clocks
//   before forwarded);
// - a readout asked for on clock R (at most one a clock, after the ray's last pair was taken)
//   reads the entry on R + 41 and sets its generation bits to the entry's g on R + 42, which
//   empties it; the answer is out on R + 43 for one clock (group_plane::ANSWER_LATENCY), with
//   the tag it was asked with;
// - after a reset the unit reads every tag's entry in the same way, a tag a clock, and raises
//   `ready` TAGS + 1 clocks after it; the pairs still in the divider are dropped.
// A tag is reused once its answer is out (its generation bits are set on R + 42, and a pair
// of the tag's next ray reaches the minimum 39 clocks after it is taken).
module group_plane #(
    parameter integer SLOT_BITS = 10,
    parameter integer TW = 10          // the tag's bits
) (
    input  wire                 clk,
    input  wire                 rst,
    // the group's normal memory, written with patch memory: a slot's n, Q2.30, x in bits 31:0
    input  wire                 nm_we,
    input  wire [SLOT_BITS-1:0] nm_addr,
    input  wire [95:0]          nm_data,
    // a pair found inside
    input  wire                 in_valid,
    input  wire [SLOT_BITS-1:0] in_slot,
    input  wire [67:0]          in_h,      // Q.54, the slot's h = n . (v0 - O)
    input  wire [95:0]          in_d,      // Q2.30
    input  wire [TW-1:0]        in_tag,
    // a ray's answer asked for
    input  wire                 rd_valid,
    input  wire [TW-1:0]        rd_tag,
    // high once the reset's sweep is done: pairs and readouts from then
    output wire                 ready,
    output reg                  out_valid,
    output reg                  out_hit,
    output reg  [30:0]          out_t,     // Q8.24
    output reg  [SLOT_BITS-1:0] out_slot,
    output reg                  out_front, // h < 0: the origin is on the front side
    output reg  [TW-1:0]        out_tag
);
    // ---- n . d: the normal's read, the operands, the tiles, the halves, the products, the sum ----
    reg [95:0] normals [0:(1 << SLOT_BITS) - 1];
    reg [95:0] n1;
    always @(posedge clk) begin
        if (nm_we) normals[nm_addr] <= nm_data;
        n1 <= normals[in_slot];
    end
    // the pair's h, slot and tag wait beside n . d: stage k holds them on T + 1 + k
    localparam integer PW = 68 + SLOT_BITS + TW;
    localparam integer LAG = 6;
    reg          lag_v [0:LAG];
    reg [PW-1:0] lag_p [0:LAG];
    reg [95:0]   d1;
    integer s;
    always @(posedge clk) begin
        lag_v[0] <= !rst && in_valid;
        lag_p[0] <= {in_h, in_slot, in_tag};
        d1 <= in_d;
        for (s = 1; s <= LAG; s = s + 1) begin
            lag_v[s] <= !rst && lag_v[s - 1];
            lag_p[s] <= lag_p[s - 1];
        end
    end
    // a 32-bit word's halves as signed 18-bit tile operands: 17 low bits, 15 signed high ones
    function signed [17:0] lo17(input [16:0] w);
        lo17 = {1'b0, w};
    endfunction
    function signed [17:0] hi15(input [14:0] w);
        hi15 = {{3{w[14]}}, w};
    endfunction
    reg        [31:0] rn [0:2];
    reg        [31:0] rdir [0:2];
    reg signed [35:0] t_ll [0:2];
    reg signed [35:0] t_lh [0:2];
    reg signed [35:0] t_hl [0:2];
    reg signed [35:0] t_hh [0:2];
    reg signed [52:0] half_lo [0:2];   // t_ll + t_lh 2^17
    reg signed [52:0] half_hi [0:2];   // t_hl + t_hh 2^17
    reg signed [63:0] prod [0:2];      // half_lo + half_hi 2^17
    reg signed [64:0] sum01;
    reg signed [63:0] prod2;
    reg signed [67:0] den;
    integer c;
    always @(posedge clk) begin
        for (c = 0; c < 3; c = c + 1) begin
            rn[c] <= n1[32 * c +: 32];
            rdir[c] <= d1[32 * c +: 32];
            t_ll[c] <= lo17(rdir[c][16:0]) * lo17(rn[c][16:0]);
            t_lh[c] <= lo17(rdir[c][16:0]) * hi15(rn[c][31:17]);
            t_hl[c] <= hi15(rdir[c][31:17]) * lo17(rn[c][16:0]);
            t_hh[c] <= hi15(rdir[c][31:17]) * hi15(rn[c][31:17]);
            half_lo[c] <= {{17{t_ll[c][35]}}, t_ll[c]} + {t_lh[c], 17'd0};
            half_hi[c] <= {{17{t_hl[c][35]}}, t_hl[c]} + {t_hh[c], 17'd0};
            prod[c] <= {{11{half_lo[c][52]}}, half_lo[c]} + {half_hi[c][46:0], 17'd0};
        end
        sum01 <= {prod[0][63], prod[0]} + {prod[1][63], prod[1]};
        prod2 <= prod[2];
        den <= {{3{sum01[64]}}, sum01} + {{4{prod2[63]}}, prod2};
    end

    // ---- the divider: t = h / (n . d), 32 clocks ----
    localparam integer DPW = SLOT_BITS + TW + 1;
    wire [67:0]          lag_h = lag_p[LAG][PW-1 -: 68];
    wire [SLOT_BITS-1:0] lag_slot = lag_p[LAG][TW +: SLOT_BITS];
    wire [TW-1:0]        lag_tag = lag_p[LAG][TW-1:0];
    wire           dv_v, dv_hit;
    wire [30:0]    dv_t;
    wire [DPW-1:0] dv_pay;
    plane_divider #(.PW(DPW)) divider (
        .clk(clk), .rst(rst), .in_valid(lag_v[LAG]), .in_inside(1'b1), .in_h(lag_h), .in_den(den),
        .in_payload({lag_slot, lag_h[67], lag_tag}), .out_valid(dv_v), .out_hit(dv_hit),
        .out_t(dv_t), .out_payload(dv_pay));

    // ---- each ray's running minimum: an entry {t, slot, front, g} a tag ----
    // An entry holds a ray's minimum when its g differs from its tag's generation bit, which
    // the readout sets to g: so a readout empties its entry without writing it (the block
    // RAM's write port is the minimum's), and the minimum writes g as the bit's complement.
    // The generation bits, a copy for each reader (Yosys maps each to a block RAM); after a
    // reset each is set to its entry's g, a tag a clock, before the unit is ready.
    localparam integer EW = 31 + SLOT_BITS + 2;
    localparam integer TAGS = 1 << TW;
    reg [EW-1:0] near_u [0:TAGS-1];   // read by the minimum
    reg [EW-1:0] near_r [0:TAGS-1];   // the same entries, read by the readout and the sweep
    reg          gen_u [0:TAGS-1];
    reg          gen_r [0:TAGS-1];
    // the tag's entry out of the block RAM a clock after t (k), registered before it is
    // compared (m): the block RAM's read takes most of a clock
    reg            k_v, k_gen, m_v, m_gen, m_fwd1, m_fwd2, w1_v;
    reg [TW-1:0]   k_tag, m_tag, w1_tag;
    reg [EW-1:0]   k_old, m_old;
    reg [EW-2:0]   k_pair, m_pair, w1_body, w2_body;   // {t, slot, front}
    always @(posedge clk) begin
        // a pair in the divider when the unit was reset comes out during the sweep: dropped
        k_v <= !rst && ready && dv_v && dv_hit;
        k_tag <= dv_pay[TW-1:0];
        k_pair <= {dv_t, dv_pay[DPW-1 -: SLOT_BITS], dv_pay[TW]};
        k_gen <= gen_u[dv_pay[TW-1:0]];
        k_old <= near_u[dv_pay[TW-1:0]];
        m_v <= !rst && k_v;
        m_tag <= k_tag;
        m_pair <= k_pair;
        m_gen <= k_gen;
        m_old <= k_old;
        // the entries the next two writes hold are not in the block RAM's read yet: whether
        // they are this tag's, found a clock ahead
        m_fwd1 <= m_v && m_tag == k_tag;
        m_fwd2 <= w1_v && w1_tag == k_tag;
    end
    // the pair against each entry it may meet, side by side, then the one it meets
    function nearer_than(input [EW-3:0] a, input [EW-3:0] b);   // {t, slot}
        nearer_than = a < b;
    endfunction
    wire held = m_fwd1 || m_fwd2 || m_old[0] != m_gen;
    wire nearer = !held || (m_fwd1 ? nearer_than(m_pair[EW-2:1], w1_body[EW-2:1])
                          : m_fwd2 ? nearer_than(m_pair[EW-2:1], w2_body[EW-2:1])
                          : nearer_than(m_pair[EW-2:1], m_old[EW-1:2]));
    wire [EW-2:0] old = m_fwd1 ? w1_body : m_fwd2 ? w2_body : m_old[EW-1:1];
    wire [EW-2:0] body = nearer ? m_pair : old;
    always @(posedge clk) begin
        w1_v <= !rst && m_v;
        w1_tag <= m_tag;
        w1_body <= body;
        w2_body <= w1_body;
        if (m_v) begin
            near_u[m_tag] <= {body, !m_gen};
            near_r[m_tag] <= {body, !m_gen};
        end
    end

    // ---- the readout: asked on R, the entry read on R + 41, the answer out on R + 43 ----
    // Reading a tag's entry also sets its generation bits to the entry's g a clock later,
    // which empties it; after a reset the same reads sweep every tag, one a clock.
    localparam integer WAIT = 41;
    reg          q_v [0:WAIT-1];
    reg [TW-1:0] q_tag [0:WAIT-1];
    reg [TW:0]   sweep;            // the tag the sweep reads, TAGS when done
    assign ready = sweep[TW];
    wire         r_v = ready ? q_v[WAIT-1] : !rst;
    wire [TW-1:0] r_tag = ready ? q_tag[WAIT-1] : sweep[TW-1:0];
    reg          a_v, a_read, a_gen;
    reg [TW-1:0] a_tag;
    reg [EW-1:0] a_entry;
    integer r;
    always @(posedge clk) begin
        sweep <= rst ? {(TW + 1){1'b0}} : sweep + {{TW{1'b0}}, !sweep[TW]};
        q_v[0] <= !rst && rd_valid;
        q_tag[0] <= rd_tag;
        for (r = 1; r < WAIT; r = r + 1) begin
            q_v[r] <= !rst && q_v[r - 1];
            q_tag[r] <= q_tag[r - 1];
        end
        a_read <= !rst && r_v;
        a_v <= !rst && ready && r_v;
        a_tag <= r_tag;
        a_gen <= gen_r[r_tag];
        a_entry <= near_r[r_tag];
        out_valid <= !rst && a_v;
        out_hit <= a_entry[0] != a_gen;
        out_t <= a_entry[EW-1 -: 31];
        out_slot <= a_entry[SLOT_BITS+1:2];
        out_front <= a_entry[1];
        out_tag <= a_tag;
        if (a_read) begin
            gen_u[a_tag] <= a_entry[0];
            gen_r[a_tag] <= a_entry[0];
        end
    end
endmodule
