// Synthesis harness of the whole one-lane accelerator (accel_single.v), as syn_rotator.v is of
// the rotator: its bus inputs from a register chain shifted in from one pin, its outputs
// folded into one registered pin, so that the part's pins do not limit what is placed (a bus
// master's own flip-flops would drive and take them). Figures: `cargo xtask rtl`.
module syn_accel (
    input  wire clk,
    input  wire rstn,
    input  wire sin,
    output reg  sout
);
    // hsel, haddr, htrans, hwrite, hsize, hwdata, hready; the stream port's push, direction
    // and pop
    localparam integer N = 1 + 12 + 2 + 1 + 3 + 32 + 1 + 1 + 96 + 1;
    reg [N-1:0] c;
    always @(posedge clk) c <= {c[N-2:0], sin};

    wire [31:0] hrdata;
    wire hreadyout, hresp, irq, sp_full, sp_valid;
    wire [127:0] sp_result;
    accel_single dut (
        .hclk(clk), .hresetn(rstn), .hsel(c[0]), .haddr(c[12:1]), .htrans(c[14:13]),
        .hwrite(c[15]), .hsize(c[18:16]), .hwdata(c[50:19]), .hready(c[51]),
        .hrdata(hrdata), .hreadyout(hreadyout), .hresp(hresp), .irq(irq),
        .sp_push(c[52]), .sp_dir(c[148:53]), .sp_pop(c[149]), .sp_full(sp_full),
        .sp_valid(sp_valid), .sp_result(sp_result));
    reg [164:0] outs;
    always @(posedge clk) begin
        outs <= {hrdata, hreadyout, hresp, irq, sp_full, sp_valid, sp_result};
        sout <= ^outs;
    end
endmodule
