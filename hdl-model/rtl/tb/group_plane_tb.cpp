// A compact build's plane unit's testbench: reads the model's vectors (hemi-bench's
// `rtl-vectors --group-plane`, host/bench/src/rtl/group_plane.rs), writes the normal memory,
// hands the unit the first pairs and resets it with them in flight (their minima must be
// gone), waits for it to be ready, hands it each pair on the model's clock and asks each ray's answer on the model's
// clock, and checks that each answer is out on the clock the model gives (the readout's clock
// plus `answer_latency`), with its tag, hit, and for a hit its t, slot and side; and that no
// answer comes that was not asked for. Prints `group_plane: rays=N vectors=M clocks=C
// mismatches=K seconds=S` (rays: the readouts; vectors: the pairs), exits 1 on any mismatch.
#include "Vgroup_plane.h"
#include "tb.h"
#include "verilated.h"
#include <deque>
#include <vector>

struct Normal {
    uint32_t slot;
    int64_t n[3];
};

struct Pair {
    uint64_t at;
    uint32_t slot, tag;
    __int128 h;
    int64_t d[3];
};

struct Readout {
    uint64_t at;
    uint32_t tag, hit, slot, front;
    int64_t t;
};

// A decimal integer of up to 128 bits.
static bool read_i128(std::istringstream &in, __int128 &out) {
    std::string s;
    if (!(in >> s) || s.empty()) return false;
    bool neg = s[0] == '-';
    __int128 v = 0;
    for (size_t i = neg; i < s.size(); i++) {
        if (s[i] < '0' || s[i] > '9') return false;
        v = v * 10 + (s[i] - '0');
    }
    out = neg ? -v : v;
    return true;
}

// Pair `p` on the unit's inputs, with tag `tag`.
static void offer(Vgroup_plane &u, const Pair &p, uint32_t tag) {
    u.in_valid = 1;
    u.in_slot = p.slot;
    u.in_tag = tag;
    tb::put(u.in_h, 0, 64, (int64_t)p.h);
    tb::put(u.in_h, 64, 4, (int64_t)(p.h >> 64));
    for (int c = 0; c < 3; c++) tb::put(u.in_d, 32 * c, 32, p.d[c]);
}

static bool read_vectors(const char *path, std::vector<Normal> &normals, std::vector<Pair> &pairs,
                         std::vector<Readout> &readouts, uint64_t &latency) {
    return tb::read_lines("group_plane", path, [&](const std::string &tag, std::istringstream &in) {
        if (tag == "L") {
            uint64_t t_latency;
            in >> t_latency >> latency;
        } else if (tag == "N") {
            Normal n;
            in >> n.slot >> n.n[0] >> n.n[1] >> n.n[2];
            normals.push_back(n);
        } else if (tag == "P") {
            Pair p;
            in >> p.at >> p.slot >> p.tag;
            if (!read_i128(in, p.h)) return false;
            in >> p.d[0] >> p.d[1] >> p.d[2];
            pairs.push_back(p);
        } else if (tag == "R") {
            Readout r;
            in >> r.at >> r.tag >> r.hit >> r.t >> r.slot >> r.front;
            readouts.push_back(r);
        }
        return bool(in);
    });
}

int main(int argc, char **argv) {
    Verilated::commandArgs(argc, argv);
    if (argc < 2) {
        fprintf(stderr, "usage: group_plane VECTORS\n");
        return 2;
    }
    std::vector<Normal> normals;
    std::vector<Pair> pairs;
    std::vector<Readout> readouts;
    uint64_t latency = 0;
    if (!read_vectors(argv[1], normals, pairs, readouts, latency)) return 2;
    if (readouts.empty()) {
        fprintf(stderr, "group_plane: no readouts in %s\n", argv[1]);
        return 2;
    }
    tb::Stopwatch watch;
    Vgroup_plane u;
    u.clk = 0;
    u.rst = 1;
    u.in_valid = 0;
    u.rd_valid = 0;
    u.nm_we = 0;
    u.eval();
    tb::tick(u);
    u.rst = 0;
    // the normal memory, written before clock 0
    for (const Normal &n : normals) {
        u.nm_we = 1;
        u.nm_addr = n.slot;
        for (int c = 0; c < 3; c++) tb::put(u.nm_data, 32 * c, 32, n.n[c]);
        tb::tick(u);
    }
    u.nm_we = 0;
    // the unit used before a reset: the first pairs, their minima never read out, must be gone
    // after it; the last 64 on the first eight tags, which the sweep empties first, so that
    // those still in the divider come out after it
    for (int i = 0; i < 50; i++) tb::tick(u);
    size_t dirty = pairs.size() < 4000 ? pairs.size() : 4000;
    for (size_t i = 0; i < dirty; i++) {
        offer(u, pairs[i], i + 64 < dirty ? pairs[i].tag : i % 8);
        tb::tick(u);
    }
    // reset with those pairs still in the unit's pipeline
    u.in_valid = 0;
    u.rst = 1;
    tb::tick(u);
    u.rst = 0;
    // the reset's sweep of the tags
    for (int i = 0; !u.ready; i++) {
        if (i > 4096) {
            printf("group_plane: not ready after a reset\n");
            return 1;
        }
        tb::tick(u);
    }
    uint64_t bad = 0, clock = 0;
    size_t next_pair = 0, next_read = 0, done = 0;
    auto fail = [&](const char *what, size_t i, int64_t model, int64_t rtl) {
        if (bad++ < 10)
            printf("group_plane: readout %zu (tag %u): %s: model %" PRId64 ", RTL %" PRId64 "\n",
                   i, i < readouts.size() ? readouts[i].tag : 0, what, model, rtl);
    };
    while (done < readouts.size()) {
        u.in_valid = 0;
        if (next_pair < pairs.size() && pairs[next_pair].at == clock) {
            offer(u, pairs[next_pair], pairs[next_pair].tag);
            next_pair++;
        }
        u.rd_valid = next_read < readouts.size() && readouts[next_read].at == clock;
        if (u.rd_valid) u.rd_tag = readouts[next_read++].tag;
        u.eval();
        bool due = readouts[done].at + latency == clock;
        if (u.out_valid && !due) {
            fail("an answer not asked for on this clock", done, 0, clock);
        } else if (due && !u.out_valid) {
            fail("no answer on its clock", done, readouts[done].at + latency, clock);
            done++;
        } else if (due) {
            const Readout &r = readouts[done];
            if (u.out_tag != r.tag) fail("tag", done, r.tag, u.out_tag);
            if (u.out_hit != r.hit) fail("hit", done, r.hit, u.out_hit);
            if (r.hit && u.out_t != r.t) fail("t", done, r.t, u.out_t);
            if (r.hit && u.out_slot != r.slot) fail("slot", done, r.slot, u.out_slot);
            if (r.hit && u.out_front != r.front) fail("side", done, r.front, u.out_front);
            done++;
        }
        tb::tick(u);
        clock++;
    }
    tb::report("group_plane", readouts.size(), pairs.size(), clock, bad, watch.seconds());
    u.final();
    return bad ? 1 : 0;
}
