// Synthesis harness of the planar intersection unit, as syn_rotator.v is of the rotator: its
// inputs from a register chain shifted in from one pin, its outputs folded into one registered
// pin, so that the part's pins do not limit what is placed. Figures: `cargo xtask rtl`.
module syn_plane #(
    parameter integer IW = 8,
    parameter integer DEPTH = 16
) (
    input  wire clk,
    input  wire rst,
    input  wire sin,
    output reg  sout
);
    localparam integer N = (IW + 5) + 32 + (IW + 1) + 192 + 3 + IW + 2;
    reg [N-1:0] chain;
    always @(posedge clk) chain <= {chain[N-2:0], sin};

    wire in_ready, out_valid, out_hit, out_front;
    wire [IW-1:0] out_patch;
    wire [31:0] out_t, out_u, out_v;
    localparam integer A = 1, D = A + IW + 4, C = D + 32, O = C + IW + 1, R = O + 96;
    localparam integer F = R + 96;
    plane_unit #(.IW(IW), .DEPTH(DEPTH)) dut (
        .clk(clk), .rst(rst),
        .pm_we(chain[0]), .pm_addr(chain[A +: IW + 4]), .pm_data(chain[D +: 32]),
        .count(chain[C +: IW + 1]), .invalidate(chain[F + 4 + IW]),
        .in_valid(chain[F]), .in_ready(in_ready),
        .in_origin(chain[O +: 96]), .in_dir(chain[R +: 96]),
        .in_uv(chain[F + 1]), .in_skip_en(chain[F + 2]), .in_skip(chain[F + 3 +: IW]),
        .in_bypass(chain[F + 3 + IW]),
        .out_valid(out_valid), .out_hit(out_hit), .out_patch(out_patch), .out_t(out_t),
        .out_u(out_u), .out_v(out_v), .out_front(out_front));
    always @(posedge clk)
        sout <= ^{in_ready, out_valid, out_hit, out_front, out_patch, out_t, out_u, out_v};
endmodule
