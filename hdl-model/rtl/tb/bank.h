// What the bank testbenches (`bank_tb.cpp`: the front's corner reads; `bank_setup_tb.cpp`: the
// set-up unit's answers behind it) share: the vector file of hemi-bench's `rtl-vectors --bank`
// (host/bench/src/rtl/bank.rs) read into groups, a group's memories written into the bank and
// a pass begun on its ports, which both tops have alike.
#pragma once
#include "tb.h"
#include "verilated.h"
#include "writer.h"
#include <cstdint>
#include <vector>

namespace bank {

struct Box {
    uint32_t slot, boxed, clocks;
    int64_t lo[3], hi[3];
};
struct Word {  // a corner (address: slot and corner) or a normal (address: slot)
    uint32_t addr;
    int64_t v[3];
};
struct Pass {
    uint64_t start;
    uint32_t count;
    int64_t o[3], axes[9];
};
struct Read {
    uint64_t clock;
    uint32_t slot, corner, last;
    size_t pass;  // its pass's place in the group
};
// A planar patch's set-up: the model's clock for its last corner, its corners, and the answer
// as the set-up unit's vectors have it (setup_tb.cpp).
struct SetUp {
    uint64_t clock;
    uint32_t n, active, kappa;
    int64_t words[4][3];
    uint32_t kappas[4];
    uint32_t kind, lo, len, band_lo, band_hi;
};
// The tag a group's pass at `place` is begun with: its parity.
static uint32_t tag_of(size_t place) { return place & 1; }

struct Group {
    std::vector<Box> boxes;
    std::vector<Word> corners, normals;
    std::vector<Pass> passes;
    std::vector<Read> reads;
    std::vector<SetUp> set_ups;
    std::vector<uint64_t> idles;
    // the passes as the bank's bitmap writer has them (`W` lines: the writer reset with the
    // group, its clocks the group's)
    std::vector<writer::Pass> writes;
};
// The `L` line: the corner's latency after the model's clock, the idle latency after a pass's
// end, the set-up unit's answer latency after a patch's last corner; and the writer's `WL`.
struct Latency {
    uint64_t corner = 0, idle = 0, answer = 0;
    writer::Shape writer;
};

static bool read_set_up(std::istringstream &in, SetUp &s) {
    in >> s.clock >> s.n >> s.active >> s.kappa;
    if (!in || s.n < 3 || s.n > 4) return false;
    for (uint32_t k = 0; k < s.n; k++) in >> s.words[k][0] >> s.words[k][1] >> s.words[k][2];
    for (uint32_t k = 0; k < s.n; k++) in >> s.kappas[k];
    in >> s.kind >> s.lo >> s.len >> s.band_lo >> s.band_hi;
    return bool(in);
}

static bool read_line(const std::string &tag, std::istringstream &in, Latency &lat,
                      std::vector<Group> &groups) {
    if (tag == "L") return bool(in >> lat.corner >> lat.idle >> lat.answer);
    if (tag == "WL") return bool(in >> lat.writer.sectors >> lat.writer.copy);
    if (tag == "G") {
        groups.emplace_back();
        return true;
    }
    if (groups.empty()) return false;
    Group &g = groups.back();
    if (tag.size() == 2 && tag[0] == 'W') return writer::read_line(tag.substr(1), in, lat.writer, g.writes);
    if (tag == "B") {
        Box b;
        in >> b.slot >> b.boxed >> b.clocks >> b.lo[0] >> b.lo[1] >> b.lo[2] >> b.hi[0] >>
            b.hi[1] >> b.hi[2];
        g.boxes.push_back(b);
    } else if (tag == "C" || tag == "N") {
        Word w;
        in >> w.addr >> w.v[0] >> w.v[1] >> w.v[2];
        (tag == "C" ? g.corners : g.normals).push_back(w);
    } else if (tag == "P") {
        Pass p;
        in >> p.start >> p.count >> p.o[0] >> p.o[1] >> p.o[2];
        for (auto &a : p.axes) in >> a;
        g.passes.push_back(p);
    } else if (tag == "K" && !g.passes.empty()) {
        Read r;
        in >> r.clock >> r.slot >> r.corner >> r.last;
        r.pass = g.passes.size() - 1;
        g.reads.push_back(r);
    } else if (tag == "S" && !g.passes.empty()) {
        SetUp s;
        if (!read_set_up(in, s)) return false;
        g.set_ups.push_back(s);
    } else if (tag == "I") {
        uint64_t t;
        in >> t;
        g.idles.push_back(t);
    } else {
        return false;
    }
    return bool(in);
}

static bool read_vectors(const char *what, const char *path, Latency &lat,
                         std::vector<Group> &groups) {
    bool ok = tb::read_lines(what, path, [&](const std::string &tag, std::istringstream &in) {
        return read_line(tag, in, lat, groups);
    });
    if (ok && lat.corner == 0) {
        fprintf(stderr, "%s: no L line in %s\n", what, path);
        return false;
    }
    return ok;
}

// The group's memories written, a box, a corner and a normal a clock.
template <typename M> void load(M &u, const Group &g, uint64_t &clocks) {
    size_t n = std::max(g.boxes.size(), std::max(g.corners.size(), g.normals.size()));
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
        u.normal_we = i < g.normals.size();
        if (u.normal_we) {
            u.normal_slot = g.normals[i].addr;
            for (int c = 0; c < 3; c++) tb::put(u.normal_data, 32 * c, 32, g.normals[i].v[c]);
        }
        tb::tick(u);
        clocks++;
    }
    u.box_we = 0;
    u.corner_we = 0;
    u.normal_we = 0;
}

// Pass `p`'s count, origin and frame on the ports of a top with the set-up unit behind its
// front (`bank_setup.v`, `bank_pass.v`), for the clock it begins on.
template <typename M> void begin(M &u, const Pass &p) {
    u.count = p.count;
    for (int c = 0; c < 3; c++) {
        tb::put(u.origin, 32 * c, 32, p.o[c]);
        tb::put(u.axis_u, 32 * c, 32, p.axes[c]);
        tb::put(u.axis_v, 32 * c, 32, p.axes[3 + c]);
        tb::put(u.axis_w, 32 * c, 32, p.axes[6 + c]);
    }
}

// The last clock a group's answers are due on: the model's clocks and their latencies.
static uint64_t last_due(const Group &g, const Latency &lat) {
    uint64_t last = 0;
    for (const Read &r : g.reads) last = std::max(last, r.clock + lat.corner);
    for (const SetUp &s : g.set_ups) last = std::max(last, s.clock + lat.corner + lat.answer);
    for (uint64_t t : g.idles) last = std::max(last, t + lat.idle);
    return last;
}

// A testbench's whole run on the vectors of `argv[1]`: every group's memories written, then
// `run(u, group, latency, clocks, bad)`; `vectors(group)` is what a group's checks count.
// Prints the closing line as `what`; the exit status.
template <typename M, typename Run, typename Count>
int main_run(const char *what, int argc, char **argv, Run run, Count vectors) {
    Verilated::commandArgs(argc, argv);
    if (argc < 2) {
        fprintf(stderr, "usage: %s VECTORS\n", what);
        return 2;
    }
    std::vector<Group> groups;
    Latency lat;
    if (!read_vectors(what, argv[1], lat, groups)) return 2;
    tb::Stopwatch watch;
    M u;
    u.clk = 0;
    u.eval();
    uint64_t bad = 0, clocks = 0, slots = 0, checked = 0;
    for (const Group &g : groups) {
        load(u, g, clocks);
        run(u, g, lat, clocks, bad);
        for (const Pass &p : g.passes) slots += p.count;
        checked += vectors(g);
    }
    tb::report(what, slots, checked, clocks, bad, watch.seconds());
    u.final();
    return bad ? 1 : 0;
}

} // namespace bank
