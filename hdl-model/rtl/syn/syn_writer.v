// Synthesis harness of a bank's bitmap writer (`bitmap_writer.v`), as `syn_horizon.v` is the
// horizon filter's: its inputs from a register chain shifted in from one pin, its write port,
// valid bits and completions registered (the block RAMs' write port registers the words at
// the clock edge as these do), then folded into one registered pin. The block RAMs it writes
// are the bank's bitmaps, counted with the memories, not here. Figures: `cargo xtask rtl`.
module syn_writer (
    input  wire clk,
    input  wire sin,
    output reg  sout
);
    localparam integer N = 1 + 1 + 9 + 2 + 6 + 7 + 4 + 4 + 1 + 1;
    reg [N-1:0] c;
    always @(posedge clk) c <= {c[N-2:0], sin};

    wire        w_valid, w_buf;
    wire [6:0]  w_row;
    wire [2:0]  w_col;
    wire [63:0] w_sector, w_band;
    wire [15:0] w_mask;
    wire [7:0]  valid0, valid1;
    wire [2:0]  ready_n;
    bitmap_writer writer (
        .clk(clk), .rst(c[0]), .a_valid(c[1]), .a_place(c[10:2]), .a_kind(c[12:11]),
        .a_lo(c[18:13]), .a_len(c[25:19]), .a_band_lo(c[29:26]), .a_band_hi(c[33:30]),
        .e_valid(c[34]), .p_start(c[35]), .w_valid(w_valid), .w_buf(w_buf), .w_row(w_row),
        .w_col(w_col), .w_sector(w_sector), .w_mask(w_mask), .w_band(w_band), .valid0(valid0),
        .valid1(valid1), .ready_n(ready_n));
    reg [174:0] q;
    always @(posedge clk) begin
        q <= {w_valid, w_buf, w_row, w_col, w_sector, w_mask, w_band, valid0, valid1, ready_n};
        sout <= ^q;
    end
endmodule
