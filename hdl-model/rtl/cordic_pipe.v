// A fully pipelined CORDIC (paper §3.4), the RTL of hdl-model/src/cordic/stage.rs: a coarse
// quadrant stage of two registers (the decision, then the turn), ITER micro-rotation stages,
// one register after each, and a gain stage of two registers (its adder tree registered
// halfway), so a vector entering on one clock edge is at the output ITER + 4 edges later
// (CordicConfig::latency).
//
// Words are W bits with the model's binary points: x and y Q2.(W-2), z Q3.(W-3). The model keeps
// the top W bits of 32-bit containers; a W-bit datapath computes exactly those bits, so the
// co-simulation compares word << (32 - W) with the model's containers.
// MODE 0 turns (x, y) by z; MODE 1 turns (x, y) onto +x and accumulates z = atan2(y, x).
// PW bits of payload ride along unchanged (the rotator's carried component and tag), in
// distributed RAM until their last two clocks (delay_line.v): as registers beside every stage
// they were most of the pipe's flip-flops.
module cordic_pipe #(
    parameter integer MODE = 0,
    parameter integer ITER = 20,
    parameter integer W = 24,
    parameter integer PW = 1
) (
    input  wire                clk,
    input  wire                rst,
    input  wire                in_valid,
    input  wire signed [W-1:0] in_x,
    input  wire signed [W-1:0] in_y,
    input  wire signed [W-1:0] in_z,
    input  wire       [PW-1:0] in_payload,
    output wire                out_valid,
    output wire signed [W-1:0] out_x,
    output wire signed [W-1:0] out_y,
    output wire signed [W-1:0] out_z,
    output wire       [PW-1:0] out_payload,
    // the payload one clock before it leaves (a unit that reads a memory by it gets the word
    // on the clock the vector leaves, without the read in the next stage's path), and two
    // clocks before (the word then also passes a register of its own: a block RAM's output
    // is slow, 5.8 ns on an ECP5)
    output wire       [PW-1:0] early_payload,
    output wire       [PW-1:0] early2_payload
);
`include "cordic_rom.vh"

    localparam [63:0] HALF_PI_R = rom_round(HALF_PI_Q62, W - 3);
    localparam [63:0] INV_GAIN_R = rom_round(inv_gain_q62(ITER), W - 2);
    localparam [W-1:0] HALF_PI = HALF_PI_R[W-1:0];
    localparam [W-1:0] INV_GAIN = INV_GAIN_R[W-1:0];
    localparam integer L = ITER + 3;

    // register k holds the vector after stage k (0: the quadrant's turn, 1..ITER: micro,
    // ITER+1: the gain stage's first half, whose partial sums are inside const_mul, ITER+2:
    // gain); the quadrant's decision is registered before them
    reg signed [W-1:0] x [0:L-1];
    reg signed [W-1:0] y [0:L-1];
    reg signed [W-1:0] z [0:L-1];
    reg                 zero [0:L-1];
    reg                 v [0:L-1];

    // quadrant stage, in two clocks: the first decides (the compare of z with ±π/2, or the
    // signs) and registers the decision, the second turns by ±π/2 as decided, to bring the
    // vector (or the angle) within the micro-rotations' reach. In one clock the compare's carry
    // chain and the choice's fanout to 3W multiplexers were the reset configuration's critical
    // path (85.3 MHz, session 24). The negations and the shifted angles are formed beside the
    // choice (kept: written inside it, Yosys built them in series with its select)
    reg signed [W-1:0] dx0, dy0, dz0;
    reg dv, turn_dn, turn_up, dzero;
    always @(posedge clk) begin
        if (rst) dv <= 1'b0;
        else dv <= in_valid;
        dx0 <= in_x; dy0 <= in_y; dz0 <= in_z;
        if (MODE == 0) begin
            turn_dn <= $signed(in_z) > $signed(HALF_PI);
            turn_up <= $signed(in_z) < -$signed(HALF_PI);
            dzero <= 1'b0;
        end else begin
            turn_dn <= in_x < 0 && in_y < 0;
            turn_up <= in_x < 0 && in_y >= 0;
            dzero <= (in_x == 0) && (in_y == 0);
        end
    end

    (* keep *) wire signed [W-1:0] neg_x = -dx0;
    (* keep *) wire signed [W-1:0] neg_y = -dy0;
    (* keep *) wire signed [W-1:0] z_down = dz0 - HALF_PI;
    (* keep *) wire signed [W-1:0] z_up = dz0 + HALF_PI;
    reg signed [W-1:0] qx, qy, qz;
    always @* begin
        qx = dx0;
        qy = dy0;
        qz = dz0;
        if (turn_dn) begin
            qx = neg_y; qy = dx0; qz = z_down;
        end else if (turn_up) begin
            qx = dy0; qy = neg_x; qz = z_up;
        end
    end

    always @(posedge clk) begin
        if (rst) v[0] <= 1'b0;
        else v[0] <= dv;
        x[0] <= qx; y[0] <= qy; z[0] <= qz; zero[0] <= dzero;
    end

    genvar i;
    generate
        for (i = 0; i < ITER; i = i + 1) begin : micro
            localparam [63:0] ATAN_R = rom_round(atan_q62(i), W - 3);
            localparam [W-1:0] ATAN = ATAN_R[W-1:0];
            // the direction is a sign bit (written as a comparison with 0, Yosys built a
            // comparator's carry chain, in series with the adders' once they took it as an input)
            wire ccw = (MODE == 0) ? !z[i][W-1] : y[i][W-1];
            wire signed [W-1:0] dx = x[i] >>> i;
            wire signed [W-1:0] dy = y[i] >>> i;
            // each of the three an adder-subtractor, one carry chain whose operand the direction
            // inverts (add_sub.v; written as a choice of a sum and a difference, Yosys built both
            // and a multiplexer)
            wire signed [W-1:0] nx, ny, nz;
            add_sub #(.W(W)) turn_x (.a(x[i]), .b(dy), .sub(ccw), .s(nx));
            add_sub #(.W(W)) turn_y (.a(y[i]), .b(dx), .sub(!ccw), .s(ny));
            add_sub #(.W(W)) turn_z (.a(z[i]), .b(ATAN), .sub(ccw), .s(nz));
            always @(posedge clk) begin
                if (rst) v[i+1] <= 1'b0;
                else v[i+1] <= v[i];
                x[i+1] <= nx;
                y[i+1] <= ny;
                z[i+1] <= nz;
                zero[i+1] <= zero[i];
            end
        end
    endgenerate

    // gain stage: each component times 1/K_n, truncated back to Q2.(W-2); the constant of the
    // build in tables of its digits (const_mul.v: no DSP tile, where `*` took four a component)
    /* verilator lint_off UNUSEDSIGNAL */
    wire signed [2*W-1:0] gx;
    wire signed [2*W-1:0] gy;
    /* verilator lint_on UNUSEDSIGNAL */
    const_mul #(.W(W), .C(INV_GAIN), .REG(1)) gain_x (.clk(clk), .x(x[ITER]), .p(gx));
    const_mul #(.W(W), .C(INV_GAIN), .REG(1)) gain_y (.clk(clk), .x(y[ITER]), .p(gy));
    // the first half carries what is not multiplied (x and y are in const_mul's registers)
    always @(posedge clk) begin
        if (rst) v[ITER+1] <= 1'b0;
        else v[ITER+1] <= v[ITER];
        z[ITER+1] <= z[ITER];
        zero[ITER+1] <= zero[ITER];
    end
    always @(posedge clk) begin
        if (rst) v[L-1] <= 1'b0;
        else v[L-1] <= v[L-2];
        x[L-1] <= gx[2*W-3 -: W];
        y[L-1] <= gy[2*W-3 -: W];
        z[L-1] <= (MODE == 1 && zero[L-2]) ? {W{1'b0}} : z[L-2];
        zero[L-1] <= zero[L-2];
    end
    // the payload: L − 1 clocks in the delay line, where a chain would have reached register
    // L − 3 (early2_payload), then the two registers early_payload and out_payload are
    wire [PW-1:0] pay_early2;
    reg  [PW-1:0] pay_early, pay_out;
    delay_line #(.W(PW), .N(L - 1)) payload (.clk(clk), .in(in_payload), .out(pay_early2));
    always @(posedge clk) begin
        pay_early <= pay_early2;
        pay_out <= pay_early;
    end

    assign out_valid = v[L-1];
    assign out_x = x[L-1];
    assign out_y = y[L-1];
    assign out_z = z[L-1];
    assign out_payload = pay_out;
    assign early_payload = pay_early;
    assign early2_payload = pay_early2;
endmodule
