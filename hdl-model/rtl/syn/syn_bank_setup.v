// Synthesis harness of a bank's whole set-up pass (`bank_setup.v`: the bank front and the
// set-up unit behind it), as `syn_bank.v` is the front's: its inputs from a register chain
// shifted in from one pin, its outputs folded into one registered pin. Figures: `cargo xtask
// rtl`.
module syn_bank_setup (
    input  wire clk,
    input  wire sin,
    output reg  sout
);
    localparam integer SB = 9;
    localparam integer BOX = 1 + SB + 72 + 72 + 1 + 2;
    localparam integer CORNER = 1 + SB + 2 + 96;
    localparam integer NORMAL = 1 + SB + 96;
    localparam integer N = BOX + CORNER + NORMAL + 1 + SB + 1 + 4 * 96;
    reg [N-1:0] c;
    always @(posedge clk) c <= {c[N-2:0], sin};
    wire [BOX-1:0]    b = c[BOX-1:0];
    wire [CORNER-1:0] k = c[BOX+CORNER-1:BOX];
    wire [NORMAL-1:0] n = c[BOX+CORNER+NORMAL-1:BOX+CORNER];
    wire [N-BOX-CORNER-NORMAL-1:0] p = c[N-1:BOX+CORNER+NORMAL];

    wire        e_valid, p_valid, p_active;
    wire [53:0] e_words;
    wire [3:0]  e_kappa, p_kappa, p_band_lo, p_band_hi;
    wire [1:0]  p_kind;
    wire [5:0]  p_lo;
    wire [6:0]  p_len;
    wire [SB-1:0] p_slot;
    bank_setup #(.SLOT_BITS(SB)) bank (
        .clk(clk),
        .box_we(b[0]), .box_slot(b[SB:1]), .box_lo(b[SB+72:SB+1]), .box_hi(b[SB+144:SB+73]),
        .box_boxed(b[SB+145]), .box_clocks(b[SB+147:SB+146]),
        .corner_we(k[0]), .corner_addr(k[SB+2:1]), .corner_data(k[SB+98:SB+3]),
        .normal_we(n[0]), .normal_slot(n[SB:1]), .normal_data(n[SB+96:SB+1]),
        .start(p[0]), .count(p[SB+1:1]), .origin(p[SB+97:SB+2]), .axis_u(p[SB+193:SB+98]),
        .axis_v(p[SB+289:SB+194]), .axis_w(p[SB+385:SB+290]),
        .out_e_valid(e_valid), .out_e_words(e_words), .out_e_kappa(e_kappa),
        .out_p_valid(p_valid), .out_p_active(p_active), .out_p_kappa(p_kappa),
        .out_p_kind(p_kind), .out_p_lo(p_lo), .out_p_len(p_len), .out_p_band_lo(p_band_lo),
        .out_p_band_hi(p_band_hi), .out_p_slot(p_slot));
    always @(posedge clk)
        sout <= ^{e_valid, e_words, e_kappa, p_valid, p_active, p_kappa, p_kind, p_lo, p_len,
                  p_band_lo, p_band_hi, p_slot};
endmodule
