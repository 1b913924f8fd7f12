// The specification of `add_sub.v` (a + b, or a - b when `sub` is set) and the check against it
// that `cargo xtask rtl` proves with Yosys's SAT solver for every a, b and sub
// (xtask/src/rtl/prove.rs), on the unit as mapped to the ECP5's cells (`add_sub_mapped`, its
// carry cells read with their simulation models). `bad` is 1 where the unit's sum differs.
module add_sub_check #(
    parameter integer W = 32
) (
    input  wire [W-1:0] a,
    input  wire [W-1:0] b,
    input  wire         sub,
    output wire         bad
);
    wire [W-1:0] s;
    add_sub_mapped unit (.a(a), .b(b), .sub(sub), .s(s));
    assign bad = s != (sub ? a - b : a + b);
endmodule
