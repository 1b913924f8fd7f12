// The exact edge unit's testbench: reads the model's vectors (hemi-bench's `rtl-vectors
// --exact`, host/bench/src/rtl/exact.rs), offers each pair from the model's clock for it until
// the unit takes it, serves the unit's corner reads from the pairs' slots (a synchronous
// memory: the word a clock after its address), and checks that each pair is taken on the
// model's clock and its verdict is out on the model's clock, with its tag. Prints `exact:
// rays=N vectors=M clocks=C mismatches=K seconds=S` (rays: the pairs; vectors: their edges),
// exits 1 on any mismatch.
#include "Vexact_edge.h"
#include "tb.h"
#include "verilated.h"
#include <deque>
#include <vector>

struct Pair {
    uint64_t at;
    uint32_t slot, quad, mask, negate, shift;
    int64_t o[3], d[3], v[12];
    uint64_t begin, verdict;
    uint32_t inside;
};

static bool read_vectors(const char *path, std::vector<Pair> &pairs) {
    return tb::read_lines("exact", path, [&](const std::string &tag, std::istringstream &in) {
        if (tag == "L") {
            uint64_t window, grid, latency;
            in >> window >> grid >> latency;
        } else if (tag == "X") {
            Pair p;
            in >> p.at >> p.slot >> p.quad >> p.mask >> p.negate >> p.shift;
            for (auto &x : p.o) in >> x;
            for (auto &x : p.d) in >> x;
            for (auto &x : p.v) in >> x;
            in >> p.begin >> p.verdict >> p.inside;
            pairs.push_back(p);
        }
        return bool(in);
    });
}

static const int SLOTS = 1024, TAGS = 1024;

int main(int argc, char **argv) {
    Verilated::commandArgs(argc, argv);
    if (argc < 2) {
        fprintf(stderr, "usage: exact VECTORS\n");
        return 2;
    }
    std::vector<Pair> pairs;
    if (!read_vectors(argv[1], pairs)) return 2;
    uint64_t edges = 0;
    for (const Pair &p : pairs) edges += __builtin_popcount(p.mask);
    tb::Stopwatch watch;
    Vexact_edge u;
    std::vector<int64_t> corners(SLOTS * 4 * 3, 0);
    u.clk = 0;
    u.rst = 1;
    u.in_valid = 0;
    u.eval();
    tb::tick(u);
    u.rst = 0;
    uint64_t bad = 0, clock = 0;
    size_t next = 0, done = 0;
    std::deque<size_t> waiting;  // taken, verdict not yet out
    uint32_t read = 0;           // the address the unit gave on the last clock
    auto fail = [&](const char *what, size_t i, uint64_t model, uint64_t rtl) {
        if (bad++ < 10)
            printf("exact: pair %zu (mask %u): %s: model %" PRIu64 ", RTL %" PRIu64 "\n", i,
                   pairs[i].mask, what, model, rtl);
    };
    while (done < pairs.size()) {
        for (int c = 0; c < 3; c++) tb::put(u.c_data, 32 * c, 32, corners[3 * read + c]);
        bool offer = next < pairs.size() && pairs[next].at <= clock;
        u.in_valid = offer;
        if (offer) {
            const Pair &p = pairs[next];
            u.in_slot = p.slot;
            u.in_quad = p.quad;
            u.in_mask = p.mask;
            u.in_negate = p.negate;
            u.in_shift = p.shift;
            u.in_tag = next % TAGS;
            for (int c = 0; c < 3; c++) {
                tb::put(u.in_origin, 32 * c, 32, p.o[c]);
                tb::put(u.in_d, 32 * c, 32, p.d[c]);
            }
            for (int k = 0; k < 12; k++) corners[12 * p.slot + k] = p.v[k];
        }
        u.eval();
        if (u.out_valid) {
            if (waiting.empty()) {
                fail("a verdict without a pair", done, 0, clock);
            } else {
                size_t i = waiting.front();
                waiting.pop_front();
                const Pair &p = pairs[i];
                if (clock != p.verdict) fail("verdict clock", i, p.verdict, clock);
                if (u.out_inside != p.inside) fail("verdict", i, p.inside, u.out_inside);
                if (u.out_tag != i % TAGS) fail("tag", i, i % TAGS, u.out_tag);
                done++;
            }
        }
        if (offer && u.in_ready) {
            if (clock != pairs[next].begin) fail("taken on", next, pairs[next].begin, clock);
            waiting.push_back(next++);
        }
        read = u.c_addr;
        tb::tick(u);
        clock++;
        // a verdict that never comes, or a pair the unit never takes
        size_t late = waiting.empty() ? next : waiting.front();
        if (late < pairs.size() && clock > pairs[late].verdict + 16) {
            fail("no verdict", late, pairs[late].verdict, clock);
            bad += pairs.size() - done;
            break;
        }
    }
    tb::report("exact", pairs.size(), edges, clock, bad, watch.seconds());
    u.final();
    return bad ? 1 : 0;
}
