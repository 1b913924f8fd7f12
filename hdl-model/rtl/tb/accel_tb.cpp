// The whole one-lane accelerator's testbench (accel_single.v): reads the model's bus accesses
// (hemi-bench's `rtl-vectors --accel`, host/bench/src/rtl/accel.rs: the register driver casting
// on the model of `Params::SINGLE`) and makes them on the RTL's AHB-Lite port, one a clock as
// the model made them (`ahb.h`), comparing every read's data (the results through RESULT_OUT,
// STATUS, ERROR, the CYCLE and BUSY counters) and the interrupt line with the model's. A file
// without a result read is refused: it would show nothing of the datapath. Prints `accel:
// rays=0 vectors=N clocks=C mismatches=K seconds=S`, exits 1 on any mismatch.
#include "Vaccel_single.h"
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
    if (!ahb::read_ops("accel", argv[1], ops, fifo)) return 2;
    size_t results = 0;
    for (const ahb::Op &o : ops) results += o.access && !o.write && o.addr == 0x084;
    if (results == 0) {
        fprintf(stderr, "accel: %s reads no result\n", argv[1]);
        return 2;
    }
    tb::Stopwatch watch;
    Vaccel_single u;
    ahb::reset(u);
    ahb::Counts c = ahb::replay("accel", u, ops);
    tb::report("accel", 0, c.accesses, c.clocks, c.mismatches, watch.seconds());
    return c.mismatches ? 1 : 0;
}
