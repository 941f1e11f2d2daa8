// SPDX-License-Identifier: BSD-3-Clause
// scratch.cpp - `make bench-scratch` (issue 22): scan.dat at 0.05 m integrated exactly with
// unbounded scratch vs 8 MB of scratch (the scan traced once into its voxel set, then applied by
// bricks, or in pieces of codes when the pools are tight), SIMPLE and DISCRETE, interleaved repetitions (thread CPU time, medians, the spread of
// the per-repetition ratios), maps checked equal voxel for voxel; and the peak RSS of the 8 MB
// integration (and of OctoMap's insertPointCloud) each in a fresh process.
// Rows: build/bench/rows/scratch.json. Usage: scratch [reps] (default 9).
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>
#include <ctime>
#include <sys/resource.h>
#include <sys/wait.h>
#include <spawn.h>
#include <unistd.h>

extern char **environ;

#include <octomap/octomap.h>

#include "occmap/occmap.h"
#include "occmap/host/occ_scan.h"
#include "bench_rows.hpp"

static const char *const SCAN = "build/data/scan.dat";
static const float RES = 0.05f;
static const size_t SMALL = (size_t)8 << 20;
static const size_t BIG = (size_t)256 << 20;
static const size_t ARENA = (size_t)512 << 20;

// Thread CPU time: the machine is shared, and the integration is single-threaded.
static double now_ms()
{
    timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return (double)t.tv_sec * 1e3 + (double)t.tv_nsec / 1e6;
}

static bool load(std::vector<occ_vec3_t> &pts)
{
    occ_vec3_t *p = nullptr;
    size_t n = 0;
    char msg[256] = "";
    if (occ_scan_read_xyz(SCAN, &p, &n, msg, sizeof msg) != OCC_OK) {
        std::fprintf(stderr, "bench-scratch: %s\n", msg);
        return false;
    }
    pts.assign(p, p + n);
    free(p);
    return true;
}

// One integration into a cleared map; returns ms (< 0 on error).
static double run(occ_map_t *m, const std::vector<occ_vec3_t> &pts, occ_insert_method_t method,
                  void *scratch, size_t bytes, occ_insert_result_t *r)
{
    occ_map_clear(m);
    occ_insert_params_t p = occ_insert_params_default();
    p.method = method;
    const occ_vec3_t o = {0, 0, 0};
    const double t0 = now_ms();
    const occ_err_t e = occ_map_insert_cloud(m, &o, pts.data(), pts.size(), &p, scratch, bytes, r);
    const double t1 = now_ms();
    return e == OCC_OK ? t1 - t0 : -1.0;
}

// Child process: integrate once and exit (its peak RSS is read by the parent).
static int child(const char *what)
{
    std::vector<occ_vec3_t> pts;
    if (!load(pts)) return 1;
    if (std::strcmp(what, "octomap") == 0) {
        octomap::OcTree t(RES);
        octomap::Pointcloud pc;
        for (const occ_vec3_t &q : pts) pc.push_back(q.x, q.y, q.z);
        t.insertPointCloud(pc, octomap::point3d(0, 0, 0));
        return t.size() > 0 ? 0 : 1;
    }
    void *arena = std::malloc(ARENA); // untouched pages are not resident
    void *scratch = std::malloc(SMALL);
    occ_map_t m;
    occ_map_config_t cfg = occ_map_config_default();
    cfg.resolution_m = RES;
    if (arena == nullptr || scratch == nullptr || occ_map_init(&m, &cfg, arena, ARENA) != OCC_OK)
        return 1;
    occ_insert_result_t r;
    return run(&m, pts, OCC_INSERT_SIMPLE, scratch, SMALL, &r) >= 0 ? 0 : 1;
}

static double child_rss_mb(const char *self, const char *what)
{
    // posix_spawn (not fork): the child does not start with a copy of this process's pages.
    pid_t pid = -1;
    char *const args[] = {(char *)self, (char *)"--rss", (char *)what, nullptr};
    if (posix_spawn(&pid, self, nullptr, nullptr, args, environ) != 0) return -1;
    int st = 0;
    struct rusage ru;
    if (wait4(pid, &st, 0, &ru) != pid || !WIFEXITED(st) || WEXITSTATUS(st) != 0)
        return -1;
    return (double)ru.ru_maxrss / 1024.0; // KiB -> MiB
}

int main(int argc, char **argv)
{
    if (argc == 3 && std::strcmp(argv[1], "--rss") == 0) return child(argv[2]);
    const int reps = argc > 1 ? std::atoi(argv[1]) : 9;
    const double rss_oct = child_rss_mb(argv[0], "octomap");
    const double rss_occ = child_rss_mb(argv[0], "occmap");
    std::vector<occ_vec3_t> pts;
    if (!load(pts)) return 1;
    void *arena_a = std::malloc(ARENA), *arena_b = std::malloc(ARENA);
    uint8_t *big = (uint8_t *)std::malloc(BIG), *small = (uint8_t *)std::malloc(SMALL);
    if (!arena_a || !arena_b || !big || !small) return 1;
    std::memset(big, 0, BIG);
    std::memset(small, 0, SMALL);
    occ_map_t ma, mb;
    occ_map_config_t cfg = occ_map_config_default();
    cfg.resolution_m = RES;
    if (occ_map_init(&ma, &cfg, arena_a, ARENA) != OCC_OK ||
        occ_map_init(&mb, &cfg, arena_b, ARENA) != OCC_OK)
        return 1;
    std::vector<BenchRow> rows;
    const struct { occ_insert_method_t m; const char *name, *label; } methods[] = {
        {OCC_INSERT_SIMPLE, "simple", "SIMPLE"}, {OCC_INSERT_DISCRETE, "discrete", "DISCRETE"}};
    for (const auto &mt : methods) {
        std::vector<double> a, b;
        occ_insert_result_t ra, rb;
        bool equal = true;
        size_t used = 0;
        for (int i = 0; i < reps; i++) {
            const double ta = run(&ma, pts, mt.m, big, BIG, &ra);
            const double tb = run(&mb, pts, mt.m, small, SMALL, &rb);
            if (ta < 0 || tb < 0) {
                std::fprintf(stderr, "bench-scratch: %s failed\n", mt.label);
                return 1;
            }
            a.push_back(ta);
            b.push_back(tb);
            used = rb.scratch_used > used ? rb.scratch_used : used;
            equal = equal && ra.voxels_updated == rb.voxels_updated &&
                    ra.voxels_occupied == rb.voxels_occupied;
        }
        // Voxel for voxel: every leaf of one map read from the other.
        occ_walk_t w;
        occ_walk_node_t nd;
        occ_walk_begin(&w, &ma);
        while (equal && occ_walk_next(&w, &nd)) {
            if (nd.has_children || !nd.observed) continue;
            occ_node_info_t info;
            equal = occ_map_read_key(&mb, nd.key, nd.level, &info) == OCC_OK && info.observed &&
                    info.level == nd.level && info.logodds == occ_value_to_logodds(nd.value);
        }
        BenchRow r;
        r.id = std::string("scratch/scan.dat/0.05/8MB/") + mt.name;
        r.work = std::string("scan.dat 0.05 m, ") + mt.label + " exact, 8 MB of scratch (used " +
                 std::to_string(used) + " B) vs unbounded (used " +
                 std::to_string(ra.scratch_used) + " B)";
        r.unit = "ms";
        r.octomap = -1;
        r.occmap = bench_median(b);
        r.base_label = "unbounded scratch";
        r.base = bench_median(a);
        bench_row_ratios(r, a, b);
        r.target = "ratio >= 0.9, scratch <= 8 MB";
        r.met = r.ratio >= 0.9 && used <= SMALL;
        r.equal = equal ? "yes" : "no";
        rows.push_back(r);
        std::printf("%s: unbounded %.1f ms, 8 MB %.1f ms, ratio %.3f [%.3f, %.3f], equal %s\n",
                    r.id.c_str(), r.base, r.occmap, r.ratio, r.ratio_min, r.ratio_max,
                    r.equal.c_str());
    }
    BenchRow rss;
    rss.id = "scratch/peak_rss";
    rss.work = "peak RSS, scan.dat 0.05 m SIMPLE exact with 8 MB of scratch (fresh process each)";
    rss.unit = "MB";
    const double oct = rss_oct, occ = rss_occ;
    rss.octomap = oct;
    rss.occmap = occ;
    rss.reps = 1;
    if (oct > 0 && occ > 0) rss.ratio = rss.ratio_min = rss.ratio_max = oct / occ;
    rss.target = "scratch <= 8 MB";
    rss.met = occ > 0;
    rows.push_back(rss);
    std::printf("%s: occmap %.1f MB, OctoMap %.1f MB\n", rss.id.c_str(), occ, oct);
    std::free(arena_a);
    std::free(arena_b);
    std::free(big);
    std::free(small);
    if (!bench_rows_write("build/bench/rows/scratch.json", rows)) {
        std::fprintf(stderr, "bench-scratch: cannot write build/bench/rows/scratch.json\n");
        return 1;
    }
    return 0;
}
