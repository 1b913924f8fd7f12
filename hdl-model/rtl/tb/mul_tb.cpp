// The multipliers' testbench: random operands and the extremes into every multiplier of
// `mul_top.v` each clock; each product checked against the exact integer one after the unit's
// latency (the registered array multipliers' ⌈A/3⌉ − 1 clocks, the registered constant one's 1). Prints `mul: rays=0
// vectors=N clocks=C mismatches=K seconds=S` (a vector: one product checked), exits 1 on any
// mismatch. Argument: the clocks to run (default 20,000).
#include "Vmul_top.h"
#include "tb.h"
#include "verilated.h"
#include <cstdlib>
#include <vector>

typedef __int128 i128;

static uint64_t state = 0x9e3779b97f4a7c15ull;
static uint64_t next() {
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    return state;
}

static int64_t sext(uint64_t v, int bits) {
    return bits == 64 ? (int64_t)v : (int64_t)(v << (64 - bits)) >> (64 - bits);
}

static uint64_t mask(int bits) { return bits == 64 ? ~0ull : (1ull << bits) - 1; }

// An operand of `bits`: one clock in eight an extreme (most negative, most positive, −1, 0).
static int64_t operand(int bits) {
    uint64_t r = next();
    switch (r & 31) {
    case 0: return sext(1ull << (bits - 1), bits);
    case 1: return (int64_t)(mask(bits) >> 1);
    case 2: return -1;
    case 3: return 0;
    default: return sext(next() & mask(bits), bits);
    }
}

// The low `bits` of a product against a Verilator word array.
template <size_t N>
static bool equal(const VlWide<N> &w, i128 want, int bits) {
    for (int k = 0; k * 32 < bits; k++) {
        int take = bits - 32 * k < 32 ? bits - 32 * k : 32;
        uint32_t got = w[k] & (uint32_t)mask(take);
        uint32_t exp = (uint32_t)((unsigned __int128)want >> (32 * k)) & (uint32_t)mask(take);
        if (got != exp) return false;
    }
    return true;
}

struct In {
    int64_t a34, b34, a26, b64, x16;
};

int main(int argc, char **argv) {
    long clocks = argc > 1 ? atol(argv[1]) : 20000;
    const long L34 = 11, L90 = 8, L16 = 1;
    Vmul_top u;
    std::vector<In> hist;
    uint64_t vectors = 0, bad = 0;
    tb::Stopwatch watch;
    for (long t = 0; t < clocks; t++) {
        int64_t a18 = operand(18), b18 = operand(18), x32 = operand(32);
        In in = {operand(34), operand(34), operand(26), operand(64), operand(16)};
        int64_t x16 = in.x16;
        u.a18 = a18 & mask(18);
        u.b18 = b18 & mask(18);
        u.x32 = x32 & mask(32);
        u.x16 = x16 & mask(16);
        u.a34 = in.a34 & mask(34);
        u.b34 = in.b34 & mask(34);
        u.a26 = in.a26 & mask(26);
        u.b64 = (uint64_t)in.b64;
        u.clk = 0;
        u.eval();
        hist.push_back(in);
        vectors += 2;
        bad += sext(u.p18, 36) != a18 * b18;
        bad += (int64_t)u.k32 != x32 * (int64_t)0x26dd3b6a;
        if (t >= L16) {
            vectors++;
            bad += sext(u.k16, 32) != hist[t - L16].x16 * (int64_t)0x26dd;
        }
        if (t >= L34) {
            const In &o = hist[t - L34];
            vectors++;
            bad += !equal(u.p34, (i128)o.a34 * o.b34, 68);
        }
        if (t >= L90) {
            const In &o = hist[t - L90];
            vectors++;
            bad += !equal(u.p90, (i128)o.a26 * o.b64, 90);
        }
        u.clk = 1;
        u.eval();
    }
    tb::report("mul", 0, vectors, clocks, bad, watch.seconds());
    return bad ? 1 : 0;
}
