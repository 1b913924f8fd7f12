// The multipliers' testbench top: `array_mul.v` at the shapes the area proxy maps to it (18 ×
// 18 unregistered, 34 × 34 and 26 × 64 with a register every three rows) and `const_mul.v` (the
// CORDIC gain stage's product by 1/K_24 at 32 bits unregistered and 16 registered, as the gain
// stage has it), fed a vector a clock by
// `mul_tb.cpp`, which checks each product against the integer one after the unit's latency.
module mul_top (
    input  wire               clk,
    input  wire signed [17:0] a18,
    input  wire signed [17:0] b18,
    output wire signed [35:0] p18,
    input  wire signed [33:0] a34,
    input  wire signed [33:0] b34,
    output wire signed [67:0] p34,
    input  wire signed [25:0] a26,
    input  wire signed [63:0] b64,
    output wire signed [89:0] p90,
    input  wire signed [31:0] x32,
    output wire signed [63:0] k32,
    input  wire signed [15:0] x16,
    output wire signed [31:0] k16
);
    array_mul #(.A(18), .B(18), .STAGE(0)) m18 (.clk(clk), .a(a18), .b(b18), .p(p18));
    array_mul #(.A(34), .B(34), .STAGE(3)) m34 (.clk(clk), .a(a34), .b(b34), .p(p34));
    array_mul #(.A(26), .B(64), .STAGE(3)) m90 (.clk(clk), .a(a26), .b(b64), .p(p90));
    const_mul #(.W(32), .C(32'h26dd_3b6a)) c32 (.clk(clk), .x(x32), .p(k32));
    const_mul #(.W(16), .C(16'h26dd), .REG(1)) c16 (.clk(clk), .x(x16), .p(k16));
endmodule
