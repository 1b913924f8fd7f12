// A bank's set-up pass into its bitmaps (`bank_pass.v`: `bank_setup.v` feeding
// `bitmap_writer.v`): reads the model's vectors (hemi-bench's `rtl-vectors --bank`,
// host/bench/src/rtl/bank.rs; `bank.h`) group by group, writes the group's memories, resets the
// writer, begins each pass on its clock with its origin and frame, and gives each pass's end
// on the clock the model's sequencer would (`WE`). It compares every answer the writer takes
// with the model's (`WA`: its clock, its slot's place, its kind, bands and, for a wedge, its
// sectors), then, as `writer_tb.cpp` does, every copy into the block RAMs and every pass's
// completion with its clock and valid bits (`writer.h`). The set-up unit's words and answers
// themselves are `bank_setup_tb.cpp`'s to check. Prints `bank_pass: rays=N vectors=M clocks=C
// mismatches=K seconds=S` (rays: the slots filtered; vectors: the answers taken, the rows
// copied and the passes completed), exits 1 on any mismatch.
#include "Vbank_pass.h"
#include "bank.h"
#include "verilated.h"
#include "writer.h"
#include <set>
#include <utility>

using bank::Group;

// What the group's checks compared, for the closing line.
static uint64_t compared = 0;

// The answer the writer takes on clock `t` against the model's next one.
static void answer(const Vbank_pass &u, uint64_t t, const writer::Answer *want,
                   writer::Checker &check) {
    if (!want) return check.mismatch(t, "an answer the model does not give, place", u.a_place, 0);
    if (want->clock != t) check.mismatch(t, "an answer; the model's clock", t, want->clock);
    if (u.a_place != want->place) check.mismatch(t, "answer place", u.a_place, want->place);
    bool same = u.a_kind == want->kind && u.a_band_lo == want->band_lo &&
                u.a_band_hi == want->band_hi;
    same &= want->kind != 2 || (u.a_lo == want->lo && u.a_len == want->len);
    if (!same) check.mismatch(t, "answer reach, kind", u.a_kind, want->kind);
    compared++;
}

// The group's passes on their clocks, the writer reset first; mismatches, counted into `bad`.
static void run(Vbank_pass &u, const Group &g, const bank::Latency &lat, uint64_t &clocks,
                uint64_t &bad) {
    u.rst = 1;
    tb::tick(u);
    tb::tick(u);
    u.rst = 0;
    clocks += 2;
    std::vector<const writer::Answer *> answers;
    std::set<uint64_t> ends;
    for (const writer::Pass &p : g.writes) {
        for (const writer::Answer &a : p.answers) answers.push_back(&a);
        ends.insert(p.end);
    }
    writer::Checker check("bank_pass", lat.writer, g.writes, bad);
    uint64_t last = std::max(bank::last_due(g, lat) + 16, writer::last_ready(g.writes) + 1);
    size_t pi = 0, ai = 0;
    for (uint64_t t = 0; t <= last; t++) {
        u.start = pi < g.passes.size() && g.passes[pi].start == t;
        if (u.start) bank::begin(u, g.passes[pi++]);
        u.pass_end = ends.count(t) > 0;
        u.eval();
        if (u.a_valid) answer(u, t, ai < answers.size() ? answers[ai++] : nullptr, check);
        check.clock(u, t);
        tb::tick(u);
        clocks++;
    }
    u.start = 0;
    u.pass_end = 0;
    if (ai != answers.size()) check.mismatch(last, "answers taken, of the model's", ai, answers.size());
    check.finish(last);
    compared += check.vectors;
}

int main(int argc, char **argv) {
    return bank::main_run<Vbank_pass>("bank_pass", argc, argv, run,
                                      [](const Group &) { return std::exchange(compared, 0); });
}
