// The culling unit's ray side, the RTL of hdl-model/src/intersect/cull.rs's `CullUnit::ray_bin`:
// the azimuth sector and polar band of a hemisphere ray's reference direction, which choose the
// sector and band rows of the candidate bitmaps its lanes walk. The model gives it no clocks of
// its own (it runs beside the rotator, on the reference direction the rotator turns), so the
// co-simulation compares its answers in order. Its latency, 2 · ITER + 17 = 45 clocks, is
// within the rotator's 3(n + 4) + 2 for CONFIG.ITER n >= 11 (86 at the reset n = 24); below
// that a culled ray's lanes wait for the difference (`cull::RAY_LATENCY`, as the model charges).
//
// A ray (x, y, z: Q2.30 words) is culled when z >= 0 and rho = max(|x|, |y|) >= 2^25 (sin θ at
// least 2^-5); the outputs of any other ray are don't-care. Its angles come from the unit's
// two vectorings (`cull_angles.v`; a culled ray's ρ has its leading one at bits 25..31, and
// (z·2^s, r)'s at 27..34, so only those places are looked at), its sector and band from their
// thresholds (`cull_bin.v`).
module cull_ray #(
    parameter integer ITER = 14,
    parameter integer W = 20,
    parameter integer SECTORS = 32
) (
    input  wire               clk,
    input  wire               in_valid,
    input  wire signed [31:0] in_x,
    input  wire signed [31:0] in_y,
    input  wire signed [31:0] in_z,
    output wire               out_valid,
    output wire               out_culled,
    output wire [5:0]         out_sector,
    output wire [3:0]         out_band
);
    // culled or not, beside the angles
    wire culled = !in_z[31] && (abs_top(in_x) || abs_top(in_y));
    /* verilator lint_off UNUSEDSIGNAL */
    function abs_top(input signed [31:0] v);
        reg [32:0] a;
        begin
            a = v[31] ? -{v[31], v} : {1'b0, v};
            abs_top = a[32:25] != 8'd0;
        end
    endfunction
    /* verilator lint_on UNUSEDSIGNAL */

    wire                valid, c_angles;
    wire signed [W-1:0] phi, theta;
    cull_angles #(.ITER(ITER), .W(W), .IW(32), .LO1(25), .HI1(31), .ZW(35), .LO2(27), .HI2(34),
        .PW(1)) angles (
        .clk(clk), .in_valid(in_valid), .in_x(in_x), .in_y(in_y), .in_z(in_z),
        .in_payload(culled), .out_valid(valid), .out_phi(phi), .out_theta(theta),
        .out_payload(c_angles));
    cull_bin #(.W(W), .SECTORS(SECTORS), .PW(1)) bin (
        .clk(clk), .in_valid(valid), .in_a({{3{phi[W-1]}}, phi}),
        .in_t({{3{theta[W-1]}}, theta}), .in_payload(c_angles),
        .out_valid(out_valid), .out_sector(out_sector), .out_band(out_band),
        .out_payload(out_culled));
endmodule
