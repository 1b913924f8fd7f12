// An adder-subtractor whose direction is data: s = a + b, or a - b when `sub` is set (the
// CORDIC's micro-rotations, cordic_pipe.v). Written as a sum with the operand inverted by `sub`,
// Yosys builds the inversion as a LUT4 a bit in front of the carry chain, because its arithmetic
// cell takes the inversion as a constant only; an ECP5 carry cell (CCU2C) has a LUT4 a bit of its
// own with a spare input, where the mapping of Yosys's `$alu` cell puts the inversion when it
// is data. So for synthesis the cell is instantiated directly (read with `read_verilog -icells`):
// half the LUT4s of the written form. The written form is the one Verilator co-simulates; the
// two are proved equal after mapping to the ECP5's cells (`cargo xtask rtl --prove`).
module add_sub #(
    parameter integer W = 32
) (
    input  wire [W-1:0] a,
    input  wire [W-1:0] b,
    input  wire         sub,
    output wire [W-1:0] s
);
`ifdef SYNTHESIS
    // the cell's other outputs (a ^ b and the carries) are not used
    wire [W-1:0] unused_x, unused_co;
    \$alu #(
        .A_SIGNED(0), .B_SIGNED(0), .A_WIDTH(W), .B_WIDTH(W), .Y_WIDTH(W)
    ) alu (
        .A(a), .B(b), .BI(sub), .CI(sub), .X(unused_x), .Y(s), .CO(unused_co)
    );
`else
    assign s = a + (b ^ {W{sub}}) + {{(W - 1){1'b0}}, sub};
`endif
endmodule
