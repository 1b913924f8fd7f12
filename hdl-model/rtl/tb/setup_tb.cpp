// The compact set-up unit's testbench: reads the model's vectors (hemi-bench's `rtl-vectors
// --setup`, host/bench/src/rtl/setup.rs) and feeds `setup_unit.v` a corner a clock, pass after
// pass (a pass waits until the pass two before it is out, as the model's double-buffered set-up
// does; the unit's two sets of pass registers need less, 21 clocks after that pass's last
// corner). It compares, in order, each edge's coarse words and κ and each patch's answer —
// whether the origin is off its plane, its κ, its kind, bands and (for a wedge) its sectors —
// and their clocks: the answer the model's latency after the patch's last corner, the last
// edge's words one clock before the model's edge latency (the patch's κ is registered then).
// Words and answers of a patch on whose plane the origin lies are not compared (the model sets
// nothing up). Prints `setup: rays=0 vectors=P clocks=C mismatches=K seconds=S` (vectors: the
// patches), exits 1 on any mismatch.
#include "Vsetup_unit.h"
#include "tb.h"
#include "verilated.h"
#include <vector>

struct Patch {
    uint32_t pass, n, shift;
    int64_t o[3], axes[9], normal[3], v[4][3];
    uint32_t active, kappa;
    int64_t words[4][3];
    uint32_t kappas[4];
    uint32_t kind, lo, len, band_lo, band_hi;
};

static bool read_patch(std::istringstream &in, Patch &p) {
    // the file's shift is the model's origin_shift: not fed, the unit forms it from the origin
    // and every edge word depends on it
    in >> p.pass >> p.n >> p.o[0] >> p.o[1] >> p.o[2] >> p.shift;
    if (!in || p.n < 3 || p.n > 4) return false;
    for (auto &x : p.axes) in >> x;
    for (auto &x : p.normal) in >> x;
    for (uint32_t k = 0; k < p.n; k++) in >> p.v[k][0] >> p.v[k][1] >> p.v[k][2];
    in >> p.active >> p.kappa;
    for (uint32_t k = 0; k < p.n; k++) in >> p.words[k][0] >> p.words[k][1] >> p.words[k][2];
    for (uint32_t k = 0; k < p.n; k++) in >> p.kappas[k];
    in >> p.kind >> p.lo >> p.len >> p.band_lo >> p.band_hi;
    return bool(in);
}

static bool read_vectors(const char *path, uint64_t (&latency)[2], std::vector<Patch> &patches) {
    return tb::read_lines("setup", path, [&](const std::string &tag, std::istringstream &in) {
        if (tag == "L") return bool(in >> latency[0] >> latency[1]);
        if (tag != "S") return true;
        Patch p;
        if (!read_patch(in, p)) return false;
        patches.push_back(p);
        return true;
    });
}

// A signed field of `bits` bits at `lsb` of a word.
static int64_t field(uint64_t w, int lsb, int bits) {
    uint64_t v = (w >> lsb) & ((1ull << bits) - 1);
    return (int64_t)(v << (64 - bits)) >> (64 - bits);
}

// Drives corner k of patch p (or nothing) onto the inputs.
static void feed(Vsetup_unit &u, const Patch *p, uint32_t k) {
    u.in_valid = p != nullptr;
    if (!p) return;
    u.in_last = k + 1 == p->n;
    u.in_pass = p->pass & 1;
    u.in_cx = (uint32_t)p->v[k][0];
    u.in_cy = (uint32_t)p->v[k][1];
    u.in_cz = (uint32_t)p->v[k][2];
    u.in_nx = (uint32_t)p->normal[0];
    u.in_ny = (uint32_t)p->normal[1];
    u.in_nz = (uint32_t)p->normal[2];
    u.in_ox = (uint32_t)p->o[0];
    u.in_oy = (uint32_t)p->o[1];
    u.in_oz = (uint32_t)p->o[2];
    uint32_t *axes[9] = {&u.in_ux, &u.in_uy, &u.in_uz, &u.in_vx, &u.in_vy,
                         &u.in_vz, &u.in_wx, &u.in_wy, &u.in_wz};
    for (int i = 0; i < 9; i++) *axes[i] = (uint32_t)p->axes[i];
}

struct Checker {
    const std::vector<Patch> &patches;
    uint64_t latency, edge_latency, bad = 0;
    size_t edge_patch = 0, edge_k = 0, out = 0;
    std::vector<uint64_t> last_beat;

    void fail(const char *what, size_t i) {
        if (bad++ < 10) printf("setup: patch %zu: %s differs\n", i, what);
    }

    void edge(const Vsetup_unit &u, uint64_t clock) {
        if (edge_patch >= patches.size()) return fail("an extra edge", edge_patch);
        const Patch &p = patches[edge_patch];
        if (edge_k + 1 == p.n && clock - last_beat[edge_patch] + 2 != edge_latency)
            fail("the last edge's clock", edge_patch);
        if (p.active) {
            bool same = u.out_e_kappa == p.kappas[edge_k];
            for (int c = 0; c < 3; c++)
                same &= field(u.out_e_words, 18 * c, 18) == p.words[edge_k][c];
            if (!same) fail("an edge's words or κ", edge_patch);
        }
        if (++edge_k == p.n) edge_patch++, edge_k = 0;
    }

    void patch(const Vsetup_unit &u, uint64_t clock) {
        if (out >= patches.size()) return fail("an extra answer", out);
        const Patch &p = patches[out];
        if (clock - last_beat[out] + 1 != latency) fail("the answer's clock", out);
        if (u.out_p_active != p.active) fail("the plane test", out);
        else if (p.active) {
            bool same = u.out_p_kappa == p.kappa && u.out_p_kind == p.kind &&
                        u.out_p_band_lo == p.band_lo && u.out_p_band_hi == p.band_hi;
            same &= p.kind != 2 || (u.out_p_lo == p.lo && u.out_p_len == p.len);
            if (!same) {
                if (bad < 10)
                    printf("setup: patch %zu: model κ %u kind %u %u+%u bands %u..%u, RTL κ %u "
                           "%u %u+%u %u..%u\n",
                           out, p.kappa, p.kind, p.lo, p.len, p.band_lo, p.band_hi,
                           u.out_p_kappa, u.out_p_kind, u.out_p_lo, u.out_p_len,
                           u.out_p_band_lo, u.out_p_band_hi);
                fail("the reach or κ", out);
            }
        }
        out++;
    }
};

int main(int argc, char **argv) {
    Verilated::commandArgs(argc, argv);
    if (argc < 2) {
        fprintf(stderr, "usage: setup VECTORS\n");
        return 2;
    }
    uint64_t latency[2] = {0, 0};
    std::vector<Patch> patches;
    if (!read_vectors(argv[1], latency, patches)) return 2;
    // each pass's first patch
    std::vector<size_t> first;
    for (size_t i = 0; i < patches.size(); i++)
        if (i == 0 || patches[i].pass != patches[i - 1].pass) first.push_back(i);
    tb::Stopwatch watch;
    Vsetup_unit u;
    u.clk = 0;
    u.eval();
    Checker check{patches, latency[0], latency[1]};
    check.last_beat.resize(patches.size());
    uint64_t clocks = 0, idle = 0;
    size_t pin = 0, pk = 0, pass = 0;
    while (check.out < patches.size()) {
        // a pass's first corner waits until every patch before the previous pass is out
        bool starts = pk == 0 && pass < first.size() && pin == first[pass];
        bool wait = starts && pass >= 2 && check.out < first[pass - 1];
        const Patch *p = pin < patches.size() && !wait ? &patches[pin] : nullptr;
        feed(u, p, pk);
        if (p) {
            if (starts) pass++;
            if (++pk == p->n) check.last_beat[pin++] = clocks, pk = 0;
        }
        tb::tick(u);
        if (u.out_e_valid) check.edge(u, clocks);
        if (u.out_p_valid) check.patch(u, clocks);
        clocks++;
        idle = (u.out_e_valid || u.out_p_valid || p) ? 0 : idle + 1;
        if (idle > 4 * latency[0]) {
            printf("setup: answers missing after %" PRIu64 " clocks\n", clocks);
            check.bad += patches.size() - check.out;
            break;
        }
    }
    if (check.edge_patch != patches.size()) check.fail("the count of edges", check.edge_patch);
    tb::report("setup", 0, patches.size(), clocks, check.bad, watch.seconds());
    u.final();
    return check.bad ? 1 : 0;
}
