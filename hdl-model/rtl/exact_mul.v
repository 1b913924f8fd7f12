// The exact edge unit's multiplier (exact_edge.v), one in the unit (two until session 43).
//
// x · y in five clocks, a carry chain a clock: the operands registered; their eight 18 x 18
// tile products (x in a 17-bit low half and a signed high half, y in three 16-bit quarters and
// a signed top one); the tiles summed in pairs of quarters; each half's row; the two rows. (The
// partial products of 34 x 32 bits in one clock, four tiles and their adders, placed at 70 MHz.)
// QW bits ride along.
module exact_mul #(
    parameter integer QW = 1
) (
    input  wire               clk,
    input  wire signed [33:0] x,
    input  wire signed [63:0] y,
    input  wire [QW-1:0]      q_in,
    output reg  [97:0]        p,
    output wire [QW-1:0]      q
);
    reg signed [33:0] rx;
    reg signed [63:0] ry;
    // x's halves and y's quarters as signed 18-bit tile operands
    wire signed [17:0] xs [0:1];
    wire signed [17:0] ys [0:3];
    assign xs[0] = {1'b0, rx[16:0]};
    assign xs[1] = {rx[33], rx[33:17]};
    assign ys[0] = {2'b0, ry[15:0]};
    assign ys[1] = {2'b0, ry[31:16]};
    assign ys[2] = {2'b0, ry[47:32]};
    assign ys[3] = {{2{ry[63]}}, ry[63:48]};
    reg signed [35:0] t [0:1][0:3];
    reg signed [52:0] pair [0:1][0:1];   // tiles j and j + 1: t_j + t_(j+1) 2^16
    reg signed [84:0] row [0:1];         // a half's: Σ_j t_j 2^(16 j)
    reg [QW-1:0] q1, q2, q3, q4, q5;
    integer i, j;
    always @(posedge clk) begin
        rx <= x;
        ry <= y;
        for (i = 0; i < 2; i = i + 1) begin
            for (j = 0; j < 4; j = j + 1) t[i][j] <= xs[i] * ys[j];
            for (j = 0; j < 2; j = j + 1)
                pair[i][j] <= {{17{t[i][2 * j][35]}}, t[i][2 * j]}
                            + {t[i][2 * j + 1][35], t[i][2 * j + 1], 16'd0};
            row[i] <= {{32{pair[i][0][52]}}, pair[i][0]} + {pair[i][1], 32'd0};
        end
        p <= {{13{row[0][84]}}, row[0]} + {row[1][80:0], 17'd0};
        q1 <= q_in;
        q2 <= q1;
        q3 <= q2;
        q4 <= q3;
        q5 <= q4;
    end
    assign q = q5;
endmodule
