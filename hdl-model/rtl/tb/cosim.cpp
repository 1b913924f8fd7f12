// The co-simulation testbench: reads the vectors the model wrote (hemi-bench's `rtl-vectors`,
// host/bench/src/rtl.rs), drives the Verilated RTL with every input at the clock the model took
// it, and compares every output the RTL produces, word and clock, with the model's. Prints one
// line `cosim: rays=N vectors=M clocks=C mismatches=K seconds=S` and exits 1 on any mismatch.
//
// Clock convention (the model's `tick`): on clock c the inputs of c are applied, the outputs
// seen are the registers' contents before the edge, then the edge. An entry the model takes on
// clock c and returns on clock c + L is L register stages in the RTL.
#include "Vcosim_top.h"
#include "tb.h"
#include "verilated.h"
#include <cstring>
#include <vector>

struct Event {
    uint64_t clk;
    uint32_t w[7];
};

struct Streams {
    std::vector<Event> rot_in, rot_out, vec_in, vec_out, frame_in, frame_angles, frame_done;
};

static bool parse_line(const std::string &tag, std::istringstream &in, Streams &s) {
    if (tag[0] == '#') return true;
    Event e{};
    in >> e.clk;
    int n = tag == "R" || tag == "F" ? 7 : tag == "f" ? 0 : 3;
    for (int i = 0; i < n; i++) in >> std::hex >> e.w[i];
    if (!in) return false;
    if (tag == "R") s.rot_in.push_back(e);
    else if (tag == "r") s.rot_out.push_back(e);
    else if (tag == "V") s.vec_in.push_back(e);
    else if (tag == "v") s.vec_out.push_back(e);
    else if (tag == "F") s.frame_in.push_back(e);
    else if (tag == "a") s.frame_angles.push_back(e);
    else if (tag == "f") s.frame_done.push_back(e);
    else return false;
    return true;
}

static int W_BITS = 32;

// a model container's top W bits, as the W-bit port takes them
static uint32_t word(uint32_t c) { return W_BITS == 32 ? c : (c >> (32 - W_BITS)); }
// a W-bit word back in the top bits of a container
static uint32_t container(uint32_t w) {
    return W_BITS == 32 ? w : (w << (32 - W_BITS));
}

struct Check {
    const char *what;
    const std::vector<Event> &expect;
    size_t next = 0;
    uint64_t mismatches = 0;
    Check(const char *w, const std::vector<Event> &e) : what(w), expect(e) {}
    void seen(uint64_t clk, const uint32_t *w) {
        if (next >= expect.size()) {
            if (mismatches++ < 10) printf("%s: extra output at clock %llu\n", what, (unsigned long long)clk);
            return;
        }
        const Event &e = expect[next++];
        bool same = e.clk == clk && !memcmp(e.w, w, 3 * sizeof(uint32_t));
        if (!same && mismatches++ < 10)
            printf("%s: output %zu: model clock %llu %08x %08x %08x, RTL clock %llu %08x %08x %08x\n",
                   what, next - 1, (unsigned long long)e.clk, e.w[0], e.w[1], e.w[2],
                   (unsigned long long)clk, w[0], w[1], w[2]);
    }
    uint64_t finish() {
        if (next < expect.size()) {
            printf("%s: %zu model outputs never came out of the RTL\n", what, expect.size() - next);
            mismatches += expect.size() - next;
        }
        return mismatches;
    }
};

int main(int argc, char **argv) {
    Verilated::commandArgs(argc, argv);
    if (argc < 3) {
        fprintf(stderr, "usage: cosim WIDTH VECTORS\n");
        return 2;
    }
    W_BITS = atoi(argv[1]);
    Streams s;
    auto line = [&](const std::string &tag, std::istringstream &in) {
        return parse_line(tag, in, s);
    };
    if (!tb::read_lines("cosim", argv[2], line)) return 2;
    uint64_t end = 0;
    for (auto *v : {&s.rot_out, &s.vec_out, &s.rot_in, &s.vec_in, &s.frame_in, &s.frame_done})
        if (!v->empty()) end = std::max(end, v->back().clk);
    end += 200;

    tb::Stopwatch watch;
    Vcosim_top top;
    top.clk = 0;
    top.rst = 1;
    for (int i = 0; i < 4; i++) {
        top.clk = !top.clk;
        top.eval();
    }
    top.rst = 0;
    Check rot("rotator", s.rot_out), vec("vectoring pipe", s.vec_out);
    size_t ri = 0, vi = 0, fi = 0, ai = 0, di = 0;
    // the angle unit: its done pulse on the model's clocks only, and its angles after every
    // clock equal to the model's latest
    uint64_t frame_bad = 0;
    uint32_t angles[3] = {0, 0, 0};
    for (uint64_t clk = 0; clk <= end; clk++) {
        top.r_valid = ri < s.rot_in.size() && s.rot_in[ri].clk == clk;
        if (top.r_valid) {
            const uint32_t *w = s.rot_in[ri++].w;
            top.r_dx = w[0]; top.r_dy = w[1]; top.r_dz = w[2];
            top.r_psi = w[3]; top.r_theta = w[4]; top.r_phi = w[5]; top.r_bypass = w[6] & 1;
        }
        top.v_valid = vi < s.vec_in.size() && s.vec_in[vi].clk == clk;
        if (top.v_valid) {
            const uint32_t *w = s.vec_in[vi++].w;
            top.v_x = word(w[0]); top.v_y = word(w[1]); top.v_z = word(w[2]);
        }
        top.f_start = fi < s.frame_in.size() && s.frame_in[fi].clk == clk;
        if (top.f_start) {
            const uint32_t *w = s.frame_in[fi++].w;
            top.f_pairs = w[0] & 1;
            top.f_w1 = word(w[1]); top.f_w2 = word(w[2]); top.f_w3 = word(w[3]);
            top.f_w4 = word(w[4]); top.f_w5 = word(w[5]); top.f_w6 = word(w[6]);
        }
        top.clk = 0;
        top.eval();
        bool done_model = di < s.frame_done.size() && s.frame_done[di].clk == clk;
        if (done_model) di++;
        if (bool(top.fo_done) != done_model && frame_bad++ < 10)
            printf("angle unit: clock %llu: done %d, model %d\n", (unsigned long long)clk,
                   int(top.fo_done), int(done_model));
        if (top.ro_valid) {
            uint32_t w[3] = {top.ro_dx, top.ro_dy, top.ro_dz};
            rot.seen(clk, w);
        }
        if (top.vo_valid) {
            uint32_t w[3] = {container(top.vo_x), container(top.vo_y), container(top.vo_z)};
            vec.seen(clk, w);
        }
        top.clk = 1;
        top.eval();
        if (ai < s.frame_angles.size() && s.frame_angles[ai].clk == clk)
            memcpy(angles, s.frame_angles[ai++].w, sizeof angles);
        uint32_t got[3] = {container(top.fo_psi), container(top.fo_theta), container(top.fo_phi)};
        if (memcmp(got, angles, sizeof angles) && frame_bad++ < 10)
            printf("angle unit: after clock %llu: %08x %08x %08x, model %08x %08x %08x\n",
                   (unsigned long long)clk, got[0], got[1], got[2], angles[0], angles[1],
                   angles[2]);
    }
    if (di < s.frame_done.size()) {
        printf("angle unit: %zu frames never completed in the RTL\n", s.frame_done.size() - di);
        frame_bad += s.frame_done.size() - di;
    }
    uint64_t bad = rot.finish() + vec.finish() + frame_bad;
    tb::report("cosim", s.rot_in.size(), s.vec_in.size() + s.frame_in.size(), end, bad,
               watch.seconds());
    top.final();
    return bad ? 1 : 0;
}
