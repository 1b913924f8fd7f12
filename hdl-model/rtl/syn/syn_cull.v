// Synthesis harness of the culling unit's ray side (`cull_ray.v`, a ray's sector and band), as
// `syn_rotator.v` is the rotator's: its inputs from a register chain shifted in from one pin,
// its outputs folded into one registered pin. Figures: `cargo xtask rtl`.
module syn_cull (
    input  wire clk,
    input  wire sin,
    output reg  sout
);
    localparam integer N = 1 + 3 * 32;
    reg [N-1:0] c;
    always @(posedge clk) c <= {c[N-2:0], sin};

    wire       valid, culled;
    wire [5:0] sector;
    wire [3:0] band;
    cull_ray unit (
        .clk(clk), .in_valid(c[0]), .in_x(c[32:1]), .in_y(c[64:33]), .in_z(c[96:65]),
        .out_valid(valid), .out_culled(culled), .out_sector(sector), .out_band(band));
    always @(posedge clk) sout <= ^{valid, culled, sector, band};
endmodule
