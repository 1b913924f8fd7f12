// The co-simulation top: the units that have RTL, side by side, each with its own ports, so one
// Verilated build per CORDIC configuration checks them all (hdl-model/rtl/tb/cosim.cpp).
module cosim_top #(
    parameter integer ITER = 20,
    parameter integer W = 24
) (
    input  wire        clk,
    input  wire        rst,
    // the rotator
    input  wire        r_valid,
    input  wire [31:0] r_dx,
    input  wire [31:0] r_dy,
    input  wire [31:0] r_dz,
    input  wire [31:0] r_psi,
    input  wire [31:0] r_theta,
    input  wire [31:0] r_phi,
    input  wire        r_bypass,
    output wire        ro_valid,
    output wire [31:0] ro_dx,
    output wire [31:0] ro_dy,
    output wire [31:0] ro_dz,
    // the angle unit's vectoring pipe, on W-bit words
    input  wire          v_valid,
    input  wire [W-1:0]  v_x,
    input  wire [W-1:0]  v_y,
    input  wire [W-1:0]  v_z,
    output wire          vo_valid,
    output wire [W-1:0]  vo_x,
    output wire [W-1:0]  vo_y,
    output wire [W-1:0]  vo_z,
    // the whole angle unit
    input  wire          f_start,
    input  wire          f_pairs,
    input  wire [W-1:0]  f_w1,
    input  wire [W-1:0]  f_w2,
    input  wire [W-1:0]  f_w3,
    input  wire [W-1:0]  f_w4,
    input  wire [W-1:0]  f_w5,
    input  wire [W-1:0]  f_w6,
    output wire          fo_busy,
    output wire          fo_done,
    output wire [W-1:0]  fo_psi,
    output wire [W-1:0]  fo_theta,
    output wire [W-1:0]  fo_phi
);
    /* verilator lint_off UNUSEDSIGNAL */
    wire [6:0] tag;
    wire payload, early, early2;
    /* verilator lint_on UNUSEDSIGNAL */
    rotator #(.ITER(ITER), .W(W)) rot (
        .clk(clk), .rst(rst), .in_valid(r_valid), .in_dx(r_dx), .in_dy(r_dy), .in_dz(r_dz),
        .in_psi(r_psi), .in_theta(r_theta), .in_phi(r_phi), .in_bypass(r_bypass),
        .out_valid(ro_valid), .out_dx(ro_dx), .out_dy(ro_dy), .out_dz(ro_dz), .out_tag(tag));
    cordic_pipe #(.MODE(1), .ITER(ITER), .W(W), .PW(1)) vec (
        .clk(clk), .rst(rst), .in_valid(v_valid), .in_x(v_x), .in_y(v_y), .in_z(v_z),
        .in_payload(1'b0), .out_valid(vo_valid), .out_x(vo_x), .out_y(vo_y), .out_z(vo_z),
        .out_payload(payload), .early_payload(early), .early2_payload(early2));
    frame_unit #(.ITER(ITER), .W(W)) frame (
        .clk(clk), .rst(rst), .start(f_start), .clear(1'b0), .pairs(f_pairs), .w1(f_w1), .w2(f_w2),
        .w3(f_w3), .w4(f_w4), .w5(f_w5), .w6(f_w6), .busy(fo_busy), .done(fo_done),
        .psi(fo_psi), .theta(fo_theta), .phi(fo_phi));
endmodule
