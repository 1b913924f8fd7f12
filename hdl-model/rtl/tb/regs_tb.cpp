// The register file's testbench: reads the model's bus accesses (hemi-bench's `rtl-vectors
// --regs`, host/bench/src/rtl/regs.rs) and makes them on the RTL's AHB-Lite port, one a clock
// as the model made them (`ahb.h`), comparing every read's data and the interrupt line with the
// model's; at the end it pops the ray FIFO through the datapath's port and compares each entry.
// The datapath's inputs stay idle (the workload never lets an entry leave the FIFO). Prints
// `regs: rays=0 vectors=N clocks=C mismatches=K seconds=S`, exits 1 on any mismatch.
#include "Vahb_regs.h"
#include "ahb.h"
#include "verilated.h"

int main(int argc, char **argv) {
    Verilated::commandArgs(argc, argv);
    if (argc < 2) {
        fprintf(stderr, "usage: tb VECTORS\n");
        return 2;
    }
    std::vector<ahb::Op> ops;
    std::vector<std::vector<uint32_t>> fifo;
    if (!ahb::read_ops("regs", argv[1], ops, fifo)) return 2;
    tb::Stopwatch watch;
    Vahb_regs u;
    ahb::reset(u);
    ahb::Counts c = ahb::replay("regs", u, ops);
    // the ray FIFO's entries, popped through the datapath's port
    u.hsel = 0;
    u.htrans = 0;
    size_t k = 0;
    for (; u.entry_valid && k < fifo.size() + 1; k++) {
        u.eval();
        for (int w = 0; w < 8; w++) {
            uint32_t got = u.entry[w];
            uint32_t want = k < fifo.size() ? fifo[k][w] : 0xFFFFFFFFu;
            if (got != want) {
                if (c.mismatches++ < 20)
                    fprintf(stderr, "regs: FIFO entry %zu word %d: %08x, model %08x\n", k, w, got,
                            want);
            }
        }
        u.entry_pop = 1;
        ahb::tick(u);
        u.entry_pop = 0;
        c.clocks++;
    }
    if (k != fifo.size()) {
        c.mismatches++;
        fprintf(stderr, "regs: %zu FIFO entries, model %zu\n", k, fifo.size());
    }
    tb::report("regs", 0, c.accesses + fifo.size(), c.clocks, c.mismatches, watch.seconds());
    return c.mismatches ? 1 : 0;
}
