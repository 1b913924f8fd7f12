// A signed A × B product as an array of rows, for the multipliers a build has no DSP tile left
// for. Row i adds a_i · b (the last row subtracts it: a's top bit weighs −2^(A−1)) to the
// running sum's high B + 1 bits, and the sum's lowest bit is then final, so each row is one
// (B + 2)-bit carry chain and an AND a bit: about 2·A·B + 2·A LUT4s, where Yosys 0.23 maps
// `a * b` without DSP tiles to about 6.1·A·B (docs/PERFORMANCE.md, "Gain stages in digit
// tables, arrays for LUT multipliers"). Each row is its own module kept whole, or ABC merges
// the rows into one logic network of the larger size. A register every STAGE rows (0: none) keeps a
// path to STAGE carry chains: ⌈A/STAGE⌉ − 1 clocks of latency; STAGE = 3 places a 34 × 34 at
// 107 MHz on an ECP5-85k. A is best the narrower operand (fewer rows).
(* keep_hierarchy *)
module array_row #(
    parameter integer B = 18,
    parameter integer NEG = 0
) (
    input  wire signed [B:0]   hi,
    input  wire                ai,
    input  wire signed [B-1:0] b,
    output wire                lo,
    output wire signed [B:0]   hi_next
);
    wire signed [B+1:0] pp = {{2{b[B-1]}}, b} & {(B + 2){ai}};
    wire signed [B+1:0] s = (NEG != 0) ? {hi[B], hi} - pp : {hi[B], hi} + pp;
    assign lo = s[0];
    assign hi_next = s[B+1:1];
endmodule

module array_mul #(
    parameter integer A = 18,
    parameter integer B = 18,
    parameter integer STAGE = 0
) (
    /* verilator lint_off UNUSEDSIGNAL */
    input  wire                  clk,  // unused without registers (STAGE = 0)
    /* verilator lint_on UNUSEDSIGNAL */
    input  wire signed [A-1:0]   a,
    input  wire signed [B-1:0]   b,
    output wire signed [A+B-1:0] p
);
    // after row i: the sum's high bits, its final low bits, and the operands for the rows left
    // (split_var: Verilator takes each entry as its own signal, not the array as one loop)
    wire signed [B:0]   hi [0:A] /* verilator split_var */;
    wire        [A-1:0] lo [0:A] /* verilator split_var */;
    wire        [A-1:0] ar [0:A] /* verilator split_var */;
    wire signed [B-1:0] br [0:A] /* verilator split_var */;
    assign hi[0] = 0;
    assign lo[0] = 0;
    assign ar[0] = a;
    assign br[0] = b;
    genvar i;
    generate
        for (i = 0; i < A; i = i + 1) begin : row
            wire bit_i;
            wire signed [B:0] h;
            array_row #(.B(B), .NEG((i == A - 1) ? 1 : 0)) r (
                .hi(hi[i]), .ai(ar[i][i]), .b(br[i]), .lo(bit_i), .hi_next(h));
            wire [A-1:0] lo_n = lo[i] | ({{(A - 1){1'b0}}, bit_i} << i);
            if (STAGE != 0 && i % STAGE == STAGE - 1 && i != A - 1) begin : staged
                reg signed [B:0]   hq;
                reg        [A-1:0] lq;
                reg        [A-1:0] aq;
                reg signed [B-1:0] bq;
                always @(posedge clk) begin
                    hq <= h;
                    lq <= lo_n;
                    aq <= ar[i];
                    bq <= br[i];
                end
                assign hi[i+1] = hq;
                assign lo[i+1] = lq;
                assign ar[i+1] = aq;
                assign br[i+1] = bq;
            end else begin : direct
                assign hi[i+1] = h;
                assign lo[i+1] = lo_n;
                assign ar[i+1] = ar[i];
                assign br[i+1] = br[i];
            end
        end
    endgenerate
    assign p = {hi[A][B-1:0], lo[A]};
endmodule
