// SPDX-License-Identifier: BSD-3-Clause
// query.cpp - queries: occmap against OctoMap 1.9.7 in the same run, the way OctoMap users do it
// (search() per point, the leaf iterator over a bounding box, castRay).
// Maps: geb079.bt (OctoMap's example) and the maps in ../shared/data/maps/ when present, each
// loaded through OctoMap and through occ_file_load (or, if that fails, copied leaf by leaf).
// Prints a table of medians (ns per operation over 9 batches, occmap and OctoMap batches
// alternating) and the median of the per-batch ratios as the speedup, and writes
// build/bench/query.json; the rows of issue 22's table (bench_rows.hpp: lookups on geb079.bt and
// fr_079, sphere and ray cast on geb079.bt) go to build/bench/rows/query.json.
// usage: query [--quick] [--json PATH] [--rows PATH] [MAP...]
#include <octomap/OcTree.h>
#include <octomap/AbstractOcTree.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <random>
#include <string>
#include <vector>

extern "C" {
#include "occmap/occmap.h"
#include "occmap/host/occ_file.h"
}

#include "bench_rows.hpp"
#include "octo_load.hpp"

using octomap::OcTree;
using octomap::OcTreeKey;
using octomap::point3d;

// Thread CPU time: the runs share the machine with other jobs, and CPU time is what both sides
// spend (wall time on a loaded 2-core VM swings by 2-3x between batches).
static long long thread_ns()
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (long long)ts.tv_sec * 1000000000LL + ts.tv_nsec;
}

static double now_ns()
{
    return std::chrono::duration<double, std::nano>(std::chrono::nanoseconds(thread_ns()))
        .count();
}

// occmap (fa over na operations) against OctoMap (fb over nb) in alternating batches, so that the
// machine's drift hits both alike: per-operation medians of each side and the median of the
// per-batch time ratios (b / a), which is the speedup reported.
struct Paired {
    double a_ns, b_ns, ratio;
    std::vector<double> va, vb; // per-batch ns per operation, in batch order (a: occmap)
};
// A template, not std::function: an indirect call per operation would add a few ns to both sides,
// a fifth of a path-cached lookup.
template <class FA, class FB>
static Paired paired(size_t na, const FA &fa, size_t nb, const FB &fb, int batches = 9)
{
    std::vector<double> ta, tb, r;
    const size_t pa = std::max<size_t>(1, na / (size_t)batches);
    const size_t pb = std::max<size_t>(1, nb / (size_t)batches);
    for (int b = 0; b < batches; b++) {
        double t0 = now_ns();
        for (size_t i = (size_t)b * pa; i < (size_t)(b + 1) * pa && i < na; i++) fa(i);
        const double a = (now_ns() - t0) / (double)pa;
        t0 = now_ns();
        for (size_t i = (size_t)b * pb; i < (size_t)(b + 1) * pb && i < nb; i++) fb(i);
        const double bb = (now_ns() - t0) / (double)pb;
        ta.push_back(a);
        tb.push_back(bb);
        r.push_back(bb / a);
    }
    const std::vector<double> va = ta, vb = tb;
    std::sort(ta.begin(), ta.end());
    std::sort(tb.begin(), tb.end());
    std::sort(r.begin(), r.end());
    return Paired{ta[ta.size() / 2], tb[tb.size() / 2], r[r.size() / 2], va, vb};
}

static volatile size_t sink;

// The rows of issue 22's table (bench_rows.hpp), written to build/bench/rows/query.json.
static std::vector<BenchRow> table_rows;

// The table's short name of a map this bench measures for it ("" for the others).
static std::string table_map(const std::string &file)
{
    if (file == "geb079.bt") return "geb079";
    if (file.compare(0, 6, "fr_079") == 0) return "fr_079";
    return "";
}

// One table row from a paired measurement (ns per operation, occmap against OctoMap's batches).
// max_ns / min_ratio < 0: that part of the target is not set.
static void table_row(const std::string &id, const std::string &work, const Paired &p,
                      const std::string &target, double max_ns, double min_ratio, bool equal)
{
    BenchRow r;
    r.id = id;
    r.work = work;
    r.unit = "ns";
    r.octomap = bench_median(p.vb);
    r.occmap = bench_median(p.va);
    bench_row_ratios(r, p.vb, p.va);
    r.target = target;
    r.met = (max_ns >= 0 || min_ratio >= 0) && (max_ns < 0 || r.occmap <= max_ns) &&
            (min_ratio < 0 || r.ratio >= min_ratio);
    r.equal = equal ? "yes" : "no";
    table_rows.push_back(r);
}

struct Row {
    std::string map, op;
    double ours_ns, octo_ns, speedup;
    std::string note;
};


static bool load_occ(const std::string &p, const OcTree &t, occ_map_t *map, void **arena, std::string *how)
{
    char msg[256] = "";
    if (occ_file_load_alloc(p.c_str(), nullptr, map, 1u << 20, arena, nullptr, msg, sizeof msg) == OCC_OK) {
        *how = "occ_file_load";
        return true;
    }
    occ_map_config_t cfg = occ_map_config_default();
    cfg.resolution_m = (float)t.getResolution();
    const size_t bytes = OCC_ARENA_BYTES(t.size(), t.size());
    *arena = malloc(bytes);
    if (*arena == nullptr || occ_map_init(map, &cfg, *arena, bytes) != OCC_OK) return false;
    for (auto it = t.begin_leafs(), end = t.end_leafs(); it != end; ++it) {
        const OcTreeKey k = it.getKey();
        occ_key_t key = {{k[0], k[1], k[2]}};
        if (occ_map_set_key(map, key, 16u - it.getDepth(), it->getLogOdds()) != OCC_OK) return false;
    }
    *how = std::string("copied leaf by leaf (occ_file_load: ") + msg + ")";
    return true;
}

// OctoMap's way for "is the sphere safe" with unknown unsafe: every voxel key in the sphere's box
// whose voxel touches the sphere is searched; a missing node (unknown) or an occupied one blocks.
static bool octo_sphere_search(const OcTree &t, const point3d &c, double r)
{
    const double res = t.getResolution();
    OcTreeKey lo, hi;
    if (!t.coordToKeyChecked(c - point3d((float)r, (float)r, (float)r), lo) ||
        !t.coordToKeyChecked(c + point3d((float)r, (float)r, (float)r), hi))
        return false;
    for (unsigned x = lo[0]; x <= hi[0]; x++)
        for (unsigned y = lo[1]; y <= hi[1]; y++)
            for (unsigned z = lo[2]; z <= hi[2]; z++) {
                const OcTreeKey k((octomap::key_type)x, (octomap::key_type)y, (octomap::key_type)z);
                const point3d p = t.keyToCoord(k);
                double d2 = 0;
                for (int i = 0; i < 3; i++) {
                    const double d = std::max(0.0, std::fabs((double)p(i) - (double)c(i)) - res / 2);
                    d2 += d * d;
                }
                if (d2 > r * r) continue;
                const octomap::OcTreeNode *n = t.search(k);
                if (n == nullptr || t.isNodeOccupied(n)) return false;
            }
    return true;
}

// OctoMap's way with the leaf iterator over the box (occupied only: OctoMap has no unknown).
static bool octo_sphere_leafs(const OcTree &t, const point3d &c, double r)
{
    const point3d rr((float)r, (float)r, (float)r);
    for (auto it = t.begin_leafs_bbx(c - rr, c + rr), end = t.end_leafs_bbx(); it != end; ++it) {
        if (!t.isNodeOccupied(*it)) continue;
        const double h = it.getSize() / 2;
        const point3d p = it.getCoordinate();
        double d2 = 0;
        for (int i = 0; i < 3; i++) {
            const double d = std::max(0.0, std::fabs((double)p(i) - (double)c(i)) - h);
            d2 += d * d;
        }
        if (d2 <= r * r) return false;
    }
    return true;
}

static occ_vec3_t v3(const point3d &p) { return occ_vec3_t{p.x(), p.y(), p.z()}; }

static void bench_map(const std::string &path, bool quick, std::vector<Row> &rows, FILE *log)
{
    OcTree *t = bench_load_octo(path);
    if (t == nullptr) {
        fprintf(log, "skip %s: OctoMap cannot read it\n", path.c_str());
        return;
    }
    occ_map_t map;
    void *arena = nullptr;
    std::string how;
    if (!load_occ(path, *t, &map, &arena, &how)) {
        fprintf(log, "skip %s: occmap cannot load it\n", path.c_str());
        delete t;
        free(arena);
        return;
    }
    const std::string name = path.substr(path.find_last_of('/') + 1);
    const std::string tmap = table_map(name);
    double x0, y0, z0, x1, y1, z1;
    t->getMetricMin(x0, y0, z0);
    t->getMetricMax(x1, y1, z1);
    fprintf(log, "%s: res %.3f m, %zu leaves, bbox %.1f x %.1f x %.1f m; occmap %s\n", name.c_str(),
            t->getResolution(), t->getNumLeafNodes(), x1 - x0, y1 - y0, z1 - z0, how.c_str());
    std::mt19937_64 rng(42);
    std::uniform_real_distribution<double> ux(x0, x1), uy(y0, y1), uz(z0, z1), u01(0, 1);
    auto rand_point = [&]() { return point3d((float)ux(rng), (float)uy(rng), (float)uz(rng)); };
    auto free_point = [&]() {
        for (;;) {
            const point3d p = rand_point();
            const octomap::OcTreeNode *n = t->search(p);
            if (n != nullptr && !t->isNodeOccupied(n)) return p;
        }
    };
    auto rand_dir = [&]() {
        for (;;) {
            const point3d d((float)(2 * u01(rng) - 1), (float)(2 * u01(rng) - 1), (float)(2 * u01(rng) - 1));
            if (d.norm() > 0.1 && d.norm() <= 1) return d;
        }
    };
    const size_t N = quick ? 2000 : 10000;

    // 1. point lookup
    {
        std::vector<point3d> pts(N * 10);
        for (auto &p : pts) p = rand_point();
        size_t same = 0;
        for (auto &p : pts) {
            const octomap::OcTreeNode *n = t->search(p);
            const occ_state_t s = occ_map_state_at(&map, v3(p));
            same += (n == nullptr ? s == OCC_STATE_UNKNOWN
                                  : (t->isNodeOccupied(n) ? s == OCC_STATE_OCCUPIED : s == OCC_STATE_FREE));
        }
        const Paired pl = paired(
            pts.size(), [&](size_t i) { sink += (size_t)occ_map_state_at(&map, v3(pts[i])); }, pts.size(),
            [&](size_t i) {
                const octomap::OcTreeNode *n = t->search(pts[i]);
                sink += n == nullptr ? 0u : (t->isNodeOccupied(n) ? 2u : 1u);
            });
        rows.push_back({name, "point lookup random (occ_map_state_at vs search)", pl.a_ns, pl.b_ns, pl.ratio,
                        std::to_string(same) + "/" + std::to_string(pts.size()) + " same state"});
        if (!tmap.empty())
            table_row("query/lookup_random/" + tmap + "/root",
                      "random point lookup, " + name + ": occ_map_state_at vs search()", pl,
                      "occmap <= 50 ns, ratio >= 4", 50.0, 4.0, same == pts.size());
        // Along trajectories (5 cm steps from free starts), as a vehicle queries: path cache.
        std::vector<point3d> traj(N * 10);
        for (size_t i = 0; i < traj.size(); i++) {
            if (i % 200 == 0) {
                traj[i] = free_point();
            } else {
                point3d q = traj[i - 1] + rand_dir().normalized() * 0.05f;
                q.x() = std::min(std::max(q.x(), (float)x0), (float)x1);
                q.y() = std::min(std::max(q.y(), (float)y0), (float)y1);
                q.z() = std::min(std::max(q.z(), (float)z0), (float)z1);
                traj[i] = q;
            }
        }
        occ_lookup_t lk;
        occ_lookup_init(&lk, &map);
        size_t same_t = 0, same_octo = 0;
        for (auto &p : traj) {
            const occ_state_t s = occ_lookup_state(&lk, v3(p));
            const octomap::OcTreeNode *n = t->search(p);
            same_t += s == occ_map_state_at(&map, v3(p));
            same_octo += (n == nullptr ? s == OCC_STATE_UNKNOWN
                                       : (t->isNodeOccupied(n) ? s == OCC_STATE_OCCUPIED : s == OCC_STATE_FREE));
        }
        const auto octo_traj = [&](size_t i) {
            const octomap::OcTreeNode *n = t->search(traj[i]);
            sink += n == nullptr ? 0u : (t->isNodeOccupied(n) ? 2u : 1u);
        };
        const Paired pt = paired(
            traj.size(), [&](size_t i) { sink += (size_t)occ_lookup_state(&lk, v3(traj[i])); }, traj.size(),
            octo_traj);
        const Paired pt2 = paired(
            traj.size(), [&](size_t i) { sink += (size_t)occ_map_state_at(&map, v3(traj[i])); }, traj.size(),
            octo_traj);
        rows.push_back({name, "point lookup trajectory 5 cm (occ_lookup_state vs search)", pt.a_ns, pt.b_ns, pt.ratio,
                        std::to_string(same_t) + "/" + std::to_string(traj.size()) + " same as occ_map_state_at"});
        if (tmap == "geb079")
            table_row("query/lookup_trajectory",
                      "trajectory lookup (5 cm steps), geb079.bt: occ_lookup_state cursor vs search()", pt,
                      "occmap < 20 ns", 20.0, -1.0, same_t == traj.size() && same_octo == traj.size());
        rows.push_back({name, "point lookup trajectory 5 cm (occ_map_state_at vs search)", pt2.a_ns, pt2.b_ns,
                        pt2.ratio, ""});
    }
    // 2. sphere r = 0.25 m at poses whose centre is free
    {
        std::vector<point3d> c(N);
        for (auto &p : c) p = free_point();
        size_t agree = 0, unsafe = 0;
        for (auto &p : c) {
            occ_collision_t col;
            occ_collide_sphere(&map, v3(p), 0.25f, OCC_UNKNOWN_UNSAFE, &col);
            agree += col.safe == octo_sphere_search(*t, p, 0.25);
            unsafe += !col.safe;
        }
        const auto ours_unsafe = [&](size_t i) {
            occ_collision_t col;
            occ_collide_sphere(&map, v3(c[i]), 0.25f, OCC_UNKNOWN_UNSAFE, &col);
            sink += col.safe;
        };
        const auto octo_leafs = [&](size_t i) {
            sink += octo_sphere_leafs(*t, c[i], 0.25);
        };
        const Paired sl = paired(N, ours_unsafe, N, octo_leafs);
        const Paired ss = paired(N, ours_unsafe, N / 10, [&](size_t i) { sink += octo_sphere_search(*t, c[i], 0.25); });
        const Paired so = paired(
            N,
            [&](size_t i) {
                occ_collision_t col;
                occ_collide_sphere(&map, v3(c[i]), 0.25f, OCC_UNKNOWN_SAFE, &col);
                sink += col.safe;
            },
            N, octo_leafs);
        rows.push_back({name, "sphere r=0.25 unknown-unsafe vs octomap leaf_bbx", sl.a_ns, sl.b_ns, sl.ratio,
                        std::to_string(unsafe) + "/" + std::to_string(N) + " unsafe"});
        rows.push_back({name, "sphere r=0.25 unknown-unsafe vs octomap search/voxel", ss.a_ns, ss.b_ns, ss.ratio,
                        std::to_string(agree) + "/" + std::to_string(N) + " same answer"});
        if (tmap == "geb079")
            table_row("query/sphere_0.25",
                      "sphere r=0.25 m, unknown unsafe, geb079.bt: occ_collide_sphere vs search() per voxel "
                      "(the same answer)",
                      ss, "none set", -1.0, -1.0, agree == N);
        rows.push_back({name, "sphere r=0.25 occupied-only vs octomap leaf_bbx", so.a_ns, so.b_ns, so.ratio, ""});
        // The same 200 poses over and over (checks around a hovering vehicle): each side's map
        // stays in cache, so this is the compute alone; the rows above include the misses after
        // the other side's batch has evicted it.
        const size_t H = 200;
        const Paired sh = paired(
            N, [&](size_t i) { ours_unsafe(i % H); }, N, [&](size_t i) { octo_leafs(i % H); });
        rows.push_back({name, "sphere r=0.25 unknown-unsafe, 200 poses repeated (hot caches)", sh.a_ns, sh.b_ns,
                        sh.ratio, ""});
    }
    // 3. ray cast, 10 m, ignore unknown (OctoMap castRay)
    {
        std::vector<point3d> o(N), d(N);
        for (size_t i = 0; i < N; i++) {
            o[i] = free_point();
            d[i] = rand_dir();
        }
        size_t same = 0, hits = 0;
        for (size_t i = 0; i < N; i++) {
            point3d end;
            const bool h = t->castRay(o[i], d[i], end, true, 10.0);
            occ_ray_result_t r;
            occ_cast_ray(&map, v3(o[i]), v3(d[i]), true, 10.0f, &r);
            same += r.hit == h && std::fabs(r.end.x - end.x()) < 1e-4f && std::fabs(r.end.y - end.y()) < 1e-4f &&
                    std::fabs(r.end.z - end.z()) < 1e-4f;
            hits += h;
        }
        // ignoreUnknown, then stopping at unknown (OctoMap's default)
        const auto cast_pair = [&](bool ignore) {
            return paired(
                N,
                [&, ignore](size_t i) {
                    occ_ray_result_t r;
                    occ_cast_ray(&map, v3(o[i]), v3(d[i]), ignore, 10.0f, &r);
                    sink += r.hit;
                },
                N,
                [&, ignore](size_t i) {
                    point3d end;
                    sink += t->castRay(o[i], d[i], end, ignore, 10.0);
                });
        };
        const Paired ri = cast_pair(true);
        rows.push_back({name, "castRay 10 m ignoreUnknown", ri.a_ns, ri.b_ns, ri.ratio,
                        std::to_string(same) + "/" + std::to_string(N) + " identical, " + std::to_string(hits) + " hits"});
        if (tmap == "geb079")
            table_row("query/raycast_10m", "10 m ray cast, ignore unknown, geb079.bt: occ_cast_ray vs castRay()",
                      ri, "none set", -1.0, -1.0, same == N);
        const Paired ru = cast_pair(false);
        rows.push_back({name, "castRay 10 m stop at unknown", ru.a_ns, ru.b_ns, ru.ratio, ""});
    }
    // 4. line of sight between two free points (lengths uniform 1..10.8 m, mean 5.9 m)
    {
        std::vector<point3d> a(N), b(N);
        double sum_len = 0;
        for (size_t i = 0; i < N; i++) {
            // Length first (uniform 1..10.8 m, mean 5.9 m), then a free pair at that length.
            bool ok = false;
            while (!ok) {
                const double len = 1.0 + 9.8 * u01(rng);
                for (int tries = 0; tries < 200 && !ok; tries++) {
                    a[i] = free_point();
                    b[i] = a[i] + rand_dir().normalized() * (float)len;
                    if (b[i].x() < x0 || b[i].x() > x1 || b[i].y() < y0 || b[i].y() > y1 || b[i].z() < z0 ||
                        b[i].z() > z1)
                        continue;
                    const octomap::OcTreeNode *n = t->search(b[i]);
                    ok = n != nullptr && !t->isNodeOccupied(n);
                }
            }
            sum_len += (b[i] - a[i]).norm();
        }
        size_t vis = 0, agree = 0;
        for (size_t i = 0; i < N; i++) {
            bool v = false;
            occ_line_of_sight(&map, v3(a[i]), v3(b[i]), OCC_UNKNOWN_SAFE, &v, nullptr);
            point3d end;
            const bool hit = t->castRay(a[i], b[i] - a[i], end, true, (b[i] - a[i]).norm());
            vis += v;
            agree += v == !hit;
        }
        const Paired pv = paired(
            N,
            [&](size_t i) {
                bool v = false;
                occ_line_of_sight(&map, v3(a[i]), v3(b[i]), OCC_UNKNOWN_SAFE, &v, nullptr);
                sink += v;
            },
            N,
            [&](size_t i) {
                point3d end;
                sink += t->castRay(a[i], b[i] - a[i], end, true, (b[i] - a[i]).norm());
            });
        char note[128];
        snprintf(note, sizeof note, "mean %.1f m, %zu visible, %zu/%zu agree with castRay", sum_len / (double)N, vis,
                 agree, N);
        rows.push_back({name, "line of sight (vs castRay to b)", pv.a_ns, pv.b_ns, pv.ratio, note});
        // 10 m segment, unknown unsafe: occmap segment volume vs OctoMap computeRayKeys + search
        std::vector<point3d> s0(N), s1(N);
        for (size_t i = 0; i < N; i++) {
            s0[i] = free_point();
            s1[i] = s0[i] + rand_dir().normalized() * 10.0f;
        }
        octomap::KeyRay kr;
        const Paired pg = paired(
            N,
            [&](size_t i) {
                occ_collision_t col;
                occ_volume_t vol;
                occ_volume_segment(&vol, v3(s0[i]), v3(s1[i]));
                occ_collide_volume(&map, &vol, OCC_UNKNOWN_UNSAFE, &col);
                sink += col.safe;
            },
            N,
            [&](size_t i) {
                bool ok = t->computeRayKeys(s0[i], s1[i], kr);
                for (auto it = kr.begin(); ok && it != kr.end(); ++it) {
                    const octomap::OcTreeNode *n = t->search(*it);
                    ok = n != nullptr && !t->isNodeOccupied(n);
                }
                sink += ok;
            });
        rows.push_back({name, "10 m segment unknown-unsafe (vs computeRayKeys+search)", pg.a_ns, pg.b_ns, pg.ratio, ""});
    }
    // 5. frustum information gain (115 x 60 deg, 0..6.5 m), unknown voxels
    {
        const int poses = quick ? 1 : 3;
        std::vector<point3d> o(poses);
        std::vector<double> yaw(poses);
        for (int i = 0; i < poses; i++) {
            o[i] = free_point();
            yaw[i] = 6.283 * u01(rng);
        }
        const double hf = 115.0 * M_PI / 180, vf = 60.0 * M_PI / 180, far_m = 6.5;
        std::vector<uint64_t> ours(poses), theirs(poses);
        const Paired pf = paired((size_t)poses, [&](size_t i) {
            const occ_vec3_t ax[3] = {{(float)std::cos(yaw[i]), (float)std::sin(yaw[i]), 0},
                                      {-(float)std::sin(yaw[i]), (float)std::cos(yaw[i]), 0}, {0, 0, 1}};
            occ_volume_t v;
            occ_volume_frustum(&v, v3(o[i]), ax, (float)hf, (float)vf, 0.0f, (float)far_m);
            occ_info_gain_t g;
            occ_info_gain(&map, &v, 0, 0, &g);
            ours[i] = g.unknown_cells;
        }, (size_t)poses,
        // OctoMap: every voxel of the frustum's box whose centre is inside, search() -> unknown.
        [&](size_t i) {
            const double res = t->getResolution();
            const double c = std::cos(yaw[i]), s = std::sin(yaw[i]);
            const double th = std::tan(hf / 2), tv = std::tan(vf / 2);
            uint64_t cnt = 0;
            const double R = far_m / std::cos(hf / 2) / std::cos(vf / 2);
            for (double x = o[i].x() - R; x <= o[i].x() + R; x += res)
                for (double y = o[i].y() - R; y <= o[i].y() + R; y += res)
                    for (double z = o[i].z() - far_m * tv; z <= o[i].z() + far_m * tv; z += res) {
                        OcTreeKey k;
                        if (!t->coordToKeyChecked(point3d((float)x, (float)y, (float)z), k)) continue;
                        const point3d p = t->keyToCoord(k);
                        const double dx = p.x() - o[i].x(), dy = p.y() - o[i].y(), dz = p.z() - o[i].z();
                        const double f = c * dx + s * dy, l = -s * dx + c * dy;
                        if (f <= 0 || f > far_m || std::fabs(l) > f * th || std::fabs(dz) > f * tv) continue;
                        if (t->search(k) == nullptr) cnt++;
                    }
            theirs[i] = cnt;
        }, poses);
        char note[160];
        snprintf(note, sizeof note, "unknown voxels pose 0: occmap %llu (touching), octomap %llu (centre inside)",
                 (unsigned long long)ours[0], (unsigned long long)theirs[0]);
        rows.push_back({name, "frustum info gain 115x60 deg 6.5 m", pf.a_ns, pf.b_ns, pf.ratio, note});
    }
    delete t;
    free(arena);
}

// Issue 5's targets, judged on geb079.bt as the issue sets them. The ratios come from this run.
// The 30 ns lookup is an absolute figure set on a machine where OctoMap's search took 250-350 ns,
// so it is also given at that machine's speed: our time scaled by (250..350) / OctoMap's search
// time in this run (random points, the same tree).
struct Target {
    std::string what, measured;
    bool met;
};
static const Row *find_row(const std::vector<Row> &rows, const std::string &map, const std::string &op)
{
    for (auto &r : rows)
        if (r.map == map && r.op == op) return &r;
    return nullptr;
}
static std::vector<Target> targets(const std::vector<Row> &rows)
{
    const std::string m = "geb079.bt";
    std::vector<Target> out;
    char buf[256];
    const auto ratio = [&](const char *what, const char *op, double want) {
        const Row *r = find_row(rows, m, op);
        if (r == nullptr) return;
        snprintf(buf, sizeof buf, "%.1fx (%s)", r->speedup, op);
        out.push_back({what, buf, r->speedup >= want});
    };
    // Three readings of "the OctoMap way": the one that gives the same answer (search per voxel:
    // OctoMap's leaf iterator never visits unknown space), leaf_bbx on the question it can answer
    // (occupied only), and leaf_bbx against our unknown-unsafe check (more work on our side).
    ratio("sphere r=0.25 unknown-unsafe >= 8x, same answer", "sphere r=0.25 unknown-unsafe vs octomap search/voxel", 8.0);
    ratio("sphere r=0.25 >= 8x vs leaf_bbx, same question", "sphere r=0.25 occupied-only vs octomap leaf_bbx", 8.0);
    ratio("sphere r=0.25 unknown-unsafe >= 8x vs leaf_bbx", "sphere r=0.25 unknown-unsafe vs octomap leaf_bbx", 8.0);
    ratio("ray cast >= 5x", "castRay 10 m ignoreUnknown", 5.0);
    ratio("line of sight >= 5x", "line of sight (vs castRay to b)", 5.0);
    const Row *rnd = find_row(rows, m, "point lookup random (occ_map_state_at vs search)");
    const Row *trj = find_row(rows, m, "point lookup trajectory 5 cm (occ_lookup_state vs search)");
    if (rnd != nullptr && trj != nullptr) {
        snprintf(buf, sizeof buf, "%.1f ns here (trajectory, path cache)", trj->ours_ns);
        out.push_back({"point lookup <= 30 ns, absolute", buf, trj->ours_ns <= 30.0});
        const double lo = trj->ours_ns * 250.0 / rnd->octo_ns, hi = trj->ours_ns * 350.0 / rnd->octo_ns;
        snprintf(buf, sizeof buf, "%.1f-%.1f ns (OctoMap search here %.0f ns, there 250-350 ns)", lo, hi, rnd->octo_ns);
        out.push_back({"point lookup <= 30 ns, at the reference machine's speed", buf, hi <= 30.0});
    }
    return out;
}

int main(int argc, char **argv)
{
    bool quick = false;
    std::string json = "build/bench/query.json";
    std::string rows_json = "build/bench/rows/query.json";
    std::vector<std::string> maps;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--quick")) quick = true;
        else if (!strcmp(argv[i], "--json") && i + 1 < argc) json = argv[++i];
        else if (!strcmp(argv[i], "--rows") && i + 1 < argc) rows_json = argv[++i];
        else maps.push_back(argv[i]);
    }
    if (maps.empty()) maps.push_back("/usr/share/doc/liboctomap-dev/examples/data/geb079.bt");
    std::vector<Row> rows;
    for (auto &m : maps) bench_map(m, quick, rows, stdout);
    printf("\n%-22s %-56s %12s %12s %8s  %s\n", "map", "operation", "occmap ns", "octomap ns", "speedup", "check");
    for (auto &r : rows) {
        printf("%-22s %-56s %12.1f %12.1f %7.1fx  %s\n", r.map.c_str(), r.op.c_str(), r.ours_ns, r.octo_ns,
               r.speedup, r.note.c_str());
    }
    const std::vector<Target> tg = targets(rows);
    if (!tg.empty()) printf("\ntargets (issue 5, geb079.bt)\n");
    for (auto &x : tg) printf("  %-58s %-5s %s\n", x.what.c_str(), x.met ? "met" : "MISS", x.measured.c_str());
    FILE *f = fopen(json.c_str(), "w");
    if (f == nullptr) {
        perror(json.c_str());
        return 1;
    }
    fprintf(f, "{\"bench\": \"query\", \"unit\": \"ns per operation (median of batches)\", \"rows\": [\n");
    for (size_t i = 0; i < rows.size(); i++) {
        const Row &r = rows[i];
        fprintf(f, "  {\"map\": \"%s\", \"op\": \"%s\", \"occmap_ns\": %.1f, \"octomap_ns\": %.1f, \"speedup\": %.2f, \"check\": \"%s\"}%s\n",
                r.map.c_str(), r.op.c_str(), r.ours_ns, r.octo_ns, r.speedup, r.note.c_str(),
                i + 1 < rows.size() ? "," : "");
    }
    fprintf(f, "], \"targets\": [\n");
    for (size_t i = 0; i < tg.size(); i++) {
        fprintf(f, "  {\"target\": \"%s\", \"met\": %s, \"measured\": \"%s\"}%s\n", tg[i].what.c_str(),
                tg[i].met ? "true" : "false", tg[i].measured.c_str(), i + 1 < tg.size() ? "," : "");
    }
    fprintf(f, "]}\n");
    fclose(f);
    printf("wrote %s\n", json.c_str());
    if (!bench_rows_write(rows_json, table_rows)) {
        perror(rows_json.c_str());
        return 1;
    }
    printf("wrote %zu table rows to %s\n", table_rows.size(), rows_json.c_str());
    return 0;
}
