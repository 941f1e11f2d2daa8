// SPDX-License-Identifier: BSD-3-Clause
// bench_rows.hpp - the one format every bench uses for the rows of `make bench`'s table (issue 22):
// a bench appends rows with bench_row_add() and writes them with bench_rows_write() to
// build/bench/rows/<bench>.json; bench/table.py joins every file there into one table
// (build/bench/table.md) and the README's performance section is generated from it.
//
// One row = one line of the table: a piece of work done by OctoMap and by occmap in the same
// process, repeated and interleaved (A, B, A, B ...). `octomap` and `occmap` are the medians in
// `unit` (ms, ns, MB, ...); `lower_is_better` says which way is good (time, memory: true).
// `ratio` is octomap / occmap for lower-is-better units (so "x faster"), and the ratio spread is
// the min and max of the per-repetition ratios (pair i of OctoMap with pair i of occmap). A row
// without an OctoMap side (scratch bytes, an 8-bit vs 16-bit comparison) sets octomap < 0, and
// may give `base_label` / `base` for what it compares against instead.
// `target` is the goal in words ("ratio >= 35", "occmap <= 50 ns"), `met` whether this
// run reached it; `equal` says whether the two maps / answers were checked equal ("yes", "no",
// "n/a").
#ifndef OCC_BENCH_ROWS_HPP_INCLUDED
#define OCC_BENCH_ROWS_HPP_INCLUDED

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

struct BenchRow {
    std::string id;        // stable key, e.g. "insert/scan.dat/0.10/simple"
    std::string work;      // what was done, e.g. "scan.dat 0.1 m, SIMPLE (exact)"
    std::string unit;      // "ms", "ns", "MB", "bytes", "x"
    bool lower_is_better = true;
    double octomap = -1;   // OctoMap's median, < 0: no OctoMap side
    double occmap = 0;     // occmap's median
    std::string base_label; // when octomap < 0: what `base` is (e.g. "16-bit values")
    double base = -1;
    double ratio = 0;      // octomap / occmap (or base / occmap), lower-is-better units
    double ratio_min = 0, ratio_max = 0; // spread of the per-repetition ratios
    int reps = 0;
    std::string target;    // the goal, in words
    bool met = false;
    std::string equal = "n/a";
};

inline double bench_median(std::vector<double> v)
{
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Fill ratio, spread and reps from paired repetitions (a[i] = OctoMap / base, b[i] = occmap).
inline void bench_row_ratios(BenchRow &r, const std::vector<double> &a, const std::vector<double> &b)
{
    const size_t n = std::min(a.size(), b.size());
    std::vector<double> q;
    for (size_t i = 0; i < n; i++)
        if (b[i] > 0 && a[i] > 0) q.push_back(r.lower_is_better ? a[i] / b[i] : b[i] / a[i]);
    r.reps = (int)n;
    if (q.empty()) return;
    r.ratio = bench_median(q);
    r.ratio_min = *std::min_element(q.begin(), q.end());
    r.ratio_max = *std::max_element(q.begin(), q.end());
}

inline std::string bench_json_str(const std::string &s)
{
    std::string o = "\"";
    for (char c : s) {
        if (c == '"' || c == '\\') o += '\\';
        o += c;
    }
    return o + "\"";
}

// Write rows as a JSON list to `path` (e.g. build/bench/rows/insert.json). Returns false on error.
inline bool bench_rows_write(const std::string &path, const std::vector<BenchRow> &rows)
{
    FILE *f = std::fopen(path.c_str(), "w");
    if (f == nullptr) return false;
    std::fprintf(f, "[\n");
    for (size_t i = 0; i < rows.size(); i++) {
        const BenchRow &r = rows[i];
        std::fprintf(f,
                     "  {\"id\": %s, \"work\": %s, \"unit\": %s, \"lower_is_better\": %s, "
                     "\"octomap\": %.6g, \"occmap\": %.6g, \"base_label\": %s, \"base\": %.6g, "
                     "\"ratio\": %.4g, \"ratio_min\": %.4g, \"ratio_max\": %.4g, \"reps\": %d, "
                     "\"target\": %s, \"met\": %s, \"equal\": %s}%s\n",
                     bench_json_str(r.id).c_str(), bench_json_str(r.work).c_str(),
                     bench_json_str(r.unit).c_str(), r.lower_is_better ? "true" : "false",
                     r.octomap, r.occmap, bench_json_str(r.base_label).c_str(), r.base, r.ratio,
                     r.ratio_min, r.ratio_max, r.reps, bench_json_str(r.target).c_str(),
                     r.met ? "true" : "false", bench_json_str(r.equal).c_str(),
                     i + 1 < rows.size() ? "," : "");
    }
    std::fprintf(f, "]\n");
    return std::fclose(f) == 0;
}

#endif
