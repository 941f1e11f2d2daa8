// SPDX-License-Identifier: BSD-3-Clause
// ab_split.cpp - the library built from AB_BASE (its symbols renamed old_*, bench/ab_split.mk)
// against this tree's, in one process, on the same inputs, in interleaved rounds (the order
// flips every round, so drift and cache warmth hit both alike):
//   inserts:    occ_map_insert_cloud(SIMPLE, DISCRETE, SUPER_RAYS) of scan.dat into a fresh map,
//               0.1 and 0.05 m, and of the 10 TUM pioneer frames at 0.05 m (SIMPLE, DISCRETE);
//               both sides' maps must be equal node for node (a walk digest);
//   proj:       occ_map_insert_depth(OCC_INSERT_PROJECTIVE) of the same 10 TUM frames as images
//               (every pixel, max range 100 m as bench/projective) at 0.05 m, maps compared alike;
//   castRay:    occ_cast_ray 10 m from random free points of geb079.bt (ignore / stop at unknown);
//   los:        occ_line_of_sight between free points 1..10.8 m apart on geb079.bt;
//   collide:    occ_collide_sphere (r 0.25 m), _capsule (1 m, r 0.3 m) and _obb (0.6 x 0.4 x
//               0.2 m, random yaw) at the same free points, unknown unsafe;
//   info gain:  occ_info_gain of a 115 x 60 deg, 6.5 m frustum (level 0) from free points;
//   lookups:    the level-0 lookup index (occ_lookup_index_state) on geb079.bt and, with
//               --fr079 PATH, fr_079: 200k random points in the map's box with warm caches
//               (a pass over the same points first) and cold (before each 1,000 points, 8 MiB
//               streamed through the caches, untimed), and 200k points of 5 cm trajectory
//               steps; each side its own index, both equal to occ_map_state_at everywhere.
// Prints, per case, each side's median and range (min..max) over the rounds and the median and
// quartiles of the per-round ratio new / old (< 1: the new code is faster). Both sides must give
// the same answers (checked on every input first).
// usage: ab_split [--rounds N] [--queries-only | --inserts-only | --lookup-only] [--case SUBSTR]
//                 [--tum DIR] [--fr079 PATH] SCAN.dat MAP.bt
// (--case runs only the insert cases whose name contains SUBSTR; --inserts-only under callgrind
// with --toggle-collect=occ_map_insert_cloud profiles this tree's side alone; the proj case:
// --case proj --toggle-collect=occ_map_insert_depth.)
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <random>
#include <vector>

extern "C" {
#include "occmap/occmap.h"
#include "occmap/occ_depth.h"
#include "occmap/occ_pose.h"
#include "occmap/host/occ_file.h"
#include "occmap/host/occ_scan.h"
}

extern "C" decltype(occ_map_init) old_occ_map_init;
extern "C" decltype(occ_map_insert_cloud) old_occ_map_insert_cloud;
extern "C" decltype(occ_map_insert_depth) old_occ_map_insert_depth;
extern "C" decltype(occ_walk_begin) old_occ_walk_begin;
extern "C" decltype(occ_walk_next) old_occ_walk_next;
extern "C" decltype(occ_cast_ray) old_occ_cast_ray;
extern "C" decltype(occ_line_of_sight) old_occ_line_of_sight;
extern "C" decltype(occ_collide_sphere) old_occ_collide_sphere;
extern "C" decltype(occ_collide_capsule) old_occ_collide_capsule;
extern "C" decltype(occ_collide_obb) old_occ_collide_obb;
extern "C" decltype(occ_info_gain) old_occ_info_gain;
extern "C" decltype(occ_lookup_index_need) old_occ_lookup_index_need;
extern "C" decltype(occ_lookup_index_build) old_occ_lookup_index_build;
extern "C" decltype(occ_lookup_index_state) old_occ_lookup_index_state;

static double cpu_ms()
{
    timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return (double)t.tv_sec * 1e3 + (double)t.tv_nsec / 1e6;
}

static double quantile(std::vector<double> v, double q)
{
    std::sort(v.begin(), v.end());
    return v[(size_t)(q * (double)(v.size() - 1) + 0.5)];
}

// Rounds of (old, new) or (new, old), alternating; fa / fb return their CPU ms.
template <class FA, class FB>
static void ab(const char *name, int rounds, const FA &fa, const FB &fb)
{
    std::vector<double> ta, tb, r;
    for (int i = 0; i < rounds; i++) {
        double a, b;
        if (i % 2 == 0) {
            a = fa();
            b = fb();
        } else {
            b = fb();
            a = fa();
        }
        ta.push_back(a);
        tb.push_back(b);
        r.push_back(b / a);
    }
    std::printf("%-34s old %8.3f ms [%8.3f..%8.3f]  new %8.3f ms [%8.3f..%8.3f]  new/old %.3f "
                "(q1 %.3f, q3 %.3f)\n",
                name, quantile(ta, 0.5), quantile(ta, 0), quantile(ta, 1), quantile(tb, 0.5),
                quantile(tb, 0), quantile(tb, 1), quantile(r, 0.5), quantile(r, 0.25),
                quantile(r, 0.75));
    std::fflush(stdout);
}

static std::vector<uint8_t> arena((size_t)768 << 20), scratch;

// One side of the library: its init, insert and walk (for the digest).
struct Lib {
    decltype(occ_map_init) *init;
    decltype(occ_map_insert_cloud) *insert;
    decltype(occ_walk_begin) *walk_begin;
    decltype(occ_walk_next) *walk_next;
    decltype(occ_map_insert_depth) *insert_depth;
};
static const Lib lib_old = {old_occ_map_init, old_occ_map_insert_cloud, old_occ_walk_begin,
                            old_occ_walk_next, old_occ_map_insert_depth};
static const Lib lib_new = {occ_map_init, occ_map_insert_cloud, occ_walk_begin, occ_walk_next,
                            occ_map_insert_depth};

struct Scan {
    std::vector<occ_vec3_t> pts;
    occ_vec3_t origin;
};

// FNV-1a over every observed node the walk reports (key, level, value, children).
static uint64_t map_digest(const Lib &l, const occ_map_t &m)
{
    uint64_t h = 1469598103934665603ull;
    const auto mix = [&h](uint64_t v) {
        for (int i = 0; i < 8; i++, v >>= 8) h = (h ^ (v & 0xFFu)) * 1099511628211ull;
    };
    occ_walk_t w;
    occ_walk_node_t n;
    l.walk_begin(&w, &m);
    while (l.walk_next(&w, &n)) {
        mix(((uint64_t)n.key.k[0] << 42) ^ ((uint64_t)n.key.k[1] << 21) ^ n.key.k[2]);
        mix(((uint64_t)n.level << 1) | (n.has_children ? 1u : 0u));
        mix((uint64_t)(uint16_t)n.value);
    }
    return h;
}

// All scans into a fresh map: CPU ms of the insert calls; *digest of the map when non-NULL.
static double insert_once(const Lib &l, const std::vector<Scan> &scans, float res,
                          occ_insert_method_t meth, occ_insert_result_t *out, uint64_t *digest)
{
    occ_map_config_t cfg = occ_map_config_default();
    cfg.resolution_m = res;
    occ_map_t m;
    if (l.init(&m, &cfg, arena.data(), arena.size()) != OCC_OK) std::abort();
    occ_insert_params_t p = occ_insert_params_default();
    p.method = meth;
    double t = 0;
    for (const Scan &s : scans) {
        const double t0 = cpu_ms();
        const occ_err_t e = l.insert(&m, &s.origin, s.pts.data(), s.pts.size(), &p,
                                     scratch.data(), scratch.size(), out);
        t += cpu_ms() - t0;
        if (e != OCC_OK) {
            std::fprintf(stderr, "ab_split: insert: %s\n", occ_err_str(e));
            std::exit(1);
        }
    }
    if (digest != nullptr) *digest = map_digest(l, m);
    return t;
}

static const char *meth_name(occ_insert_method_t m)
{
    return m == OCC_INSERT_SIMPLE ? "simple" : m == OCC_INSERT_DISCRETE ? "discrete" : "super rays";
}

static void bench_insert(const char *data, const std::vector<Scan> &scans, float res,
                         occ_insert_method_t meth, int rounds, const char *filter)
{
    char name[64];
    std::snprintf(name, sizeof name, "%s %s %.2f m", meth_name(meth), data, res);
    if (filter != nullptr && std::strstr(name, filter) == nullptr) return;
    occ_map_config_t cfg = occ_map_config_default();
    cfg.resolution_m = res;
    occ_map_t tmp;
    static uint8_t small[OCC_ARENA_BYTES(2, 2)];
    occ_map_init(&tmp, &cfg, small, sizeof small);
    occ_insert_params_t p = occ_insert_params_default();
    p.method = meth;
    size_t need = 0;
    for (const Scan &s : scans)
        need = std::max(need, occ_insert_scratch_bytes_scan(&tmp, &s.origin, s.pts.data(),
                                                            s.pts.size(), &p));
    scratch.assign(need, 0);
    occ_insert_result_t ro, rn;
    uint64_t dold = 0, dnew = 0;
    insert_once(lib_old, scans, res, meth, &ro, &dold);
    insert_once(lib_new, scans, res, meth, &rn, &dnew);
    ro.scratch_used = rn.scratch_used = 0; /* a layout change may use other scratch */
    if (std::memcmp(&ro, &rn, sizeof ro) != 0 || dold != dnew) {
        std::fprintf(stderr, "ab_split: %s: old and new results differ (visits %zu / %zu, updated %zu / %zu, changed %zu / %zu, digest %s)\n",
                     name, (size_t)ro.voxel_visits, (size_t)rn.voxel_visits, (size_t)ro.voxels_updated,
                     (size_t)rn.voxels_updated, (size_t)ro.voxels_changed, (size_t)rn.voxels_changed,
                     dold == dnew ? "equal" : "differs");
        std::exit(1);
    }
    std::printf("%s: last scan %zu rays, %zu voxel visits, %zu voxels updated\n", name,
                (size_t)rn.rays_cast, (size_t)rn.voxel_visits, (size_t)rn.voxels_updated);
    ab(name, rounds, [&] { return insert_once(lib_old, scans, res, meth, &ro, nullptr); },
       [&] { return insert_once(lib_new, scans, res, meth, &rn, nullptr); });
}

static void bench_inserts(const std::vector<occ_vec3_t> &pts, const std::vector<Scan> &tum,
                          int rounds, const char *filter)
{
    const std::vector<Scan> scan = {Scan{pts, {0, 0, 0}}};
    const occ_insert_method_t ms[] = {OCC_INSERT_SIMPLE, OCC_INSERT_DISCRETE,
                                      OCC_INSERT_SUPER_RAYS};
    for (const float res : {0.1f, 0.05f})
        for (const occ_insert_method_t m : ms) bench_insert("scan.dat", scan, res, m, rounds, filter);
    if (!tum.empty())
        for (const occ_insert_method_t m : {OCC_INSERT_SIMPLE, OCC_INSERT_DISCRETE})
            bench_insert("tum10", tum, 0.05f, m, rounds, filter);
}

// One TUM frame as the camera gave it (the proj case).
struct DepthFrame {
    std::vector<uint16_t> pix;
    uint32_t w = 0, h = 0;
    occ_pose_t pose;
};

// bench/projective's: TUM freiburg2 intrinsics, every pixel, max range 100 m (all hits).
static occ_depth_params_t proj_params()
{
    const occ_depth_camera_t c = occ_depth_camera_tum_fr2();
    return occ_depth_params_t{{c.fx, c.fy, c.cx, c.cy}, 0.0f, 100.0f, 1u};
}

static occ_depth_image_t image_of(const DepthFrame &f)
{
    return occ_depth_image_t{f.pix.data(), OCC_DEPTH_U16, f.w, f.h, (size_t)f.w * 2u,
                             1.0f / 5000.0f};
}

// All frames into a fresh map by projection: CPU ms of the insert calls; *digest as above.
static double proj_once(const Lib &l, const std::vector<DepthFrame> &fr, occ_insert_result_t *out,
                        uint64_t *digest)
{
    occ_map_config_t cfg = occ_map_config_default();
    cfg.resolution_m = 0.05f;
    occ_map_t m;
    if (l.init(&m, &cfg, arena.data(), arena.size()) != OCC_OK) std::abort();
    occ_insert_params_t p = occ_insert_params_default();
    p.method = OCC_INSERT_PROJECTIVE;
    const occ_depth_params_t dp = proj_params();
    double t = 0;
    for (const DepthFrame &f : fr) {
        const occ_depth_image_t im = image_of(f);
        occ_depth_result_t r;
        const double t0 = cpu_ms();
        const occ_err_t e = l.insert_depth(&m, &im, &dp, &f.pose, &p, scratch.data(),
                                           scratch.size(), &r);
        t += cpu_ms() - t0;
        if (e != OCC_OK) {
            std::fprintf(stderr, "ab_split: insert_depth: %s\n", occ_err_str(e));
            std::exit(1);
        }
        *out = r.insert;
    }
    if (digest != nullptr) *digest = map_digest(l, m);
    return t;
}

static void bench_proj(const std::vector<DepthFrame> &fr, int rounds, const char *filter)
{
    const char *name = "proj tum10 0.05 m";
    if (fr.empty() || (filter != nullptr && std::strstr(name, filter) == nullptr)) return;
    occ_map_config_t cfg = occ_map_config_default();
    cfg.resolution_m = 0.05f;
    occ_map_t tmp;
    static uint8_t small[OCC_ARENA_BYTES(2, 2)];
    occ_map_init(&tmp, &cfg, small, sizeof small);
    occ_insert_params_t p = occ_insert_params_default();
    p.method = OCC_INSERT_PROJECTIVE;
    scratch.assign(occ_depth_scratch_bytes(&tmp, fr[0].w, fr[0].h, 1u, proj_params().max_range_m, &p),
                   0);
    occ_insert_result_t ro, rn;
    uint64_t dold = 0, dnew = 0;
    proj_once(lib_old, fr, &ro, &dold);
    proj_once(lib_new, fr, &rn, &dnew);
    ro.scratch_used = rn.scratch_used = 0; /* a layout change may use other scratch */
    ro.voxel_visits = rn.voxel_visits = 0; /* nodes tested: a walk change may test others */
    ro.coarse_updated = rn.coarse_updated = 0; /* and decide a free region at another level */
    if (std::memcmp(&ro, &rn, sizeof ro) != 0 || dold != dnew) {
        std::fprintf(stderr, "ab_split: %s: old and new results differ (updated %zu / %zu, changed %zu / %zu, digest %s)\n",
                     name, (size_t)ro.voxels_updated, (size_t)rn.voxels_updated,
                     (size_t)ro.voxels_changed, (size_t)rn.voxels_changed,
                     dold == dnew ? "equal" : "differs");
        std::exit(1);
    }
    std::printf("%s: last frame %zu voxels updated, %zu occupied\n", name,
                (size_t)rn.voxels_updated, (size_t)rn.voxels_occupied);
    ab(name, rounds, [&] { return proj_once(lib_old, fr, &ro, nullptr); },
       [&] { return proj_once(lib_new, fr, &rn, nullptr); });
}

static std::vector<DepthFrame> load_tum_images(const char *dir)
{
    std::vector<DepthFrame> out;
    occ_scan_frame_t *f = nullptr;
    size_t n = 0;
    char msg[256] = "";
    if (occ_depth_read_tum_dir(dir, 1, 10, &f, &n, msg, sizeof msg) != OCC_OK) return out;
    for (size_t i = 0; i < n; i++) {
        DepthFrame fr;
        char path[600];
        std::snprintf(path, sizeof path, "%s/depth/%s", dir, f[i].name);
        uint16_t *pix = nullptr;
        if (occ_depth_read_png_image(path, &pix, &fr.w, &fr.h, msg, sizeof msg) != OCC_OK) {
            std::fprintf(stderr, "ab_split: proj frames skipped: %s\n", msg);
            out.clear();
            break;
        }
        fr.pix.assign(pix, pix + (size_t)fr.w * fr.h);
        std::free(pix);
        fr.pose.p = occ_vec3_t{f[i].pose_t[0], f[i].pose_t[1], f[i].pose_t[2]};
        occ_quat_normalize(occ_quat_t{f[i].pose_q[0], f[i].pose_q[1], f[i].pose_q[2], f[i].pose_q[3]},
                           &fr.pose.q);
        out.push_back(fr);
    }
    occ_scan_frames_free(f, n);
    return out;
}

static std::vector<Scan> load_tum(const char *dir)
{
    std::vector<Scan> out;
    occ_scan_frame_t *f = nullptr;
    size_t n = 0;
    char msg[256] = "";
    if (occ_depth_read_tum_dir(dir, 1, 10, &f, &n, msg, sizeof msg) != OCC_OK) {
        std::fprintf(stderr, "ab_split: TUM frames skipped: %s\n", msg);
        return out;
    }
    for (size_t i = 0; i < n; i++)
        out.push_back(Scan{std::vector<occ_vec3_t>(f[i].points, f[i].points + f[i].n_points),
                           f[i].origin});
    occ_scan_frames_free(f, n);
    return out;
}

struct Box {
    occ_vec3_t lo, hi;
};

static Box map_box(const occ_map_t &m)
{
    Box b = {{1e30f, 1e30f, 1e30f}, {-1e30f, -1e30f, -1e30f}};
    occ_walk_t w;
    occ_walk_node_t n;
    occ_walk_begin(&w, &m);
    while (occ_walk_next(&w, &n)) {
        if (n.has_children || !n.observed) continue;
        const occ_vec3_t c = occ_map_key_center(&m, n.key, n.level);
        const float h = occ_map_node_size(&m, n.level) * 0.5f;
        b.lo = {std::min(b.lo.x, c.x - h), std::min(b.lo.y, c.y - h), std::min(b.lo.z, c.z - h)};
        b.hi = {std::max(b.hi.x, c.x + h), std::max(b.hi.y, c.y + h), std::max(b.hi.z, c.z + h)};
    }
    return b;
}

// CPU ms of f(0..n-1); the results are summed so that the calls cannot be dropped.
template <class F>
static double time_all(size_t n, const F &f)
{
    size_t sum = 0;
    const double t0 = cpu_ms();
    for (size_t i = 0; i < n; i++) sum += f(i) ? 1u : 0u;
    const double t = cpu_ms() - t0;
    if (sum > n) std::abort();
    return t;
}

static bool same_ray(const occ_ray_result_t &a, const occ_ray_result_t &b)
{
    return a.hit == b.hit && a.stop == b.stop && std::memcmp(&a.key, &b.key, sizeof a.key) == 0 &&
           std::memcmp(&a.end, &b.end, sizeof a.end) == 0;
}

static bool same_collision(const occ_collision_t &a, const occ_collision_t &b)
{
    return a.safe == b.safe && a.outside == b.outside &&
           std::memcmp(&a.node.key, &b.node.key, sizeof a.node.key) == 0 &&
           a.node.level == b.node.level && a.node.state == b.node.state;
}

static occ_vec3_t unit(occ_vec3_t d)
{
    const float n = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
    return {d.x / n, d.y / n, d.z / n};
}

// One side's collision checks.
struct CollideFns {
    decltype(occ_collide_sphere) *sphere;
    decltype(occ_collide_capsule) *capsule;
    decltype(occ_collide_obb) *obb;
};

// Case c at point o (the centre; the capsule's first end), direction d (capsule, obb heading).
static occ_err_t collide_one(const CollideFns &f, int c, const occ_map_t *m, occ_vec3_t o,
                             occ_vec3_t d, occ_collision_t *col)
{
    if (c == 0) return f.sphere(m, o, 0.25f, OCC_UNKNOWN_UNSAFE, col);
    if (c == 1) {
        const occ_vec3_t u = unit(d);
        return f.capsule(m, o, {o.x + u.x, o.y + u.y, o.z + u.z}, 0.3f, OCC_UNKNOWN_UNSAFE, col);
    }
    const occ_vec3_t u = unit({d.x, d.y, 0.0f});
    const occ_vec3_t ax[3] = {{u.x, u.y, 0}, {-u.y, u.x, 0}, {0, 0, 1}};
    const float half[3] = {0.3f, 0.2f, 0.1f};
    return f.obb(m, o, half, ax, OCC_UNKNOWN_UNSAFE, col);
}

static void bench_collide(const occ_map_t &m, const std::vector<occ_vec3_t> &o,
                          const std::vector<occ_vec3_t> &d, int rounds)
{
    const CollideFns olds = {old_occ_collide_sphere, old_occ_collide_capsule, old_occ_collide_obb};
    const CollideFns news = {occ_collide_sphere, occ_collide_capsule, occ_collide_obb};
    const char *names[3] = {"collide sphere r 0.25 m (20k)", "collide capsule 1 m r 0.3 m (20k)",
                            "collide obb 0.6x0.4x0.2 m (20k)"};
    for (int c = 0; c < 3; c++) {
        for (size_t i = 0; i < o.size(); i++) {
            occ_collision_t co, cn;
            const occ_err_t eo = collide_one(olds, c, &m, o[i], d[i], &co);
            const occ_err_t en = collide_one(news, c, &m, o[i], d[i], &cn);
            if (eo != en || !same_collision(co, cn)) {
                std::fprintf(stderr, "ab_split: %s %zu differs\n", names[c], i);
                std::exit(1);
            }
        }
        const auto all = [&](const CollideFns &f) {
            return time_all(o.size(), [&](size_t i) {
                occ_collision_t col;
                collide_one(f, c, &m, o[i], d[i], &col);
                return col.safe;
            });
        };
        ab(names[c], rounds, [&] { return all(olds); }, [&] { return all(news); });
    }
}

// Frustum 115 x 60 deg, 0..6.5 m, looking along d (level), from o.
static occ_volume_t gain_frustum(occ_vec3_t o, occ_vec3_t d)
{
    const occ_vec3_t u = unit({d.x, d.y, 0.0f});
    const occ_vec3_t ax[3] = {{u.x, u.y, 0}, {-u.y, u.x, 0}, {0, 0, 1}};
    occ_volume_t v;
    if (occ_volume_frustum(&v, o, ax, 2.007f, 1.047f, 0.0f, 6.5f) != OCC_OK) std::abort();
    return v;
}

static void bench_info_gain(const occ_map_t &m, const std::vector<occ_vec3_t> &o,
                            const std::vector<occ_vec3_t> &d, int rounds)
{
    const size_t n = 10;
    for (size_t i = 0; i < n; i++) {
        const occ_volume_t v = gain_frustum(o[i], d[i]);
        occ_info_gain_t go, gn;
        const occ_err_t eo = old_occ_info_gain(&m, &v, 0, 0, &go);
        const occ_err_t en = occ_info_gain(&m, &v, 0, 0, &gn);
        if (eo != en || go.unknown_cells != gn.unknown_cells || go.entropy_bits != gn.entropy_bits) {
            std::fprintf(stderr, "ab_split: info gain %zu differs\n", i);
            std::exit(1);
        }
    }
    const auto all = [&](decltype(occ_info_gain) *gain) {
        return time_all(n, [&](size_t i) {
            const occ_volume_t v = gain_frustum(o[i], d[i]);
            occ_info_gain_t g;
            gain(&m, &v, 0, 0, &g);
            return g.unknown_cells > 0u;
        });
    };
    ab("info gain frustum 6.5 m (10)", rounds, [&] { return all(old_occ_info_gain); },
       [&] { return all(occ_info_gain); });
}

static void bench_queries(const occ_map_t &m, int rounds)
{
    const Box b = map_box(m);
    std::mt19937_64 rng(42);
    std::uniform_real_distribution<float> ux(b.lo.x, b.hi.x), uy(b.lo.y, b.hi.y),
        uz(b.lo.z, b.hi.z), u01(0, 1);
    std::normal_distribution<float> g(0, 1);
    const auto free_point = [&] {
        for (;;) {
            const occ_vec3_t p = {ux(rng), uy(rng), uz(rng)};
            if (occ_map_state_at(&m, p) == OCC_STATE_FREE) return p;
        }
    };
    const auto inside = [&](occ_vec3_t p) {
        return p.x >= b.lo.x && p.x <= b.hi.x && p.y >= b.lo.y && p.y <= b.hi.y &&
               p.z >= b.lo.z && p.z <= b.hi.z;
    };
    const size_t N = 20000;
    std::vector<occ_vec3_t> o(N), d(N), e(N);
    for (size_t i = 0; i < N; i++) {
        o[i] = free_point();
        d[i] = {g(rng), g(rng), g(rng)};
        // A free end point 1..10.8 m away, for line of sight.
        for (;;) {
            const float len = 1.0f + 9.8f * u01(rng);
            const float n = std::sqrt(d[i].x * d[i].x + d[i].y * d[i].y + d[i].z * d[i].z);
            e[i] = {o[i].x + d[i].x / n * len, o[i].y + d[i].y / n * len, o[i].z + d[i].z / n * len};
            if (inside(e[i]) && occ_map_state_at(&m, e[i]) == OCC_STATE_FREE) break;
            d[i] = {g(rng), g(rng), g(rng)};
        }
    }
    for (int ignore = 1; ignore >= 0; ignore--) {
        for (size_t i = 0; i < N; i++) {
            occ_ray_result_t ro, rn;
            const occ_err_t eo = old_occ_cast_ray(&m, o[i], d[i], ignore != 0, 10.0f, &ro);
            const occ_err_t en = occ_cast_ray(&m, o[i], d[i], ignore != 0, 10.0f, &rn);
            if (eo != en || !same_ray(ro, rn)) {
                std::fprintf(stderr, "ab_split: castRay %zu differs\n", i);
                std::exit(1);
            }
        }
        const auto cast_all = [&](decltype(occ_cast_ray) *cast) {
            return time_all(N, [&](size_t i) {
                occ_ray_result_t r;
                cast(&m, o[i], d[i], ignore != 0, 10.0f, &r);
                return r.hit;
            });
        };
        ab(ignore ? "castRay 10 m ignore unknown (20k)" : "castRay 10 m stop at unknown (20k)",
           rounds, [&] { return cast_all(old_occ_cast_ray); },
           [&] { return cast_all(occ_cast_ray); });
    }
    for (size_t i = 0; i < N; i++) {
        bool vo = false, vn = false;
        occ_ray_result_t ro, rn;
        old_occ_line_of_sight(&m, o[i], e[i], OCC_UNKNOWN_SAFE, &vo, &ro);
        occ_line_of_sight(&m, o[i], e[i], OCC_UNKNOWN_SAFE, &vn, &rn);
        if (vo != vn || (!vo && !same_ray(ro, rn))) {
            std::fprintf(stderr, "ab_split: line of sight %zu differs\n", i);
            std::exit(1);
        }
    }
    const auto los_all = [&](decltype(occ_line_of_sight) *los) {
        return time_all(N, [&](size_t i) {
            bool v = false;
            los(&m, o[i], e[i], OCC_UNKNOWN_SAFE, &v, nullptr);
            return v;
        });
    };
    ab("line of sight 1..10.8 m (20k)", rounds, [&] { return los_all(old_occ_line_of_sight); },
       [&] { return los_all(occ_line_of_sight); });
    bench_collide(m, o, d, rounds);
    bench_info_gain(m, o, d, rounds);
}

// One side's lookup index: its own struct (the old library's may be laid out otherwise: a
// buffer larger than this tree's struct, passed through) and table.
struct IndexSide {
    alignas(64) unsigned char raw[sizeof(occ_lookup_index_t) + 256];
    std::vector<uint32_t> mem;
    size_t bytes = 0;
    decltype(occ_lookup_index_state) *state = nullptr;
    const occ_lookup_index_t *idx() const { return reinterpret_cast<const occ_lookup_index_t *>(raw); }
};

static void index_side(IndexSide &s, const occ_map_t &m, bool old)
{
    decltype(occ_lookup_index_need) *need = old ? old_occ_lookup_index_need : occ_lookup_index_need;
    decltype(occ_lookup_index_build) *build = old ? old_occ_lookup_index_build : occ_lookup_index_build;
    s.state = old ? old_occ_lookup_index_state : occ_lookup_index_state;
    if (need(&m, 0u, &s.bytes) != OCC_OK) std::abort();
    s.mem.assign(s.bytes / 4 + 1, 0u);
    const double t0 = cpu_ms();
    if (build(reinterpret_cast<occ_lookup_index_t *>(s.raw), &m, 0u, s.mem.data(), s.mem.size() * 4) != OCC_OK) {
        std::fprintf(stderr, "ab_split: lookup index build failed\n");
        std::exit(1);
    }
    std::printf("  %s index level 0: %.3f MB, built in %.1f ms\n", old ? "old" : "new",
                (double)s.bytes / 1e6, cpu_ms() - t0);
}

// Streams `bytes` through the caches (the cold case's eviction, not timed).
static void evict_caches(size_t bytes)
{
    static std::vector<uint64_t> junk;
    junk.resize(bytes / 8);
    static uint64_t x = 1;
    for (size_t i = 0; i < junk.size(); i += 8) junk[i] += x++;
}

// CPU ms of the lookups of pts[i0, i1).
static double time_lookups(const IndexSide &s, const std::vector<occ_vec3_t> &pts, size_t i0, size_t i1)
{
    size_t sum = 0;
    const double t0 = cpu_ms();
    for (size_t i = i0; i < i1; i++) sum += (size_t)s.state(s.idx(), pts[i]);
    const double t = cpu_ms() - t0;
    if (sum > 2 * pts.size()) std::abort();
    return t;
}

static double lookups_warm(const IndexSide &s, const std::vector<occ_vec3_t> &pts)
{
    (void)time_lookups(s, pts, 0, pts.size());
    return time_lookups(s, pts, 0, pts.size());
}

static double lookups_cold(const IndexSide &s, const std::vector<occ_vec3_t> &pts)
{
    double t = 0;
    for (size_t i = 0; i < pts.size(); i += 1000) {
        evict_caches((size_t)8 << 20);
        t += time_lookups(s, pts, i, std::min(pts.size(), i + 1000));
    }
    return t;
}

static void bench_lookups(const char *name, const occ_map_t &m, int rounds)
{
    std::printf("%s:\n", name);
    IndexSide olds, news;
    index_side(olds, m, true);
    index_side(news, m, false);
    const Box b = map_box(m);
    std::mt19937_64 rng(42);
    std::uniform_real_distribution<float> ux(b.lo.x, b.hi.x), uy(b.lo.y, b.hi.y),
        uz(b.lo.z, b.hi.z), u01(0, 1);
    const size_t N = 200000;
    std::vector<occ_vec3_t> pts(N), traj(N);
    for (auto &p : pts) p = {ux(rng), uy(rng), uz(rng)};
    // 5 cm steps in random directions, clamped to the box, from a random start every 200 steps.
    for (size_t i = 0; i < N; i++) {
        if (i % 200 == 0) {
            traj[i] = {ux(rng), uy(rng), uz(rng)};
            continue;
        }
        occ_vec3_t d = {2 * u01(rng) - 1, 2 * u01(rng) - 1, 2 * u01(rng) - 1};
        if (d.x * d.x + d.y * d.y + d.z * d.z < 1e-6f) d = {1, 0, 0};
        d = unit(d);
        const occ_vec3_t q = traj[i - 1];
        traj[i] = {std::min(std::max(q.x + 0.05f * d.x, b.lo.x), b.hi.x),
                   std::min(std::max(q.y + 0.05f * d.y, b.lo.y), b.hi.y),
                   std::min(std::max(q.z + 0.05f * d.z, b.lo.z), b.hi.z)};
    }
    for (const auto *v : {&pts, &traj}) {
        for (const occ_vec3_t &p : *v) {
            const occ_state_t want = occ_map_state_at(&m, p);
            if (olds.state(olds.idx(), p) != want || news.state(news.idx(), p) != want) {
                std::fprintf(stderr, "ab_split: %s: lookup at (%g %g %g) differs\n", name,
                             (double)p.x, (double)p.y, (double)p.z);
                std::exit(1);
            }
        }
    }
    char label[80];
    std::snprintf(label, sizeof label, "lookup random warm %s (200k)", name);
    ab(label, rounds, [&] { return lookups_warm(olds, pts); }, [&] { return lookups_warm(news, pts); });
    std::snprintf(label, sizeof label, "lookup random cold %s (200k)", name);
    ab(label, rounds, [&] { return lookups_cold(olds, pts); }, [&] { return lookups_cold(news, pts); });
    std::snprintf(label, sizeof label, "lookup trajectory %s (200k)", name);
    ab(label, rounds, [&] { return time_lookups(olds, traj, 0, N); },
       [&] { return time_lookups(news, traj, 0, N); });
}

int main(int argc, char **argv)
{
    int rounds = 15;
    bool queries_only = false, inserts_only = false, lookup_only = false;
    const char *filter = nullptr, *tum_dir = nullptr, *fr079 = nullptr;
    int a = 1;
    for (; a < argc && argv[a][0] == '-'; a++) {
        if (std::strcmp(argv[a], "--rounds") == 0 && a + 1 < argc) {
            rounds = std::max(1, std::atoi(argv[++a]));
        } else if (std::strcmp(argv[a], "--queries-only") == 0) {
            queries_only = true; /* e.g. under callgrind, where the inserts take minutes */
        } else if (std::strcmp(argv[a], "--inserts-only") == 0) {
            inserts_only = true;
        } else if (std::strcmp(argv[a], "--lookup-only") == 0) {
            lookup_only = true;
        } else if (std::strcmp(argv[a], "--fr079") == 0 && a + 1 < argc) {
            fr079 = argv[++a];
        } else if (std::strcmp(argv[a], "--case") == 0 && a + 1 < argc) {
            filter = argv[++a];
        } else if (std::strcmp(argv[a], "--tum") == 0 && a + 1 < argc) {
            tum_dir = argv[++a];
        } else {
            break;
        }
    }
    if (argc - a != 2) {
        std::fprintf(stderr, "usage: ab_split [--rounds N] [--queries-only | --inserts-only | "
                             "--lookup-only] [--case SUBSTR] [--tum DIR] [--fr079 PATH] SCAN.dat MAP.bt\n");
        return 2;
    }
    char msg[256] = "";
    occ_vec3_t *pts = nullptr;
    size_t n = 0;
    if (!lookup_only && occ_scan_read_xyz(argv[a], &pts, &n, msg, sizeof msg) != OCC_OK) {
        std::fprintf(stderr, "ab_split: %s\n", msg);
        return 1;
    }
    const std::vector<occ_vec3_t> scan(pts, pts + n);
    std::free(pts);
    occ_map_t m;
    void *map_arena = nullptr;
    if (occ_file_load_alloc(argv[a + 1], nullptr, &m, 0, &map_arena, nullptr, msg, sizeof msg) !=
        OCC_OK) {
        std::fprintf(stderr, "ab_split: %s\n", msg);
        return 1;
    }
    std::printf("A/B old (AB_BASE) vs new (this tree), %d interleaved rounds, CPU time\n", rounds);
    if (lookup_only) {
        bench_lookups("geb079", m, rounds);
        std::free(map_arena);
        if (fr079 != nullptr) {
            void *fr_arena = nullptr;
            occ_map_t fr;
            if (occ_file_load_alloc(fr079, nullptr, &fr, 0, &fr_arena, nullptr, msg, sizeof msg) != OCC_OK) {
                std::fprintf(stderr, "ab_split: %s\n", msg);
                return 1;
            }
            bench_lookups("fr_079", fr, rounds);
            std::free(fr_arena);
        }
        return 0;
    }
    if (!queries_only) {
        const std::vector<Scan> tum = tum_dir != nullptr ? load_tum(tum_dir) : std::vector<Scan>();
        bench_inserts(scan, tum, rounds, filter);
        if (tum_dir != nullptr) bench_proj(load_tum_images(tum_dir), rounds, filter);
    }
    if (!inserts_only) bench_queries(m, rounds);
    std::free(map_arena);
    return 0;
}
