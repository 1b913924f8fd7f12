// The planar intersection unit's testbench: reads the model's vectors (hemi-bench's
// `rtl-vectors --plane`, host/bench/src/rtl/plane.rs), loads patch memory, starts every ray on
// the clock the model started it (the RTL must be ready then) and compares every result the RTL
// gives, fields and clock, with the model's. Segments end with `E` (the unit is reset and its
// memory reloaded between them). Prints `plane: rays=N clocks=C mismatches=K seconds=S`, exits 1
// on any mismatch.
#include "Vplane_unit.h"
#include "tb.h"
#include "verilated.h"
#include <vector>

struct Ray {
    uint64_t clk;
    uint32_t o[3], d[3], uv, skip_en, skip, bypass;
};
struct Result {
    uint64_t clk;
    uint32_t hit, patch, t, u, v, front;
    bool operator==(const Result &r) const {
        return clk == r.clk && hit == r.hit && patch == r.patch && t == r.t && u == r.u &&
               v == r.v && front == r.front;
    }
};
struct Segment {
    std::vector<std::vector<uint32_t>> slots;
    uint32_t count = 0;
    std::vector<Ray> rays;
    std::vector<Result> results;
};

static bool read_segments(const char *path, std::vector<Segment> &out) {
    Segment seg;
    return tb::read_lines("plane", path, [&](const std::string &tag, std::istringstream &in) {
        if (tag == "P") {
            uint32_t slot;
            in >> std::dec >> slot;
            std::vector<uint32_t> w(16);
            for (auto &x : w) in >> std::hex >> x;
            seg.slots.push_back(w);
        } else if (tag == "N") {
            in >> std::dec >> seg.count;
        } else if (tag == "T") {
            Ray r;
            in >> std::dec >> r.clk >> std::hex >> r.o[0] >> r.o[1] >> r.o[2] >> r.d[0] >> r.d[1] >>
                r.d[2] >> r.uv >> r.skip_en >> r.skip >> r.bypass;
            seg.rays.push_back(r);
        } else if (tag == "H") {
            Result r;
            in >> std::dec >> r.clk >> std::hex >> r.hit >> r.patch >> r.t >> r.u >> r.v >> r.front;
            seg.results.push_back(r);
        } else if (tag == "E") {
            out.push_back(seg);
            seg = Segment();
            return true;
        }
        return bool(in);
    });
}

// one segment; returns its mismatches
static uint64_t run(Vplane_unit &u, const Segment &s, uint64_t &clocks) {
    u.rst = 1;
    u.in_valid = 0;
    u.pm_we = 0;
    u.count = s.count;
    // settle the clock low first: the first rising edge must be seen as one (it writes word 0)
    u.clk = 0;
    u.eval();
    for (size_t i = 0; i < s.slots.size(); i++)
        for (int w = 0; w < 16; w++) {
            u.pm_we = 1;
            u.pm_addr = (uint32_t)(i * 16 + w);
            u.pm_data = s.slots[i][w];
            tb::tick(u);
        }
    u.pm_we = 0;
    tb::tick(u);
    u.rst = 0;
    uint64_t bad = 0;
    size_t ri = 0, oi = 0;
    uint64_t end = (s.results.empty() ? 0 : s.results.back().clk) + 300;
    for (uint64_t clk = 0; clk <= end; clk++) {
        u.in_valid = ri < s.rays.size() && s.rays[ri].clk == clk;
        if (u.in_valid) {
            const Ray &r = s.rays[ri++];
            for (int c = 0; c < 3; c++) {
                u.in_origin[c] = r.o[c];
                u.in_dir[c] = r.d[c];
            }
            u.in_uv = r.uv;
            u.in_skip_en = r.skip_en;
            u.in_skip = r.skip;
            u.in_bypass = r.bypass;
        }
        u.clk = 0;
        u.eval();
        if (u.in_valid && !u.in_ready && bad++ < 10)
            printf("plane: clock %" PRIu64 ": the model started a ray, the RTL was not ready\n", clk);
        if (u.out_valid) {
            Result got{clk, u.out_hit, u.out_patch, u.out_t, u.out_u, u.out_v, u.out_front};
            if (oi >= s.results.size()) {
                if (bad++ < 10) printf("plane: extra result at clock %" PRIu64 "\n", clk);
            } else {
                const Result &e = s.results[oi];
                if (!(e == got) && bad++ < 10)
                    printf("plane: result %zu: model clock %" PRIu64 " hit %u patch %x t %08x u %08x "
                           "v %08x front %u; RTL clock %" PRIu64 " hit %u patch %x t %08x u %08x v %08x "
                           "front %u\n",
                           oi, e.clk, e.hit, e.patch, e.t, e.u, e.v, e.front, got.clk, got.hit,
                           got.patch, got.t, got.u, got.v, got.front);
                oi++;
            }
        }
        u.clk = 1;
        u.eval();
    }
    if (oi < s.results.size()) {
        printf("plane: %zu model results never came out of the RTL\n", s.results.size() - oi);
        bad += s.results.size() - oi;
    }
    clocks += end;
    return bad;
}

int main(int argc, char **argv) {
    Verilated::commandArgs(argc, argv);
    if (argc < 2) {
        fprintf(stderr, "usage: plane VECTORS\n");
        return 2;
    }
    std::vector<Segment> segs;
    if (!read_segments(argv[1], segs)) return 2;
    tb::Stopwatch watch;
    Vplane_unit u;
    u.clk = 0;
    uint64_t bad = 0, clocks = 0, rays = 0;
    for (const Segment &s : segs) {
        bad += run(u, s, clocks);
        rays += s.rays.size();
    }
    tb::report("plane", rays, 0, clocks, bad, watch.seconds());
    u.final();
    return bad ? 1 : 0;
}
