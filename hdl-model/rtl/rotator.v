// The ray rotator (paper §3.4, fig. 6), the RTL of hdl-model/src/rotator.rs: three rotation-mode
// CORDIC pipes in series with a register between consecutive pipes, 3 (ITER + 4) + 2 clocks.
//   1. psi about z: (x, y) turned by psi, z carried;
//   2. theta about y: (z, x) turned by theta, y carried;
//   3. phi about z: (x1, y) turned by phi, z1 carried.
// The later pipes' angles, the unrotated direction and the bypass bit wait in a side table of
// 128 slots, allocated round robin, and a 7-bit tag rides with the vector (as in the model: the
// longest latency, 104 clocks, is under 128, so a slot is free again before it is reused).
// Ports are the model's 32-bit containers: the pipes take their top W bits, and a bypassed
// direction (trace mode) leaves exactly as written.
module rotator #(
    parameter integer ITER = 20,
    parameter integer W = 24
) (
    input  wire        clk,
    input  wire        rst,
    input  wire        in_valid,
    input  wire [31:0] in_dx,
    input  wire [31:0] in_dy,
    input  wire [31:0] in_dz,
    /* verilator lint_off UNUSEDSIGNAL */ // below W = 32 the angles' low bits are not used
    input  wire [31:0] in_psi,
    input  wire [31:0] in_theta,
    input  wire [31:0] in_phi,
    /* verilator lint_on UNUSEDSIGNAL */
    input  wire        in_bypass,
    output wire        out_valid,
    output wire [31:0] out_dx,
    output wire [31:0] out_dy,
    output wire [31:0] out_dz,
    output wire [6:0]  out_tag
);
    localparam integer PW = W + 7;

    reg [31:0] side_theta [0:127];
    reg [31:0] side_phi [0:127];
    reg [95:0] side_dir [0:127];
    reg        side_bypass [0:127];
    reg [6:0]  next_slot;

    always @(posedge clk) begin
        if (rst) next_slot <= 7'd0;
        else if (in_valid) next_slot <= next_slot + 7'd1;
        if (in_valid) begin
            side_theta[next_slot] <= in_theta;
            side_phi[next_slot] <= in_phi;
            side_dir[next_slot] <= {in_dz, in_dy, in_dx};
            side_bypass[next_slot] <= in_bypass;
        end
    end

    // pipe 1: psi
    wire a_v;
    /* verilator lint_off UNUSEDSIGNAL */ // the angle left over is not needed
    wire signed [W-1:0] a_x, a_y, a_z;
    /* verilator lint_on UNUSEDSIGNAL */
    wire [PW-1:0] a_p;
    /* verilator lint_off UNUSEDSIGNAL */ // only the early tag is read
    wire [PW-1:0] a_early, b_early, c_early, a_early2, b_early2, c_early2;
    /* verilator lint_on UNUSEDSIGNAL */
    cordic_pipe #(.MODE(0), .ITER(ITER), .W(W), .PW(PW)) psi (
        .clk(clk), .rst(rst), .in_valid(in_valid),
        .in_x(in_dx[31 -: W]), .in_y(in_dy[31 -: W]),
        // a bypassed entry leaves as written (the side table's direction below), so its angle
        // is turned by as it comes: no multiplexer before the quadrant stage, the critical
        // path with it
        .in_z(in_psi[31 -: W]),
        .in_payload({next_slot, in_dz[31 -: W]}),
        .out_valid(a_v), .out_x(a_x), .out_y(a_y), .out_z(a_z), .out_payload(a_p),
        .early_payload(a_early), .early2_payload(a_early2));

    // theta is read from the side table by the tag one clock before it leaves pipe 1, so the
    // block RAM's output is registered on its own and not in the next pipe's quadrant stage
    reg [W-1:0] theta_q;
    always @(posedge clk) theta_q <= side_theta[a_early[PW-1:W]][31 -: W];

    // register between pipes 1 and 2: (z, x) to turn by theta, y carried
    reg ab_v;
    reg signed [W-1:0] ab_x, ab_y, ab_z;
    reg [PW-1:0] ab_p;
    always @(posedge clk) begin
        if (rst) ab_v <= 1'b0;
        else ab_v <= a_v;
        ab_x <= a_p[W-1:0];
        ab_y <= a_x;
        ab_z <= theta_q;
        ab_p <= {a_p[PW-1:W], a_y};
    end

    // pipe 2: theta
    wire b_v;
    /* verilator lint_off UNUSEDSIGNAL */ // the angle left over is not needed
    wire signed [W-1:0] b_x, b_y, b_z;
    /* verilator lint_on UNUSEDSIGNAL */
    wire [PW-1:0] b_p;
    cordic_pipe #(.MODE(0), .ITER(ITER), .W(W), .PW(PW)) theta (
        .clk(clk), .rst(rst), .in_valid(ab_v), .in_x(ab_x), .in_y(ab_y), .in_z(ab_z),
        .in_payload(ab_p),
        .out_valid(b_v), .out_x(b_x), .out_y(b_y), .out_z(b_z), .out_payload(b_p),
        .early_payload(b_early), .early2_payload(b_early2));

    reg [W-1:0] phi_q;
    always @(posedge clk) phi_q <= side_phi[b_early[PW-1:W]][31 -: W];

    // register between pipes 2 and 3: (x1, y) to turn by phi, z1 carried
    reg bc_v;
    reg signed [W-1:0] bc_x, bc_y, bc_z;
    reg [PW-1:0] bc_p;
    always @(posedge clk) begin
        if (rst) bc_v <= 1'b0;
        else bc_v <= b_v;
        bc_x <= b_y;
        bc_y <= b_p[W-1:0];
        bc_z <= phi_q;
        bc_p <= {b_p[PW-1:W], b_x};
    end

    // pipe 3: phi
    wire c_v;
    /* verilator lint_off UNUSEDSIGNAL */ // the angle left over is not needed
    wire signed [W-1:0] c_x, c_y, c_z;
    /* verilator lint_on UNUSEDSIGNAL */
    wire [PW-1:0] c_p;
    cordic_pipe #(.MODE(0), .ITER(ITER), .W(W), .PW(PW)) phi (
        .clk(clk), .rst(rst), .in_valid(bc_v), .in_x(bc_x), .in_y(bc_y), .in_z(bc_z),
        .in_payload(bc_p),
        .out_valid(c_v), .out_x(c_x), .out_y(c_y), .out_z(c_z), .out_payload(c_p),
        .early_payload(c_early), .early2_payload(c_early2));

    // the unrotated direction and the bypass bit read by the tag two clocks before the vector
    // leaves pipe 3 and registered once more, so that the side table's (block RAM's) slow
    // output reaches a register of its own and not the output multiplexer: the rotator's
    // critical path at ITER 12, W 16 (docs/PERFORMANCE.md)
    reg [95:0] orig_read, orig;
    reg        bypass_read, rotated;
    always @(posedge clk) begin
        orig_read <= side_dir[c_early2[PW-1:W]];
        bypass_read <= side_bypass[c_early2[PW-1:W]];
        orig <= orig_read;
        rotated <= !bypass_read;
    end

    wire [6:0] tag = c_p[PW-1:W];
    // a W-bit word back in the top bits of its 32-bit container
    /* verilator lint_off UNUSEDSIGNAL */
    wire [63:0] cx = {c_x, {(64 - W){1'b0}}};
    wire [63:0] cy = {c_y, {(64 - W){1'b0}}};
    wire [63:0] cz = {c_p[W-1:0], {(64 - W){1'b0}}};
    /* verilator lint_on UNUSEDSIGNAL */
    assign out_valid = c_v;
    assign out_tag = tag;
    assign out_dx = rotated ? cx[63:32] : orig[31:0];
    assign out_dy = rotated ? cy[63:32] : orig[63:32];
    assign out_dz = rotated ? cz[63:32] : orig[95:64];
endmodule
