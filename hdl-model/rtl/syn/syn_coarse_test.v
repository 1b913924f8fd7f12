// Synthesis harness of a compact lane's coarse edge test (`coarse_test.v`), as `syn_rotator.v`
// is the rotator's: its inputs from a register chain shifted in from one pin, its outputs
// folded into one registered pin. The set-up unit's edge words (`coarse_edge.v`) are placed
// inside the set-up unit's harness, so this one holds the lane's test alone and the final
// line counts it once. Figures: `cargo xtask rtl`.
module syn_coarse_test (
    input  wire clk,
    input  wire sin,
    output reg  sout
);
    localparam integer N = 1 + 54 + 216 + 4 + 1;
    reg [N-1:0] c;
    always @(posedge clk) c <= {c[N-2:0], sin};

    wire       t_valid, t_decided, t_inside;
    wire [2:0] t_undecided;
    coarse_test test_unit (
        .clk(clk), .in_valid(c[0]), .in_d(c[54:1]), .in_words(c[270:55]),
        .in_kappa(c[274:271]), .in_quad(c[275]), .out_valid(t_valid), .out_decided(t_decided),
        .out_inside(t_inside), .out_undecided(t_undecided));
    always @(posedge clk) sout <= ^{t_valid, t_decided, t_inside, t_undecided};
endmodule
