// A W-bit signed word times a constant C, as a table per hex digit (a constant-coefficient
// multiplier): the word's digits, four bits each, each index a 16-entry table of digit × C, the
// tables' words summed shifted by their digit's place in a tree of adders. The top digit is
// signed (its table holds −8·C to 7·C), the others unsigned, so the sum is the exact signed
// product x·C, the same bits as `x * C`.
//
// Why not `x * C`: Yosys maps a 32-bit product to four DSP tiles (the rotator's six gain stages
// took 24 of the part's 156), or without tiles to about 6.1·W² LUT4s. A table of a 4-bit index
// is one LUT4 per bit of its word, so the product is about W/4 · (W + 4) LUT4s of tables and
// W/4 − 1 adders, with no DSP tile. The CORDIC's gain stages multiply by 1/K_n, a constant of
// the build here (ITER, W); a build whose CONFIG chooses ITER and WIDTH at run time would hold
// the same tables in distributed RAM and refill them (digit × C for 16 digits, one adder) when
// CONFIG is applied: not built.
module const_mul #(
    parameter integer W = 32,
    parameter [W-1:0] C = 0,
    // 1: the tree registered after its second level, so the product is out a clock after x
    // (the CORDIC gain stage's two clocks; in one, a 32-bit tree held the rotator to 76 MHz)
    parameter integer REG = 0
) (
    /* verilator lint_off UNUSEDSIGNAL */
    input  wire                  clk,  // unused without the register (REG = 0)
    /* verilator lint_on UNUSEDSIGNAL */
    input  wire signed [W-1:0]   x,
    output wire signed [2*W-1:0] p
);
    localparam integer DIGITS = (W + 3) / 4;
    localparam integer TW = W + 5;  // digit × C: |digit| ≤ 15 and C < 2^W, signed

    // the table of digit × C for the 16 digits, entry k in bits [k·TW +: TW]; `top` reads the
    // digit as signed (k ≥ 8 is k − 16)
    function [16*TW-1:0] table_of(input integer top);
        integer k;
        reg signed [TW-1:0] coef, m, e;
        begin
            table_of = 0;
            coef = $signed({5'b0, C});
            for (k = 0; k < 16; k = k + 1) begin
                m = $signed({{(TW - 5){1'b0}}, k[4:0]});
                if (top != 0 && k >= 8) m = m - 16;
                e = coef * m;
                table_of[k*TW +: TW] = e;
            end
        end
    endfunction

    localparam [16*TW-1:0] UNSIGNED_T = table_of(0);
    localparam [16*TW-1:0] SIGNED_T = table_of(1);

    // the digits padded to eight terms (W ≤ 32), so the tree below has one shape
    wire signed [2*W-1:0] term [0:7];
    genvar j;
    generate
        for (j = 0; j < 8; j = j + 1) begin : digit
            if (j < DIGITS) begin : used
                localparam integer LO = 4 * j;
                localparam integer BITS = (W - LO < 4) ? W - LO : 4;
                // the top digit sign-extended to four bits, the others as they are
                wire [3:0] dig;
                if (j == DIGITS - 1 && BITS == 1) begin : sign
                    assign dig = {4{x[W-1]}};
                end else if (j == DIGITS - 1) begin : top
                    assign dig = {{(4 - BITS + 1){x[W-1]}}, x[LO +: BITS - 1]};
                end else begin : low
                    assign dig = x[LO +: 4];
                end
                localparam [16*TW-1:0] T = (j == DIGITS - 1) ? SIGNED_T : UNSIGNED_T;
                wire signed [TW-1:0] e = T[dig*TW +: TW];
                assign term[j] = $signed({{(2*W-TW){e[TW-1]}}, e}) <<< LO;
            end else begin : unused
                assign term[j] = 0;
            end
        end
    endgenerate

    // a balanced tree: three adders deep
    wire signed [2*W-1:0] s01 = term[0] + term[1];
    wire signed [2*W-1:0] s23 = term[2] + term[3];
    wire signed [2*W-1:0] s45 = term[4] + term[5];
    wire signed [2*W-1:0] s67 = term[6] + term[7];
    wire signed [2*W-1:0] s03 = s01 + s23;
    wire signed [2*W-1:0] s47 = s45 + s67;
    generate
        if (REG != 0) begin : staged
            reg signed [2*W-1:0] s03_q, s47_q;
            always @(posedge clk) begin
                s03_q <= s03;
                s47_q <= s47;
            end
            assign p = s03_q + s47_q;
        end else begin : direct
            assign p = s03 + s47;
        end
    endgenerate
endmodule
