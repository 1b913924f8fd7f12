// The co-simulation top of the compact datapath's coarse edge units: the set-up unit's edge
// words (`coarse_edge.v`) and a lane's test on them (`coarse_test.v`), side by side on one
// clock, each fed a vector a clock by `coarse_tb.cpp`.
module coarse_top (
    input  wire         clk,
    input  wire         e_valid,
    input  wire [98:0]  e_u,
    input  wire [98:0]  e_v,
    input  wire [2:0]   e_shift,
    input  wire         e_negate,
    output wire         e_out_valid,
    output wire [53:0]  e_words,
    output wire [3:0]   e_kappa,
    input  wire         t_valid,
    input  wire [53:0]  t_d,
    input  wire [215:0] t_words,
    input  wire [3:0]   t_kappa,
    input  wire         t_quad,
    output wire         t_out_valid,
    output wire         t_decided,
    output wire         t_inside,
    output wire [2:0]   t_undecided
);
    coarse_edge edge_unit (
        .clk(clk), .in_valid(e_valid), .in_u(e_u), .in_v(e_v), .in_shift(e_shift),
        .in_negate(e_negate), .out_valid(e_out_valid), .out_words(e_words),
        .out_kappa(e_kappa),
        /* verilator lint_off PINCONNECTEMPTY */ // a set-up unit's reach takes it
        .out_u18()
        /* verilator lint_on PINCONNECTEMPTY */);
    coarse_test test_unit (
        .clk(clk), .in_valid(t_valid), .in_d(t_d), .in_words(t_words), .in_kappa(t_kappa),
        .in_quad(t_quad), .out_valid(t_out_valid), .out_decided(t_decided),
        .out_inside(t_inside), .out_undecided(t_undecided));
endmodule
