// The angle unit (paper §3.4, "another Cordic, which is not indicated in figure 6"), the RTL of
// hdl-model/src/frame.rs: one vectoring-mode CORDIC pipe (cordic_pipe.v, MODE 1) and the
// sequencing around it that turns a frame description into the angles ψ, θ, φ the rotator
// takes.
//
// - From a normal (start with pairs = 0; w1..w3 = n, w4, w5 = (cos ψ, sin ψ)): φ = atan2(n_y,
//   n_x) enters the clock after the start, ψ the clock after; when φ leaves, its gain-
//   compensated magnitude ρ = |(n_x, n_y)| and n_z go back in as θ = atan2(ρ, n_z).
// - From pairs (pairs = 1; w1, w2 = (cos φ, sin φ), w3, w4 = (cos θ, sin θ), w5, w6 = (cos ψ,
//   sin ψ)): φ enters on the start's clock, θ and ψ on the next two.
//
// Latency: 2(n + 4) + 1 clocks from a normal, n + 6 from pairs (n = ITER). `done` is high on the
// clock the last angle leaves the pipe (the model's `FrameUnit::tick` returning true), and each
// angle's register takes its value on the edge that ends the clock its pass leaves. Words are W
// bits, the top W of the model's 32-bit containers. A start must come while the unit is idle.
module frame_unit #(
    parameter integer ITER = 20,
    parameter integer W = 24
) (
    input  wire         clk,
    input  wire         rst,
    input  wire         start,
    input  wire         clear,  // the angles to zero (an APPLY_CONFIG: the model's new unit)
    input  wire         pairs,
    input  wire [W-1:0] w1,
    input  wire [W-1:0] w2,
    input  wire [W-1:0] w3,
    input  wire [W-1:0] w4,
    input  wire [W-1:0] w5,
    input  wire [W-1:0] w6,
    output wire         busy,
    output wire         done,
    output reg  [W-1:0] psi,
    output reg  [W-1:0] theta,
    output reg  [W-1:0] phi
);
    // which angle a pass gives: ψ, θ, φ alone (pairs), φ then θ (normal)
    localparam [1:0] T_PSI = 2'd0, T_THETA = 2'd1, T_PHI = 2'd2, T_PHI_THEN_THETA = 2'd3;

    // the pass presented to the pipe's input on the next clock (the model's `feed`), and the
    // passes waiting behind it
    reg         pend_v, q0_v;
    reg [W-1:0] pend_x, pend_y, q0_x, q0_y;
    reg [1:0]   pend_t, q0_t;
    reg [W-1:0] nz;
    reg [1:0]   outstanding;

    wire         out_valid;
    wire [W-1:0] out_x, out_z;
    wire [1:0]   out_t;
    // a start from pairs feeds φ on its own clock; everything else was fed a clock before
    wire         in_valid = (start && pairs) || pend_v;
    wire [W-1:0] in_x = (start && pairs) ? w1 : pend_x;
    wire [W-1:0] in_y = (start && pairs) ? w2 : pend_y;
    wire [1:0]   in_t = (start && pairs) ? T_PHI : pend_t;

    /* verilator lint_off UNUSEDSIGNAL */
    wire [W-1:0] out_y;
    wire [1:0]   early, early2;
    /* verilator lint_on UNUSEDSIGNAL */
    cordic_pipe #(.MODE(1), .ITER(ITER), .W(W), .PW(2)) pipe (
        .clk(clk), .rst(rst), .in_valid(in_valid), .in_x(in_x), .in_y(in_y), .in_z({W{1'b0}}),
        .in_payload(in_t), .out_valid(out_valid), .out_x(out_x), .out_y(out_y), .out_z(out_z),
        .out_payload(out_t), .early_payload(early), .early2_payload(early2));

    assign busy = outstanding != 2'd0;
    assign done = out_valid && outstanding == 2'd1;
    wire follow = out_valid && out_t == T_PHI_THEN_THETA;

    always @(posedge clk) begin
        if (rst) begin
            pend_v <= 1'b0;
            q0_v <= 1'b0;
            outstanding <= 2'd0;
            psi <= {W{1'b0}};
            theta <= {W{1'b0}};
            phi <= {W{1'b0}};
        end else if (start) begin
            // the start's passes (the unit is idle: nothing leaves the pipe on this clock)
            outstanding <= 2'd3;
            nz <= w3;
            pend_v <= 1'b1;
            q0_v <= 1'b1;
            if (pairs) begin
                {pend_x, pend_y, pend_t} <= {w3, w4, T_THETA};
                {q0_x, q0_y, q0_t} <= {w5, w6, T_PSI};
            end else begin
                {pend_x, pend_y, pend_t} <= {w1, w2, T_PHI_THEN_THETA};
                {q0_x, q0_y, q0_t} <= {w4, w5, T_PSI};
            end
        end else begin
            if (out_valid) begin
                outstanding <= outstanding - 2'd1;
                case (out_t)
                    T_PSI: psi <= out_z;
                    T_THETA: theta <= out_z;
                    default: phi <= out_z;
                endcase
            end
            if (follow) begin
                // θ = atan2(ρ, n_z): the magnitude out of the φ pass is ρ
                {pend_v, pend_x, pend_y, pend_t} <= {1'b1, nz, out_x, T_THETA};
            end else begin
                {pend_v, pend_x, pend_y, pend_t} <= {q0_v, q0_x, q0_y, q0_t};
                q0_v <= 1'b0;
            end
        end
        // (an APPLY_CONFIG comes only while the unit is idle: no angle leaves on its clock; a
        // frame started on the same clock computes its angles afresh)
        if (clear && !rst) begin
            psi <= {W{1'b0}};
            theta <= {W{1'b0}};
            phi <= {W{1'b0}};
        end
    end
endmodule
