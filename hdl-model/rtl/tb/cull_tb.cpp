// The culling unit's ray-side testbench: reads the model's vectors (hemi-bench's `rtl-vectors
// --cull`, host/bench/src/rtl/cull.rs), feeds one reference direction a clock to `cull_ray.v`
// and compares, in order, whether it is culled and, for a culled ray, its sector and band with
// the model's. Prints `cull: rays=N vectors=0 clocks=C mismatches=K seconds=S` (rays: the
// directions fed), exits 1 on any mismatch.
#include "Vcull_ray.h"
#include "verilated.h"
#include <chrono>
#include <cinttypes>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

struct Ray {
    int64_t d[3];
    uint32_t culled, sector, band;
};

static bool read_vectors(const char *path, std::vector<Ray> &rays) {
    std::ifstream f(path);
    if (!f) return false;
    std::string line;
    while (std::getline(f, line)) {
        std::istringstream in(line);
        std::string tag;
        in >> tag;
        if (tag != "R") continue;
        Ray r;
        in >> r.d[0] >> r.d[1] >> r.d[2] >> r.culled >> r.sector >> r.band;
        if (!in) {
            fprintf(stderr, "cull: bad line: %s\n", line.c_str());
            return false;
        }
        rays.push_back(r);
    }
    return true;
}

int main(int argc, char **argv) {
    Verilated::commandArgs(argc, argv);
    if (argc < 2) {
        fprintf(stderr, "usage: cull VECTORS\n");
        return 2;
    }
    std::vector<Ray> rays;
    if (!read_vectors(argv[1], rays)) {
        fprintf(stderr, "cull: cannot read %s\n", argv[1]);
        return 2;
    }
    auto t0 = std::chrono::steady_clock::now();
    Vcull_ray u;
    u.clk = 0;
    u.eval();
    uint64_t bad = 0, clocks = 0;
    size_t in = 0, out = 0;
    while (out < rays.size()) {
        u.in_valid = in < rays.size();
        if (u.in_valid) {
            const Ray &r = rays[in++];
            u.in_x = (uint32_t)r.d[0];
            u.in_y = (uint32_t)r.d[1];
            u.in_z = (uint32_t)r.d[2];
        }
        u.clk = 1;
        u.eval();
        u.clk = 0;
        u.eval();
        clocks++;
        if (u.out_valid) {
            const Ray &r = rays[out];
            bool same = u.out_culled == r.culled &&
                        (!r.culled || (u.out_sector == r.sector && u.out_band == r.band));
            if (!same && bad++ < 10)
                printf("cull: ray %zu (%" PRId64 " %" PRId64 " %" PRId64 "): model culled %u "
                       "sector %u band %u, RTL %u %u %u\n",
                       out, r.d[0], r.d[1], r.d[2], r.culled, r.sector, r.band, u.out_culled,
                       u.out_sector, u.out_band);
            out++;
        }
        if (clocks > rays.size() + 256) {
            printf("cull: outputs missing after %" PRIu64 " clocks\n", clocks);
            bad += rays.size() - out;
            break;
        }
    }
    double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    printf("cull: rays=%zu vectors=0 clocks=%" PRIu64 " mismatches=%" PRIu64 " seconds=%.3f\n",
           rays.size(), clocks, bad, secs);
    u.final();
    return bad ? 1 : 0;
}
