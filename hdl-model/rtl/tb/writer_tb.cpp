// The bitmap writer's testbench: reads the model's vectors (hemi-bench's `rtl-vectors --writer`,
// host/bench/src/rtl/writer.rs) and drives `bitmap_writer.v` with them clock by clock: each pass's
// start (`P`), each answer (`A`) and each pass's end (`E`) on its clock. It compares every copy
// into the block RAMs with the model's (`C`: its first row's clock at the write port, its
// buffer and its column; `X`: the words of each of its rows, the others zero), every pass's
// completion with its clock (`R`) and, on it, the valid bits of the pass's buffer with the
// columns the model copied for it. Prints `writer: rays=N vectors=M clocks=C mismatches=K
// seconds=S` (rays: the answers; vectors: the rows copied and the passes completed), exits 1 on
// any mismatch.
#include "Vbitmap_writer.h"
#include "verilated.h"
#include "writer.h"
#include <map>

using writer::Answer;
using writer::Pass;

// What the writer is handed on one clock.
struct Inputs {
    const Answer *answer = nullptr;
    bool end = false, start = false;
};

int main(int argc, char **argv) {
    Verilated::commandArgs(argc, argv);
    if (argc < 2) {
        fprintf(stderr, "usage: writer VECTORS\n");
        return 2;
    }
    writer::Shape shape;
    std::vector<Pass> passes;
    bool read = tb::read_lines("writer", argv[1], [&](const std::string &tag, std::istringstream &in) {
        return writer::read_line(tag, in, shape, passes);
    });
    if (!read) return 2;
    if (shape.sectors == 0 || shape.copy == 0) {
        fprintf(stderr, "writer: no L line in %s\n", argv[1]);
        return 2;
    }
    // every input on the clock it is presented
    std::map<uint64_t, Inputs> inputs;
    uint64_t answers = 0;
    for (const Pass &p : passes) {
        inputs[p.start].start = true;
        for (const Answer &a : p.answers) inputs[a.clock].answer = &a;
        inputs[p.end].end = true;
        answers += p.answers.size();
    }
    uint64_t last = writer::last_ready(passes);

    tb::Stopwatch watch;
    Vbitmap_writer u;
    u.clk = 0;
    u.rst = 1;
    u.a_valid = u.e_valid = u.p_start = 0;
    u.eval();
    tb::tick(u);
    tb::tick(u);
    u.rst = 0;
    uint64_t bad = 0;
    writer::Checker check("writer", shape, passes, bad);
    for (uint64_t t = 0; t <= last + 1; t++) {
        auto in = inputs.find(t);
        const Inputs none;
        const Inputs &now = in == inputs.end() ? none : in->second;
        u.p_start = now.start;
        u.e_valid = now.end;
        u.a_valid = now.answer != nullptr;
        if (now.answer) {
            const Answer &a = *now.answer;
            u.a_place = a.place;
            u.a_kind = a.kind;
            u.a_lo = a.lo;
            u.a_len = a.len;
            u.a_band_lo = a.band_lo;
            u.a_band_hi = a.band_hi;
        }
        u.eval();
        check.clock(u, t);
        tb::tick(u);
    }
    check.finish(last);
    tb::report("writer", answers, check.vectors, last + 1, bad, watch.seconds());
    return bad ? 1 : 0;
}
