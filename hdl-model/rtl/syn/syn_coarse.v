// Synthesis harness of the compact datapath's coarse edge units (`coarse_edge.v`, one set-up
// unit's edge words, and `coarse_test.v`, one lane's test), as `syn_rotator.v` is the rotator's:
// their inputs from a register chain shifted in from one pin, their outputs folded into one
// registered pin. Figures: `cargo xtask rtl`.
module syn_coarse (
    input  wire clk,
    input  wire sin,
    output reg  sout
);
    localparam integer N = 2 * 99 + 3 + 1 + 54 + 216 + 4 + 1 + 2;
    reg [N-1:0] c;
    always @(posedge clk) c <= {c[N-2:0], sin};

    wire        e_valid, t_valid;
    wire [53:0] e_words;
    wire [3:0]  e_kappa;
    wire        t_decided, t_inside;
    wire [2:0]  t_undecided;
    coarse_edge edge_unit (
        .clk(clk), .in_valid(c[0]), .in_u(c[99:1]), .in_v(c[198:100]), .in_shift(c[201:199]),
        .in_negate(c[202]), .out_valid(e_valid), .out_words(e_words), .out_kappa(e_kappa),
        /* verilator lint_off PINCONNECTEMPTY */ // a set-up unit's reach takes it
        .out_u18()
        /* verilator lint_on PINCONNECTEMPTY */);
    coarse_test test_unit (
        .clk(clk), .in_valid(c[203]), .in_d(c[257:204]), .in_words(c[473:258]),
        .in_kappa(c[477:474]), .in_quad(c[478]), .out_valid(t_valid), .out_decided(t_decided),
        .out_inside(t_inside), .out_undecided(t_undecided));
    always @(posedge clk)
        sout <= ^{e_valid, e_words, e_kappa, t_valid, t_decided, t_inside, t_undecided};
endmodule
