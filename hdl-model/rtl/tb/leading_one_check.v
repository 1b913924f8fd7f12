// The specification of `leading_one.v` and the check against it that `cargo xtask rtl` proves
// with Yosys's SAT solver for every word m (xtask/src/rtl/prove.rs): the first bit set from HI
// down to LO + 1, found by a plain loop, or LO when there is none. `bad` is 1 where the unit's
// word differs from it.
module leading_one_check #(
    parameter integer W = 66,
    parameter integer LO = 0,
    parameter integer HI = 65
) (
    input  wire [W-1:0] m,
    output wire         bad
);
    reg [W-1:0] spec;
    reg         found;
    integer     b;
    always @* begin
        spec = {W{1'b0}};
        found = 1'b0;
        for (b = HI; b > LO; b = b - 1) begin
            if (!found && m[b]) begin
                spec[b] = 1'b1;
                found = 1'b1;
            end
        end
        if (!found) spec[LO] = 1'b1;
    end
    wire [W-1:0] lead;
    leading_one #(.W(W), .LO(LO), .HI(HI)) unit (.m(m), .lead(lead));
    assign bad = lead != spec;
endmodule
