// SPDX-License-Identifier: BSD-3-Clause
// shared.cpp - `make bench` step for the shared map (issue 20, occ_shared.h). The writer replays
// the real TUM frames and scan.dat (tests/support/shared_replay.h: eviction in a small arena)
// in three configurations, interleaved round by round on fresh maps (the order rotates):
//   plain   - the single-threaded map (never shared)
//   shared  - the same map shared, no reader running (the publish copy per scan is the cost)
//   readers - shared, with 4 reader threads, each at 50 Hz (the top of an avoidance loop's
//             10-50 Hz) opening an empty view (occ_read_begin + occ_read_end) and then a whole
//             view answering the probe set (states, sphere and capsule checks, ray casts,
//             sectors). A reader spinning flat out measures only how many cores the machine
//             has: readers never block the writer, but on a shared 2-core box they take its CPU.
// Each scan is one write section (occ_map_write_begin/end: one publish per scan, the pattern
// occ_shared.h recommends). The writer's cost is its thread's CPU time
// (CLOCK_THREAD_CPUTIME_ID: what sharing and the readers cost the writer, not what the
// neighbours' load or the readers' own CPU take from it), per scan over the whole run; each row
// is the median over rounds with the spread of the per-round ratios. The runs' final maps are
// serialized and compared (CRC): sharing and reading must not change what the writer builds.
// Readers' latency is their thread's CPU time too, less the clock's own cost (calibrated in each
// reader: the median of empty clock pairs), median / p99 / max over every view of every round.
// Rows (bench_rows.hpp) go to build/bench/rows/shared.json.
// usage: shared [--rows PATH] [rounds (11)] [scans per run (300)] [arena MiB (8)] [reader Hz (50)]
#include <pthread.h>
#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "bench_rows.hpp"

extern "C" {
#include "occmap/occmap.h"
#include "support/shared_replay.h"
}

#define N_READERS 4u
#define TARGET_SLOWDOWN 1.20 // issue 20: the writer's throughput drops by at most 20%

static double cpu_s()
{
    timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static std::string fmt(const char *f, ...)
{
    char buf[512];
    va_list ap;
    va_start(ap, f);
    std::vsnprintf(buf, sizeof buf, f, ap);
    va_end(ap);
    return buf;
}

// The p-quantile (0..1) by rank: p = 0.99 of 1000 samples is the 990th smallest.
static double pct(std::vector<double> v, double p)
{
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    const size_t i = p <= 0.0 ? 0u : (size_t)std::ceil(p * (double)v.size()) - 1u;
    return v[std::min(i, v.size() - 1u)];
}

struct Reader {
    occ_map_t *map = nullptr;
    unsigned slot = 0;
    double clock_cost = 0;          // median CPU seconds of an empty pair of cpu_s() calls
    std::vector<double> begin_end;  // occ_read_begin + occ_read_end, seconds
    std::vector<double> view;       // begin + the probe set + end, seconds
    occ_sectors_t sec;
};

static unsigned stop_flag; // atomic
static long reader_period_ns = 20000000; // 50 Hz per reader

static void *reader_main(void *arg)
{
    Reader *const r = static_cast<Reader *>(arg);
    std::vector<double> empty;
    for (int i = 0; i < 201; i++) {
        const double t0 = cpu_s();
        empty.push_back(cpu_s() - t0);
    }
    r->clock_cost = pct(empty, 0.5);
    sr_answers_t a;
    const timespec pause = {0, reader_period_ns};
    while (__atomic_load_n(&stop_flag, __ATOMIC_ACQUIRE) == 0u) {
        occ_view_t v;
        const double t0 = cpu_s();
        if (occ_read_begin(r->map, r->slot, &v) != OCC_OK) break;
        occ_read_end(r->map, &v);
        const double t1 = cpu_s();
        if (occ_read_begin(r->map, r->slot, &v) != OCC_OK) break;
        sr_answer(occ_view_map(&v), SR_Q_ALL, &r->sec, &a);
        occ_read_end(r->map, &v);
        const double t2 = cpu_s();
        r->begin_end.push_back(std::max(0.0, t1 - t0 - r->clock_cost));
        r->view.push_back(std::max(0.0, t2 - t1 - r->clock_cost));
        nanosleep(&pause, nullptr);
    }
    return nullptr;
}

enum { PLAIN, SHARED, READERS, N_CONF };
static const char *const conf_name[N_CONF] = {"plain", "shared", "readers"};

struct Run {
    double cpu_ms_per_scan = 0;
    uint32_t crc = 0;           // of the final map, serialized
    uint32_t publishes = 0, deferred = 0;
    size_t copied_last = 0;
};

// One run: a fresh map and replay, `scans` scans; the writer thread's CPU time per scan.
static Run run(int conf, size_t scans, size_t arena_bytes, Reader *rd, std::vector<uint8_t> &file)
{
    Run out;
    sr_writer_t w;
    if (!sr_writer_init(&w, 8u, 16u)) std::exit(77);
    std::vector<uint8_t> arena(arena_bytes), shmem;
    occ_map_t map;
    const occ_map_config_t cfg = occ_map_config_default();
    if (occ_map_init(&map, &cfg, arena.data(), arena.size()) != OCC_OK) std::exit(1);
    if (conf != PLAIN) {
        shmem.resize(occ_shared_bytes(&map, N_READERS));
        if (occ_map_share(&map, shmem.data(), shmem.size(), N_READERS) != OCC_OK) std::exit(1);
    }
    pthread_t th[N_READERS];
    __atomic_store_n(&stop_flag, 0u, __ATOMIC_RELEASE);
    if (conf == READERS) {
        for (unsigned i = 0; i < N_READERS; i++) {
            rd[i].map = &map;
            rd[i].slot = i;
            pthread_create(&th[i], nullptr, reader_main, &rd[i]);
        }
    }
    const bool sections = conf != PLAIN;
    const double t0 = cpu_s();
    for (size_t k = 0; k < scans; k++) {
        if (sections && occ_map_write_begin(&map) != OCC_OK) std::exit(1);
        (void)sr_writer_step(&w, &map);
        if (sections && occ_map_write_end(&map) != OCC_OK) std::exit(1);
    }
    out.cpu_ms_per_scan = 1e3 * (cpu_s() - t0) / (double)scans;
    __atomic_store_n(&stop_flag, 1u, __ATOMIC_RELEASE);
    if (conf == READERS) {
        for (unsigned i = 0; i < N_READERS; i++) pthread_join(th[i], nullptr);
    }
    occ_shared_info_t info;
    if (conf != PLAIN && occ_shared_info(&map, &info) == OCC_OK) {
        out.publishes = info.publishes;
        out.deferred = info.deferred;
        out.copied_last = info.copied_bytes_last;
    }
    occ_io_buf_t b = {file.data(), file.size(), 0u};
    if (occ_io_write(&map, OCC_FORMAT_SNAPSHOT, occ_io_buf_write, &b, nullptr) != OCC_OK) {
        std::printf("shared bench: the map does not fit the %zu-byte file buffer\n", file.size());
        std::exit(1);
    }
    out.crc = occ_crc32(0u, file.data(), b.len);
    sr_writer_free(&w);
    return out;
}

static BenchRow writer_row(const char *id, const std::string &work,
                           const std::vector<double> &plain, const std::vector<double> &other,
                           bool equal)
{
    BenchRow r;
    r.id = id;
    r.work = work;
    r.unit = "ms";
    r.base_label = "plain map";
    r.base = bench_median(plain);
    r.occmap = bench_median(other);
    bench_row_ratios(r, plain, other); // plain / shared: 1 = free, below 1 = the cost
    r.target = fmt("shared <= %.2fx plain (ratio >= %.2f)", TARGET_SLOWDOWN, 1.0 / TARGET_SLOWDOWN);
    r.met = r.ratio >= 1.0 / TARGET_SLOWDOWN;
    r.equal = equal ? "yes" : "no";
    return r;
}

static void latency_rows(std::vector<BenchRow> &rows, const char *id, const std::string &what,
                         const std::vector<double> &s)
{
    static const struct {
        const char *name, *label;
        double p;
    } q[] = {{"p50", "median", 0.5}, {"p99", "p99", 0.99}, {"max", "max", 1.0}};
    for (const auto &k : q) {
        BenchRow r;
        r.id = std::string(id) + "/" + k.name;
        r.work = what + ", " + k.label;
        r.unit = "us";
        r.occmap = 1e6 * pct(s, k.p);
        r.reps = (int)s.size();
        r.target = "none set";
        rows.push_back(r);
    }
}

int main(int argc, char **argv)
{
    std::string rows_json = "build/bench/rows/shared.json";
    std::vector<long> pos;
    for (int i = 1; i < argc; i++) {
        if (!std::strcmp(argv[i], "--rows") && i + 1 < argc) rows_json = argv[++i];
        else pos.push_back(std::atol(argv[i]));
    }
    const unsigned rounds = pos.size() > 0 && pos[0] > 0 ? (unsigned)pos[0] : 11u;
    const size_t scans = pos.size() > 1 && pos[1] > 0 ? (size_t)pos[1] : 300u;
    const size_t arena_bytes = (pos.size() > 2 && pos[2] > 0 ? (size_t)pos[2] : 8u) << 20;
    if (pos.size() > 3 && pos[3] > 0) reader_period_ns = 1000000000L / pos[3];
    const long hz = 1000000000L / reader_period_ns;

    static Reader rd[N_READERS];
    std::vector<uint8_t> file(arena_bytes + (1u << 20));
    std::vector<double> ms[N_CONF];
    std::vector<Run> last(N_CONF);
    bool equal_shared = true, equal_readers = true;
    for (unsigned r = 0; r < rounds; r++) {
        Run got[N_CONF];
        for (int j = 0; j < N_CONF; j++) {
            const int c = (j + (int)r) % N_CONF; // rotate the order: no config always first
            got[c] = run(c, scans, arena_bytes, rd, file);
            ms[c].push_back(got[c].cpu_ms_per_scan);
            last[(size_t)c] = got[c];
        }
        equal_shared = equal_shared && got[SHARED].crc == got[PLAIN].crc;
        equal_readers = equal_readers && got[READERS].crc == got[PLAIN].crc;
    }
    std::printf("shared bench: writer thread CPU time, %zu TUM/scan.dat scans per run in %zu MiB "
                "with eviction, one write section per scan, %u interleaved rounds; median of the "
                "rounds [min-max]; readers at %ld Hz each\n",
                scans, arena_bytes >> 20, rounds, hz);
    for (int c = 0; c < N_CONF; c++) {
        std::vector<double> ratio;
        for (unsigned r = 0; r < rounds; r++) ratio.push_back(ms[c][r] / ms[PLAIN][r]);
        std::printf("  %-8s %8.3f ms/scan [%.3f-%.3f]  %s/plain x%.3f [%.3f-%.3f]\n",
                    conf_name[c], bench_median(ms[c]), pct(ms[c], 0.0), pct(ms[c], 1.0),
                    conf_name[c], bench_median(ratio), pct(ratio, 0.0), pct(ratio, 1.0));
    }
    std::printf("  last shared run: %u publishes, %u deferred, last publish copied %zu bytes; "
                "with readers: %u publishes, %u deferred; final maps equal to plain's: "
                "shared %s, readers %s\n",
                last[SHARED].publishes, last[SHARED].deferred, last[SHARED].copied_last,
                last[READERS].publishes, last[READERS].deferred, equal_shared ? "yes" : "NO",
                equal_readers ? "yes" : "NO");
    std::vector<double> be, vw;
    double cost = 0;
    for (unsigned i = 0; i < N_READERS; i++) {
        be.insert(be.end(), rd[i].begin_end.begin(), rd[i].begin_end.end());
        vw.insert(vw.end(), rd[i].view.begin(), rd[i].view.end());
        cost = std::max(cost, rd[i].clock_cost);
    }
    std::printf("  readers (%zu views while the writer ran; thread CPU less the clock's own "
                "%.2f us): begin+end median %.3f us, p99 %.3f us, max %.3f us; whole view "
                "(probe set incl. 2 sector updates) median %.1f us, p99 %.1f us, max %.1f us\n",
                vw.size(), 1e6 * cost, 1e6 * pct(be, 0.5), 1e6 * pct(be, 0.99), 1e6 * pct(be, 1.0),
                1e6 * pct(vw, 0.5), 1e6 * pct(vw, 0.99), 1e6 * pct(vw, 1.0));

    const std::string base = fmt("shared map writer, 10 TUM frames + scan.dat in %zu MiB with "
                                 "eviction, one write section per scan: writer thread CPU ms per "
                                 "scan", arena_bytes >> 20);
    const std::string rd_text = fmt("%u reader threads at %ld Hz each", N_READERS, hz);
    const std::string per = "; ratio = plain / shared (1 = free, higher is better)";
    std::vector<BenchRow> rows;
    rows.push_back(writer_row("shared/writer_cpu/shared_vs_plain",
                              base + ", shared (no reader) vs the plain map" + per, ms[PLAIN],
                              ms[SHARED], equal_shared));
    rows.push_back(writer_row("shared/writer_cpu/readers_vs_plain",
                              base + ", shared with " + rd_text + " vs the plain map" + per,
                              ms[PLAIN], ms[READERS], equal_readers));
    const std::string cpu_text = fmt(" while the writer runs (%s; thread CPU us, less the "
                                     "clock's own %.2f us)", rd_text.c_str(), 1e6 * cost);
    latency_rows(rows, "shared/reader_latency/begin_end",
                 std::string("reader latency, occ_read_begin + occ_read_end") + cpu_text, be);
    latency_rows(rows, "shared/reader_latency/view",
                 std::string("reader latency, a whole view: begin + probe set (96 states, 12 "
                             "spheres, 12 capsules, 12 rays, 2 sectors) + end") + cpu_text, vw);
    if (!bench_rows_write(rows_json, rows)) {
        std::printf("FAIL: cannot write %s\n", rows_json.c_str());
        return 1;
    }
    std::printf("wrote %zu table rows to %s\n", rows.size(), rows_json.c_str());
    return equal_shared && equal_readers ? 0 : 1;
}
