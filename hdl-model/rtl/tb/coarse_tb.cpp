// The coarse edge units' testbench: reads the model's vectors (hemi-bench's `rtl-vectors
// --coarse`, host/bench/src/rtl/coarse.rs), feeds one edge a clock to the set-up unit's edge
// words (`E` lines: u, v, shift, negate and the model's words and kappa) and one pair a clock
// to the lane's test (`C` lines: d', the patch's words, kappa, quad and the model's verdict),
// and compares every output, in order, with the model's. Prints `coarse: rays=N vectors=M
// clocks=C mismatches=K seconds=S` (rays: the pairs tested), exits 1 on any mismatch.
#include "Vcoarse_top.h"
#include "tb.h"
#include "verilated.h"
#include <vector>

struct Edge {
    int64_t u[3], v[3];
    uint32_t shift, negate;
    int64_t w[3];
    uint32_t kappa;
};
struct Pair {
    int64_t d[3];
    uint32_t quad, kappa;
    int64_t e[12];
    uint32_t decided, inside, undecided;
};

static bool read_vectors(const char *path, std::vector<Edge> &edges, std::vector<Pair> &pairs) {
    return tb::read_lines("coarse", path, [&](const std::string &tag, std::istringstream &in) {
        if (tag == "E") {
            Edge e;
            in >> e.u[0] >> e.u[1] >> e.u[2] >> e.v[0] >> e.v[1] >> e.v[2] >> e.shift >> e.negate >>
                e.w[0] >> e.w[1] >> e.w[2] >> e.kappa;
            edges.push_back(e);
        } else if (tag == "C") {
            Pair p;
            in >> p.d[0] >> p.d[1] >> p.d[2] >> p.quad >> p.kappa;
            for (auto &x : p.e) in >> x;
            in >> p.decided >> p.inside >> p.undecided;
            pairs.push_back(p);
        }
        return bool(in);
    });
}

static int64_t field(uint64_t bits, int lo, int width) {
    int64_t v = (int64_t)((bits >> lo) & ((1ull << width) - 1));
    return v >= (1ll << (width - 1)) ? v - (1ll << width) : v;
}

int main(int argc, char **argv) {
    Verilated::commandArgs(argc, argv);
    if (argc < 2) {
        fprintf(stderr, "usage: coarse VECTORS\n");
        return 2;
    }
    std::vector<Edge> edges;
    std::vector<Pair> pairs;
    if (!read_vectors(argv[1], edges, pairs)) return 2;
    tb::Stopwatch watch;
    Vcoarse_top u;
    u.clk = 0;
    u.eval();
    uint64_t bad = 0, clocks = 0;
    size_t ei = 0, pi = 0, eo = 0, po = 0;
    while (eo < edges.size() || po < pairs.size()) {
        u.e_valid = ei < edges.size();
        if (u.e_valid) {
            const Edge &e = edges[ei++];
            for (int c = 0; c < 3; c++) {
                tb::put(u.e_u, 33 * c, 33, e.u[c]);
                tb::put(u.e_v, 33 * c, 33, e.v[c]);
            }
            u.e_shift = e.shift;
            u.e_negate = e.negate;
        }
        u.t_valid = pi < pairs.size();
        if (u.t_valid) {
            const Pair &p = pairs[pi++];
            uint64_t d = 0;
            for (int c = 0; c < 3; c++) d |= ((uint64_t)p.d[c] & 0x3ffff) << (18 * c);
            u.t_d = d;
            for (int k = 0; k < 12; k++) tb::put(u.t_words, 18 * k, 18, p.e[k]);
            u.t_kappa = p.kappa;
            u.t_quad = p.quad;
        }
        tb::tick(u);
        clocks++;
        if (u.e_out_valid && eo < edges.size()) {
            const Edge &e = edges[eo];
            int64_t w[3];
            for (int c = 0; c < 3; c++) w[c] = field(u.e_words, 18 * c, 18);
            bool same = w[0] == e.w[0] && w[1] == e.w[1] && w[2] == e.w[2] && u.e_kappa == e.kappa;
            if (!same && bad++ < 10)
                printf("coarse: edge %zu u %" PRId64 " %" PRId64 " %" PRId64 " v %" PRId64 " %" PRId64
                       " %" PRId64 ": model %" PRId64 " %" PRId64 " %" PRId64 " k%u, RTL %" PRId64
                       " %" PRId64 " %" PRId64 " k%u\n",
                       eo, e.u[0], e.u[1], e.u[2], e.v[0], e.v[1], e.v[2], e.w[0], e.w[1], e.w[2],
                       e.kappa, w[0], w[1], w[2], u.e_kappa);
            eo++;
        }
        if (u.t_out_valid && po < pairs.size()) {
            const Pair &p = pairs[po];
            bool same = u.t_decided == p.decided && u.t_inside == p.inside &&
                        u.t_undecided == p.undecided;
            if (!same && bad++ < 10)
                printf("coarse: pair %zu: model decided %u inside %u undecided %u, RTL %u %u %u\n",
                       po, p.decided, p.inside, p.undecided, u.t_decided, u.t_inside,
                       u.t_undecided);
            po++;
        }
        if (clocks > edges.size() + pairs.size() + 16) {
            printf("coarse: outputs missing after %" PRIu64 " clocks\n", clocks);
            bad += (edges.size() - eo) + (pairs.size() - po);
            break;
        }
    }
    tb::report("coarse", pairs.size(), edges.size(), clocks, bad, watch.seconds());
    u.final();
    return bad ? 1 : 0;
}
