// The register file's testbench: reads the model's bus accesses (hemi-bench's `rtl-vectors
// --regs`, host/bench/src/rtl/regs.rs) and makes them on the RTL's AHB-Lite port, one a clock
// as the model made them (an access's address phase on the clock before the model's, its data
// phase on the model's clock), comparing every read's data and the interrupt line with the
// model's; at the end it pops the ray FIFO through the datapath's port and compares each entry.
// The datapath's inputs stay idle (the workload never lets an entry leave the FIFO). Prints
// `regs: rays=0 vectors=N clocks=C mismatches=K seconds=S`, exits 1 on any mismatch.
#include "Vahb_regs.h"
#include "tb.h"
#include "verilated.h"
#include <vector>

struct Op {
    bool access = false, write = false;
    uint64_t model_clk = 0;
    uint32_t addr = 0, data = 0, irq = 0;
};

static bool read_vectors(const char *path, std::vector<Op> &ops,
                         std::vector<std::vector<uint32_t>> &fifo) {
    return tb::read_lines("regs", path, [&](const std::string &tag, std::istringstream &in) {
        if (tag == "I") {
            uint32_t n;
            in >> std::dec >> n;
            for (uint32_t k = 0; k < n; k++) ops.push_back(Op());
        } else if (tag == "W" || tag == "R") {
            Op o;
            o.access = true;
            o.write = tag == "W";
            in >> std::dec >> o.model_clk >> std::hex >> o.addr >> o.data >> std::dec >> o.irq;
            ops.push_back(o);
        } else if (tag == "Q") {
            size_t n;
            in >> std::dec >> n;
        } else if (tag == "F") {
            std::vector<uint32_t> w(8);
            for (auto &x : w) in >> std::hex >> x;
            fifo.push_back(w);
        }
        return bool(in);
    });
}

// The slave's clock is HCLK, not `clk` (`tb::tick`'s).
static void tick(Vahb_regs &u) {
    u.hclk = 1;
    u.eval();
    u.hclk = 0;
    u.eval();
}

int main(int argc, char **argv) {
    Verilated::commandArgs(argc, argv);
    if (argc < 2) {
        fprintf(stderr, "usage: tb VECTORS\n");
        return 2;
    }
    std::vector<Op> ops;
    std::vector<std::vector<uint32_t>> fifo;
    if (!read_vectors(argv[1], ops, fifo)) return 2;
    tb::Stopwatch watch;
    Vahb_regs u;
    u.hclk = 0;
    u.hresetn = 0;
    u.hsel = 0;
    u.htrans = 0;
    u.hready = 1;
    u.hsize = 2;
    u.eval();
    tick(u);
    tick(u);
    u.hresetn = 1;
    uint64_t mismatches = 0, accesses = 0, clocks = 0;
    auto report = [&](const char *what, const Op &o, uint64_t t, uint32_t got, uint32_t want) {
        if (mismatches++ < 20)
            fprintf(stderr, "regs: clock %" PRIu64 " (model %" PRIu64 ") %s %03x: %s %08x, model %08x\n",
                    t, o.model_clk, o.write ? "W" : "R", o.addr, what, got, want);
    };
    // clock t: the data phase of ops[t], the address phase of ops[t + 1]; while the slave
    // holds HREADYOUT low (a PATCH_DATA read's wait states) both are held, as a master holds
    // them, and the clock passes (the model ticked as many times before its read)
    for (uint64_t t = 0; t <= ops.size(); t++) {
        const Op *next = t + 1 < ops.size() ? &ops[t + 1] : nullptr;
        u.hsel = next && next->access;
        u.htrans = next && next->access ? 2 : 0;
        u.hwrite = next && next->write;
        u.haddr = next ? next->addr & 0xFFF : 0;
        u.hwdata = t < ops.size() && ops[t].access && ops[t].write ? ops[t].data : 0;
        u.eval();
        for (int w = 0; !u.hreadyout; w++) {
            if (w == 8) {
                mismatches++;
                fprintf(stderr, "regs: clock %" PRIu64 ": HREADYOUT low for 8 clocks\n", t);
                break;
            }
            u.hready = 0;
            u.eval();
            tick(u);
            clocks++;
            u.hready = 1;
            u.eval();
        }
        if (t < ops.size() && ops[t].access) {
            const Op &o = ops[t];
            accesses++;
            if (!o.write && u.hrdata != o.data) report("read", o, t, u.hrdata, o.data);
            if (u.irq != o.irq) report("irq", o, t, u.irq, o.irq);
        }
        tick(u);
        clocks++;
    }
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
                if (mismatches++ < 20)
                    fprintf(stderr, "regs: FIFO entry %zu word %d: %08x, model %08x\n", k, w, got,
                            want);
            }
        }
        u.entry_pop = 1;
        tick(u);
        u.entry_pop = 0;
        clocks++;
    }
    if (k != fifo.size()) {
        mismatches++;
        fprintf(stderr, "regs: %zu FIFO entries, model %zu\n", k, fifo.size());
    }
    tb::report("regs", 0, accesses + fifo.size(), clocks, mismatches, watch.seconds());
    return mismatches ? 1 : 0;
}
