// t = h / (n . d) for the planar lane (hdl-model/src/intersect/mod.rs, `DivideStage`) and a
// compact build's plane unit (group_plane.v), as a restoring divider of one quotient bit per
// stage: the model's exact quotient (h << 30) / (n . d), truncated towards zero, kept when it is
// positive and fits the 31 bits of a positive Q8.24 t. Magnitudes are divided (a positive
// quotient needs both signs equal); one stage settles the signs, 31 stages give the bits (the
// first also the "does it fit" test, |h| << 30 < |n . d| << 31, that is |h| < 2 |n . d|), so a
// token is at the output 32 clocks after it enters. PW bits of payload ride along. A reset
// empties the stages (their valid bits), so that nothing started before it comes out after.
// (Until session 41 the valid bits had no reset: after a soft reset of the one-lane
// accelerator, a division in flight came out as the new first ray's.)
//
// The bits as long division: the numerator's bits below |h| are zeros, so the remainder starts
// as |h| (below 2 |n . d| when it fits) and each stage subtracts |n . d| where it can, then
// doubles it: a 70-bit subtract a stage, its borrow the quotient bit. (Until session 40 each
// stage compared the whole 100-bit numerator with |n . d| shifted to the bit: 17,942 LUT4s
// where this takes about a third.)
module plane_divider #(
    parameter integer PW = 1
) (
    input  wire               clk,
    input  wire               rst,
    input  wire               in_valid,
    input  wire               in_inside,   // the edge stage found the ray inside the pyramid
    input  wire signed [67:0] in_h,        // Q.54
    input  wire signed [67:0] in_den,      // Q.60
    input  wire [PW-1:0]      in_payload,
    output wire               out_valid,
    output wire               out_hit,     // t > 0 and within Q8.24
    output wire [30:0]        out_t,
    output wire [PW-1:0]      out_payload
);
    localparam integer S = 32;
    localparam integer RW = 70;   // a remainder below 2 |n . d| < 2^69, doubled

    reg          v [0:S-1];
    reg          ok [0:S-1];
    reg [RW-1:0] r [0:S-1];
    reg [67:0]   d [0:S-1];
    reg [30:0]   q [0:S-1];

    wire [67:0] abs_h = in_h[67] ? -in_h : in_h;
    wire [67:0] abs_d = in_den[67] ? -in_den : in_den;
    wire same_sign = in_h[67] == in_den[67];

    always @(posedge clk) begin
        v[0] <= in_valid && !rst;
        ok[0] <= in_inside && in_den != 0 && same_sign;
        r[0] <= {2'b0, abs_h};
        d[0] <= abs_d;
        q[0] <= 31'd0;
    end

    genvar i;
    generate
        for (i = 1; i < S; i = i + 1) begin : bit_stage
            localparam integer B = S - 1 - i;  // quotient bit 30 first
            wire [RW:0] diff = {1'b0, r[i-1]} - {3'b0, d[i-1]};
            wire take = !diff[RW];
            // what is left is below |n . d| < 2^68
            wire [RW-2:0] rest = take ? diff[RW-2:0] : r[i-1][RW-2:0];
            // the first bit's stage also tests |h| < 2 |n . d| on the magnitudes, beside its
            // subtract (after the negations, in the signs' stage, it was a compact plane
            // unit's slowest path, 86 to 88 MHz)
            wire fits = i != 1 || r[i-1] < {1'b0, d[i-1], 1'b0};
            always @(posedge clk) begin
                v[i] <= v[i-1] && !rst;
                ok[i] <= ok[i-1] && fits;
                r[i] <= {rest, 1'b0};
                d[i] <= d[i-1];
                q[i] <= q[i-1] | ({30'd0, take} << B);
            end
        end
    endgenerate

    assign out_valid = v[S-1];
    assign out_hit = ok[S-1] && q[S-1] != 0;
    assign out_t = q[S-1];
    // the payload waits beside the stages in distributed RAM (delay_line.v)
    delay_line #(.W(PW), .N(S)) payload (.clk(clk), .in(in_payload), .out(out_payload));
endmodule
