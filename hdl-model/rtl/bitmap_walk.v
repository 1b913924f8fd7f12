// One lane's walk over its bank's candidate bitmaps (hdl-model/src/intersect/bitmap_walk.rs):
// a ray's candidates, the slots set in both its sector row and its band row, one a clock in
// slot order, for the lane's coarse edge test.
//
// The bitmaps are this module's memories, written through the port `bitmap_writer.v` drives
// (a copied row a clock: sector word, mask word and band word of one column, side by side), in
// two buffers; the writer's valid bits say which columns of a buffer its pass has copied (the
// others read as zero). Rows: a sector's 64-slot words and a band's (block RAM, 64 bits wide),
// and for each sector row and column a mask word of the bands its slots reach (distributed
// RAM, one memory a column, so that a ray reads all of its sector's mask words at once).
//
//   ray -> M: its sector's mask words read, the ray's band bit of each valid column kept
//       -> R: a column a clock, the lowest still to read: sector word and band word read
//       -> B: the block RAMs' read, C: the register after it
//       -> A: sector & band, the ray's own slot (SKIP_PATCH) cleared
//       -> H: the ray's latest word with a candidate held until the ray's next such word or
//          its end, so that it goes on marked as the last when it is; into a queue of words
//       -> E: the word taken from the queue, its lowest slot out a clock, until its last
//   A ray without a candidate here (no column holds its band, or every word it reads is
//   empty once its skip is cleared) ends on the z port, in the order of such rays, without an
//   output clock: a lane sees every ray of its group, and a clock for each such ray would cost
//   the default build its targets (charged in the model, the Cornell box takes 1.03 cycles a
//   ray instead of 0.99; docs/PERFORMANCE.md, "Session 42").
//
// Clocks: a ray is taken while M is free or leaves it on that clock; it reads its columns one a
// clock (a ray of no column a clock too, for its end); its first candidate is out seven clocks
// after it was taken at the earliest; the words come out back to back, a candidate a clock. So
// the output takes a ray its candidates' clocks and the reader a clock a column (a word the
// skip emptied costs a read, not an output). The model's lane clock (`WordWalk::clocks`) is
// the larger of its candidates and its words, the reads overlapped with the previous ray's
// candidates, and a compact build's lane without a candidate for the ray costs nothing:
// answers are co-simulated, the clocks are not yet the model's.
//
// Whoever hands the walk its rays sets r_skip_en only for a SKIP_PATCH in this bank (r_skip is
// its place here), as `plane_unit.v` ignores a skip beyond PATCH_COUNT: a slot of another bank
// or beyond the slots would alias a place of this one. The walk's neighbours are reset with
// it: it takes no ray and gives no output while `rst` is high.
//
// Verilog-2005, accepted by Verilator and Yosys.
module bitmap_walk #(
    parameter integer SECTORS = 32,
    parameter integer BANDS = 16,
    parameter integer SLOT_BITS = 9,
    parameter integer TAG_BITS = 8
) (
    input  wire                 clk,
    input  wire                 rst,
    // the block RAMs' write port, as bitmap_writer.v drives it
    input  wire                 w_valid,
    input  wire                 w_buf,
    input  wire [6:0]           w_row,
    input  wire [COL_BITS-1:0]  w_col,
    input  wire [63:0]          w_sector,
    input  wire [BANDS-1:0]     w_mask,
    input  wire [63:0]          w_band,
    // the columns each buffer's pass has copied
    input  wire [COLS-1:0]      valid0,
    input  wire [COLS-1:0]      valid1,
    // a ray: the buffer its origin's pass filled, its sector and band, the slot it skips
    input  wire                 r_valid,
    output wire                 r_ready,
    input  wire                 r_buf,
    input  wire [SB-1:0]        r_sector,
    input  wire [BB-1:0]        r_band,
    input  wire                 r_skip_en,
    input  wire [SLOT_BITS-1:0] r_skip,
    input  wire [TAG_BITS-1:0]  r_tag,
    // its candidates, one a clock, in slot order, o_last on its last
    output wire                 o_valid,
    input  wire                 o_ready,
    output wire [SLOT_BITS-1:0] o_place,
    output wire [TAG_BITS-1:0]  o_tag,
    output wire                 o_last,
    // a ray without a candidate here: its end, in the order of such rays, with no output clock
    output wire                 z_valid,
    output reg  [TAG_BITS-1:0]  z_tag
);
    localparam integer COL_BITS = SLOT_BITS - 6;
    localparam integer COLS = 1 << COL_BITS;
    localparam integer SB = $clog2(SECTORS);
    localparam integer BB = $clog2(BANDS);
    localparam [6:0] S7 = SECTORS[6:0];
    localparam [6:0] B7 = BANDS[6:0];

    // ---- the bitmaps ----
    reg [63:0] sec_mem [0:2*SECTORS*COLS-1];
    reg [63:0] band_mem [0:2*BANDS*COLS-1];
    wire [COLS-1:0] valid;
    wire [COLS-1:0] cols_in;  // the columns whose mask word holds the ray's band
    genvar c;
    generate
        for (c = 0; c < COLS; c = c + 1) begin : mask
            reg [BANDS-1:0] m [0:2*SECTORS-1];
            always @(posedge clk)
                if (w_valid && w_row < S7 && w_col == c) m[{w_buf, w_row[SB-1:0]}] <= w_mask;
            wire [BANDS-1:0] word = m[{r_buf, r_sector}];
            assign cols_in[c] = valid[c] && word[r_band];
        end
    endgenerate
    always @(posedge clk) begin
        if (w_valid && w_row < S7) sec_mem[{w_buf, w_row[SB-1:0], w_col}] <= w_sector;
        if (w_valid && w_row < B7) band_mem[{w_buf, w_row[BB-1:0], w_col}] <= w_band;
    end

    // ---- M: the ray's columns to read (its band's bit of each valid column's mask word) ----
    reg                 m_v, m_buf, m_skip_en;
    reg [SB-1:0]        m_sector;
    reg [BB-1:0]        m_band;
    reg [SLOT_BITS-1:0] m_skip;
    reg [TAG_BITS-1:0]  m_tag;
    reg [COLS-1:0]      m_cols;
    assign valid = r_buf ? valid1 : valid0;
    integer k;

    // ---- R: the lowest column still to read, while the queue has room for what is read ----
    reg [COL_BITS-1:0] low;
    always @* begin
        low = {COL_BITS{1'b0}};
        for (k = COLS - 1; k >= 0; k = k - 1)
            if (m_cols[k]) low = k[COL_BITS-1:0];
    end
    wire [COLS-1:0] rest = m_cols & (m_cols - 1'b1);
    reg  [3:0] q_n;
    reg        b_v, c_v, a_v, h_v;
    // room in the queue for every word read and not yet in it
    wire       room = q_n + {3'b0, b_v} + {3'b0, c_v} + {3'b0, a_v} + {3'b0, h_v} < 4'd8;
    wire       read = m_v && room;
    wire       m_done = read && rest == {COLS{1'b0}};
    assign r_ready = !rst && (!m_v || m_done);
    wire take = r_valid && r_ready;

    always @(posedge clk) begin
        if (rst) m_v <= 1'b0;
        else if (take) m_v <= 1'b1;
        else if (m_done) m_v <= 1'b0;
        if (take) begin
            {m_buf, m_sector, m_band, m_skip_en, m_skip, m_tag} <=
                {r_buf, r_sector, r_band, r_skip_en, r_skip, r_tag};
            m_cols <= cols_in;
        end else if (read) m_cols <= rest;
    end

    // ---- B: the block RAMs' read (a ray of no column reads nothing: its end goes on) ----
    reg [63:0]          b_sec, b_band;
    reg                 b_empty, b_last;
    reg [COL_BITS-1:0]  b_col;
    reg [TAG_BITS-1:0]  b_tag;
    reg [63:0]          b_skip;  // the ray's skipped slot's bit, if in this column
    always @(posedge clk) begin
        b_v <= !rst && read;
        if (read) begin
            b_sec <= sec_mem[{m_buf, m_sector, low}];
            b_band <= band_mem[{m_buf, m_band, low}];
        end
        b_empty <= m_cols == {COLS{1'b0}};
        b_last <= rest == {COLS{1'b0}};
        b_col <= low;
        b_tag <= m_tag;
        b_skip <= m_skip_en && m_skip[SLOT_BITS-1:6] == low ? 64'd1 << m_skip[5:0] : 64'd0;
    end

    // ---- C: the register after the block RAMs (their outputs come late in the clock) ----
    reg [63:0]          c_sec, c_band, c_skip;
    reg                 c_empty, c_last;
    reg [COL_BITS-1:0]  c_col;
    reg [TAG_BITS-1:0]  c_tag;
    always @(posedge clk) begin
        c_v <= !rst && b_v;
        {c_sec, c_band, c_skip, c_empty, c_last, c_col, c_tag} <=
            {b_sec, b_band, b_skip, b_empty, b_last, b_col, b_tag};
    end

    // ---- A: the word's candidates, the skipped slot cleared, and the word less its first ----
    reg [63:0]          a_word, a_rest;
    reg                 a_last;
    reg [COL_BITS-1:0]  a_col;
    reg [TAG_BITS-1:0]  a_tag;
    wire [63:0] word = c_empty ? 64'd0 : c_sec & c_band & ~c_skip;
    always @(posedge clk) begin
        a_v <= !rst && c_v;
        a_word <= word;
        a_rest <= word & (word - 64'd1);
        a_last <= c_last;
        a_col <= c_col;
        a_tag <= c_tag;
    end
    // ---- H: a ray's latest word with a candidate held back, so that the word its last
    // candidate is in knows it is the last: pushed when the ray's next word with a candidate
    // comes (which is held in its place), when its ray's last word comes empty (pushed as the
    // last), or the clock after it came if it is its ray's last word. A ray whose last word
    // comes empty with nothing of it held has no candidate here: its end goes to the z port.
    reg [63:0]          h_word, h_rest;
    reg                 h_last;
    reg [COL_BITS-1:0]  h_col;
    reg [TAG_BITS-1:0]  h_tag;
    wire a_some = a_word != 64'd0;
    wire keep = a_v && a_some;
    wire ends_empty = a_v && a_last && !a_some;
    wire push = h_v && (h_last || keep || ends_empty);
    reg  z_v;
    assign z_valid = z_v && !rst;
    always @(posedge clk) begin
        if (rst) begin
            h_v <= 1'b0;
            z_v <= 1'b0;
        end else begin
            if (keep) h_v <= 1'b1;
            else if (push) h_v <= 1'b0;
            // held and not its ray's last: a word of the ray now ending
            z_v <= ends_empty && !(h_v && !h_last);
        end
        z_tag <= a_tag;
        if (keep) {h_word, h_rest, h_last, h_col, h_tag} <= {a_word, a_rest, a_last, a_col, a_tag};
    end

    // ---- the queue of words (eight registers) and E, the word being given out ----
    // E holds its word and the word less its first candidate (`rest`), so that whether this
    // candidate is the word's last comes from a register, not from this clock's subtraction
    localparam integer QW = 128 + 1 + COL_BITS + TAG_BITS;
    reg [QW-1:0] q [0:7];
    reg [2:0]    q_rp, q_wp;
    reg                 e_v, e_last;
    reg [63:0]          e_word, e_rest;
    reg [COL_BITS-1:0]  e_col;
    reg [TAG_BITS-1:0]  e_tag;
    // this candidate's bit alone (the word less the rest); its place is the OR of the indices
    // of its one bit, a bit of the place an OR of 32 bits (no priority chain)
    wire [63:0] e_low = e_word ^ e_rest;
    wire [5:0]  e_bit = {|(e_low & 64'hFFFF_FFFF_0000_0000), |(e_low & 64'hFFFF_0000_FFFF_0000),
                         |(e_low & 64'hFF00_FF00_FF00_FF00), |(e_low & 64'hF0F0_F0F0_F0F0_F0F0),
                         |(e_low & 64'hCCCC_CCCC_CCCC_CCCC), |(e_low & 64'hAAAA_AAAA_AAAA_AAAA)};
    wire e_end = e_rest == 64'd0;  // its last candidate
    assign o_valid = e_v && !rst;
    assign o_place = {e_col, e_bit};
    assign o_tag = e_tag;
    assign o_last = e_last && e_end;
    wire out = o_valid && o_ready;
    wire next = !e_v || (out && e_end);  // E takes the queue's head
    wire pop = next && q_n != 4'd0;
    always @(posedge clk) begin
        if (rst) begin
            e_v <= 1'b0;
            q_n <= 4'd0;
            q_rp <= 3'd0;
            q_wp <= 3'd0;
        end else begin
            if (next) e_v <= q_n != 4'd0;
            q_n <= q_n + {3'b0, push} - {3'b0, pop};
            if (push) q_wp <= q_wp + 3'd1;
            if (pop) q_rp <= q_rp + 3'd1;
        end
        if (push) q[q_wp] <= {h_word, h_rest, h_last || ends_empty, h_col, h_tag};
        if (pop) {e_word, e_rest, e_last, e_col, e_tag} <= q[q_rp];
        else if (out) begin
            e_word <= e_rest;
            e_rest <= e_rest & (e_rest - 64'd1);
        end
    end
endmodule
