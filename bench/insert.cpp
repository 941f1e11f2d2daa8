// SPDX-License-Identifier: BSD-3-Clause
// insert.cpp - point-cloud integration: occmap against OctoMap 1.9.7 in the same run.
// Prints a table (median ms per scan of >= 5 repetitions, ratio to the matching OctoMap call,
// memory vs OctoMap's memoryUsage(), whether the maps are equal) and writes build/bench/insert.json.
// Every configuration runs in interleaved rounds (OctoMap, OctoMap discretize, each occmap
// method, then the next round), so the per-round ratios pair runs made under the same load; the
// rows of issue 22's table (bench_rows.hpp) go to build/bench/rows/insert.json.
// usage: insert [--reps N] [--quick] [--json PATH] [--rows PATH] [--only DATA] [--res R]
//               [--frames N]
#include <octomap/OcTree.h>
#include <octomap/octomap.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "../tests/support/oracle_res.hpp"
#include "bench_rows.hpp"

extern "C" {
#include "occmap/occmap.h"
#include "occmap/host/occ_scan.h"
}

using octomap::OcTree;
using octomap::point3d;

struct Scan {
    std::vector<occ_vec3_t> pts;
    occ_vec3_t origin;
};
struct Dataset {
    std::string name;
    std::vector<Scan> scans;
    size_t points() const
    {
        size_t n = 0;
        for (const Scan &s : scans) n += s.pts.size();
        return n;
    }
};

// Thread CPU time: the machine may be shared, and both sides are single-threaded, so CPU time
// is the fairer clock for ratios (wall time is reported too).
static double now_ms()
{
    timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return (double)t.tv_sec * 1e3 + (double)t.tv_nsec / 1e6;
}

static double median(std::vector<double> v)
{
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

// ---- OctoMap side ---------------------------------------------------------------------------
// ---- equality: every OctoMap leaf against our map, every our leaf against OctoMap -------------
struct Diff {
    size_t checked = 0, bad = 0;
    size_t extra_free = 0, missed_occ = 0, extra_occ = 0; // ours vs reference, in voxels
};

static unsigned octo_search(const OcTree &t, const occ_key_t &k, float *lo)
{
    octomap::OcTreeKey key((octomap::key_type)k.k[0], (octomap::key_type)k.k[1],
                           (octomap::key_type)k.k[2]);
    octomap::OcTreeNode *node = t.getRoot();
    unsigned depth = 0;
    if (node == nullptr) return 99;
    while (depth < 16u && t.nodeHasChildren(node)) {
        const unsigned pos = octomap::computeChildIdx(key, (int)(15 - depth));
        if (!t.nodeChildExists(node, pos)) return 99;
        node = t.getNodeChild(node, pos);
        depth++;
    }
    *lo = node->getLogOdds();
    return 16u - depth;
}

static Diff compare(const occ_map_t &m, const OcTree &t, float tol)
{
    Diff d;
    for (auto it = t.begin_leafs(); it != t.end_leafs(); ++it) {
        const unsigned level = 16u - it.getDepth();
        const octomap::OcTreeKey k = it.getKey();
        const uint32_t mask = ~((1u << level) - 1u);
        occ_key_t key = {{k[0] & mask, k[1] & mask, k[2] & mask}};
        occ_node_info_t info;
        d.checked++;
        if (occ_map_read_key(&m, key, level, &info) != OCC_OK || !info.observed) {
            d.bad++;
            if (it->getLogOdds() >= 0.0f) d.missed_occ += (size_t)1 << (3 * level);
            continue;
        }
        if (info.level < level) continue; // ours is finer here: checked from our side below
        if (std::fabs(info.logodds - it->getLogOdds()) > tol) {
            d.bad++;
            const bool ro = it->getLogOdds() >= 0.0f, oo = info.logodds >= 0.0f;
            if (ro && !oo) d.missed_occ += (size_t)1 << (3 * level);
            if (!ro && oo) d.extra_occ += (size_t)1 << (3 * level);
        }
    }
    occ_walk_t w;
    occ_walk_node_t n;
    occ_walk_begin(&w, &m);
    while (occ_walk_next(&w, &n)) {
        if (n.has_children || !n.observed) continue;
        d.checked++;
        float lo = 0.0f;
        const unsigned lvl = octo_search(t, n.key, &lo);
        const float ours = occ_value_to_logodds(n.value);
        if (lvl == 99u) {
            d.bad++;
            if (ours < 0.0f) d.extra_free += (size_t)1 << (3 * n.level);
            else d.extra_occ += (size_t)1 << (3 * n.level);
            continue;
        }
        if (lvl < n.level) continue; // OctoMap finer: checked from its side above
        if (std::fabs(ours - lo) > tol) d.bad++;
    }
    return d;
}

// ---- data -----------------------------------------------------------------------------------
static bool load_xyz(const char *path, Dataset &d)
{
    occ_vec3_t *pts = nullptr;
    size_t n = 0;
    char msg[256] = "";
    if (occ_scan_read_xyz(path, &pts, &n, msg, sizeof msg) != OCC_OK) {
        std::fprintf(stderr, "bench: %s\n", msg);
        return false;
    }
    Scan s;
    s.pts.assign(pts, pts + n);
    s.origin = occ_vec3_t{0, 0, 0};
    free(pts);
    d.scans.push_back(s);
    return true;
}

static bool load_frames(occ_scan_frame_t *f, size_t n, Dataset &d)
{
    for (size_t i = 0; i < n; i++) {
        Scan s;
        s.pts.assign(f[i].points, f[i].points + f[i].n_points);
        s.origin = f[i].origin;
        d.scans.push_back(s);
    }
    occ_scan_frames_free(f, n);
    return n > 0;
}

// ---- one configuration -------------------------------------------------------------------------
struct Row {
    std::string data, method;
    double res;
    double ms, ratio;
    size_t bytes, octo_bytes;
    std::string equal;
    size_t voxels, visits;
};

static std::vector<Row> rows;
static std::vector<BenchRow> bench_rows_out; // the rows of the issue-22 table
static std::vector<uint8_t> arena, scratch;

// OctoMap's sensor model exactly (logodds of 0.7, 0.4, 0.1192, 0.971).
static occ_map_config_t octomap_config(float res)
{
    occ_map_config_t cfg = occ_map_config_default();
    cfg.resolution_m = res;
    cfg.hit = std::log(0.7f / 0.3f);
    cfg.miss = std::log(0.4f / 0.6f);
    cfg.clamp_min = std::log(0.1192f / (1.0f - 0.1192f));
    cfg.clamp_max = std::log(0.971f / (1.0f - 0.971f));
    return cfg;
}

// One pass over the dataset into a fresh map: CPU ms per scan.
static double run_occ_once(const Dataset &d, float res, const occ_insert_params_t &p, occ_map_t &m,
                           occ_insert_result_t &last)
{
    const occ_map_config_t cfg = octomap_config(res);
    if (occ_map_init(&m, &cfg, arena.data(), arena.size()) != OCC_OK) std::abort();
    double total = 0;
    size_t visits = 0;
    for (const Scan &s : d.scans) {
        occ_insert_result_t out;
        const double t0 = now_ms();
        const occ_err_t e = occ_map_insert_cloud(&m, &s.origin, s.pts.data(), s.pts.size(), &p,
                                                 scratch.data(), scratch.size(), &out);
        total += now_ms() - t0;
        if (e != OCC_OK) {
            std::fprintf(stderr, "bench: insert failed: %s\n", occ_err_str(e));
            std::exit(1);
        }
        visits += out.voxel_visits;
        last = out;
    }
    last.voxel_visits = visits;
    return total / (double)d.scans.size();
}

// One OctoMap pass over the dataset into a fresh tree (kept in `keep`): CPU ms per scan.
static double run_octo_once(const Dataset &d, float res, bool discretize, OcTree *&keep)
{
    delete keep;
    keep = new OcTree(oracle_user_resolution((double)res)); // OcTree(0.1) for 0.1f
    double total = 0;
    for (const Scan &s : d.scans) {
        octomap::Pointcloud pc;
        pc.reserve(s.pts.size());
        for (const occ_vec3_t &p : s.pts) pc.push_back(p.x, p.y, p.z);
        const double t0 = now_ms();
        keep->insertPointCloud(pc, point3d(s.origin.x, s.origin.y, s.origin.z), -1.0, false,
                               discretize);
        total += now_ms() - t0;
    }
    return total / (double)d.scans.size();
}

static const char *method_name(occ_insert_method_t m)
{
    switch (m) {
    case OCC_INSERT_SIMPLE: return "simple";
    case OCC_INSERT_DISCRETE: return "discrete";
    case OCC_INSERT_FAST_DISCRETE: return "fast";
    case OCC_INSERT_SUPER_RAYS: return "superrays";
    case OCC_INSERT_PROJECTIVE: return "projective";
    }
    return "?";
}

// One occmap method of one configuration: its times per round and, from the last round, its map's
// check against the matching OctoMap tree.
struct MethodRun {
    occ_insert_method_t meth;
    occ_insert_params_t p;
    std::vector<double> t;  // CPU ms per scan, one per round
    std::string eq;         // the printed equality note
    bool equal = false;     // map equal to the reference tree (every leaf within tol)
    occ_insert_result_t out = {};
    occ_map_stats_t st = {};
};

static bool vs_discrete(occ_insert_method_t m)
{
    return m == OCC_INSERT_DISCRETE || m == OCC_INSERT_FAST_DISCRETE;
}

// The last round's map against the matching OctoMap tree (DISCRETE, FAST: discretize = true).
static void check_run(MethodRun &mr, const occ_map_t &m, const OcTree &ref, float tol, unsigned dfast)
{
    occ_map_pool_stats(&m, &mr.st);
    const Diff df = compare(m, ref, tol);
    mr.equal = df.bad == 0;
    char buf[160];
    if (mr.meth == OCC_INSERT_FAST_DISCRETE && dfast > 0) {
        std::snprintf(buf, sizeof buf, "d=%u: +%zu free, %zu occ missed (voxels)", dfast,
                      df.extra_free, df.missed_occ);
        mr.equal = false; // approximate by design
    } else {
        std::snprintf(buf, sizeof buf, "%s (%zu of %zu leaves differ)", df.bad == 0 ? "yes" : "NO",
                      df.bad, df.checked);
    }
    mr.eq = buf;
}

// One row of the issue-22 table from paired rounds (a[i]: OctoMap or the base, b[i]: occmap).
static void add_bench_row(const std::string &id, const std::string &work,
                          const std::vector<double> &a, const std::vector<double> &b,
                          bool octomap_side, const std::string &target, double want,
                          const std::string &equal)
{
    BenchRow r;
    r.id = id;
    r.work = work;
    r.unit = "ms";
    r.occmap = bench_median(b);
    if (octomap_side) r.octomap = bench_median(a);
    else {
        r.base_label = "SIMPLE";
        r.base = bench_median(a);
    }
    bench_row_ratios(r, a, b);
    r.target = target;
    r.met = r.ratio >= want;
    r.equal = equal;
    bench_rows_out.push_back(r);
}

// The issue-22 rows this configuration gives (scan.dat 0.1 / 0.05, TUM 0.05 / 0.1 / 0.2).
static void table_rows(const Dataset &d, const char *res_s, const std::vector<MethodRun> &runs,
                       const std::vector<double> &t_os, const std::vector<double> &t_od)
{
    const bool scan = d.name == "scan.dat", tum = d.name == "tum_fr2_pioneer";
    const std::string r = res_s, base = "insert/" + (tum ? std::string("tum") : d.name) + "/" + r + "/";
    const char *want_s = r == "0.05" ? "ratio >= 45" : "ratio >= 35";
    const double want = r == "0.05" ? 45.0 : 35.0;
    const std::string frames = std::to_string(d.scans.size()) + " TUM frames";
    const std::string ms_per = " (CPU ms per scan, " + std::to_string(d.scans.size()) + " scan" +
                               (d.scans.size() == 1 ? "" : "s") + ")";
    if (scan && (r == "0.10" || r == "0.05")) {
        add_bench_row(base + "simple", "scan.dat " + r + " m, SIMPLE (exact) vs insertPointCloud" + ms_per,
                      t_os, runs[0].t, true, want_s, want, runs[0].equal ? "yes" : "no");
        add_bench_row(base + "discrete",
                      "scan.dat " + r + " m, DISCRETE (exact) vs insertPointCloud discretize" + ms_per,
                      t_od, runs[1].t, true, want_s, want, runs[1].equal ? "yes" : "no");
    }
    if ((scan || tum) && r == "0.05") {
        const MethodRun *best = nullptr; // the fastest method whose map equals OctoMap's
        for (const MethodRun &mr : runs)
            if (mr.equal && (best == nullptr || median(mr.t) < median(best->t))) best = &mr;
        if (best != nullptr) {
            const bool disc = vs_discrete(best->meth);
            const std::string name = tum ? frames : "scan.dat";
            add_bench_row(base + "best",
                          name + " 0.05 m, best exact method: " + method_name(best->meth) +
                              " vs insertPointCloud" + (disc ? " discretize" : "") + ms_per,
                          disc ? t_od : t_os, best->t, true, tum ? "ratio >= 10" : "ratio >= 45",
                          tum ? 10.0 : 45.0, "yes");
        }
    }
    if (tum && (r == "0.10" || r == "0.20"))
        add_bench_row(base + "superray_vs_simple",
                      frames + " " + r + " m, SUPER_RAYS vs SIMPLE" + ms_per, runs[0].t,
                      runs[3].t, false, "ratio >= 1.5 vs SIMPLE", 1.5, runs[3].equal ? "yes" : "no");
}

// One dataset at one resolution: `reps` interleaved rounds (OctoMap, OctoMap discretize, then
// each occmap method, each into a fresh map), medians of CPU ms per scan; the maps of the last
// round are compared.
static void bench_dataset(const Dataset &d, float res, int reps)
{
    const float tol = 0.002f * (float)d.scans.size() + 0.001f;
    OcTree *octo_simple = nullptr, *octo_disc = nullptr;
    unsigned dfast = 0;
    while (res * (float)(1u << (dfast + 1)) <= 0.2f + 1e-6f) dfast++;
    const occ_insert_method_t methods[] = {OCC_INSERT_SIMPLE, OCC_INSERT_DISCRETE,
                                           OCC_INSERT_FAST_DISCRETE, OCC_INSERT_SUPER_RAYS};
    std::vector<MethodRun> runs;
    for (occ_insert_method_t meth : methods) {
        MethodRun mr;
        mr.meth = meth;
        mr.p = occ_insert_params_default();
        mr.p.method = meth;
        mr.p.fast_n = 0;
        mr.p.fast_d = (uint8_t)dfast;
        runs.push_back(mr);
    }
    std::vector<double> t_os, t_od;
    for (int r = 0; r < reps; r++) {
        t_os.push_back(run_octo_once(d, res, false, octo_simple));
        t_od.push_back(run_octo_once(d, res, true, octo_disc));
        for (MethodRun &mr : runs) {
            occ_map_t m;
            mr.t.push_back(run_occ_once(d, res, mr.p, m, mr.out));
            if (r == reps - 1)
                check_run(mr, m, vs_discrete(mr.meth) ? *octo_disc : *octo_simple, tol, dfast);
        }
    }
    const double m_os = median(t_os), m_od = median(t_od);
    const size_t mem_os = octo_simple->memoryUsage(), mem_od = octo_disc->memoryUsage();
    rows.push_back(Row{d.name, "octomap", (double)res, m_os, 1.0, mem_os, mem_os, "-", 0, 0});
    rows.push_back(Row{d.name, "octomap-discrete", (double)res, m_od, 1.0, mem_od, mem_od, "-", 0, 0});
    for (MethodRun &mr : runs) {
        const double t = median(mr.t);
        const bool vd = vs_discrete(mr.meth);
        std::string eq = mr.eq;
        char buf[160];
        if (mr.meth == OCC_INSERT_SUPER_RAYS && mr.out.rays_cast > 0) {
            // The super-ray target is a ratio to SIMPLE in the same rounds; points per traversal
            // (last scan) says how much the grouping found.
            std::vector<double> q;
            for (size_t i = 0; i < mr.t.size(); i++) q.push_back(runs[0].t[i] / mr.t[i]);
            std::snprintf(buf, sizeof buf,
                          "; %.2fx SIMPLE (median of %d interleaved pairs), %.1f points per traversal",
                          median(q), reps,
                          (double)mr.out.points_integrated / (double)mr.out.rays_cast);
            eq += buf;
        }
        std::string name = method_name(mr.meth);
        if (mr.meth == OCC_INSERT_FAST_DISCRETE) name += "(n=0,d=" + std::to_string(dfast) + ")";
        rows.push_back(Row{d.name, name, (double)res, t, (vd ? m_od : m_os) / t, mr.st.bytes_used,
                           vd ? mem_od : mem_os, eq, mr.out.voxels_updated, mr.out.voxel_visits});
        const Row &r = rows.back();
        std::printf("%-22s %5.2f %-18s %10.2f ms %8.1fx  mem %10zu B (%5.1f%% of OctoMap)  visits "
                    "%zu  equal: %s\n",
                    r.data.c_str(), r.res, r.method.c_str(), r.ms, r.ratio, r.bytes,
                    100.0 * (double)r.bytes / (double)r.octo_bytes, r.visits, r.equal.c_str());
    }
    std::printf("%-22s %5.2f %-18s %10.2f ms   (OctoMap, %zu B)\n", d.name.c_str(), (double)res,
                "octomap", m_os, mem_os);
    std::printf("%-22s %5.2f %-18s %10.2f ms   (OctoMap, %zu B)\n", d.name.c_str(), (double)res,
                "octomap-discrete", m_od, mem_od);
    std::fflush(stdout);
    char resbuf[32];
    std::snprintf(resbuf, sizeof resbuf, "%.2f", (double)res);
    table_rows(d, resbuf, runs, t_os, t_od);
    delete octo_simple;
    delete octo_disc;
}

int main(int argc, char **argv)
{
    int reps = 5;
    bool quick = false;
    std::string json = "build/bench/insert.json";
    std::string rows_json = "build/bench/rows/insert.json";
    std::string only;
    float res_only = 0.0f;
    size_t max_frames = 0;
    for (int i = 1; i < argc; i++) {
        if (!std::strcmp(argv[i], "--reps") && i + 1 < argc) reps = std::atoi(argv[++i]);
        else if (!std::strcmp(argv[i], "--quick")) quick = true;
        else if (!std::strcmp(argv[i], "--json") && i + 1 < argc) json = argv[++i];
        else if (!std::strcmp(argv[i], "--rows") && i + 1 < argc) rows_json = argv[++i];
        else if (!std::strcmp(argv[i], "--only") && i + 1 < argc) only = argv[++i];
        else if (!std::strcmp(argv[i], "--res") && i + 1 < argc) res_only = (float)std::atof(argv[++i]);
        else if (!std::strcmp(argv[i], "--frames") && i + 1 < argc) max_frames = (size_t)std::atoi(argv[++i]);
    }
    if (reps < 1) reps = 1;
    std::vector<Dataset> sets;
    {
        Dataset d;
        d.name = "scan.dat";
        if (load_xyz("build/data/scan.dat", d)) sets.push_back(d);
    }
    {
        Dataset d;
        d.name = "spherical_scan.graph";
        occ_scan_frame_t *f = nullptr;
        size_t n = 0;
        char msg[256] = "";
        if (occ_scan_read_graph("/usr/share/doc/liboctomap-dev/examples/data/spherical_scan.graph",
                                &f, &n, msg, sizeof msg) == OCC_OK && load_frames(f, n, d))
            sets.push_back(d);
        else std::fprintf(stderr, "bench: %s\n", msg);
    }
    {
        Dataset d;
        d.name = "tum_fr2_pioneer";
        occ_scan_frame_t *f = nullptr;
        size_t n = 0;
        char msg[256] = "";
        if (occ_depth_read_tum_dir("../shared/data/depth/tum_fr2_pioneer_slam2", 1, max_frames, &f, &n, msg,
                                   sizeof msg) == OCC_OK && load_frames(f, n, d))
            sets.push_back(d);
        else std::fprintf(stderr, "bench: TUM frames skipped: %s\n", msg);
    }
    arena.assign((size_t)1536 << 20, 0);
    size_t need = 0;
    const float resolutions[] = {0.2f, 0.1f, 0.05f};
    for (const Dataset &d : sets) {
        occ_map_t tmp;
        occ_map_config_t cfg = occ_map_config_default();
        cfg.resolution_m = 0.05f;
        uint8_t small[OCC_ARENA_BYTES(2, 2)];
        occ_map_init(&tmp, &cfg, small, sizeof small);
        occ_insert_params_t p = occ_insert_params_default();
        for (const Scan &s : d.scans)
            need = std::max(need, occ_insert_scratch_bytes_scan(&tmp, &s.origin, s.pts.data(),
                                                                s.pts.size(), &p));
    }
    scratch.assign(need, 0);
    std::printf("occmap insert bench: scratch %zu MB, arena %zu MB, %d reps (median)\n",
                need >> 20, arena.size() >> 20, reps);
    for (const Dataset &d : sets) {
        if (!only.empty() && d.name.find(only) == std::string::npos) continue;
        for (float res : resolutions) {
            if (quick && res < 0.1f && d.name != "scan.dat") continue;
            if (res_only > 0.0f && std::fabs(res - res_only) > 1e-4f) continue;
            bench_dataset(d, res, reps);
        }
    }
    FILE *f = std::fopen(json.c_str(), "w");
    if (f != nullptr) {
        std::fprintf(f, "{\"rows\": [\n");
        for (size_t i = 0; i < rows.size(); i++) {
            const Row &r = rows[i];
            std::fprintf(f,
                         "  {\"data\": \"%s\", \"res_m\": %.2f, \"method\": \"%s\", \"ms\": %.3f, "
                         "\"speedup_vs_octomap\": %.2f, \"memory_bytes\": %zu, "
                         "\"octomap_memory_bytes\": %zu, \"equal\": \"%s\", \"voxels_updated\": "
                         "%zu, \"voxel_visits\": %zu}%s\n",
                         r.data.c_str(), r.res, r.method.c_str(), r.ms, r.ratio, r.bytes,
                         r.octo_bytes, r.equal.c_str(), r.voxels, r.visits,
                         i + 1 < rows.size() ? "," : "");
        }
        std::fprintf(f, "]}\n");
        std::fclose(f);
    }
    if (!bench_rows_write(rows_json, bench_rows_out)) {
        std::fprintf(stderr, "bench: cannot write %s\n", rows_json.c_str());
        return 1;
    }
    std::printf("wrote %zu table rows to %s\n", bench_rows_out.size(), rows_json.c_str());
    return 0;
}
