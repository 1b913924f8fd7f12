// The co-simulation top of the culling unit: its ray side (`cull_ray.v`, a ray's sector and
// band) and its patch side (`cull_reach.v`, a patch's reach), side by side on one clock, each
// fed by `cull_tb.cpp` (a direction a clock; a corner a clock).
module cull_top (
    input  wire               clk,
    input  wire               r_valid,
    input  wire signed [31:0] r_x,
    input  wire signed [31:0] r_y,
    input  wire signed [31:0] r_z,
    output wire               r_out_valid,
    output wire               r_culled,
    output wire        [5:0]  r_sector,
    output wire        [3:0]  r_band,
    input  wire               p_valid,
    input  wire               p_last,
    input  wire signed [32:0] p_ax,
    input  wire signed [32:0] p_ay,
    input  wire signed [32:0] p_az,
    input  wire signed [17:0] p_ex,
    input  wire signed [17:0] p_ey,
    input  wire signed [17:0] p_ez,
    input  wire        [3:0]  p_kappa,
    input  wire signed [31:0] p_ux,
    input  wire signed [31:0] p_uy,
    input  wire signed [31:0] p_uz,
    input  wire signed [31:0] p_vx,
    input  wire signed [31:0] p_vy,
    input  wire signed [31:0] p_vz,
    input  wire signed [31:0] p_wx,
    input  wire signed [31:0] p_wy,
    input  wire signed [31:0] p_wz,
    output wire               p_out_valid,
    output wire        [1:0]  p_kind,
    output wire        [5:0]  p_lo,
    output wire        [6:0]  p_len,
    output wire        [3:0]  p_band_lo,
    output wire        [3:0]  p_band_hi
);
    cull_ray ray_side (
        .clk(clk), .in_valid(r_valid), .in_x(r_x), .in_y(r_y), .in_z(r_z),
        .out_valid(r_out_valid), .out_culled(r_culled), .out_sector(r_sector),
        .out_band(r_band));
    cull_reach patch_side (
        .clk(clk), .in_valid(p_valid), .in_last(p_last), .in_ax(p_ax), .in_ay(p_ay),
        .in_az(p_az), .in_ex(p_ex), .in_ey(p_ey), .in_ez(p_ez), .in_kappa(p_kappa),
        .in_ux(p_ux), .in_uy(p_uy), .in_uz(p_uz), .in_vx(p_vx), .in_vy(p_vy), .in_vz(p_vz),
        .in_wx(p_wx), .in_wy(p_wy), .in_wz(p_wz), .out_valid(p_out_valid), .out_kind(p_kind),
        .out_lo(p_lo), .out_len(p_len), .out_band_lo(p_band_lo), .out_band_hi(p_band_hi));
endmodule
