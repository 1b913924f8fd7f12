// The whole one-lane accelerator (accel_single.v) as a simulator the host drives: `hemi …
// --backend rtl` runs its passes on the Verilated RTL through the register driver, over this
// program's standard input and output (host/hemi/src/backend/rtl.rs).
//
// Every command is a clock, as the model's bus makes each access a clock (`ModelBus`): an
// access's data phase, a clock without an access, or a stream port clock. A clock ends (its
// edge) when the next command is known, because an access's address phase is presented in the
// clock before its data phase, and the host sends the next access only once a read's word is
// back. So back-to-back accesses reach the RTL back to back, as the model takes them.
//
// Commands, little-endian records of nine bytes (an op and two words):
// - 'W' offset value: a write;
// - 'R' offset 0: a read (a PATCH_DATA read with its wait states), answered with its word (4
//   bytes);
// - 'I' n 0: n clocks without an access;
// - 'T' 0 0: the stream port as the next clock, a stream port clock, will find it, answered
//   with a byte (bit 0 FULL, bit 1 VALID) and the result at the head (16 bytes);
// - 'K' flags 0 [dx dy dz]: a stream port clock: bit 0 pushes the direction that follows (12
//   more bytes), bit 1 pops the result at the head;
// - 'C' 0 0: answered with CYCLE as it will read once the current clock ends (8 bytes): the
//   RTL's counter, less the address phases it had a clock of their own for (the first
//   access's), which the model does not have, until a soft reset starts the count again on
//   both.
// End of input ends the program.
#include "Vaccel_single.h"
#include "Vaccel_single___024root.h"
#include "ahb.h"
#include "verilated.h"

namespace {

struct Sim {
    Vaccel_single u;
    bool pending = false;        // a clock whose edge waits for the next command
    bool pending_write = false;  // that clock is a write's data phase
    bool pending_reset = false;  // the write is CTRL.SOFT_RESET
    uint32_t pending_data = 0;
    uint64_t offset = 0;         // clocks the model has not had: an address phase of its own

    // Ends the pending clock with the next one's address phase (`access`), or none: the edge,
    // and the stream port's inputs of the clock released. With no clock pending (the first
    // command, or one after 'T'), an access's address phase is a clock of its own, which the
    // model does not have: CYCLE counts it, `clocks` does not.
    void close(bool access, bool write, uint32_t addr) {
        u.hsel = access;
        u.htrans = access ? 2 : 0;
        u.hwrite = write;
        u.haddr = addr & 0xFFF;
        u.hwdata = pending && pending_write ? pending_data : 0;
        u.eval();
        if (!pending && !access) return;
        ahb::tick(u);
        if (!pending) offset++;
        if (pending && pending_reset) offset = 0;
        u.sp_push = 0;
        u.sp_pop = 0;
        pending = false;
    }

    void begin(bool write, bool reset, uint32_t data) {
        pending = true;
        pending_write = write;
        pending_reset = reset;
        pending_data = data;
    }

    void write(uint32_t addr, uint32_t value) {
        close(true, true, addr);
        begin(true, (addr & 0xFFF) == 0x00C && (value >> 31), value);
    }

    uint32_t read(uint32_t addr) {
        close(true, false, addr);
        begin(false, false, 0);
        u.hsel = 0;
        u.htrans = 0;
        u.hwdata = 0;
        u.eval();
        // a PATCH_DATA read's wait states: the bus holds, the clock passes
        for (int w = 0; !u.hreadyout && w < 8; w++) {
            u.hready = 0;
            u.eval();
            ahb::tick(u);
            u.hready = 1;
            u.eval();
        }
        return u.hrdata;
    }

    void idle(uint32_t n) {
        for (uint32_t k = 0; k < n; k++) {
            close(false, false, 0);
            begin(false, false, 0);
        }
    }

    // The port as the next clock finds it: the pending clock ends without an address phase
    // (the next clock is the port's, without an access).
    void peek(uint8_t *out) {
        close(false, false, 0);
        out[0] = (uint8_t)(u.sp_full | u.sp_valid << 1);
        for (int k = 0; k < 4; k++)
            for (int b = 0; b < 4; b++) out[1 + 4 * k + b] = (uint8_t)(u.sp_result[k] >> (8 * b));
    }

    void port(bool push, bool pop, const uint32_t *dir) {
        close(false, false, 0);
        u.sp_push = push;
        u.sp_pop = pop;
        for (int k = 0; k < 3; k++) u.sp_dir[k] = dir[k];
        begin(false, false, 0);
    }

    uint64_t clocks() const {
        uint64_t c = u.rootp->accel_single__DOT__regs__DOT__cycles;
        if (!pending) return c - offset;
        return pending_reset ? 1 : c + 1 - offset;
    }
};

bool get(uint8_t *buf, size_t n) { return fread(buf, 1, n, stdin) == n; }

uint32_t word(const uint8_t *b) {
    return (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
}

void put(const uint8_t *b, size_t n) {
    fwrite(b, 1, n, stdout);
    fflush(stdout);
}

void put_le(uint64_t v, int n) {
    uint8_t b[8];
    for (int k = 0; k < n; k++) b[k] = (uint8_t)(v >> (8 * k));
    put(b, n);
}

} // namespace

int main(int argc, char **argv) {
    Verilated::commandArgs(argc, argv);
    static Sim s;
    ahb::reset(s.u);
    uint8_t rec[9];
    while (get(rec, sizeof rec)) {
        uint32_t a = word(rec + 1), b = word(rec + 5);
        switch (rec[0]) {
        case 'W': s.write(a, b); break;
        case 'R': put_le(s.read(a), 4); break;
        case 'I': s.idle(a); break;
        case 'C': put_le(s.clocks(), 8); break;
        case 'T': {
            uint8_t out[17];
            s.peek(out);
            put(out, sizeof out);
            break;
        }
        case 'K': {
            uint32_t dir[3] = {0, 0, 0};
            uint8_t d[12];
            if (a & 1) {
                if (!get(d, sizeof d)) return 2;
                for (int k = 0; k < 3; k++) dir[k] = word(d + 4 * k);
            }
            s.port(a & 1, (a >> 1) & 1, dir);
            break;
        }
        default: fprintf(stderr, "accel-sim: unknown command %02x\n", rec[0]); return 2;
        }
    }
    return 0;
}
