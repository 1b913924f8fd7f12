// Synthesis harness of the rotator for place and route figures: an FPGA part has far fewer pins
// than the rotator has port bits, so its inputs come from a register chain shifted in from one
// pin and its outputs are folded into one registered pin. The harness adds one register per
// input bit and an XOR tree; every register of the unit itself is kept (its inputs are not
// constant and every output bit reaches the pin). Figures: `cargo xtask rtl`.
module syn_rotator #(
    parameter integer ITER = 20,
    parameter integer W = 24
) (
    input  wire clk,
    input  wire rst,
    input  wire sin,
    output reg  sout
);
    localparam integer N = 6 * 32 + 2;
    reg [N-1:0] chain;
    always @(posedge clk) chain <= {chain[N-2:0], sin};

    wire out_valid;
    wire [31:0] dx, dy, dz;
    wire [6:0] tag;
    rotator #(.ITER(ITER), .W(W)) dut (
        .clk(clk), .rst(rst), .in_valid(chain[0]),
        .in_dx(chain[32:1]), .in_dy(chain[64:33]), .in_dz(chain[96:65]),
        .in_psi(chain[128:97]), .in_theta(chain[160:129]), .in_phi(chain[192:161]),
        .in_bypass(chain[193]),
        .out_valid(out_valid), .out_dx(dx), .out_dy(dy), .out_dz(dz), .out_tag(tag));
    always @(posedge clk) sout <= ^{out_valid, dx, dy, dz, tag};
endmodule
