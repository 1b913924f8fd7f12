// Synthesis harness of the angle unit (`frame_unit.v`) for place and route figures, as
// `syn_rotator.v` is the rotator's: its inputs from a register chain shifted in from one pin, its
// outputs folded into one registered pin. Figures: `cargo xtask rtl`.
module syn_frame #(
    parameter integer ITER = 20,
    parameter integer W = 24
) (
    input  wire clk,
    input  wire rst,
    input  wire sin,
    output reg  sout
);
    localparam integer N = 6 * W + 2;
    reg [N-1:0] c;
    always @(posedge clk) c <= {c[N-2:0], sin};

    wire busy, done;
    wire [W-1:0] psi, theta, phi;
    frame_unit #(.ITER(ITER), .W(W)) dut (
        .clk(clk), .rst(rst), .start(c[0] && !busy), .clear(1'b0), .pairs(c[1]), .w1(c[W+1:2]),
        .w2(c[2*W+1:W+2]), .w3(c[3*W+1:2*W+2]), .w4(c[4*W+1:3*W+2]), .w5(c[5*W+1:4*W+2]),
        .w6(c[6*W+1:5*W+2]), .busy(busy), .done(done), .psi(psi), .theta(theta), .phi(phi));
    always @(posedge clk) sout <= ^{busy, done, psi, theta, phi};
endmodule
