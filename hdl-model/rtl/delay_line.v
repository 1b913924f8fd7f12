// A word delayed N clocks, as a chain of N registers would delay it (out holds, after clock edge
// t + N − 1, what in held at edge t), for words that move every clock and are never stalled:
// a CORDIC pipe's payload, a corner waiting for its edges' words.
//
// Why not the chain: a chain of N registers is N·W flip-flops, and the default build ran out of
// flip-flops before it ran out of anything else but LUT4s (docs/PERFORMANCE.md, session 43).
// From N = 8 the word waits instead in distributed RAM: segments of 16 entries written in turn
// (an ECP5 TRELLIS_DPR16X4 holds 16 × 4 bits in six LUT4s' worth of a slice pair), each read
// K − 1 entries behind its write pointer into a register, which delays it K clocks (2 ≤ K ≤
// 16); the segments share one pointer. N·W flip-flops become ⌈W/4⌉ such cells and W flip-flops
// a segment. Below N = 8 the chain stays: the RAM's LUT4s would cost more than its flip-flops
// save, and the default build is shorter still of LUT4s. The RAM is never reset: only the
// distance between the pointer's write and its read matters, not where it starts.
module delay_line #(
    parameter integer W = 8,
    parameter integer N = 4
) (
    input  wire         clk,
    input  wire [W-1:0] in,
    output wire [W-1:0] out
);
    // the segments, each of K clocks: ⌈N/16⌉ of them, as equal as can be
    localparam integer SEGS = (N + 15) / 16;
    genvar s;
    generate
        if (N < 8) begin : chain
            reg [W-1:0] r [0:N-1];
            integer k;
            always @(posedge clk) begin
                r[0] <= in;
                for (k = 1; k < N; k = k + 1) r[k] <= r[k-1];
            end
            assign out = r[N-1];
        end else begin : ram
            reg [3:0] wp = 4'd0;
            always @(posedge clk) wp <= wp + 4'd1;
            wire [W-1:0] link [0:SEGS];
            assign link[0] = in;
            for (s = 0; s < SEGS; s = s + 1) begin : seg
                localparam integer K = N / SEGS + ((s < N % SEGS) ? 1 : 0);
                localparam [31:0] BACK = K - 1;
                reg [W-1:0] mem [0:15];
                reg [W-1:0] held;
                wire [3:0] rp = wp - BACK[3:0];
                always @(posedge clk) begin
                    mem[wp] <= link[s];
                    held <= mem[rp];
                end
                assign link[s+1] = held;
            end
            assign out = link[SEGS];
        end
    endgenerate
endmodule
