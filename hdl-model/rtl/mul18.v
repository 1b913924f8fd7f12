// A registered product of two signed words of up to 18 bits, p <= a * b on each clock with
// `ce`, on one ECP5 multiplier tile with the tile's own output register. Yosys 0.23 maps a
// written product to the tile's combinational mode and the register after it to the fabric,
// so each product's clock ran from a fabric flip-flop over the routing to the tile, through its
// multiplier and back to a fabric flip-flop: in the joined set-up pass (`bank_pass.v`) 3.9 ns
// in the tile and 5.6 ns of routing, its critical path at three of five placement seeds
// (session 45). With the tile's register the way back is out of the product's clock; the
// product still leaves on the clock after its operands, as written.
//
// For synthesis with the ECP5 flow (`HEMI_ECP5`, which `cargo xtask rtl` defines for
// `synth_ecp5` alone) the tile is instantiated (read with `read_verilog -icells`, as in
// `add_sub.v`); every other reader, Verilator and the iCE40 flow among them, takes the written
// form. Yosys has no simulation model of the tile, so the two forms are not proved equal: the
// instance is Yosys's own mapping of a signed product (`ecp5/dsp_map.v`, the same ports and
// signs) with the output register's three parameters added.
// AW and BW are at most 18: the tile form takes each operand into 18 bits.
module mul18 #(
    parameter integer AW = 18,
    parameter integer BW = 18
) (
    input  wire                      clk,
    input  wire                      ce,
    input  wire signed [AW-1:0]      a,
    input  wire signed [BW-1:0]      b,
    output wire signed [AW+BW-1:0]   p
);
`ifdef HEMI_ECP5
    // sign-extended by the signed assignment
    wire signed [17:0] a18 = a;
    wire signed [17:0] b18 = b;
    /* verilator lint_off UNUSEDSIGNAL */
    wire [35:0] p36;
    /* verilator lint_on UNUSEDSIGNAL */
    assign p = p36[AW+BW-1:0];
    MULT18X18D #(
        .REG_OUTPUT_CLK("CLK0"), .REG_OUTPUT_CE("CE0"), .REG_OUTPUT_RST("RST0")
    ) tile (
        .A0(a18[0]), .B0(b18[0]),
        .A1(a18[1]), .B1(b18[1]),
        .A2(a18[2]), .B2(b18[2]),
        .A3(a18[3]), .B3(b18[3]),
        .A4(a18[4]), .B4(b18[4]),
        .A5(a18[5]), .B5(b18[5]),
        .A6(a18[6]), .B6(b18[6]),
        .A7(a18[7]), .B7(b18[7]),
        .A8(a18[8]), .B8(b18[8]),
        .A9(a18[9]), .B9(b18[9]),
        .A10(a18[10]), .B10(b18[10]),
        .A11(a18[11]), .B11(b18[11]),
        .A12(a18[12]), .B12(b18[12]),
        .A13(a18[13]), .B13(b18[13]),
        .A14(a18[14]), .B14(b18[14]),
        .A15(a18[15]), .B15(b18[15]),
        .A16(a18[16]), .B16(b18[16]),
        .A17(a18[17]), .B17(b18[17]),
        .C0(1'b0), .C1(1'b0), .C2(1'b0), .C3(1'b0), .C4(1'b0), .C5(1'b0),
        .C6(1'b0), .C7(1'b0), .C8(1'b0), .C9(1'b0), .C10(1'b0), .C11(1'b0),
        .C12(1'b0), .C13(1'b0), .C14(1'b0), .C15(1'b0), .C16(1'b0), .C17(1'b0),
        .SIGNEDA(1'b1), .SIGNEDB(1'b1), .SOURCEA(1'b0), .SOURCEB(1'b0),
        .CLK0(clk), .CE0(ce), .RST0(1'b0),
        .P0(p36[0]), .P1(p36[1]), .P2(p36[2]), .P3(p36[3]), .P4(p36[4]), .P5(p36[5]),
        .P6(p36[6]), .P7(p36[7]), .P8(p36[8]), .P9(p36[9]), .P10(p36[10]), .P11(p36[11]),
        .P12(p36[12]), .P13(p36[13]), .P14(p36[14]), .P15(p36[15]), .P16(p36[16]), .P17(p36[17]),
        .P18(p36[18]), .P19(p36[19]), .P20(p36[20]), .P21(p36[21]), .P22(p36[22]), .P23(p36[23]),
        .P24(p36[24]), .P25(p36[25]), .P26(p36[26]), .P27(p36[27]), .P28(p36[28]), .P29(p36[29]),
        .P30(p36[30]), .P31(p36[31]), .P32(p36[32]), .P33(p36[33]), .P34(p36[34]), .P35(p36[35])
    );
`else
    reg signed [AW+BW-1:0] r;
    always @(posedge clk) if (ce) r <= a * b;
    assign p = r;
`endif
endmodule
