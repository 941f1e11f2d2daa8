// SPDX-License-Identifier: BSD-3-Clause
// lookup_index.cpp - random and trajectory point lookups (issue 22): OctoMap 1.9.7's search(),
// occ_map_state_at (a descent from the root) and the lookup index (occ_lookup_index_state, and
// the batch occ_lookup_index_states) over the same points, interleaved batch by batch (OctoMap,
// root, index, batch, OctoMap, ...), thread CPU time, medians over the batches; the ratio is the
// median of the per-batch OctoMap / index ratios, its spread their min and max.
// Maps: geb079.bt and ../shared/data/maps/fr_079_t1_model.ot (skipped when absent). The index
// level is the finest that fits --budget MB (default 32); the bytes of every level are printed.
// Every answer is checked against occ_map_state_at (and OctoMap's state) before timing.
// Writes build/bench/rows/lookup_index.json.
//   usage: lookup_index [--quick] [--budget MB] [--rows PATH] MAP...
#include <octomap/AbstractOcTree.h>
#include <octomap/OcTree.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <random>
#include <string>
#include <vector>

#include "bench_rows.hpp"
#include "octo_load.hpp"

extern "C" {
#include "occmap/host/occ_file.h"
#include "occmap/occmap.h"
}

using octomap::OcTree;
using octomap::point3d;

static double thread_ns()
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec * 1e9 + (double)ts.tv_nsec;
}


static occ_vec3_t v3(const point3d &p) { return occ_vec3_t{p.x(), p.y(), p.z()}; }
static volatile size_t sink;

static occ_state_t octo_state(const OcTree &t, const point3d &p)
{
    const octomap::OcTreeNode *n = t.search(p);
    return n == nullptr ? OCC_STATE_UNKNOWN : (t.isNodeOccupied(n) ? OCC_STATE_OCCUPIED : OCC_STATE_FREE);
}

// ns per point of each side, per batch.
struct Sides {
    std::vector<double> octo, root, index, batch;
};

static Sides run(const OcTree &t, const occ_map_t &map, const occ_lookup_index_t &idx,
                 const std::vector<point3d> &pts, int batches)
{
    std::vector<occ_vec3_t> q(pts.size());
    for (size_t i = 0; i < pts.size(); i++) q[i] = v3(pts[i]);
    std::vector<occ_state_t> out(pts.size());
    Sides s;
    const size_t per = pts.size() / (size_t)batches;
    for (int b = 0; b < batches; b++) {
        const size_t i0 = (size_t)b * per, i1 = i0 + per;
        double t0 = thread_ns();
        for (size_t i = i0; i < i1; i++) {
            const octomap::OcTreeNode *n = t.search(pts[i]);
            sink += n == nullptr ? 0u : (t.isNodeOccupied(n) ? 2u : 1u);
        }
        double t1 = thread_ns();
        s.octo.push_back((t1 - t0) / (double)per);
        t0 = thread_ns();
        for (size_t i = i0; i < i1; i++) sink += (size_t)occ_map_state_at(&map, q[i]);
        t1 = thread_ns();
        s.root.push_back((t1 - t0) / (double)per);
        t0 = thread_ns();
        for (size_t i = i0; i < i1; i++) sink += (size_t)occ_lookup_index_state(&idx, q[i]);
        t1 = thread_ns();
        s.index.push_back((t1 - t0) / (double)per);
        t0 = thread_ns();
        (void)occ_lookup_index_states(&idx, &q[i0], per, &out[i0]);
        t1 = thread_ns();
        sink += (size_t)out[i0];
        s.batch.push_back((t1 - t0) / (double)per);
    }
    return s;
}

static BenchRow row(const std::string &id, const std::string &work, const std::vector<double> &octo,
                    const std::vector<double> &ours, const std::string &target, bool met, bool equal)
{
    BenchRow r;
    r.id = id;
    r.work = work;
    r.unit = "ns";
    r.octomap = bench_median(octo);
    r.occmap = bench_median(ours);
    bench_row_ratios(r, octo, ours);
    r.target = target;
    r.met = met;
    r.equal = equal ? "yes" : "no";
    return r;
}

// Every point: the index (single and batch) equals occ_map_state_at; OctoMap agrees with both
// (counted: OctoMap has no unknown band and may differ only there).
static bool check(const OcTree &t, const occ_map_t &map, const occ_lookup_index_t &idx,
                  const std::vector<point3d> &pts, size_t *octo_same)
{
    std::vector<occ_vec3_t> q(pts.size());
    for (size_t i = 0; i < pts.size(); i++) q[i] = v3(pts[i]);
    std::vector<occ_state_t> out(pts.size());
    if (occ_lookup_index_states(&idx, q.data(), q.size(), out.data()) != OCC_OK) return false;
    bool ok = true;
    *octo_same = 0;
    for (size_t i = 0; i < pts.size(); i++) {
        const occ_state_t want = occ_map_state_at(&map, q[i]);
        ok = ok && occ_lookup_index_state(&idx, q[i]) == want && out[i] == want;
        *octo_same += octo_state(t, pts[i]) == want;
    }
    return ok;
}

static void bench_map(const std::string &path, bool quick, size_t budget, std::vector<BenchRow> &rows)
{
    OcTree *t = bench_load_octo(path);
    occ_map_t map;
    void *arena = nullptr;
    char msg[256] = "";
    if (t == nullptr ||
        occ_file_load_alloc(path.c_str(), nullptr, &map, 0u, &arena, nullptr, msg, sizeof msg) != OCC_OK) {
        printf("skip %s: cannot load it (%s)\n", path.c_str(), msg);
        delete t;
        free(arena);
        return;
    }
    std::string name = path.substr(path.find_last_of('/') + 1);
    name = name.substr(0, name.find_first_of('.'));
    if (name.compare(0, 6, "fr_079") == 0) name = "fr_079";
    double x0, y0, z0, x1, y1, z1;
    t->getMetricMin(x0, y0, z0);
    t->getMetricMax(x1, y1, z1);
    printf("%s: res %.3f m, bbox %.1f x %.1f x %.1f m, %zu OctoMap leaves\n", name.c_str(),
           t->getResolution(), x1 - x0, y1 - y0, z1 - z0, t->getNumLeafNodes());
    for (unsigned l = 0; l <= 6; l++) {
        size_t b = 0;
        occ_lookup_index_need(&map, l, &b);
        printf("  level %u: %.2f MB\n", l, (double)b / 1e6);
    }
    unsigned level = 0;
    if (occ_lookup_index_pick(&map, budget, &level) != OCC_OK) {
        printf("skip %s: no level fits %zu bytes\n", name.c_str(), budget);
        return;
    }
    size_t bytes = 0;
    occ_lookup_index_need(&map, level, &bytes);
    std::vector<uint32_t> mem(bytes / 4 + 1);
    occ_lookup_index_t idx;
    const double tb = thread_ns();
    const occ_err_t e = occ_lookup_index_build(&idx, &map, level, mem.data(), mem.size() * 4);
    printf("  index level %u, %.2f MB, built in %.1f ms (%s)\n", level, (double)bytes / 1e6,
           (thread_ns() - tb) / 1e6, occ_err_str(e));
    std::mt19937_64 rng(42);
    std::uniform_real_distribution<double> ux(x0, x1), uy(y0, y1), uz(z0, z1), u01(0, 1);
    const size_t N = quick ? 20000 : 200000;
    const int batches = 9;
    std::vector<point3d> pts(N);
    for (auto &p : pts) p = point3d((float)ux(rng), (float)uy(rng), (float)uz(rng));
    // A trajectory: 5 cm steps in random directions from random starts (200 steps each).
    std::vector<point3d> traj(N);
    for (size_t i = 0; i < N; i++) {
        if (i % 200 == 0) {
            traj[i] = point3d((float)ux(rng), (float)uy(rng), (float)uz(rng));
            continue;
        }
        point3d d((float)(2 * u01(rng) - 1), (float)(2 * u01(rng) - 1), (float)(2 * u01(rng) - 1));
        if (d.norm() < 1e-3) d = point3d(1, 0, 0);
        point3d q = traj[i - 1] + d.normalized() * 0.05f;
        q.x() = std::min(std::max(q.x(), (float)x0), (float)x1);
        q.y() = std::min(std::max(q.y(), (float)y0), (float)y1);
        q.z() = std::min(std::max(q.z(), (float)z0), (float)z1);
        traj[i] = q;
    }
    size_t same_r = 0, same_t = 0;
    const bool eq_r = e == OCC_OK && check(*t, map, idx, pts, &same_r);
    const bool eq_t = e == OCC_OK && check(*t, map, idx, traj, &same_t);
    printf("  index == occ_map_state_at: random %s, trajectory %s; OctoMap same state %zu/%zu, %zu/%zu\n",
           eq_r ? "yes" : "NO", eq_t ? "yes" : "NO", same_r, N, same_t, N);
    const Sides r = run(*t, map, idx, pts, batches);
    const Sides tr = run(*t, map, idx, traj, batches);
    const std::string lv = " (index level " + std::to_string(level) + ", " +
                           std::to_string((bytes + 500000) / 1000000) + " MB)";
    const std::string rid = "query/lookup_random/" + name;
    BenchRow a = row(rid + "/index", "random point lookup, " + name + ", occ_lookup_index_state vs search" + lv,
                     r.octo, r.index, "occmap <= 50 ns, ratio >= 4", false, eq_r);
    a.met = a.occmap <= 50 && a.ratio >= 4;
    BenchRow b = row(rid + "/index/batch", "random point lookup, " + name + ", occ_lookup_index_states vs search" + lv,
                     r.octo, r.batch, "occmap <= 50 ns, ratio >= 4", false, eq_r);
    b.met = b.occmap <= 50 && b.ratio >= 4;
    char root_note[96];
    snprintf(root_note, sizeof root_note, "; occ_map_state_at in the same run: %.1f ns random, %.1f ns trajectory",
             bench_median(r.root), bench_median(tr.root));
    a.work += root_note;
    const std::string tid = name == "geb079" ? "query/lookup_trajectory/index"
                                             : "query/lookup_trajectory/" + name + "/index";
    BenchRow d = row(tid, "trajectory lookup 5 cm steps, " + name + ", occ_lookup_index_state vs search" + lv,
                     tr.octo, tr.index, "occmap < 20 ns", false, eq_t);
    d.met = d.occmap < 20;
    for (const BenchRow *x : {&a, &b, &d}) {
        printf("  %-44s octomap %6.1f ns  occmap %6.1f ns  ratio %5.2f [%4.2f, %4.2f]  %s\n", x->id.c_str(),
               x->octomap, x->occmap, x->ratio, x->ratio_min, x->ratio_max, x->met ? "met" : "not met");
        rows.push_back(*x);
    }
    printf("  occ_map_state_at: random %.1f ns, trajectory %.1f ns; batch on the trajectory %.1f ns\n",
           bench_median(r.root), bench_median(tr.root), bench_median(tr.batch));
    delete t;
    free(arena);
}

int main(int argc, char **argv)
{
    bool quick = false;
    size_t budget = 32u << 20;
    std::string out = "build/bench/rows/lookup_index.json";
    std::vector<std::string> maps;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--quick")) quick = true;
        else if (!strcmp(argv[i], "--budget") && i + 1 < argc) budget = (size_t)(atof(argv[++i]) * 1048576.0);
        else if (!strcmp(argv[i], "--rows") && i + 1 < argc) out = argv[++i];
        else maps.push_back(argv[i]);
    }
    std::vector<BenchRow> rows;
    for (const auto &m : maps) bench_map(m, quick, budget, rows);
    if (!bench_rows_write(out, rows)) {
        fprintf(stderr, "cannot write %s\n", out.c_str());
        return 1;
    }
    printf("wrote %s (%zu rows)\n", out.c_str(), rows.size());
    return 0;
}
