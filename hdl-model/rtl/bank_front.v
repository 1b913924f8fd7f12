// The front of one bank's set-up pass (hdl-model/src/intersect/horizon.rs, `PassTiming`): its
// slots' boxes read a slot a clock into the horizon filter (`horizon_filter.v`), the patches
// it keeps queued in a FIFO of 2^FIFO_BITS slot numbers, and the set-up unit's corners read
// from patch memory a clock each, three for a triangle, four for a quad, one for any other
// slot (`intersect::corner_clocks`).
//
// The model counts a pass as if the filter had no latency: the filter takes a slot a clock; a
// patch it keeps enters the FIFO on that clock, once the patch FIFO-size places ahead of it has
// left; the set-up unit takes the FIFO's oldest patch once the one before has had its corners.
// This front keeps those clocks, each HORIZON_LATENCY (9) later, by stopping the whole filter
// (and the box read before it) while its oldest verdict is a kept patch that finds the FIFO
// full and the set-up unit busy: a pipe that stops as one is the model's filter, delayed. A kept
// patch that finds the FIFO empty and the set-up unit free goes to it on the clock of its
// verdict (the FIFO falls through). So a kept patch's first corner address is out 9 clocks
// after the model's clock for its set-up, and its corner, read, CORNER_READ (2) clocks after
// that (c_valid).
//
// Every read from a block RAM takes two clocks, the RAM's and a register after it (BOX_READ):
// an ECP5 block RAM's output comes about 6 ns after its clock, too late for an adder behind it
// at 100 MHz.
//
// A pass begins on the clock after `start` (its origin and axis latched then and carried
// down the pipe with each slot, so the next pass may begin while this one's verdicts are in the
// filter: the model begins it once the set-up units are done). `busy` falls HORIZON_LATENCY
// clocks after the model's pass ends.
//
// The memories are written from outside: a slot's box (24-bit ends, whether it counts for the
// filter: planar, complete and bounded, as the slot box write path (`slot_box.v`) keeps it) and
// its set-up clocks less one; its four corners (Q8.24 words); its normal (Q2.30), read with
// each corner. A pass's tag (its parity, for the set-up unit's two sets of pass registers)
// rides with each of its slots to the corners.
// Verilog-2005, accepted by Verilator and Yosys.
module bank_front #(
    parameter integer SLOT_BITS = 9,
    parameter integer FIFO_BITS = 4
) (
    input  wire                   clk,
    // a slot's box, whether it counts and its set-up clocks less one
    input  wire                   box_we,
    input  wire [SLOT_BITS-1:0]   box_slot,
    input  wire [71:0]            box_lo,
    input  wire [71:0]            box_hi,
    input  wire                   box_boxed,
    input  wire [1:0]             box_clocks,
    // a corner of a slot
    input  wire                   corner_we,
    input  wire [SLOT_BITS+1:0]   corner_addr,  // slot and corner
    input  wire [95:0]            corner_data,
    // a slot's normal
    input  wire                   normal_we,
    input  wire [SLOT_BITS-1:0]   normal_slot,
    input  wire [95:0]            normal_data,
    // a pass over the bank's first `count` slots from origin `o` in a frame with axis `w`
    input  wire                   start,
    input  wire [SLOT_BITS:0]     count,
    input  wire [95:0]            o,
    input  wire [95:0]            w,
    input  wire                   tag,
    // the set-up unit's corners, a clock each, with the slot's normal and the pass's tag
    output reg                    c_valid,
    output reg                    c_planar,     // a triangle's or a quad's
    output reg                    c_pass,
    output reg                    c_last,
    output reg  [SLOT_BITS-1:0]   c_slot,
    output reg  [1:0]             c_corner,
    output reg  [95:0]            c_data,
    output reg  [95:0]            c_normal,
    output wire                   busy
);
    localparam integer PAY = SLOT_BITS + 3;     // a slot, its set-up clocks less one, its tag
    localparam integer DEPTH = 1 << FIFO_BITS;   // held[FIFO_BITS]: the FIFO is full

    reg [146:0] boxes [0:(1 << SLOT_BITS) - 1];
    reg [95:0]  corners [0:(4 << SLOT_BITS) - 1];
    reg [95:0]  normals [0:(1 << SLOT_BITS) - 1];
    always @(posedge clk) if (box_we) boxes[box_slot] <= {box_clocks, box_boxed, box_hi, box_lo};
    always @(posedge clk) if (corner_we) corners[corner_addr] <= corner_data;
    always @(posedge clk) if (normal_we) normals[normal_slot] <= normal_data;

    // ---- the filter's side: the next slot's box read, then seven stages
    wire              f_valid, f_below;
    wire [PAY-1:0]    f_pay;
    reg               full_wait;     // see `adv`, below
    wire              adv = !full_wait;
    reg               issuing;
    reg [SLOT_BITS:0] next, last;
    reg [95:0]        pass_o, pass_w;
    reg               pass_tag;
    wire              read = issuing && adv;
    always @(posedge clk) begin
        if (start) begin
            issuing <= count != 0;
            next <= 0;
            last <= count - 1;
            pass_o <= o;
            pass_w <= w;
            pass_tag <= tag;
        end else if (read) begin
            next <= next + 1;
            issuing <= next != last;
        end
    end
    initial issuing = 1'b0;

    // the box read: the RAM's clock, then its register (what rides along waits beside it)
    reg               ram_valid, rd_valid, ram_tag, rd_tag;
    reg [146:0]       ram_box, rd_box;
    reg [SLOT_BITS-1:0] ram_slot, rd_slot;
    reg [95:0]        ram_o, ram_w, rd_o, rd_w;
    always @(posedge clk) if (adv) begin
        ram_box <= boxes[next[SLOT_BITS-1:0]];
        ram_valid <= read;
        ram_slot <= next[SLOT_BITS-1:0];
        ram_o <= pass_o;
        ram_w <= pass_w;
        ram_tag <= pass_tag;
        rd_box <= ram_box;
        rd_valid <= ram_valid;
        rd_slot <= ram_slot;
        rd_o <= ram_o;
        rd_w <= ram_w;
        rd_tag <= ram_tag;
    end
    initial begin
        ram_valid = 1'b0;
        rd_valid = 1'b0;
    end

    horizon_filter filter (
        .clk(clk), .en(adv), .in_valid(rd_valid), .in_boxed(rd_box[144]),
        .in_lo(rd_box[71:0]), .in_hi(rd_box[143:72]), .in_o(rd_o), .in_w(rd_w),
        .out_valid(f_valid), .out_below(f_below));

    // the slot and its clocks beside the filter's seven stages, and whether each holds a slot
    reg [PAY-1:0] pay [0:6];
    reg [6:0]     pay_valid;
    integer i;
    always @(posedge clk) if (adv) begin
        pay[0] <= {rd_tag, rd_box[146:145], rd_slot};
        pay_valid[0] <= rd_valid;
        for (i = 1; i < 7; i = i + 1) begin
            pay[i] <= pay[i - 1];
            pay_valid[i] <= pay_valid[i - 1];
        end
    end
    initial pay_valid = 7'd0;
    assign f_pay = pay[6];

    // ---- the FIFO and the set-up unit's corners
    reg [PAY-1:0]     fifo [0:DEPTH-1];
    reg [FIFO_BITS-1:0] head, tail;
    reg [FIFO_BITS:0] held;
    reg [1:0]         left;         // corners still to read of the current patch
    reg [1:0]         corner;
    reg [SLOT_BITS-1:0] slot;
    reg               planar, slot_tag;
    // held == 0, kept in a register of its own beside the count: the FIFO's head is chosen by
    // it on the way into the corner RAMs' address, where a compare of the count was a LUT more
    reg               empty;
    initial begin
        head = 0;
        tail = 0;
        held = 0;
        empty = 1'b1;
        left = 0;
    end
    wire kept = f_valid && !f_below;
    wire free = left == 0;
    // the set-up unit takes a patch when free: the FIFO's oldest, or the verdict falling through
    wire pop = free && (!empty || kept);
    wire [PAY-1:0] oldest = empty ? f_pay : fifo[head];
    // the filter stops while a kept verdict finds the FIFO full and the set-up unit busy
    always @* full_wait = kept && held[FIFO_BITS] && !free;
    wire push = kept && adv;
    wire [FIFO_BITS:0] held_next = held + {{FIFO_BITS{1'b0}}, push && !(pop && empty)}
        - {{FIFO_BITS{1'b0}}, pop && !empty};
    always @(posedge clk) begin
        if (push && !(pop && empty)) begin
            fifo[tail] <= f_pay;
            tail <= tail + 1;
        end
        if (pop && !empty) head <= head + 1;
        held <= held_next;
        empty <= held_next == 0;
    end

    // the corner read: the address this clock, the RAM's clock, then its register, with what
    // rides along beside it
    wire [SLOT_BITS-1:0] a_slot = pop ? oldest[SLOT_BITS-1:0] : slot;
    wire [1:0]           a_corner = pop ? 2'd0 : corner;
    wire [1:0]           oldest_left = oldest[SLOT_BITS+1:SLOT_BITS];
    reg                  ram_c_valid, ram_c_last, ram_c_planar, ram_c_pass;
    reg [SLOT_BITS-1:0]  ram_c_slot;
    reg [1:0]            ram_c_corner;
    reg [95:0]           ram_c_data, ram_c_normal;
    always @(posedge clk) begin
        ram_c_valid <= pop || !free;
        ram_c_slot <= a_slot;
        ram_c_corner <= a_corner;
        ram_c_last <= pop ? oldest_left == 2'd0 : left == 2'd1;
        ram_c_planar <= pop ? oldest_left != 2'd0 : planar;
        ram_c_pass <= pop ? oldest[PAY-1] : slot_tag;
        ram_c_data <= corners[{a_slot, a_corner}];
        ram_c_normal <= normals[a_slot];
        c_valid <= ram_c_valid;
        c_slot <= ram_c_slot;
        c_corner <= ram_c_corner;
        c_last <= ram_c_last;
        c_data <= ram_c_data;
        c_normal <= ram_c_normal;
        c_planar <= ram_c_planar;
        c_pass <= ram_c_pass;
        if (pop) begin
            slot <= oldest[SLOT_BITS-1:0];
            left <= oldest_left;
            planar <= oldest_left != 2'd0;
            slot_tag <= oldest[PAY-1];
            corner <= 2'd1;
        end else if (!free) begin
            left <= left - 2'd1;
            corner <= corner + 2'd1;
        end
    end
    initial begin
        ram_c_valid = 1'b0;
        c_valid = 1'b0;
    end

    assign busy = issuing || ram_valid || rd_valid || |pay_valid || !empty || !free;
endmodule
