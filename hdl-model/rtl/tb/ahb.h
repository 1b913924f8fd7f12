// What the bus-level testbenches share (regs_tb.cpp, the register file alone; accel_tb.cpp, the
// whole one-lane accelerator): the model's bus accesses read from a vector file
// (host/bench/src/rtl/regs.rs's lines) and made on an AHB-Lite slave one a clock as the model
// made them, an access's address phase on the clock before the model's and its data phase on
// the model's clock, every read's data and the interrupt line compared with the model's; and
// the stream port's clocks (`S`), which a testbench's hooks drive and check.
#pragma once
#include "tb.h"
#include <vector>

namespace ahb {

struct Op {
    bool access = false, write = false, stream = false;
    uint64_t model_clk = 0;
    uint32_t addr = 0, data = 0, irq = 0;
    // a stream port clock: an entry pushed (its direction), a result popped (its words), and
    // the port's FULL and VALID as the model's driver saw them before the clock
    uint32_t push = 0, pop = 0, full = 0, valid = 0;
    uint32_t dir[3] = {0, 0, 0}, result[4] = {0, 0, 0, 0};
};

// The accesses of `path` (`I n` idle clocks, `W`/`R clk addr data irq`, `S clk push pop dx dy
// dz full valid r0 r1 r2 r3` a stream port clock); the ray FIFO's entries at the end (`F w0 …
// w7`, after `Q n`) into `fifo`.
inline bool read_ops(const char *what, const char *path, std::vector<Op> &ops,
                     std::vector<std::vector<uint32_t>> &fifo) {
    return tb::read_lines(what, path, [&](const std::string &tag, std::istringstream &in) {
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
        } else if (tag == "S") {
            Op o;
            o.stream = true;
            in >> std::dec >> o.model_clk >> o.push >> o.pop >> std::hex;
            for (auto &d : o.dir) in >> d;
            in >> std::dec >> o.full >> o.valid >> std::hex;
            for (auto &r : o.result) in >> r;
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
template <typename M> void tick(M &u) {
    u.hclk = 1;
    u.eval();
    u.hclk = 0;
    u.eval();
}

// Power-on reset: two clocks with HRESETn low, the bus idle.
template <typename M> void reset(M &u) {
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
}

// What a replay counted.
struct Counts {
    uint64_t accesses = 0, clocks = 0, mismatches = 0;
};

// The hooks of a slave without a stream port: a stream clock in its file is a mismatch.
struct NoStream {
    template <typename M> void drive(M &, const Op &) {}
    template <typename M> uint64_t check(M &, const Op &, uint64_t t) {
        fprintf(stderr, "clock %" PRIu64 ": a stream port clock for a slave without one\n", t);
        return 1;
    }
    template <typename M> void release(M &) {}
};

// Makes `ops` on the slave. Clock t is the data phase of ops[t] and the address phase of
// ops[t + 1]; while the slave holds HREADYOUT low (a PATCH_DATA read's wait states) both are
// held, as a master holds them, and the clock passes (the model ticked as many times before its
// read).
template <typename M, typename H = NoStream>
Counts replay(const char *what, M &u, const std::vector<Op> &ops, H hooks = H()) {
    Counts c;
    auto report = [&](const char *kind, const Op &o, uint64_t t, uint32_t got, uint32_t want) {
        if (c.mismatches++ < 20)
            fprintf(stderr, "%s: clock %" PRIu64 " (model %" PRIu64 ") %s %03x: %s %08x, model %08x\n",
                    what, t, o.model_clk, o.write ? "W" : "R", o.addr, kind, got, want);
    };
    for (uint64_t t = 0; t <= ops.size(); t++) {
        const Op *next = t + 1 < ops.size() ? &ops[t + 1] : nullptr;
        u.hsel = next && next->access;
        u.htrans = next && next->access ? 2 : 0;
        u.hwrite = next && next->write;
        u.haddr = next ? next->addr & 0xFFF : 0;
        u.hwdata = t < ops.size() && ops[t].access && ops[t].write ? ops[t].data : 0;
        bool stream = t < ops.size() && ops[t].stream;
        if (stream) hooks.drive(u, ops[t]);
        u.eval();
        for (int w = 0; !u.hreadyout; w++) {
            if (w == 8) {
                c.mismatches++;
                fprintf(stderr, "%s: clock %" PRIu64 ": HREADYOUT low for 8 clocks\n", what, t);
                break;
            }
            u.hready = 0;
            u.eval();
            tick(u);
            c.clocks++;
            u.hready = 1;
            u.eval();
        }
        if (t < ops.size() && ops[t].access) {
            const Op &o = ops[t];
            c.accesses++;
            if (!o.write && u.hrdata != o.data) report("read", o, t, u.hrdata, o.data);
            if (u.irq != o.irq) report("irq", o, t, u.irq, o.irq);
        }
        if (stream) c.mismatches += hooks.check(u, ops[t], t);
        tick(u);
        if (stream) hooks.release(u);
        c.clocks++;
    }
    return c;
}

} // namespace ahb
