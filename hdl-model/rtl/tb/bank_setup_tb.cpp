// A bank's whole set-up pass's testbench (`bank_setup.v`: the bank front feeding its set-up
// unit): reads the model's vectors (hemi-bench's `rtl-vectors --bank`,
// host/bench/src/rtl/bank.rs; `bank.h`) group by group, writes the group's memories, begins
// each pass on its clock with its origin and frame, and compares, in order, every planar
// patch's answer — whether the origin is off its plane, its κ, its kind, bands and (for a
// wedge) its sectors — on its clock (`S`: the model's clock for the patch's last corner, which
// reaches the set-up unit the corner latency later; the answer the answer latency after that),
// and each edge's coarse words and κ in order. Words and answers of a patch on whose plane the
// origin lies are not compared (the model sets nothing up). Prints `bank_setup: rays=N
// vectors=M clocks=C mismatches=K seconds=S` (rays: the slots filtered; vectors: the patches
// set up), exits 1 on any mismatch.
#include "Vbank_setup.h"
#include "bank.h"
#include "verilated.h"

using bank::Group;

// A signed field of `bits` bits at `lsb` of a word.
static int64_t field(uint64_t w, int lsb, int bits) {
    uint64_t v = (w >> lsb) & ((1ull << bits) - 1);
    return (int64_t)(v << (64 - bits)) >> (64 - bits);
}

struct Checker {
    const Group &g;
    const bank::Latency &lat;
    uint64_t &bad;
    size_t edge_patch = 0, edge_k = 0, out = 0;

    void fail(const char *what, size_t i) {
        if (bad++ < 10) printf("bank_setup: patch %zu: %s differs\n", i, what);
    }

    void edge(const Vbank_setup &u) {
        if (edge_patch >= g.set_ups.size()) return fail("an extra edge", edge_patch);
        const bank::SetUp &s = g.set_ups[edge_patch];
        if (s.active) {
            bool same = u.out_e_kappa == s.kappas[edge_k];
            for (int c = 0; c < 3; c++)
                same &= field(u.out_e_words, 18 * c, 18) == s.words[edge_k][c];
            if (!same) fail("an edge's words or κ", edge_patch);
        }
        if (++edge_k == s.n) edge_patch++, edge_k = 0;
    }

    void patch(const Vbank_setup &u, uint64_t t) {
        if (out >= g.set_ups.size()) return fail("an extra answer", out);
        const bank::SetUp &s = g.set_ups[out];
        if (t != s.clock + lat.corner + lat.answer) {
            if (bad < 10)
                printf("bank_setup: patch %zu: answer on clock %" PRIu64 ", due on %" PRIu64 "\n",
                       out, t, s.clock + lat.corner + lat.answer);
            fail("the answer's clock", out);
        }
        if (u.out_p_active != s.active) {
            fail("the plane test", out);
        } else if (s.active) {
            bool same = u.out_p_kappa == s.kappa && u.out_p_kind == s.kind &&
                        u.out_p_band_lo == s.band_lo && u.out_p_band_hi == s.band_hi;
            same &= s.kind != 2 || (u.out_p_lo == s.lo && u.out_p_len == s.len);
            if (!same) fail("the reach or κ", out);
        }
        out++;
    }
};

// The group's passes, each begun on its clock; mismatches, counted into `bad`.
static void run(Vbank_setup &u, const Group &g, const bank::Latency &lat, uint64_t &clocks,
                uint64_t &bad) {
    uint64_t last = bank::last_due(g, lat);
    Checker check{g, lat, bad};
    size_t pi = 0;
    for (uint64_t t = 0; t <= last + 16; t++) {
        u.start = pi < g.passes.size() && g.passes[pi].start == t;
        if (u.start) bank::begin(u, g.passes[pi++]);
        tb::tick(u);
        clocks++;
        if (u.out_e_valid) check.edge(u);
        if (u.out_p_valid) check.patch(u, t);
    }
    u.start = 0;
    if (check.out < g.set_ups.size() || check.edge_patch < g.set_ups.size()) {
        printf("bank_setup: %zu answers, %zu patches' edges missing at the group's end\n",
               g.set_ups.size() - check.out, g.set_ups.size() - check.edge_patch);
        bad += g.set_ups.size() - check.out + 1;
    }
}

int main(int argc, char **argv) {
    return bank::main_run<Vbank_setup>("bank_setup", argc, argv, run,
                                  [](const Group &g) { return g.set_ups.size(); });
}
