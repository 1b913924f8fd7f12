// The bank front's testbench: reads the model's vectors (hemi-bench's `rtl-vectors --bank`,
// host/bench/src/rtl/bank.rs; `bank.h`) group by group: writes the group's boxes, corners and
// normals into the bank's memories, then begins each pass on its clock and compares, clock by
// clock, every corner the RTL reads with the model's (`K`: the model's clock, which the RTL
// must meet the corner latency later; a corner on any other clock is a mismatch) and the clock
// the bank falls idle (`I`: the model's pass end, plus the idle latency). Prints
// `bank: rays=N vectors=M clocks=C mismatches=K seconds=S` (rays: the slots filtered; vectors:
// the corners and idle clocks compared), exits 1 on any mismatch.
#include "Vbank_front.h"
#include "bank.h"
#include "verilated.h"

using bank::Group;

// The group's passes, each begun on its clock; mismatches, counted into `bad`.
static void run(Vbank_front &u, const Group &g, const bank::Latency &lat, uint64_t &clocks,
                uint64_t &bad) {
    uint64_t last = bank::last_due(g, lat);
    size_t pi = 0, ri = 0, ii = 0;
    bool was_busy = u.busy;
    for (uint64_t t = 0; t <= last + 16; t++) {
        // the pass that begins on clock t is started on the edge before it
        u.start = pi < g.passes.size() && g.passes[pi].start == t;
        if (u.start) {
            u.tag = bank::tag_of(pi);
            const bank::Pass &p = g.passes[pi++];
            u.count = p.count;
            for (int c = 0; c < 3; c++) {
                tb::put(u.o, 32 * c, 32, p.o[c]);
                tb::put(u.w, 32 * c, 32, p.axes[6 + c]);
            }
        }
        tb::tick(u);
        clocks++;
        bool due = ri < g.reads.size() && g.reads[ri].clock + lat.corner == t;
        if (due) {
            const bank::Read &r = g.reads[ri++];
            if ((!u.c_valid || u.c_slot != r.slot || u.c_corner != r.corner ||
                 u.c_last != r.last || u.c_pass != bank::tag_of(r.pass)) &&
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
            bool want = ii < g.idles.size() && g.idles[ii] + lat.idle == t;
            if (want) {
                ii++;
            } else if (bad++ < 10) {
                printf("bank: clock %" PRIu64 ": RTL idle, the model's next end at %" PRIu64 "\n",
                       t, ii < g.idles.size() ? g.idles[ii] + lat.idle : 0);
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
    return bank::main_run<Vbank_front>("bank", argc, argv, run,
                                  [](const Group &g) { return g.reads.size() + g.idles.size(); });
}
