// The horizon filter's testbench: reads the model's vectors (hemi-bench's `rtl-vectors
// --horizon`, host/bench/src/rtl/horizon.rs), feeds one write a clock to the slot box's write
// path (`W` lines: the word, the value and the box the model holds after it, which the RTL
// writes a clock later) and one box a clock to the filter (`H` lines: the box, whether it counts, the origin, the axis and the
// model's verdict), and compares every box after its write and every verdict, in order, with
// the model's; a verdict must leave as many clocks after its box went in as the file's `L`
// line says (the model's HORIZON_LATENCY less the box read). Prints
// `horizon: rays=N vectors=M clocks=C mismatches=K seconds=S` (rays: the boxes filtered),
// exits 1 on any mismatch.
#include "Vhorizon_top.h"
#include "tb.h"
#include "verilated.h"
#include <cstdint>
#include <vector>

struct Write {
    uint32_t word, value;
    int64_t lo[3], hi[3];
    uint32_t written;
};
struct Box {
    uint32_t boxed;
    int64_t lo[3], hi[3], o[3], w[3];
    uint32_t below;
};

static bool read_vectors(const char *path, uint64_t &latency, std::vector<Write> &writes,
                         std::vector<Box> &boxes) {
    return tb::read_lines("horizon", path, [&](const std::string &tag, std::istringstream &in) {
        if (tag == "L") {
            in >> latency;
        } else if (tag == "W") {
            Write w;
            in >> w.word >> w.value >> w.lo[0] >> w.lo[1] >> w.lo[2] >> w.hi[0] >> w.hi[1] >>
                w.hi[2] >> w.written;
            writes.push_back(w);
        } else if (tag == "H") {
            Box b;
            in >> b.boxed >> b.lo[0] >> b.lo[1] >> b.lo[2] >> b.hi[0] >> b.hi[1] >> b.hi[2] >>
                b.o[0] >> b.o[1] >> b.o[2] >> b.w[0] >> b.w[1] >> b.w[2] >> b.below;
            boxes.push_back(b);
        }
        return bool(in);
    });
}

int main(int argc, char **argv) {
    Verilated::commandArgs(argc, argv);
    if (argc < 2) {
        fprintf(stderr, "usage: horizon VECTORS\n");
        return 2;
    }
    std::vector<Write> writes;
    std::vector<Box> boxes;
    uint64_t latency = 0;
    if (!read_vectors(argv[1], latency, writes, boxes)) return 2;
    if (latency == 0) {
        fprintf(stderr, "horizon: no L line in %s\n", argv[1]);
        return 2;
    }
    tb::Stopwatch watch;
    Vhorizon_top u;
    u.clk = 0;
    u.eval();
    uint64_t bad = 0, clocks = 0;
    // the write fed on the clock before, whose box is written at the end of this one
    size_t wi = 0, bi = 0, bo = 0, due = SIZE_MAX;
    std::vector<uint64_t> entered;
    while (wi < writes.size() || due != SIZE_MAX || bo < boxes.size()) {
        size_t wrote = due;
        due = wi < writes.size() ? wi : SIZE_MAX;
        u.b_we = wi < writes.size();
        if (u.b_we) {
            u.b_word = writes[wi].word;
            u.b_value = writes[wi].value;
            wi++;
        }
        u.f_valid = bi < boxes.size();
        if (u.f_valid) {
            const Box &b = boxes[bi++];
            u.f_boxed = b.boxed;
            for (int c = 0; c < 3; c++) {
                tb::put(u.f_lo, 24 * c, 24, b.lo[c]);
                tb::put(u.f_hi, 24 * c, 24, b.hi[c]);
                tb::put(u.f_o, 32 * c, 32, b.o[c]);
                tb::put(u.f_w, 32 * c, 32, b.w[c]);
            }
            entered.push_back(clocks);
        }
        tb::tick(u);
        clocks++;
        if (wrote != SIZE_MAX) {
            const Write &w = writes[wrote];
            bool same = u.b_written == w.written;
            for (int c = 0; c < 3; c++)
                same = same && tb::get(u.b_lo, 24 * c, 24) == w.lo[c] &&
                       tb::get(u.b_hi, 24 * c, 24) == w.hi[c];
            if (!same && bad++ < 10)
                printf("horizon: write %zu (word %u value %u): model lo %" PRId64 " %" PRId64 " %" PRId64
                       " hi %" PRId64 " %" PRId64 " %" PRId64 " written %u, RTL written %u\n",
                       wrote, w.word, w.value, w.lo[0], w.lo[1], w.lo[2], w.hi[0], w.hi[1], w.hi[2],
                       w.written, (unsigned)u.b_written);
        }
        if (u.f_out_valid && bo < boxes.size()) {
            const Box &b = boxes[bo];
            bool late = clocks - entered[bo] != latency;
            if ((u.f_below != b.below || late) && bad++ < 10)
                printf("horizon: box %zu: model below %u, RTL %u after %" PRIu64 " clocks\n", bo,
                       b.below, (unsigned)u.f_below, clocks - entered[bo]);
            bo++;
        }
        if (clocks > writes.size() + boxes.size() + 16) {
            printf("horizon: outputs missing after %" PRIu64 " clocks\n", clocks);
            bad += boxes.size() - bo;
            break;
        }
    }
    tb::report("horizon", boxes.size(), writes.size() + boxes.size(), clocks, bad, watch.seconds());
    u.final();
    return bad ? 1 : 0;
}
