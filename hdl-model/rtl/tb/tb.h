// What the co-simulation testbenches (hdl-model/rtl/tb/*.cpp) share: a vector file read line by
// line, a clock's two edges, fields of wide signals put and got, a wall-clock timer and the
// closing line `cargo xtask rtl` parses (`rtl::parse_report`). Until session 27 each testbench
// wrote these out again.
#pragma once
#include <chrono>
#include <cinttypes>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

namespace tb {

// Hands `line(tag, in)` every line of `path` but blank ones: its first word, and a stream on the
// rest. `line` returns false for a line it cannot read, which is printed (after `what`) and ends
// the read.
// False if the file cannot be opened or a line was refused.
template <typename F> bool read_lines(const char *what, const char *path, F line) {
    std::ifstream f(path);
    if (!f) {
        fprintf(stderr, "%s: cannot read %s\n", what, path);
        return false;
    }
    std::string text;
    while (std::getline(f, text)) {
        std::istringstream in(text);
        std::string tag;
        if (!(in >> tag)) continue;
        if (!line(tag, in)) {
            fprintf(stderr, "%s: bad line: %s\n", what, text.c_str());
            return false;
        }
    }
    return true;
}

// A rising, then a falling edge of the model's `clk`, evaluated after each.
template <typename M> void tick(M &m) {
    m.clk = 1;
    m.eval();
    m.clk = 0;
    m.eval();
}

// `width` bits of `value` (two's complement) at bit `lo` of a Verilator wide signal.
template <typename W> void put(W &w, int lo, int width, int64_t value) {
    for (int b = 0; b < width; b++) {
        int at = lo + b;
        uint32_t bit = (uint32_t)(((uint64_t)value >> b) & 1);
        w[at / 32] = (w[at / 32] & ~(1u << (at % 32))) | (bit << (at % 32));
    }
}

// `width` bits at bit `lo` of a Verilator wide signal, sign-extended.
template <typename W> int64_t get(const W &w, int lo, int width) {
    uint64_t v = 0;
    for (int b = 0; b < width; b++) {
        int at = lo + b;
        v |= (uint64_t)((w[at / 32] >> (at % 32)) & 1) << b;
    }
    return v >= (1ull << (width - 1)) ? (int64_t)v - (int64_t)(1ull << width) : (int64_t)v;
}

// Wall-clock seconds since it was made.
struct Stopwatch {
    std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
    double seconds() const {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
};

// The closing line: `WHAT: rays=N vectors=M clocks=C mismatches=K seconds=S`.
inline void report(const char *what, uint64_t rays, uint64_t vectors, uint64_t clocks,
                   uint64_t mismatches, double seconds) {
    printf("%s: rays=%" PRIu64 " vectors=%" PRIu64 " clocks=%" PRIu64 " mismatches=%" PRIu64
           " seconds=%.3f\n",
           what, rays, vectors, clocks, mismatches, seconds);
}

} // namespace tb
