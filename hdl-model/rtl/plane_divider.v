// t = h / (n . d) for the planar lane (hdl-model/src/intersect/mod.rs, `DivideStage`), as a
// restoring divider of one quotient bit per stage: the model's exact quotient (h << 30) / (n . d),
// truncated towards zero, kept when it is positive and fits the 31 bits of a positive Q8.24 t.
// Magnitudes are divided (a positive quotient needs both signs equal); one stage settles the
// signs and the "does it fit" test (|h| << 30 < |n . d| << 31), 31 stages give the bits, so a
// token is at the output 32 clocks after it enters. PW bits of payload ride along.
module plane_divider #(
    parameter integer PW = 1
) (
    input  wire               clk,
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
    localparam integer RW = 100;

    reg          v [0:S-1];
    reg          ok [0:S-1];
    reg [RW-1:0] r [0:S-1];
    reg [RW-1:0] d [0:S-1];
    reg [30:0]   q [0:S-1];
    reg [PW-1:0] p [0:S-1];

    wire [67:0] abs_h = in_h[67] ? -in_h : in_h;
    wire [67:0] abs_d = in_den[67] ? -in_den : in_den;
    wire [RW-1:0] num = {{(RW - 68){1'b0}}, abs_h} << 30;
    wire [RW-1:0] den = {{(RW - 68){1'b0}}, abs_d};
    wire fits = num < (den << 31);
    wire same_sign = in_h[67] == in_den[67];

    always @(posedge clk) begin
        v[0] <= in_valid;
        ok[0] <= in_inside && in_den != 0 && same_sign && fits;
        r[0] <= num;
        d[0] <= den;
        q[0] <= 31'd0;
        p[0] <= in_payload;
    end

    genvar i;
    generate
        for (i = 1; i < S; i = i + 1) begin : bit_stage
            localparam integer B = S - 1 - i;  // quotient bit 30 first
            wire [RW-1:0] dd = d[i-1] << B;
            wire take = r[i-1] >= dd;
            always @(posedge clk) begin
                v[i] <= v[i-1];
                ok[i] <= ok[i-1];
                r[i] <= take ? r[i-1] - dd : r[i-1];
                d[i] <= d[i-1];
                q[i] <= q[i-1] | ({30'd0, take} << B);
                p[i] <= p[i-1];
            end
        end
    endgenerate

    assign out_valid = v[S-1];
    assign out_hit = ok[S-1] && q[S-1] != 0;
    assign out_t = q[S-1];
    assign out_payload = p[S-1];
endmodule
