// The bank front's testbench: reads the model's vectors (hemi-bench's `rtl-vectors --bank`,
// host/bench/src/rtl/bank.rs) group by group: writes the group's boxes and corners into the
// bank's memories (`B`, `C` lines), then begins each pass (`P`) on its clock and compares, clock
// by clock, every corner the RTL reads with the model's (`K`: the model's clock, which the RTL
// must meet the `L` line's corner latency later; a corner on any other clock is a mismatch)
// and the clock the bank falls idle (`I`: the model's pass end, plus the idle latency). Prints
// `bank: rays=N vectors=M clocks=C mismatches=K seconds=S` (rays: the slots filtered; vectors:
// the corners and idle clocks compared), exits 1 on any mismatch.
#include "Vbank_front.h"
#include "tb.h"
#include "verilated.h"
#include <cstdint>
#include <vector>

struct Box {
    uint32_t slot, boxed, clocks;
    int64_t lo[3], hi[3];
};
struct Corner {
    uint32_t addr;
    int64_t v[3];
};
struct Pass {
    uint64_t start;
    uint32_t count;
    int64_t o[3], w[3];
};
struct Read {
    uint64_t clock;
    uint32_t slot, corner, last;
};
struct Group {
    std::vector<Box> boxes;
    std::vector<Corner> corners;
    std::vector<Pass> passes;
    std::vector<Read> reads;
    std::vector<uint64_t> idles;
};

static bool read_vectors(const char *path, uint64_t &corner_lat, uint64_t &idle_lat,
                         std::vector<Group> &groups) {
    return tb::read_lines("bank", path, [&](const std::string &tag, std::istringstream &in) {
        if (tag == "L") {
            in >> corner_lat >> idle_lat;
            return bool(in);
        }
        if (tag == "G") {
            groups.emplace_back();
            return true;
        }
        if (groups.empty()) return false;
        Group &g = groups.back();
        if (tag == "B") {
            Box b;
            in >> b.slot >> b.boxed >> b.clocks >> b.lo[0] >> b.lo[1] >> b.lo[2] >> b.hi[0] >>
                b.hi[1] >> b.hi[2];
            g.boxes.push_back(b);
        } else if (tag == "C") {
            Corner c;
            in >> c.addr >> c.v[0] >> c.v[1] >> c.v[2];
            g.corners.push_back(c);
        } else if (tag == "P") {
            Pass p;
            in >> p.start >> p.count >> p.o[0] >> p.o[1] >> p.o[2] >> p.w[0] >> p.w[1] >> p.w[2];
            g.passes.push_back(p);
        } else if (tag == "K") {
            Read r;
            in >> r.clock >> r.slot >> r.corner >> r.last;
            g.reads.push_back(r);
        } else if (tag == "I") {
            uint64_t t;
            in >> t;
            g.idles.push_back(t);
        } else {
            return false;
        }
        return bool(in);
    });
}

// The group's memories written, a box and a corner a clock.
static void load(Vbank_front &u, const Group &g, uint64_t &clocks) {
    size_t n = g.boxes.size() > g.corners.size() ? g.boxes.size() : g.corners.size();
    for (size_t i = 0; i < n; i++) {
        u.box_we = i < g.boxes.size();
        if (u.box_we) {
            const Box &b = g.boxes[i];
            u.box_slot = b.slot;
            u.box_boxed = b.boxed;
            u.box_clocks = b.clocks;
            for (int c = 0; c < 3; c++) {
                tb::put(u.box_lo, 24 * c, 24, b.lo[c]);
                tb::put(u.box_hi, 24 * c, 24, b.hi[c]);
            }
        }
        u.corner_we = i < g.corners.size();
        if (u.corner_we) {
            u.corner_addr = g.corners[i].addr;
            for (int c = 0; c < 3; c++) tb::put(u.corner_data, 32 * c, 32, g.corners[i].v[c]);
        }
        tb::tick(u);
        clocks++;
    }
    u.box_we = 0;
    u.corner_we = 0;
}

// The group's passes, each begun on its clock; mismatches, counted into `bad`.
static void run(Vbank_front &u, const Group &g, uint64_t corner_lat, uint64_t idle_lat,
                uint64_t &clocks, uint64_t &bad) {
    uint64_t last = 0;
    for (const Read &r : g.reads) last = std::max(last, r.clock + corner_lat);
    for (uint64_t t : g.idles) last = std::max(last, t + idle_lat);
    size_t pi = 0, ri = 0, ii = 0;
    bool was_busy = u.busy;
    for (uint64_t t = 0; t <= last + 16; t++) {
        // the pass that begins on clock t is started on the edge before it
        u.start = pi < g.passes.size() && g.passes[pi].start == t;
        if (u.start) {
            const Pass &p = g.passes[pi++];
            u.count = p.count;
            for (int c = 0; c < 3; c++) {
                tb::put(u.o, 32 * c, 32, p.o[c]);
                tb::put(u.w, 32 * c, 32, p.w[c]);
            }
        }
        tb::tick(u);
        clocks++;
        bool due = ri < g.reads.size() && g.reads[ri].clock + corner_lat == t;
        if (due) {
            const Read &r = g.reads[ri++];
            if ((!u.c_valid || u.c_slot != r.slot || u.c_corner != r.corner ||
                 u.c_last != r.last) &&
                bad++ < 10)
                printf("bank: clock %" PRIu64 ": model reads slot %u corner %u (last %u), RTL "
                       "valid %u slot %u corner %u last %u\n",
                       t, r.slot, r.corner, r.last, (unsigned)u.c_valid, (unsigned)u.c_slot,
                       (unsigned)u.c_corner, (unsigned)u.c_last);
        } else if (u.c_valid && bad++ < 10) {
            printf("bank: clock %" PRIu64 ": RTL reads slot %u corner %u, the model nothing\n", t,
                   (unsigned)u.c_slot, (unsigned)u.c_corner);
        }
        if (was_busy && !u.busy) {
            bool want = ii < g.idles.size() && g.idles[ii] + idle_lat == t;
            if (want) {
                ii++;
            } else if (bad++ < 10) {
                printf("bank: clock %" PRIu64 ": RTL idle, the model's next end at %" PRIu64 "\n",
                       t, ii < g.idles.size() ? g.idles[ii] + idle_lat : 0);
            }
        }
        was_busy = u.busy;
    }
    u.start = 0;
    if (ri < g.reads.size() || ii < g.idles.size() || pi < g.passes.size()) {
        printf("bank: %zu corners, %zu idle clocks, %zu passes left at the group's end\n",
               g.reads.size() - ri, g.idles.size() - ii, g.passes.size() - pi);
        bad += g.reads.size() - ri + g.idles.size() - ii + 1;
    }
}

int main(int argc, char **argv) {
    Verilated::commandArgs(argc, argv);
    if (argc < 2) {
        fprintf(stderr, "usage: bank VECTORS\n");
        return 2;
    }
    std::vector<Group> groups;
    uint64_t corner_lat = 0, idle_lat = 0;
    if (!read_vectors(argv[1], corner_lat, idle_lat, groups)) return 2;
    if (corner_lat == 0) {
        fprintf(stderr, "bank: no L line in %s\n", argv[1]);
        return 2;
    }
    tb::Stopwatch watch;
    Vbank_front u;
    u.clk = 0;
    u.eval();
    uint64_t bad = 0, clocks = 0, slots = 0, vectors = 0;
    for (const Group &g : groups) {
        load(u, g, clocks);
        run(u, g, corner_lat, idle_lat, clocks, bad);
        for (const Pass &p : g.passes) slots += p.count;
        vectors += g.reads.size() + g.idles.size();
    }
    tb::report("bank", slots, vectors, clocks, bad, watch.seconds());
    u.final();
    return bad ? 1 : 0;
}
