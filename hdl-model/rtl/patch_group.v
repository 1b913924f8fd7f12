// One group of the register file's patch memory (`ahb_regs.v`): a block RAM of 2^AW words read
// every clock at `at`, its word registered twice (the RAM's own output register, then `word`,
// so that its slow output, 5.8 ns on an ECP5, has a clock to itself), and written a clock after
// the access that asks for it (`write`, at `at`, with `data`), from registers.
//
// No RAM is read at the word being written on the same clock (the register file's write comes a
// clock after its access, when PATCH_ADDR has moved on by one word), so the memory is marked
// `no_rw_check`: otherwise Yosys keeps the read-before-write order of a collision with a bypass
// after the RAM (1,400 LUT4s over the file's 70 RAMs, and a LUT between the RAM's output and its
// register on the critical path). A simulation that meets one stops. Memories start at zero, as
// the model's (an ECP5's block RAMs do without the initial loop, and Yosys would unroll it word
// by word).
module patch_group #(
    parameter integer AW = 10
) (
    input  wire          clk,
    input  wire [AW-1:0] at,
    input  wire          write,
    input  wire [31:0]   data,
    output reg  [31:0]   word
);
    (* no_rw_check *) reg [31:0] mem [0:(1 << AW)-1];
    reg [31:0] q;
`ifndef SYNTHESIS
    integer j;
    initial for (j = 0; j < (1 << AW); j = j + 1) mem[j] = 32'd0;
`endif
    reg          pend;
    reg [AW-1:0] pend_at;
    always @(posedge clk) begin
        q <= mem[at];
        word <= q;
        pend <= write;
        pend_at <= at;
        if (pend) mem[pend_at] <= data;
`ifndef SYNTHESIS
        if (pend && pend_at == at) $fatal(1, "a RAM read the word it writes");
`endif
    end
endmodule
