// Synthesis harness of the register file (`ahb_regs.v`) for place and route figures, as
// `syn_rotator.v` is the rotator's: the bus's and the datapath ports' inputs come from a
// register chain shifted in from one pin, every output is registered (as the bus master
// registers HRDATA at the end of the data phase) and the registers are folded into one
// registered pin. Until session 25 the outputs went into the fold unregistered, so the
// critical path ran on through five levels of XOR the unit does not have. Figures:
// `cargo xtask rtl`.
module syn_regs #(
    parameter integer SLOT_BITS = 10
) (
    input  wire clk,
    input  wire rstn,
    input  wire sin,
    output reg  sout
);
    // hsel, haddr, htrans, hwrite, hsize, hwdata, hready; entry_pop; dp_busy, frame_busy,
    // frame_done, frame_angles, stack_high, result_push, result_level, result_valid,
    // result_words, dp_raise, sp_push, sp_dir, sp_pop
    localparam integer N = 1 + 12 + 2 + 1 + 3 + 32 + 1 + 1 + 3 + 96 + 8 + 1 + 8 + 1 + 128 + 32
        + 1 + 96 + 1;
    reg [N-1:0] c;
    always @(posedge clk) c <= {c[N-2:0], sin};

    wire [31:0] hrdata, config_active, bz_config_active, patch_count;
    wire [255:0] entry;
    wire hreadyout, hresp, irq, entry_valid, result_pop, enable, apply, soft_reset, invalidate;
    wire frame_ok, pm_we, sp_full, sp_valid;
    wire [SLOT_BITS+3:0] pm_addr;
    wire [31:0] pm_data;
    ahb_regs #(.SLOT_BITS(SLOT_BITS)) dut (
        .hclk(clk), .hresetn(rstn), .hsel(c[0]), .haddr(c[12:1]), .htrans(c[14:13]),
        .hwrite(c[15]), .hsize(c[18:16]), .hwdata(c[50:19]), .hready(c[51]),
        .hrdata(hrdata), .hreadyout(hreadyout), .hresp(hresp), .irq(irq),
        .entry_valid(entry_valid), .entry(entry), .entry_pop(c[52]),
        .dp_busy(c[53]), .frame_busy(c[54]), .frame_done(c[55]), .frame_angles(c[151:56]),
        .stack_high(c[159:152]), .result_push(c[160]), .result_level(c[168:161]),
        .result_valid(c[169]), .result_words(c[297:170]), .result_pop(result_pop),
        .dp_raise(c[329:298]), .sp_push(c[330]), .sp_dir(c[426:331]), .sp_pop(c[427]),
        .sp_full(sp_full), .sp_valid(sp_valid), .enable(enable), .frame_ok(frame_ok), .pm_we(pm_we),
        .pm_addr(pm_addr), .pm_data(pm_data), .config_active(config_active), .bz_config_active(bz_config_active),
        .patch_count(patch_count), .apply(apply), .soft_reset(soft_reset),
        .invalidate(invalidate));
    localparam integer M = 32 + 1 + 1 + 1 + 1 + 256 + 1 + 1 + 32 + 32 + 32 + 1 + 1 + 1 + 1 + 1
        + SLOT_BITS + 4 + 32 + 2;
    reg [M-1:0] outs;
    always @(posedge clk) begin
        outs <= {hrdata, hreadyout, hresp, irq, entry_valid, entry, result_pop, enable,
            config_active, bz_config_active, patch_count, apply, soft_reset, invalidate,
            frame_ok, pm_we, pm_addr, pm_data, sp_full, sp_valid};
        sout <= ^outs;
    end
endmodule
