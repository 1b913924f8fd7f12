// A lane's bitmap walk's testbench: reads the model's vectors (hemi-bench's `rtl-vectors
// --walk`, host/bench/src/rtl/walk.rs) and drives `bitmap_walk.v` with them. Pass by pass it
// clears the valid bits of the pass's buffer (`P`), writes each column the model's writer
// copies (`C`) through the write port a row a clock (`X`: a row's sector, mask and band words;
// the other rows zero) and sets the column's valid bit after its last row, as
// `bitmap_writer.v` does; then hands the walk the pass's rays (`Y`: sector, band, the skipped
// place or -1, and the model's candidates in slot order), while the next pass's columns are
// written into the other buffer. A pass's writes wait until the rays of the pass before the
// last (the same buffer) are out. The walk's candidates are taken on three clocks in four, with
// a stall of up to 60 clocks now and then, and every ray's are compared with the model's, in
// order, with its tag and its last; a ray without a candidate must end on the z port, in the
// order of such rays. Now and then the walk is reset with rays in flight, which are handed to
// it again; a run in which no ray comes out for 100,000 clocks stops. Prints `walk: rays=N
// vectors=M clocks=C mismatches=K seconds=S` (vectors: the candidates), exits 1 on any
// mismatch.
#include "Vbitmap_walk.h"
#include "tb.h"
#include "verilated.h"
#include <algorithm>
#include <deque>
#include <vector>

struct Row {
    uint32_t row;
    uint64_t sector, mask, band;
};

struct Copy {
    uint32_t col;
    std::vector<Row> rows;
};

struct Ray {
    uint32_t sector, band;
    int32_t skip;
    std::vector<uint32_t> candidates;
};

struct Pass {
    uint32_t buf;
    std::vector<Copy> copies;
    std::vector<Ray> rays;
};

static bool read_vectors(const char *path, uint32_t &copy_rows, std::vector<Pass> &passes) {
    return tb::read_lines("walk", path, [&](const std::string &tag, std::istringstream &in) {
        if (tag == "L") return bool(in >> copy_rows);
        if (tag == "P") {
            passes.push_back(Pass{});
            return bool(in >> passes.back().buf);
        }
        if (passes.empty()) return false;
        Pass &p = passes.back();
        if (tag == "C") {
            p.copies.push_back(Copy{});
            return bool(in >> p.copies.back().col);
        }
        if (tag == "X" && !p.copies.empty()) {
            Row r;
            if (!(in >> r.row >> r.sector >> r.mask >> r.band)) return false;
            p.copies.back().rows.push_back(r);
            return true;
        }
        if (tag == "Y") {
            Ray r;
            uint32_t n;
            if (!(in >> r.sector >> r.band >> r.skip >> n)) return false;
            r.candidates.resize(n);
            for (auto &c : r.candidates)
                if (!(in >> c)) return false;
            p.rays.push_back(r);
            return true;
        }
        return false;
    });
}

// The write port's schedule: every row of every copy of a pass, the column's valid bit after
// its last row.
struct Writes {
    const Pass *pass = nullptr;
    size_t copy = 0;
    uint32_t row = 0;
};

int main(int argc, char **argv) {
    Verilated::commandArgs(argc, argv);
    if (argc < 2) {
        fprintf(stderr, "usage: walk VECTORS\n");
        return 2;
    }
    uint32_t copy_rows = 0;
    std::vector<Pass> passes;
    if (!read_vectors(argv[1], copy_rows, passes) || copy_rows == 0) return 2;
    tb::Stopwatch watch;
    Vbitmap_walk w;
    w.rst = 1;
    w.valid0 = w.valid1 = 0;
    tb::tick(w);
    tb::tick(w);
    w.rst = 0;

    uint64_t clock = 0, bad = 0, rays = 0, candidates = 0, resets = 0;
    uint32_t valid[2] = {0, 0};
    size_t written = 0;     // passes whose writes are done
    size_t cast_pass = 0, cast_ray = 0;  // the next ray to hand the walk
    std::vector<size_t> out_of(passes.size(), 0);  // each pass's rays whose outputs are done
    Writes wr;
    // the rays handed over and not yet out (pass, ray, tag, candidates seen, hand order), those
    // with candidates (ended on the candidate port) and those without (on the z port)
    struct Flight {
        size_t pass, ray;
        uint32_t tag;
        size_t seen;
        uint64_t seq;
    };
    std::deque<Flight> with_c, without_c;
    // rays to hand over again after a reset, oldest first (pass, ray, hand order)
    std::deque<Flight> redo;
    uint64_t seq = 0;
    uint32_t next_tag = 0;
    const uint64_t limit = 400ull * 1000 * 1000;
    auto in_flight = [&] { return !with_c.empty() || !without_c.empty(); };
    uint64_t progress = 0;  // the clock a ray last came out
    auto done = [&](const Flight &f) {
        progress = clock;
        out_of[f.pass]++;
        rays++;
        candidates += passes[f.pass].rays[f.ray].candidates.size();
    };
    auto complain = [&](const Flight &f, const char *what) {
        const Ray &r = passes[f.pass].rays[f.ray];
        if (bad < 20)
            printf("walk: pass %zu ray %zu (sector %u band %u skip %d, %zu candidates, tag %u): "
                   "%s: place %u tag %u last %u\n",
                   f.pass, f.ray, r.sector, r.band, r.skip, r.candidates.size(), f.tag, what,
                   w.o_place, w.o_tag, w.o_last);
        bad++;
    };
    while ((written < passes.size() || cast_pass < passes.size() || in_flight() ||
            !redo.empty()) &&
           clock < limit && clock - progress < 100000) {
        // now and then a reset with rays in flight: a clock of nothing else, then the rays not
        // yet out handed over again, in their first order (the bitmaps are memories: they stay)
        if (clock % 7919 == 7918 && in_flight()) {
            w.rst = 1;
            w.w_valid = w.r_valid = 0;
            w.o_ready = 0;
            tb::tick(w);
            w.rst = 0;
            clock++;
            resets++;
            for (auto *q : {&with_c, &without_c})
                for (Flight f : *q) redo.push_back(Flight{f.pass, f.ray, 0, 0, f.seq});
            with_c.clear();
            without_c.clear();
            std::sort(redo.begin(), redo.end(),
                      [](const Flight &a, const Flight &b) { return a.seq < b.seq; });
            continue;
        }
        // the write port: a pass's writes begin once the pass before it is written and the one
        // that last filled its buffer (two back) is out
        w.w_valid = 0;
        if (!wr.pass && written < passes.size() &&
            (written < 2 || out_of[written - 2] == passes[written - 2].rays.size())) {
            wr = Writes{&passes[written], 0, 0};
            valid[wr.pass->buf] = 0;
        }
        if (wr.pass && wr.copy < wr.pass->copies.size()) {
            const Copy &c = wr.pass->copies[wr.copy];
            Row r{wr.row, 0, 0, 0};
            for (const Row &x : c.rows)
                if (x.row == wr.row) r = x;
            w.w_valid = 1;
            w.w_buf = wr.pass->buf;
            w.w_row = r.row;
            w.w_col = c.col;
            w.w_sector = r.sector;
            w.w_mask = (uint32_t)r.mask;
            w.w_band = r.band;
        }
        // the ray on offer: one to hand again, or the next
        w.r_valid = 0;
        Flight offer{0, 0, next_tag, 0, seq};
        bool again = !redo.empty();
        if (again) {
            offer = redo.front();
            offer.tag = next_tag;
        } else if (cast_pass < written && cast_pass < passes.size() &&
                   cast_ray < passes[cast_pass].rays.size()) {
            offer.pass = cast_pass;
            offer.ray = cast_ray;
        }
        bool offered = again || (cast_pass < written && cast_pass < passes.size() &&
                                 cast_ray < passes[cast_pass].rays.size());
        if (offered) {
            const Pass &p = passes[offer.pass];
            const Ray &r = p.rays[offer.ray];
            w.r_valid = 1;
            w.r_buf = p.buf;
            w.r_sector = r.sector;
            w.r_band = r.band;
            w.r_skip_en = r.skip >= 0;
            w.r_skip = r.skip >= 0 ? (uint32_t)r.skip : 0;
            w.r_tag = next_tag;
        }
        // three clocks in four, and a stall of up to 60 clocks every 1,009
        uint64_t stall = clock / 1009 % 61;
        w.o_ready = (clock & 3) != 3 && clock % 1009 >= stall;
        w.eval();
        // what this clock's edge takes
        bool took = w.r_valid && w.r_ready;
        if (w.o_valid && w.o_ready) {
            if (with_c.empty()) {
                printf("walk: clock %" PRIu64 ": a candidate with no ray in flight\n", clock);
                bad++;
            } else {
                Flight &f = with_c.front();
                const Ray &r = passes[f.pass].rays[f.ray];
                bool ok = w.o_tag == f.tag && f.seen < r.candidates.size() &&
                          w.o_place == r.candidates[f.seen];
                f.seen++;
                if (!ok || (bool)w.o_last != (f.seen == r.candidates.size()))
                    complain(f, "candidate");
                if (w.o_last) {
                    done(f);
                    with_c.pop_front();
                }
            }
        }
        if (w.z_valid) {
            if (without_c.empty() || w.z_tag != without_c.front().tag) {
                if (bad < 20)
                    printf("walk: clock %" PRIu64 ": the end of ray tag %u without a candidate, "
                           "not the next such ray\n",
                           clock, w.z_tag);
                bad++;
            } else {
                done(without_c.front());
                without_c.pop_front();
            }
        }
        tb::tick(w);
        clock++;
        if (took) {
            const Ray &r = passes[offer.pass].rays[offer.ray];
            (r.candidates.empty() ? without_c : with_c).push_back(offer);
            next_tag = (next_tag + 1) & 0xFF;
            if (again) {
                redo.pop_front();
            } else {
                seq++;
                if (++cast_ray == passes[cast_pass].rays.size()) {
                    cast_pass++;
                    cast_ray = 0;
                }
            }
        }
        // the row written on this edge; a copy's valid bit after its last row
        if (wr.pass && wr.copy < wr.pass->copies.size()) {
            if (++wr.row == copy_rows) {
                valid[wr.pass->buf] |= 1u << wr.pass->copies[wr.copy].col;
                wr.copy++;
                wr.row = 0;
            }
        }
        if (wr.pass && wr.copy == wr.pass->copies.size()) {
            wr.pass = nullptr;
            written++;
        }
        w.valid0 = valid[0];
        w.valid1 = valid[1];
        // a pass's rays skip ahead of no pass: those of a pass with none are done
        while (cast_pass < written && cast_pass < passes.size() &&
               passes[cast_pass].rays.empty())
            cast_pass++;
    }
    size_t total = 0;
    for (const Pass &p : passes) total += p.rays.size();
    if (rays != total) {
        printf("walk: %" PRIu64 " of %zu rays out after %" PRIu64 " clocks (%zu in flight)\n",
               rays, total, clock, with_c.size() + without_c.size());
        bad++;
    }
    printf("walk: %" PRIu64 " resets with rays in flight\n", resets);
    tb::report("walk", rays, candidates, clock, bad, watch.seconds());
    return bad ? 1 : 0;
}
