// |x| of a two's-complement word, W bits (the magnitude of the most negative word is that word
// again, as `x[W-1] ? -x : x` gives it): 0 - x or 0 + x as one adder-subtractor whose operand
// the sign inverts (add_sub.v), one carry chain, where `x[W-1] ? -x : x` took a negation's
// chain and a multiplexer a bit after it. Used where synthesis measured it smaller: the reach's
// and the culling's normalisations (Yosys 0.23, the set-up unit: 449 LUT4s fewer). In the
// coarse edge unit it measured 883 LUT4s more, its wide multiplexers mapped otherwise; kept
// written there.
module magnitude #(
    parameter integer W = 34
) (
    input  wire [W-1:0] x,
    output wire [W-1:0] m
);
    add_sub #(.W(W)) negate_if (.a({W{1'b0}}), .b(x), .sub(x[W-1]), .s(m));
endmodule
