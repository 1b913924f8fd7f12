// The culling unit's testbench: reads the model's vectors (hemi-bench's `rtl-vectors --cull`,
// host/bench/src/rtl/cull.rs) and feeds `cull_top.v` both streams at once: one reference
// direction a clock to the ray side (`cull_ray.v`), one corner a clock to the patch side
// (`cull_reach.v`). It compares, in order, whether a ray is culled and a culled ray's sector
// and band, and a patch's kind, bands and (for a wedge of sectors) its first sector and count.
// Prints `cull: rays=N vectors=P clocks=C mismatches=K seconds=S` (rays: the directions fed;
// vectors: the patches), exits 1 on any mismatch.
#include "Vcull_top.h"
#include "tb.h"
#include "verilated.h"
#include <algorithm>
#include <vector>

struct Ray {
    int64_t d[3];
    uint32_t culled, sector, band;
};

struct Patch {
    uint32_t n, kappa;
    int64_t axes[9], a[4][3], e[4][3];
    uint32_t kind, lo, len, band_lo, band_hi;
};

static bool read_patch(std::istringstream &in, Patch &p) {
    in >> p.n >> p.kappa;
    for (auto &x : p.axes) in >> x;
    if (!in || p.n < 3 || p.n > 4) return false;
    for (uint32_t k = 0; k < p.n; k++) in >> p.a[k][0] >> p.a[k][1] >> p.a[k][2];
    for (uint32_t k = 0; k < p.n; k++) in >> p.e[k][0] >> p.e[k][1] >> p.e[k][2];
    in >> p.kind >> p.lo >> p.len >> p.band_lo >> p.band_hi;
    return bool(in);
}

static bool read_vectors(const char *path, std::vector<Ray> &rays, std::vector<Patch> &patches) {
    return tb::read_lines("cull", path, [&](const std::string &tag, std::istringstream &in) {
        if (tag == "R") {
            Ray r;
            in >> r.d[0] >> r.d[1] >> r.d[2] >> r.culled >> r.sector >> r.band;
            rays.push_back(r);
            return bool(in);
        }
        if (tag == "P") {
            Patch p;
            if (!read_patch(in, p)) return false;
            patches.push_back(p);
        }
        return true;
    });
}

// Verilator's words for a signed port of `bits` bits (two's complement, the rest cleared).
static uint64_t word(int64_t v, int bits) { return (uint64_t)v & ((1ull << bits) - 1); }

// Drives one corner of a patch (or none) onto the patch side's inputs.
static void feed_corner(Vcull_top &u, const Patch *p, uint32_t k) {
    u.p_valid = p != nullptr;
    if (!p) return;
    u.p_last = k + 1 == p->n;
    u.p_ax = word(p->a[k][0], 33);
    u.p_ay = word(p->a[k][1], 33);
    u.p_az = word(p->a[k][2], 33);
    u.p_ex = word(p->e[k][0], 18);
    u.p_ey = word(p->e[k][1], 18);
    u.p_ez = word(p->e[k][2], 18);
    u.p_kappa = p->kappa;
    u.p_ux = word(p->axes[0], 32);
    u.p_uy = word(p->axes[1], 32);
    u.p_uz = word(p->axes[2], 32);
    u.p_vx = word(p->axes[3], 32);
    u.p_vy = word(p->axes[4], 32);
    u.p_vz = word(p->axes[5], 32);
    u.p_wx = word(p->axes[6], 32);
    u.p_wy = word(p->axes[7], 32);
    u.p_wz = word(p->axes[8], 32);
}

static bool same_reach(const Vcull_top &u, const Patch &p) {
    bool same = u.p_kind == p.kind && u.p_band_lo == p.band_lo && u.p_band_hi == p.band_hi;
    return same && (p.kind != 2 || (u.p_lo == p.lo && u.p_len == p.len));
}

int main(int argc, char **argv) {
    Verilated::commandArgs(argc, argv);
    if (argc < 2) {
        fprintf(stderr, "usage: cull VECTORS\n");
        return 2;
    }
    std::vector<Ray> rays;
    std::vector<Patch> patches;
    if (!read_vectors(argv[1], rays, patches)) return 2;
    size_t corners = 0;
    for (const Patch &p : patches) corners += p.n;
    tb::Stopwatch watch;
    Vcull_top u;
    u.clk = 0;
    u.eval();
    uint64_t bad = 0, clocks = 0;
    size_t in = 0, out = 0, pin = 0, pk = 0, pout = 0;
    const size_t limit = std::max(rays.size(), corners) + 256;
    while (out < rays.size() || pout < patches.size()) {
        u.r_valid = in < rays.size();
        if (u.r_valid) {
            const Ray &r = rays[in++];
            u.r_x = (uint32_t)r.d[0];
            u.r_y = (uint32_t)r.d[1];
            u.r_z = (uint32_t)r.d[2];
        }
        feed_corner(u, pin < patches.size() ? &patches[pin] : nullptr, pk);
        if (pin < patches.size() && ++pk == patches[pin].n) pin++, pk = 0;
        tb::tick(u);
        clocks++;
        if (u.r_out_valid && out < rays.size()) {
            const Ray &r = rays[out];
            bool same = u.r_culled == r.culled &&
                        (!r.culled || (u.r_sector == r.sector && u.r_band == r.band));
            if (!same && bad++ < 10)
                printf("cull: ray %zu (%" PRId64 " %" PRId64 " %" PRId64 "): model culled %u "
                       "sector %u band %u, RTL %u %u %u\n",
                       out, r.d[0], r.d[1], r.d[2], r.culled, r.sector, r.band, u.r_culled,
                       u.r_sector, u.r_band);
            out++;
        }
        if (u.p_out_valid && pout < patches.size()) {
            const Patch &p = patches[pout];
            if (!same_reach(u, p) && bad++ < 10)
                printf("cull: patch %zu: model kind %u sectors %u+%u bands %u..%u, RTL %u "
                       "%u+%u %u..%u\n",
                       pout, p.kind, p.lo, p.len, p.band_lo, p.band_hi, u.p_kind, u.p_lo,
                       u.p_len, u.p_band_lo, u.p_band_hi);
            pout++;
        }
        if (clocks > limit) {
            printf("cull: outputs missing after %" PRIu64 " clocks\n", clocks);
            bad += rays.size() - out + patches.size() - pout;
            break;
        }
    }
    tb::report("cull", rays.size(), patches.size(), clocks, bad, watch.seconds());
    u.final();
    return bad ? 1 : 0;
}
