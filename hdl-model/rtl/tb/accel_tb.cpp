// The whole one-lane accelerator's testbench (accel_single.v): reads the model's bus accesses
// (hemi-bench's `rtl-vectors --accel`, host/bench/src/rtl/accel.rs: the register driver casting
// on the model of `Params::SINGLE`) and makes them on the RTL's AHB-Lite port, one a clock as
// the model made them (`ahb.h`), comparing every read's data (the results through RESULT_OUT,
// STATUS, ERROR, the CYCLE and BUSY counters) and the interrupt line with the model's; and the
// stream port's clocks, comparing its FULL and VALID and every result it pops. A file without a
// result read (through RESULT_OUT or the port) is refused: it would show nothing of the
// datapath. Prints `accel: rays=0 vectors=N clocks=C mismatches=K seconds=S`, exits 1 on any
// mismatch.
#include "Vaccel_single.h"
#include "ahb.h"
#include "verilated.h"

namespace {

// The stream port's inputs for one clock, and its outputs checked against the model's.
struct Port {
    void drive(Vaccel_single &u, const ahb::Op &o) {
        u.sp_push = o.push;
        u.sp_pop = o.pop;
        for (int k = 0; k < 3; k++) u.sp_dir[k] = o.dir[k];
    }
    uint64_t check(Vaccel_single &u, const ahb::Op &o, uint64_t t) {
        bool bad = u.sp_full != o.full || u.sp_valid != o.valid;
        for (int k = 0; o.pop && k < 4; k++) bad = bad || u.sp_result[k] != o.result[k];
        if (bad)
            fprintf(stderr,
                    "accel: clock %" PRIu64 " (model %" PRIu64 ") stream: full %u valid %u "
                    "result %08x %08x %08x %08x, model full %u valid %u result %08x %08x %08x "
                    "%08x\n",
                    t, o.model_clk, u.sp_full, u.sp_valid, u.sp_result[0], u.sp_result[1],
                    u.sp_result[2], u.sp_result[3], o.full, o.valid, o.result[0], o.result[1],
                    o.result[2], o.result[3]);
        return bad;
    }
    void release(Vaccel_single &u) {
        u.sp_push = 0;
        u.sp_pop = 0;
    }
};

} // namespace

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
    for (const ahb::Op &o : ops)
        results += (o.access && !o.write && o.addr == 0x084) || (o.stream && o.pop);
    if (results == 0) {
        fprintf(stderr, "accel: %s reads no result\n", argv[1]);
        return 2;
    }
    tb::Stopwatch watch;
    Vaccel_single u;
    ahb::reset(u);
    ahb::Counts c = ahb::replay("accel", u, ops, Port());
    tb::report("accel", 0, c.accesses, c.clocks, c.mismatches, watch.seconds());
    return c.mismatches ? 1 : 0;
}
