// The leading one of a word among its bits LO..HI, as a one-hot word: bit b (LO < b ≤ HI) is set
// when m[b] is and no bit above it up to HI is; bit LO is set when none of LO+1..HI is (whatever
// m[LO]); every other bit is zero. The culling's normalisations (`cull_angles.v`) shift by it.
//
// Why sliding windows: "no one above b" is an OR of up to HI − LO bits, and however it was
// written (a running OR, group ORs, a balanced tree of slices) Yosys's ABC shared the ORs of
// neighbouring bits into chains. On 66 bits that took 11 cells, LUT4s and the wide-LUT muxes,
// the set-up pass's critical path (92.8 MHz placed, session 32). Here every bit has ORs of its
// own windows, w1[i] of bits i..i+3, w2[i] of i..i+15 and w3[i] of i..i+63, each a LUT4 of four
// of the level below, and the windows are kept as wires so that ABC maps each as one LUT4:
// four LUT4s deep for any word up to HI − LO ≤ 128, at about four LUT4s a bit (279 on 66 bits).
module leading_one #(
    parameter integer W = 66,
    parameter integer LO = 0,
    parameter integer HI = 65
) (
    /* verilator lint_off UNUSEDSIGNAL */
    input  wire [W-1:0] m,  // bits LO..HI but LO's own value
    /* verilator lint_on UNUSEDSIGNAL */
    output wire [W-1:0] lead
);
    // the bits LO+1..HI of m, zero elsewhere and beyond the word (padded so that every window
    // below stays inside its vector)
    wire [W+127:0] mm;
    /* verilator lint_off UNUSEDSIGNAL */
    (* keep *) wire [W+124:0] w1;
    (* keep *) wire [W+112:0] w2;
    (* keep *) wire [W+64:0]  w3;
    /* verilator lint_on UNUSEDSIGNAL */
    genvar i;
    generate
        for (i = 0; i < W + 128; i = i + 1) begin : pad
            if (i > LO && i <= HI) begin : bit_in
                assign mm[i] = m[i];
            end else begin : bit_out
                assign mm[i] = 1'b0;
            end
        end
        for (i = 0; i < W + 125; i = i + 1) begin : four
            assign w1[i] = |mm[i +: 4];
        end
        for (i = 0; i < W + 113; i = i + 1) begin : sixteen
            assign w2[i] = w1[i] | w1[i + 4] | w1[i + 8] | w1[i + 12];
        end
        for (i = 0; i < W + 65; i = i + 1) begin : sixty_four
            assign w3[i] = w2[i] | w2[i + 16] | w2[i + 32] | w2[i + 48];
        end
        // bits i+1..i+128 of mm: any one above bit i
        for (i = 0; i < W; i = i + 1) begin : out
            if (i == LO) begin : at_lo
                assign lead[i] = !(w3[i + 1] | w3[i + 65]);
            end else if (i > LO && i <= HI) begin : above_lo
                assign lead[i] = m[i] & !(w3[i + 1] | w3[i + 65]);
            end else begin : outside
                assign lead[i] = 1'b0;
            end
        end
    endgenerate
endmodule
