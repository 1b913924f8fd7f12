// One bank's bitmap writer (hdl-model/src/intersect/bitmap_write.rs, `ColumnWriter`): the set-up
// answers of a pass into the candidate bitmaps the lanes walk, a column of 64 slots at a time.
//
// An answer sets its slot's bit in a word of each sector row of its wedge (every row for a
// wedge of every sector) and of each band row of its bands, and ORs its bands into its sectors'
// mask words. The rows are block RAM outside this module, double-buffered (a pass's buffer, its
// parity); the lanes read the other buffer on the second port, so this writer has one port and
// cannot read-modify-write there. So:
//
// - Answers wait in a FIFO of 2^FIFO_BITS (block RAM; two a slot, as the model assumes), in
//   order, each tagged with its pass's buffer. An answer below the horizon sets nothing and does
//   not enter. The FIFO's head comes from a queue of four registers behind the block RAM (the
//   read is issued without waiting for this clock's take, which would be too slow), so an
//   answer is the writer's FIFO_LATENCY (4) clocks after it is presented at the earliest: the
//   block RAM's write, its read, the register after it (the block RAM's output comes too late
//   in its clock for logic behind it) and the entry's rows worked out into the queue. A pass's
//   end (`e_valid`, alone or with the pass's last answer) is seen as late, as the count of
//   answers before it.
// - The gatherer takes the head once it is idle and writes the open column's words in
//   distributed RAM, a row a clock, sector word, mask word and band word side by side: an
//   answer holds it for the more of its sector rows and its band rows (`row_writes`).
// - An answer of another column closes the open one: its copy is asked of the copy engine on
//   that clock, and the new column gathers in the other copy of the distributed RAM, once that
//   copy's own last column has been copied. A pass's end closes the open column the same way
//   once the gatherer has written every answer before it.
// - The copy engine copies a closed column into the block RAMs a row a clock (COPY rows: the
//   more of the sector and band rows), clearing the distributed RAM as it reads it, and sets
//   the column's valid bit at its last row; copies run in order, one at a time. `p_start`
//   clears the valid bits of the buffer the next pass fills, so that the walk reads the
//   columns that pass does not write as zero.
// - Every decision above is taken on registered state, and what it writes or copies is done
//   on the next clock (WRITE_LATENCY, 1), the distributed RAM's read-modify-write alone in its
//   clock: so the block RAMs' write port (`w_*`) shows a copy's rows a clock after the model's
//   clocks for them, and `ready_n`, the passes whose every answer is in the block RAMs, counts
//   a pass on the clock after its last copy's last row (the model's `close`).
//
// The clocks are the model's exactly, checked by rtl/tb/writer_tb.cpp.
// Verilog-2005, accepted by Verilator and Yosys.
module bitmap_writer #(
    parameter integer SECTORS = 32,
    parameter integer BANDS = 16,
    parameter integer SLOT_BITS = 9,
    parameter integer FIFO_BITS = 10
) (
    input  wire                 clk,
    input  wire                 rst,
    // a set-up answer: the slot's place in the bank, its wedge (kind 0 below the horizon, 1
    // every sector, 2 sectors lo .. lo + len - 1 modulo SECTORS) and its bands
    input  wire                 a_valid,
    input  wire [SLOT_BITS-1:0] a_place,
    input  wire [1:0]           a_kind,
    /* verilator lint_off UNUSEDSIGNAL */ // below 64 sectors their top bits are not used
    input  wire [5:0]           a_lo,
    input  wire [6:0]           a_len,
    /* verilator lint_on UNUSEDSIGNAL */
    input  wire [3:0]           a_band_lo,
    input  wire [3:0]           a_band_hi,
    // the pass's end, after (or with) its last answer
    input  wire                 e_valid,
    // a pass begins: the valid bits of the buffer it fills are cleared
    input  wire                 p_start,
    // the block RAMs' write port: row `w_row` of buffer `w_buf`, column `w_col` (the sector
    // row's word and mask word below SECTORS, the band row's word below BANDS)
    output wire                 w_valid,
    output wire                 w_buf,
    output wire [6:0]           w_row,
    output wire [COL_BITS-1:0]  w_col,
    output wire [63:0]          w_sector,
    output wire [BANDS-1:0]     w_mask,
    output wire [63:0]          w_band,
    // the columns of each buffer this buffer's pass has written
    output reg  [COLS-1:0]      valid0,
    output reg  [COLS-1:0]      valid1,
    // passes complete on this clock
    output wire [2:0]           ready_n
);
    localparam integer COL_BITS = SLOT_BITS - 6;
    localparam integer COLS = 1 << COL_BITS;
    localparam integer COPY = SECTORS > BANDS ? SECTORS : BANDS;
    localparam integer SB = $clog2(SECTORS);
    // a FIFO entry: buffer, place, every sector, lo, len, bands and its rows (`row_writes`,
    // worked out as it enters: 36 bits, two block RAMs wide, at 32 sectors)
    localparam integer E = 1 + SLOT_BITS + 1 + SB + (SB + 1) + 4 + 4 + (SB + 1);
    localparam [6:0] S7 = SECTORS[6:0];
    localparam [6:0] B7 = BANDS[6:0];
    localparam [6:0] C7 = COPY[6:0];

    // ---- the FIFO: block RAM, a register, then a queue of four registers (its head) ----
    reg  [E-1:0] fifo [0:(1<<FIFO_BITS)-1];
    reg  [FIFO_BITS-1:0] wp, rp;
    reg  [FIFO_BITS:0] stored;
    reg  [E-1:0] rdata, rdata_r;  // the block RAM's output, and the register after it
    reg          rd_v, rd_v2;
    // the queue's entries with what else the gatherer needs of their reach worked out as they
    // enter: their sector rows, band rows, first sector row and mask word
    localparam integer Q = E + (SB + 1) + 5 + SB + BANDS;
    reg  [Q-1:0] oq0, oq1, oq2, oq3;
    reg  [2:0]   oq_n;
    reg          push_buf;  // the buffer of the pass whose answers are coming in
    wire         pop;

    wire push = a_valid && a_kind != 2'd0;
    wire [SB:0]  a_rows;
    wire [E-1:0] din = {push_buf, a_place, a_kind == 2'd1, a_lo[SB-1:0], a_len[SB:0], a_band_lo,
                        a_band_hi, a_rows};
    row_writes #(.SECTORS(SECTORS)) rw (.full(a_kind == 2'd1), .len(a_len[SB:0]),
        .band_lo(a_band_lo), .band_hi(a_band_hi), .rows(a_rows));
    // a read is issued while the queue has room for it, whether or not the head leaves now
    wire issue = stored != 0 && oq_n + {2'b0, rd_v} + {2'b0, rd_v2} < 3'd4;
    wire [2:0] kept = oq_n - {2'b0, pop};
    // an entry's fields: buffer, place, every sector, lo, len, band_lo, band_hi, rows
    wire [Q-1:0] rq;
    wire         r_full = rdata_r[E-SLOT_BITS-2];
    wire [SB-1:0] r_lo = rdata_r[E-SLOT_BITS-3 -: SB];
    wire [SB:0]  r_len = rdata_r[E-SLOT_BITS-SB-3 -: SB + 1];
    wire [3:0]   r_blo = rdata_r[SB + 8 -: 4];
    wire [3:0]   r_bhi = rdata_r[SB + 4 -: 4];
    assign rq[Q-1 -: E] = rdata_r;
    assign rq[Q-E-1 -: SB + 1] = r_full ? S7[SB:0] : r_len;
    assign rq[Q-E-SB-2 -: 5] = r_bhi < r_blo ? 5'd0 : {1'b0, r_bhi} - {1'b0, r_blo} + 5'd1;
    assign rq[BANDS + SB - 1 -: SB] = r_full ? {SB{1'b0}} : r_lo;
    assign rq[BANDS-1:0] = ({BANDS{1'b1}} << r_blo) & ~(({BANDS{1'b1}} << r_bhi) << 1);

    always @(posedge clk) begin
        if (push) fifo[wp] <= din;
        if (issue) rdata <= fifo[rp];
    end

    always @(posedge clk) begin
        if (rst) begin
            wp <= 0;
            rp <= 0;
            stored <= 0;
            rd_v <= 1'b0;
            rd_v2 <= 1'b0;
            oq_n <= 3'd0;
            push_buf <= 1'b0;
        end else begin
            if (push) wp <= wp + 1'b1;
            if (issue) rp <= rp + 1'b1;
            stored <= stored + {{FIFO_BITS{1'b0}}, push} - {{FIFO_BITS{1'b0}}, issue};
            rd_v <= issue;
            rd_v2 <= rd_v;
            oq_n <= kept + {2'b0, rd_v2};
            if (e_valid) push_buf <= ~push_buf;
        end
        if (rd_v) rdata_r <= rdata;
        if (pop) begin
            oq0 <= oq1;
            oq1 <= oq2;
            oq2 <= oq3;
        end
        if (rd_v2) begin
            case (kept[1:0])
                2'd0: oq0 <= rq;
                2'd1: oq1 <= rq;
                2'd2: oq2 <= rq;
                default: oq3 <= rq;
            endcase
        end
    end

    wire                 h_valid = oq_n != 3'd0;
    wire                 h_buf = oq0[Q-1];
    wire [SLOT_BITS-1:0] h_place = oq0[Q-2 -: SLOT_BITS];
    wire [SB:0]          h_rows = oq0[Q-E+SB -: SB + 1];  // the entry's last field
    wire [SB:0]          h_sectors = oq0[Q-E-1 -: SB + 1];
    wire [4:0]           h_bands = oq0[Q-E-SB-2 -: 5];
    wire [SB-1:0]        h_first = oq0[BANDS + SB - 1 -: SB];
    wire [BANDS-1:0]     h_mask = oq0[BANDS-1:0];
    wire [3:0]           h_blo = oq0[Q-E+SB+8 -: 4];

    // ---- the passes' ends: each the count of answers before it, seen as late as an answer ----
    reg  [FIFO_BITS:0] pushed, taken;       // answers in, answers taken (modulo 2^(FIFO_BITS+1))
    reg  [FIFO_BITS:0] e_ptr1, e_ptr2, e_ptr3;
    reg                e_d1, e_d2, e_d3;
    reg  [FIFO_BITS:0] end_ptr [0:3];       // the ends seen, oldest first
    reg  [2:0]         ends;
    wire [FIFO_BITS:0] pushed_now = pushed + {{FIFO_BITS{1'b0}}, push};
    wire [2:0]         ends_left;           // the ends still waiting after this clock's
    wire [1:0]         end_at = ends_left[1:0];

    // ---- the gatherer: what it takes and closes on this clock ----
    reg                 open;      // a column is open
    reg [COL_BITS-1:0]  open_col;
    reg                 open_cb;   // the distributed-RAM copy it gathers in
    reg                 open_buf;
    reg                 next_cb;   // the copy the next column gathers in
    reg [SB:0]          left;      // rows still to write of the current answer
    reg [SB:0]          s_left;    // its sector rows still to write
    reg [4:0]           b_left;    // its band rows still to write
    reg [SB-1:0]        s_next;    // its next sector row (modulo SECTORS, by its width)
    reg [3:0]           b_next;    // its next band row
    reg [5:0]           cur_place;
    reg [BANDS-1:0]     cur_mask;
    wire                cb_busy0, cb_busy1;

    reg  idle;                     // no rows left to write (left is 0)
    // an end is reached once the gatherer has written every answer before it, one a clock (a
    // second end waiting on the same answers, a pass's with none above the horizon, waits a
    // clock more; it waits for the first one's copy anyway)
    wire end0 = idle && ends != 3'd0 && end_ptr[0] == taken;
    assign ends_left = ends - {2'b0, end0};
    wire open_now = open && !end0;
    wire h_col_same = open_now && open_col == h_place[SLOT_BITS-1:6] && open_buf == h_buf;
    wire cb_free = next_cb ? !cb_busy1 : !cb_busy0;
    // the head taken this clock: an answer of the open column, or one that opens a column in a
    // free copy
    wire take = idle && h_valid && (h_col_same || cb_free);
    assign pop = take;
    // a close this clock: an end, or an answer of another column than the open one's
    wire close = (end0 && open) || (idle && h_valid && open_now && !h_col_same);

    // the row to write: the taken answer's first, or the current answer's next
    wire        g_we = take || !idle;
    wire        g_cb = take ? (h_col_same ? open_cb : next_cb) : open_cb;
    wire        g_s = take || s_left != 0;
    wire        g_b = take ? h_bands != 5'd0 : b_left != 5'd0;
    wire [SB-1:0] g_srow = take ? h_first : s_next;
    wire [3:0]  g_brow = take ? h_blo : b_next;
    wire [5:0]  g_bit = take ? h_place[5:0] : cur_place;
    wire [BANDS-1:0] g_mask = take ? h_mask : cur_mask;

    always @(posedge clk) begin
        if (rst) begin
            open <= 1'b0;
            next_cb <= 1'b0;
            left <= 0;
            idle <= 1'b1;
            pushed <= 0;
            taken <= 0;
            e_d1 <= 1'b0;
            e_d2 <= 1'b0;
            e_d3 <= 1'b0;
            ends <= 3'd0;
        end else begin
            if (close) open <= 1'b0;
            if (take) begin
                if (!h_col_same) begin
                    open <= 1'b1;
                    open_col <= h_place[SLOT_BITS-1:6];
                    open_cb <= next_cb;
                    open_buf <= h_buf;
                    next_cb <= ~next_cb;
                end
                left <= h_rows - 1'b1;
                idle <= h_rows == 1;
                s_left <= h_sectors - 1'b1;
                b_left <= h_bands == 5'd0 ? 5'd0 : h_bands - 5'd1;
                s_next <= h_first + 1'b1;
                b_next <= h_blo + 4'd1;
                cur_place <= h_place[5:0];
                cur_mask <= h_mask;
            end else if (!idle) begin
                left <= left - 1'b1;
                idle <= left == 1;
                if (s_left != 0) s_left <= s_left - 1'b1;
                if (b_left != 5'd0) b_left <= b_left - 5'd1;
                s_next <= s_next + 1'b1;
                b_next <= b_next + 4'd1;
            end
            pushed <= pushed_now;
            if (take) taken <= taken + 1'b1;
            // an end is seen four clocks after it is presented (in the queue from the fourth),
            // as an answer is at the earliest
            e_d1 <= e_valid;
            e_ptr1 <= pushed_now;
            e_d2 <= e_d1;
            e_ptr2 <= e_ptr1;
            e_d3 <= e_d2;
            e_ptr3 <= e_ptr2;
            ends <= ends_left + {2'b0, e_d3};
        end
        // the ends queue: the reached one leaves, the one seen now joins behind the others
        if (end0) begin
            end_ptr[0] <= end_ptr[1];
            end_ptr[1] <= end_ptr[2];
            end_ptr[2] <= end_ptr[3];
        end
        if (e_d3) end_ptr[end_at] <= e_ptr3;
    end

    // ---- the copy engine: what it copies on this clock ----
    reg                pend0, pend1;          // a closed column waits in copy 0, 1
    reg [COL_BITS-1:0] pend_col0, pend_col1;
    reg                pend_buf0, pend_buf1;
    reg                busy;
    reg                c_cb;                  // the copy being (or next to be) copied
    reg [6:0]          row;
    reg [2:0]          issued, done;          // copies asked, copies done (modulo 8)

    // a close asks for the copy the open column gathers in
    wire ask0 = close && !open_cb;
    wire ask1 = close && open_cb;
    wire waiting = c_cb ? (pend1 || ask1) : (pend0 || ask0);
    wire start = !busy && waiting;
    wire active = busy || start;
    wire [6:0] c_row = start ? 7'd0 : row;
    wire last = busy && row == C7 - 7'd1;  // a copy takes more than one clock
    wire [COL_BITS-1:0] c_col = c_cb ? (pend1 ? pend_col1 : open_col) :
                                       (pend0 ? pend_col0 : open_col);
    wire c_buf = c_cb ? (pend1 ? pend_buf1 : open_buf) : (pend0 ? pend_buf0 : open_buf);
    assign cb_busy0 = pend0 || (busy && !c_cb);
    assign cb_busy1 = pend1 || (busy && c_cb);

    always @(posedge clk) begin
        if (rst) begin
            pend0 <= 1'b0;
            pend1 <= 1'b0;
            busy <= 1'b0;
            c_cb <= 1'b0;
            issued <= 3'd0;
            done <= 3'd0;
        end else begin
            if (ask0) begin
                pend0 <= 1'b1;
                pend_col0 <= open_col;
                pend_buf0 <= open_buf;
            end
            if (ask1) begin
                pend1 <= 1'b1;
                pend_col1 <= open_col;
                pend_buf1 <= open_buf;
            end
            if (close) issued <= issued + 3'd1;
            if (start) busy <= 1'b1;
            if (start) row <= 7'd1;
            else if (busy) row <= row + 7'd1;
            if (last) begin
                busy <= 1'b0;
                c_cb <= ~c_cb;
                done <= done + 3'd1;
                if (c_cb) pend1 <= 1'b0;
                else pend0 <= 1'b0;
            end
        end
    end

    // ---- the next clock's work, registered: a row gathered, a row copied ----
    reg                 gw_s, gw_b;            // the gatherer writes a sector row, a band row
    reg                 gw_cb;
    reg [SB-1:0]        gw_srow;  // SB = log2 SECTORS
    reg [3:0]           gw_brow;
    reg [5:0]           gw_bit;
    reg [BANDS-1:0]     gw_mask;
    reg                 cw, cw_cb, cw_buf, cw_last;
    reg [6:0]           cw_row;
    reg [COL_BITS-1:0]  cw_col;

    always @(posedge clk) begin
        if (rst) begin
            gw_s <= 1'b0;
            gw_b <= 1'b0;
            cw <= 1'b0;
        end else begin
            gw_s <= g_we && g_s;
            gw_b <= g_we && g_b;
            cw <= active;
        end
        gw_cb <= g_cb;
        gw_srow <= g_srow;
        gw_brow <= g_brow;
        gw_bit <= g_bit;
        gw_mask <= g_mask;
        cw_cb <= c_cb;
        cw_buf <= c_buf;
        cw_last <= last;
        cw_row <= c_row;
        cw_col <= c_col;
    end

    // ---- the distributed RAM: two copies of a column's sector, mask and band words ----
    reg [63:0]      sec0 [0:SECTORS-1];
    reg [63:0]      sec1 [0:SECTORS-1];
    reg [BANDS-1:0] msk0 [0:SECTORS-1];
    reg [BANDS-1:0] msk1 [0:SECTORS-1];
    reg [63:0]      bnd0 [0:BANDS-1];
    reg [63:0]      bnd1 [0:BANDS-1];

    // each copy is the gatherer's or the copy engine's on a clock, never both
    wire          e0 = cw && !cw_cb;
    wire          e1 = cw && cw_cb;
    wire [SB-1:0] sa0 = e0 ? cw_row[SB-1:0] : gw_srow;
    wire [SB-1:0] sa1 = e1 ? cw_row[SB-1:0] : gw_srow;
    wire [3:0]    ba0 = e0 ? cw_row[3:0] : gw_brow;
    wire [3:0]    ba1 = e1 ? cw_row[3:0] : gw_brow;
    wire [63:0]      s0 = sec0[sa0], s1 = sec1[sa1];
    wire [BANDS-1:0] m0 = msk0[sa0], m1 = msk1[sa1];
    wire [63:0]      b0 = bnd0[ba0], b1 = bnd1[ba1];
    wire c_sec = cw_row < S7;
    wire c_bnd = cw_row < B7;
    wire [63:0] gw_word = 64'd1 << gw_bit;
    wire gs0 = gw_s && !gw_cb, gs1 = gw_s && gw_cb;
    wire gb0 = gw_b && !gw_cb, gb1 = gw_b && gw_cb;

    always @(posedge clk) begin
        if ((e0 && c_sec) || gs0) begin
            sec0[sa0] <= e0 ? 64'd0 : s0 | gw_word;
            msk0[sa0] <= e0 ? {BANDS{1'b0}} : m0 | gw_mask;
        end
        if ((e1 && c_sec) || gs1) begin
            sec1[sa1] <= e1 ? 64'd0 : s1 | gw_word;
            msk1[sa1] <= e1 ? {BANDS{1'b0}} : m1 | gw_mask;
        end
        if ((e0 && c_bnd) || gb0) bnd0[ba0] <= e0 ? 64'd0 : b0 | gw_word;
        if ((e1 && c_bnd) || gb1) bnd1[ba1] <= e1 ? 64'd0 : b1 | gw_word;
    end

    assign w_valid = cw;
    assign w_buf = cw_buf;
    assign w_row = cw_row;
    assign w_col = cw_col;
    assign w_sector = cw_cb ? s1 : s0;
    assign w_mask = cw_cb ? m1 : m0;
    assign w_band = cw_cb ? b1 : b0;

    // ---- valid bits, and the passes done ----
    reg start_buf;  // the buffer the next pass fills
    always @(posedge clk) begin
        if (rst) begin
            valid0 <= {COLS{1'b0}};
            valid1 <= {COLS{1'b0}};
            start_buf <= 1'b0;
        end else begin
            if (p_start) begin
                start_buf <= ~start_buf;
                if (start_buf) valid1 <= {COLS{1'b0}};
                else valid0 <= {COLS{1'b0}};
            end
            if (cw_last && !cw_buf) valid0[cw_col] <= 1'b1;
            if (cw_last && cw_buf) valid1[cw_col] <= 1'b1;
        end
    end

    // A pass's end waits for the copies asked up to it (the one it asks included), at most two
    // (one copying, one waiting). A pass is complete on the clock after the end is reached with
    // nothing to wait for, or after its last copy's last row is written (a clock after the
    // copy engine's last decision for it): `ready_n` counts them.
    wire [2:0] need = issued + {2'b0, close} - done;
    wire [2:0] now_n = {2'b0, end0 && need == 3'd0};
    wire [2:0] one_n = {2'b0, end0 && need == 3'd1};
    wire [2:0] two_n = {2'b0, end0 && need == 3'd2};
    reg  [2:0] ready_reg, wait1, wait2;  // complete after this clock; waiting for one copy, two
    reg  [2:0] ready_out;
    assign ready_n = ready_out;

    always @(posedge clk) begin
        if (rst) begin
            ready_reg <= 3'd0;
            wait1 <= 3'd0;
            wait2 <= 3'd0;
            ready_out <= 3'd0;
        end else begin
            ready_out <= ready_reg + now_n;
            if (last) begin
                ready_reg <= wait1 + one_n;
                wait1 <= wait2 + two_n;
                wait2 <= 3'd0;
            end else begin
                ready_reg <= 3'd0;
                wait1 <= wait1 + one_n;
                wait2 <= wait2 + two_n;
            end
        end
    end
endmodule

// An answer's row writes for the bitmap writer (`bitmap_write::row_writes`): the more of its
// sector rows (every sector's, or `len`) and its band rows.
module row_writes #(
    parameter integer SECTORS = 32
) (
    input  wire                         full,
    input  wire [$clog2(SECTORS):0]     len,
    input  wire [3:0]                   band_lo,
    input  wire [3:0]                   band_hi,
    output wire [$clog2(SECTORS):0]     rows
);
    localparam integer SB = $clog2(SECTORS);
    localparam [SB:0] S = SECTORS[SB:0];
    wire [4:0]  bands = band_hi < band_lo ? 5'd0 : {1'b0, band_hi} - {1'b0, band_lo} + 5'd1;
    wire [SB:0] sectors = full ? S : len;
    wire [7:0]  b8 = {3'b0, bands};
    wire [7:0]  s8 = {{(7 - SB){1'b0}}, sectors};
    /* verilator lint_off UNUSEDSIGNAL */ // its top bits are zero
    wire [7:0]  wide = b8 > s8 ? b8 : s8;
    /* verilator lint_on UNUSEDSIGNAL */
    assign rows = wide[SB:0];
endmodule
