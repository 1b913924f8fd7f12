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
#include "tb.h"
#include "verilated.h"
#include <cstdint>
#include <map>
#include <vector>

struct Answer {
    uint64_t clock;
    uint32_t place, kind, lo, len, band_lo, band_hi;
};
struct Words {
    uint64_t sector = 0, mask = 0, band = 0;
};
struct Copy {
    uint64_t clock;
    uint32_t buffer, column;
    std::map<uint32_t, Words> rows;
};
struct Pass {
    uint64_t start, end = 0, ready = 0;
    std::vector<Answer> answers;
    std::vector<Copy> copies;
};

static bool read_vectors(const char *path, uint32_t &sectors, uint32_t &copy,
                         std::vector<Pass> &passes) {
    return tb::read_lines("writer", path, [&](const std::string &tag, std::istringstream &in) {
        if (tag == "L") {
            in >> sectors >> copy;
            return bool(in);
        }
        if (tag == "P") {
            Pass p;
            in >> p.start;
            passes.push_back(p);
            return bool(in);
        }
        if (passes.empty()) return false;
        Pass &p = passes.back();
        if (tag == "A") {
            Answer a;
            in >> a.clock >> a.place >> a.kind >> a.lo >> a.len >> a.band_lo >> a.band_hi;
            p.answers.push_back(a);
        } else if (tag == "E") {
            in >> p.end;
        } else if (tag == "C") {
            Copy c;
            in >> c.clock >> c.buffer >> c.column;
            p.copies.push_back(c);
        } else if (tag == "X") {
            uint32_t row;
            Words w;
            in >> row >> w.sector >> w.mask >> w.band;
            if (p.copies.empty()) return false;
            p.copies.back().rows[row] = w;
        } else if (tag == "R") {
            in >> p.ready;
        } else {
            return false;
        }
        return bool(in);
    });
}

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
    uint32_t sectors = 0, copy = 0;
    std::vector<Pass> passes;
    if (!read_vectors(argv[1], sectors, copy, passes)) return 2;
    if (sectors == 0 || copy == 0) {
        fprintf(stderr, "writer: no L line in %s\n", argv[1]);
        return 2;
    }
    // every input on the clock it is presented; the copies and completions in order
    std::map<uint64_t, Inputs> inputs;
    std::vector<const Copy *> copies;
    std::vector<const Pass *> ready;
    uint64_t answers = 0, last = 0;
    for (const Pass &p : passes) {
        inputs[p.start].start = true;
        for (const Answer &a : p.answers) inputs[a.clock].answer = &a;
        inputs[p.end].end = true;
        for (const Copy &c : p.copies) copies.push_back(&c);
        ready.push_back(&p);
        answers += p.answers.size();
        last = std::max(last, p.ready);
    }
    std::vector<const Pass *> by_ready = ready;
    std::stable_sort(by_ready.begin(), by_ready.end(),
                     [](const Pass *a, const Pass *b) { return a->ready < b->ready; });

    tb::Stopwatch watch;
    Vbitmap_writer u;
    u.clk = 0;
    u.rst = 1;
    u.a_valid = u.e_valid = u.p_start = 0;
    u.eval();
    tb::tick(u);
    tb::tick(u);
    u.rst = 0;
    uint64_t bad = 0, vectors = 0;
    size_t ci = 0, ri = 0;
    const Copy *cur = nullptr;
    uint64_t cur_row = 0;
    auto mismatch = [&](uint64_t t, const char *what, uint64_t got, uint64_t want) {
        if (bad < 20)
            fprintf(stderr, "writer: clock %" PRIu64 ": %s 0x%" PRIx64 ", the model 0x%" PRIx64 "\n",
                    t, what, got, want);
        bad++;
    };
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
        if (u.w_valid) {
            if (u.w_row == 0) {
                if (ci == copies.size()) {
                    mismatch(t, "a copy the model does not make, column", u.w_col, 0);
                    cur = nullptr;
                } else {
                    cur = copies[ci++];
                    cur_row = 0;
                    if (cur->clock != t) mismatch(t, "a copy begins; the model's clock", t, cur->clock);
                    if (u.w_buf != cur->buffer) mismatch(t, "copy buffer", u.w_buf, cur->buffer);
                    if (u.w_col != cur->column) mismatch(t, "copy column", u.w_col, cur->column);
                }
            }
            if (cur) {
                uint32_t row = u.w_row;
                if (row != cur_row) mismatch(t, "copy row", row, cur_row);
                cur_row++;
                auto r = cur->rows.find(row);
                Words w = r == cur->rows.end() ? Words() : r->second;
                if (row < sectors && u.w_sector != w.sector) mismatch(t, "sector word", u.w_sector, w.sector);
                if (row < sectors && u.w_mask != w.mask) mismatch(t, "mask word", u.w_mask, w.mask);
                if (row < 16 && u.w_band != w.band) mismatch(t, "band word", u.w_band, w.band);
                vectors++;
            }
        }
        for (uint32_t k = 0; k < u.ready_n; k++) {
            if (ri == by_ready.size()) {
                mismatch(t, "a pass complete the model does not have", 1, 0);
                continue;
            }
            const Pass *p = by_ready[ri++];
            if (p->ready != t) mismatch(t, "a pass complete; the model's clock", t, p->ready);
            vectors++;
            // its buffer's valid bits: the columns it copied
            if (p->copies.empty()) continue;
            uint32_t want = 0;
            for (const Copy &c : p->copies) want |= 1u << c.column;
            uint32_t got = p->copies[0].buffer ? u.valid1 : u.valid0;
            if (got != want) mismatch(t, "valid bits", got, want);
        }
        tb::tick(u);
    }
    if (ci != copies.size()) mismatch(last, "copies made, of the model's", ci, copies.size());
    if (ri != by_ready.size()) mismatch(last, "passes complete, of the model's", ri, by_ready.size());
    tb::report("writer", answers, vectors, last + 1, bad, watch.seconds());
    return bad ? 1 : 0;
}
