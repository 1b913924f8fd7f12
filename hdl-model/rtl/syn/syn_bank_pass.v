// Synthesis harness of a bank's set-up pass into its bitmaps (`bank_pass.v`: `bank_setup.v`
// feeding `bitmap_writer.v`), as `syn_bank_setup.v` and `syn_writer.v` are theirs: its inputs
// from a register chain shifted in from one pin; its edge words and the writer's write port,
// valid bits and completions registered (the block RAMs' write port registers the words at the
// clock edge as these do), then folded into one registered pin. Figures: `cargo xtask rtl`.
module syn_bank_pass (
    input  wire clk,
    input  wire sin,
    output reg  sout
);
    localparam integer SB = 9;
    localparam integer BOX = 1 + SB + 72 + 72 + 1 + 2;
    localparam integer CORNER = 1 + SB + 2 + 96;
    localparam integer NORMAL = 1 + SB + 96;
    localparam integer N = BOX + CORNER + NORMAL + 1 + SB + 1 + 4 * 96 + 2;
    reg [N-1:0] c;
    always @(posedge clk) c <= {c[N-2:0], sin};
    wire [BOX-1:0]    b = c[BOX-1:0];
    wire [CORNER-1:0] k = c[BOX+CORNER-1:BOX];
    wire [NORMAL-1:0] n = c[BOX+CORNER+NORMAL-1:BOX+CORNER];
    wire [N-BOX-CORNER-NORMAL-1:0] p = c[N-1:BOX+CORNER+NORMAL];

    wire        e_valid, p_valid;
    wire [53:0] e_words;
    wire [3:0]  e_kappa, p_kappa;
    /* verilator lint_off UNUSEDSIGNAL */ // the writer's input, an output for the co-simulation
    wire        a_valid;
    wire [SB-1:0] a_place;
    wire [1:0]  a_kind;
    wire [5:0]  a_lo;
    wire [6:0]  a_len;
    wire [3:0]  a_band_lo, a_band_hi;
    /* verilator lint_on UNUSEDSIGNAL */
    wire        w_valid, w_buf;
    wire [6:0]  w_row;
    wire [2:0]  w_col;
    wire [63:0] w_sector, w_band;
    wire [15:0] w_mask;
    wire [7:0]  valid0, valid1;
    wire [2:0]  ready_n;
    bank_pass #(.SLOT_BITS(SB)) bank (
        .clk(clk), .rst(p[SB+386]),
        .box_we(b[0]), .box_slot(b[SB:1]), .box_lo(b[SB+72:SB+1]), .box_hi(b[SB+144:SB+73]),
        .box_boxed(b[SB+145]), .box_clocks(b[SB+147:SB+146]),
        .corner_we(k[0]), .corner_addr(k[SB+2:1]), .corner_data(k[SB+98:SB+3]),
        .normal_we(n[0]), .normal_slot(n[SB:1]), .normal_data(n[SB+96:SB+1]),
        .start(p[0]), .count(p[SB+1:1]), .origin(p[SB+97:SB+2]), .axis_u(p[SB+193:SB+98]),
        .axis_v(p[SB+289:SB+194]), .axis_w(p[SB+385:SB+290]), .pass_end(p[SB+387]),
        .out_e_valid(e_valid), .out_e_words(e_words), .out_e_kappa(e_kappa),
        .out_p_valid(p_valid), .out_p_kappa(p_kappa),
        .a_valid(a_valid), .a_place(a_place), .a_kind(a_kind), .a_lo(a_lo), .a_len(a_len),
        .a_band_lo(a_band_lo), .a_band_hi(a_band_hi),
        .w_valid(w_valid), .w_buf(w_buf), .w_row(w_row), .w_col(w_col), .w_sector(w_sector),
        .w_mask(w_mask), .w_band(w_band), .valid0(valid0), .valid1(valid1), .ready_n(ready_n));
    reg [238:0] q;
    always @(posedge clk) begin
        q <= {e_valid, e_words, e_kappa, p_valid, p_kappa, w_valid, w_buf, w_row, w_col,
              w_sector, w_mask, w_band, valid0, valid1, ready_n};
        sout <= ^q;
    end
endmodule
