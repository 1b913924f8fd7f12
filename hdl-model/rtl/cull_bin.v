// An azimuth's sector and a polar angle's band, the RTL of hdl-model/src/intersect/cull.rs's
// `CullUnit::sector_of` and `CullUnit::band_of`: the sector floor(((a + π) mod 2π) · SECTORS / 2π)
// and the band min(floor(max(t, 0) · 32 / π), 15), each as the count of constant thresholds at
// or below the angle (the model's integer divisions exactly: floor(a · S / D) >= k exactly when
// a >= ceil(k · D / S)). Both sides of the culling unit use it: a ray's bin (`cull_ray.v`) and
// the ends of a patch's reach (`cull_reach.v`).
//
// Angles are Q3.29 words, a in [-3π, 3π) and t of either sign. Three clocks: (a + π) mod 2π
// and t as words, the thresholds compared (each a thermometer: the thresholds increase), the
// thermometers counted. (As one clock of 64-bit compares counted by a chain of incrementers,
// the ray side placed at 10 MHz.) PW bits of payload ride along.
module cull_bin #(
    parameter integer SECTORS = 32,
    parameter integer PW = 1
) (
    input  wire               clk,
    input  wire               in_valid,
    input  wire signed [34:0] in_a,
    input  wire signed [34:0] in_t,
    input  wire      [PW-1:0] in_payload,
    output reg                out_valid,
    output reg         [5:0]  out_sector,
    output reg         [3:0]  out_band,
    output reg       [PW-1:0] out_payload
);
    localparam integer BANDS = 16;
    // π in Q3.29, as cull.rs has it
    localparam [63:0] PI = 64'd1686629713;
    localparam [34:0] PI35 = {3'b0, PI[31:0]};

    // (a + π) mod 2π, in [0, 2π) < 2^32: a + 3π, a + π or a − π, chosen by a's compares with
    // ±π beside the adds rather than after them
    /* verilator lint_off UNUSEDSIGNAL */
    wire signed [34:0] a_mod = in_a < -$signed(PI35) ? in_a + $signed(3 * PI35)
        : in_a >= $signed(PI35) ? in_a - $signed(PI35) : in_a + $signed(PI35);
    /* verilator lint_on UNUSEDSIGNAL */
    reg               v0;
    reg        [31:0] a0;
    reg signed [34:0] t0;
    reg      [PW-1:0] p0;
    always @(posedge clk) begin
        v0 <= in_valid;
        a0 <= a_mod[31:0];
        t0 <= in_t;
        p0 <= in_payload;
    end

    // threshold k of the sectors, ceil(k · 2π / SECTORS), and of the bands, ceil(k · π / 32)
    // (below 2^32: the 64-bit quotients' top bits are zero)
    /* verilator lint_off UNUSEDSIGNAL */
    function [63:0] wide(input [31:0] v);
        wide = {32'd0, v};
    endfunction
    localparam [63:0] S64 = wide(SECTORS), B64 = wide(2 * BANDS);
    function [31:0] sector_at(input [63:0] k);
        reg [63:0] t;
        begin
            t = (k * 2 * PI + S64 - 1) / S64;
            sector_at = t[31:0];
        end
    endfunction
    function [34:0] band_at(input [63:0] k);
        reg [63:0] t;
        begin
            t = (k * PI + B64 - 1) / B64;
            band_at = t[34:0];
        end
    endfunction
    /* verilator lint_on UNUSEDSIGNAL */
    // thermometers: bit k - 1 set when the angle is at or past threshold k
    wire [63:0] ts;
    wire [15:0] tb;
    genvar gk;
    generate
        for (gk = 1; gk <= 64; gk = gk + 1) begin : sector_threshold
            if (gk < SECTORS) assign ts[gk-1] = a0 >= sector_at(gk);
            else assign ts[gk-1] = 1'b0;
        end
        for (gk = 1; gk <= BANDS; gk = gk + 1) begin : band_threshold
            if (gk < BANDS) assign tb[gk-1] = t0 >= $signed(band_at(gk));
            else assign tb[gk-1] = 1'b0;
        end
    endgenerate
    reg          v1;
    reg   [63:0] ts1;
    reg   [15:0] tb1;
    reg [PW-1:0] p1;
    always @(posedge clk) begin
        v1 <= v0;
        ts1 <= ts;
        tb1 <= tb;
        p1 <= p0;
    end

    // a thermometer's count c (bit i set for i < c): bit j of c is the XOR of bits m·2^j - 1,
    // m >= 1 (the count of multiples of 2^j up to c, mod 2), each bit a tree of its own
    function [5:0] ones(input [63:0] t);
        integer j, m;
        begin
            ones = 6'd0;
            for (j = 0; j < 6; j = j + 1)
                for (m = 1; m * (1 << j) <= 64; m = m + 1)
                    ones[j] = ones[j] ^ t[m * (1 << j) - 1];
        end
    endfunction
    /* verilator lint_off UNUSEDSIGNAL */
    wire [5:0] sector_n = ones(ts1), band_n = ones({48'd0, tb1});
    /* verilator lint_on UNUSEDSIGNAL */
    always @(posedge clk) begin
        out_valid <= v1;
        out_sector <= sector_n;
        out_band <= band_n[3:0];
        out_payload <= p1;
    end
endmodule
