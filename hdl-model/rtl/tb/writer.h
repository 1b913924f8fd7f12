// What the bitmap writer's testbenches (`writer_tb.cpp`: the writer alone; `bank_pass_tb.cpp`:
// behind its bank's set-up pass) share: the writer's vector lines (hemi-bench's
// host/bench/src/rtl/writer.rs: `L`, `P`, `A`, `E`, `C`, `X`, `R`, which the bank's vectors
// carry as `WL`, `WP`, …) read into passes, and the checks of the writer's outputs clock by
// clock: every copy into the block RAMs (its first row's clock, its buffer, its column and the
// words of each row), every pass's completion with its clock and, on it, the valid bits of the
// pass's buffer.
#pragma once
#include "tb.h"
#include <algorithm>
#include <cstdint>
#include <map>
#include <vector>

namespace writer {

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
// The `L` line: the sectors and a copy's clocks.
struct Shape {
    uint32_t sectors = 0, copy = 0;
};

// One line of the writer's vectors (its tag without the prefix) into `passes`.
static bool read_line(const std::string &tag, std::istringstream &in, Shape &shape,
                      std::vector<Pass> &passes) {
    if (tag == "L") return bool(in >> shape.sectors >> shape.copy);
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
}

// The last clock the passes' checks need: their completions'.
static uint64_t last_ready(const std::vector<Pass> &passes) {
    uint64_t last = 0;
    for (const Pass &p : passes) last = std::max(last, p.ready);
    return last;
}

// The writer's outputs checked clock by clock against `passes` (clocks from the same origin
// as the ones `clock` is given), mismatches counted into `bad` and the first ones printed
// after `what`; `vectors` counts the rows and completions compared.
struct Checker {
    const char *what;
    Shape shape;
    uint64_t &bad;
    std::vector<const Copy *> copies;
    std::vector<const Pass *> by_ready;
    size_t ci = 0, ri = 0;
    const Copy *cur = nullptr;
    uint64_t cur_row = 0, vectors = 0;

    Checker(const char *what, Shape shape, const std::vector<Pass> &passes, uint64_t &bad)
        : what(what), shape(shape), bad(bad) {
        for (const Pass &p : passes) {
            for (const Copy &c : p.copies) copies.push_back(&c);
            by_ready.push_back(&p);
        }
        std::stable_sort(by_ready.begin(), by_ready.end(),
                         [](const Pass *a, const Pass *b) { return a->ready < b->ready; });
    }

    void mismatch(uint64_t t, const char *which, uint64_t got, uint64_t want) {
        if (bad < 20)
            fprintf(stderr, "%s: clock %" PRIu64 ": %s 0x%" PRIx64 ", the model 0x%" PRIx64 "\n",
                    what, t, which, got, want);
        bad++;
    }

    // A row at the write port on clock `t`.
    template <typename M> void row(const M &u, uint64_t t) {
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
        if (!cur) return;
        uint32_t r = u.w_row;
        if (r != cur_row) mismatch(t, "copy row", r, cur_row);
        cur_row++;
        auto found = cur->rows.find(r);
        Words w = found == cur->rows.end() ? Words() : found->second;
        if (r < shape.sectors && u.w_sector != w.sector) mismatch(t, "sector word", u.w_sector, w.sector);
        if (r < shape.sectors && u.w_mask != w.mask) mismatch(t, "mask word", u.w_mask, w.mask);
        if (r < 16 && u.w_band != w.band) mismatch(t, "band word", u.w_band, w.band);
        vectors++;
    }

    // The passes complete on clock `t`, with their buffers' valid bits.
    template <typename M> void ready(const M &u, uint64_t t) {
        for (uint32_t k = 0; k < u.ready_n; k++) {
            if (ri == by_ready.size()) {
                mismatch(t, "a pass complete the model does not have", 1, 0);
                continue;
            }
            const Pass *p = by_ready[ri++];
            if (p->ready != t) mismatch(t, "a pass complete; the model's clock", t, p->ready);
            vectors++;
            if (p->copies.empty()) continue;
            uint32_t want = 0;
            for (const Copy &c : p->copies) want |= 1u << c.column;
            uint32_t got = p->copies[0].buffer ? u.valid1 : u.valid0;
            if (got != want) mismatch(t, "valid bits", got, want);
        }
    }

    // The outputs of clock `t` (after the clock's inputs are evaluated, before its edge).
    template <typename M> void clock(const M &u, uint64_t t) {
        if (u.w_valid) row(u, t);
        ready(u, t);
    }

    // At the end, on clock `t`: every copy and completion of the model's seen.
    void finish(uint64_t t) {
        if (ci != copies.size()) mismatch(t, "copies made, of the model's", ci, copies.size());
        if (ri != by_ready.size()) mismatch(t, "passes complete, of the model's", ri, by_ready.size());
    }
};

} // namespace writer
