// Synthesis harness of a lane's bitmap walk (`bitmap_walk.v`), as `syn_writer.v` is the
// writer's: its inputs from a register chain shifted in from one pin, its outputs registered
// (the lane's coarse test registers its pair as it takes it), then folded into one registered
// pin. The walk holds its bank's bitmaps (the sector and band words in block RAM, the mask
// words in distributed RAM), so they are counted here. Figures: `cargo xtask rtl`.
module syn_walk (
    input  wire clk,
    input  wire sin,
    output reg  sout
);
    // write port, valid bits, ray, output ready
    localparam integer N = 1 + 1 + 1 + 7 + 3 + 64 + 16 + 64 + 8 + 8 + 1 + 1 + 5 + 4 + 1 + 9 + 8
                         + 1;
    reg [N-1:0] c;
    always @(posedge clk) c <= {c[N-2:0], sin};

    wire       r_ready, o_valid, o_last, z_valid;
    wire [8:0] o_place;
    wire [7:0] o_tag, z_tag;
    bitmap_walk walk (
        .clk(clk), .rst(c[0]), .w_valid(c[1]), .w_buf(c[2]), .w_row(c[9:3]), .w_col(c[12:10]),
        .w_sector(c[76:13]), .w_mask(c[92:77]), .w_band(c[156:93]), .valid0(c[164:157]),
        .valid1(c[172:165]), .r_valid(c[173]), .r_ready(r_ready), .r_buf(c[174]),
        .r_sector(c[179:175]), .r_band(c[183:180]), .r_skip_en(c[184]), .r_skip(c[193:185]),
        .r_tag(c[201:194]), .o_valid(o_valid), .o_ready(c[202]), .o_place(o_place),
        .o_tag(o_tag), .o_last(o_last), .z_valid(z_valid), .z_tag(z_tag));
    reg [28:0] q;
    always @(posedge clk) begin
        q <= {r_ready, o_valid, o_last, o_place, o_tag, z_valid, z_tag};
        sout <= ^q;
    end
endmodule
