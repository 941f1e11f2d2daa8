// SPDX-License-Identifier: BSD-3-Clause
// oracle_query.cpp - brute-force references for the query tests: Eigen geometry in double,
// one cell at a time, and OctoMap's castRay. Shares no code with the core's query math.
#include "oracle_res.hpp"
#include "oracle_query.h"

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <octomap/OcTree.h>
#include <octomap/AbstractOcTree.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

using Eigen::Vector3d;
using Eigen::Matrix3d;

enum Kind { K_AABB, K_SPHERE, K_OBB, K_CAPSULE, K_SEGMENT, K_FRUSTUM };

struct oracle_q_shape {
    Kind kind;
    Vector3d mn, mx;        // AABB / bounds
    Vector3d c, a, b, half; // centre, segment, OBB half extents
    Matrix3d R = Matrix3d::Identity();
    double r = 0;
    std::vector<Vector3d> corners; // frustum
    std::vector<Vector3d> normals; // frustum outward normals
    std::vector<double> offs;
};

static Matrix3d rot(double yaw, double pitch, double roll)
{
    return (Eigen::AngleAxisd(yaw, Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Vector3d::UnitY()) *
            Eigen::AngleAxisd(roll, Vector3d::UnitX()))
        .toRotationMatrix();
}

static Vector3d v3(const double *p) { return Vector3d(p[0], p[1], p[2]); }

extern "C" oracle_q_shape_t *oracle_q_aabb(const double mn[3], const double mx[3])
{
    auto *s = new oracle_q_shape;
    s->kind = K_AABB;
    s->mn = v3(mn);
    s->mx = v3(mx);
    return s;
}

extern "C" oracle_q_shape_t *oracle_q_sphere(const double c[3], double r)
{
    auto *s = new oracle_q_shape;
    s->kind = K_SPHERE;
    s->c = v3(c);
    s->r = r;
    s->mn = s->c - Vector3d::Constant(r);
    s->mx = s->c + Vector3d::Constant(r);
    return s;
}

extern "C" oracle_q_shape_t *oracle_q_obb(const double c[3], const double half[3], double yaw,
                                         double pitch, double roll)
{
    auto *s = new oracle_q_shape;
    s->kind = K_OBB;
    s->c = v3(c);
    s->half = v3(half);
    s->R = rot(yaw, pitch, roll);
    const Vector3d ext = s->R.cwiseAbs() * s->half;
    s->mn = s->c - ext;
    s->mx = s->c + ext;
    return s;
}

extern "C" oracle_q_shape_t *oracle_q_capsule(const double a[3], const double b[3], double r)
{
    auto *s = new oracle_q_shape;
    s->kind = K_CAPSULE;
    s->a = v3(a);
    s->b = v3(b);
    s->r = r;
    s->mn = s->a.cwiseMin(s->b) - Vector3d::Constant(r);
    s->mx = s->a.cwiseMax(s->b) + Vector3d::Constant(r);
    return s;
}

extern "C" oracle_q_shape_t *oracle_q_segment(const double a[3], const double b[3])
{
    oracle_q_shape_t *s = oracle_q_capsule(a, b, 0.0);
    s->kind = K_SEGMENT;
    return s;
}

extern "C" oracle_q_shape_t *oracle_q_frustum(const double origin[3], double yaw, double pitch,
                                             double roll, double hfov, double vfov, double near_m,
                                             double far_m)
{
    auto *s = new oracle_q_shape;
    s->kind = K_FRUSTUM;
    s->c = v3(origin);
    s->R = rot(yaw, pitch, roll);
    const Vector3d f = s->R.col(0), l = s->R.col(1), u = s->R.col(2);
    const double th = std::tan(hfov / 2), tv = std::tan(vfov / 2);
    for (double d : {near_m, far_m}) {
        for (int sl : {1, -1}) {
            for (int su : {1, -1}) {
                s->corners.push_back(s->c + d * f + sl * d * th * l + su * d * tv * u);
            }
        }
    }
    // Planes from corner triples: a plane through the apex and two far corners, etc.
    auto add_plane = [&](Vector3d n, const Vector3d &p) {
        n.normalize();
        s->normals.push_back(n);
        s->offs.push_back(n.dot(p));
    };
    add_plane(-f, s->c + near_m * f);
    add_plane(f, s->c + far_m * f);
    // Side planes: normal = cross of the two far-edge rays, oriented away from the axis.
    const Vector3d axisp = s->c + (near_m + far_m) / 2 * f;
    const int quads[4][2] = {{4, 5}, {6, 7}, {4, 6}, {5, 7}}; // left, right, top, bottom
    for (auto &q : quads) {
        const Vector3d e1 = s->corners[q[0]] - s->c, e2 = s->corners[q[1]] - s->c;
        Vector3d n = e1.cross(e2);
        if (n.dot(axisp - s->c) > 0) {
            n = -n;
        }
        add_plane(n, s->c);
    }
    s->mn = s->corners[0];
    s->mx = s->corners[0];
    for (auto &p : s->corners) {
        s->mn = s->mn.cwiseMin(p);
        s->mx = s->mx.cwiseMax(p);
    }
    return s;
}

extern "C" void oracle_q_axes(const oracle_q_shape_t *s, float axes[9])
{
    for (int i = 0; i < 3; i++) {
        for (int k = 0; k < 3; k++) {
            axes[3 * i + k] = (float)s->R(k, i);
        }
    }
}

extern "C" void oracle_q_free(oracle_q_shape_t *s) { delete s; }

// ---- geometry ---------------------------------------------------------------------------------
static double box_point_dist(const Eigen::AlignedBox3d &box, const Vector3d &p)
{
    return box.exteriorDistance(p);
}

// Minimum over t in [0,1] of the distance from a + t(b-a) to the box: convex in t, golden section.
static double seg_box_dist(const Eigen::AlignedBox3d &box, const Vector3d &a, const Vector3d &b)
{
    const double g = (std::sqrt(5.0) - 1) / 2;
    double lo = 0, hi = 1;
    auto f = [&](double t) { return box_point_dist(box, a + t * (b - a)); };
    double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
    double f1 = f(x1), f2 = f(x2);
    for (int i = 0; i < 64; i++) {
        if (f1 <= f2) {
            hi = x2;
            x2 = x1;
            f2 = f1;
            x1 = hi - g * (hi - lo);
            f1 = f(x1);
        } else {
            lo = x1;
            x1 = x2;
            f1 = f2;
            x2 = lo + g * (hi - lo);
            f2 = f(x2);
        }
    }
    return std::min({f(0), f(1), f1, f2});
}

static double point_seg_dist(const Vector3d &p, const Vector3d &a, const Vector3d &b)
{
    const Vector3d d = b - a;
    const double dd = d.squaredNorm();
    const double t = dd > 0 ? std::min(1.0, std::max(0.0, (p - a).dot(d) / dd)) : 0.0;
    return (p - (a + t * d)).norm();
}

static int classify_dist(double dist, double r)
{
    if (dist > r + ORACLE_Q_EPS) return 0;
    if (dist < r - ORACLE_Q_EPS) return 1;
    return -1;
}

static int classify_sep(double sep)
{
    if (sep > ORACLE_Q_EPS) return 0;
    if (sep < -ORACLE_Q_EPS) return 1;
    return -1;
}

// Separation of the projections of the cube and a point set (or OBB) on unit axis L.
static double sep_axis(const Vector3d &L, const Vector3d &cc, double h, double lo, double hi)
{
    const double pc = L.dot(cc), rad = h * L.cwiseAbs().sum();
    return std::max(lo - (pc + rad), (pc - rad) - hi);
}

static int cube_test(const oracle_q_shape *s, const Vector3d &cc, double h)
{
    const Eigen::AlignedBox3d box(cc - Vector3d::Constant(h), cc + Vector3d::Constant(h));
    switch (s->kind) {
    case K_AABB: {
        double sep = -1e300;
        for (int i = 0; i < 3; i++) {
            sep = std::max({sep, s->mn[i] - (cc[i] + h), (cc[i] - h) - s->mx[i]});
        }
        return classify_sep(sep);
    }
    case K_SPHERE:
        return classify_dist(box_point_dist(box, s->c), s->r);
    case K_CAPSULE: {
        // Cheap bounds first: the centre's distance to the segment +- the half diagonal.
        const double dc = point_seg_dist(cc, s->a, s->b), diag = std::sqrt(3.0) * h;
        if (dc - diag > s->r + ORACLE_Q_EPS) return 0;
        if (dc < s->r - ORACLE_Q_EPS) return 1;
        return classify_dist(seg_box_dist(box, s->a, s->b), s->r);
    }
    case K_SEGMENT: {
        if (point_seg_dist(cc, s->a, s->b) - std::sqrt(3.0) * h > ORACLE_Q_EPS) return 0;
        const double d = seg_box_dist(box, s->a, s->b);
        if (d > ORACLE_Q_EPS) return 0;
        const Eigen::AlignedBox3d inner(cc - Vector3d::Constant(h - ORACLE_Q_EPS),
                                        cc + Vector3d::Constant(h - ORACLE_Q_EPS));
        return seg_box_dist(inner, s->a, s->b) < 1e-9 ? 1 : -1;
    }
    case K_OBB: {
        Vector3d axes[15];
        int na = 0;
        for (int i = 0; i < 3; i++) {
            axes[na++] = Vector3d::Unit(i);
            axes[na++] = s->R.col(i);
            for (int j = 0; j < 3; j++) {
                axes[na++] = Vector3d::Unit(i).cross(s->R.col(j));
            }
        }
        double sep = -1e300;
        for (int ai = 0; ai < na; ai++) {
            Vector3d L = axes[ai];
            const double n = L.norm();
            if (n < 1e-9) continue;
            L /= n;
            double rb = 0;
            for (int j = 0; j < 3; j++) rb += s->half[j] * std::fabs(L.dot(s->R.col(j)));
            const double po = L.dot(s->c);
            sep = std::max(sep, sep_axis(L, cc, h, po - rb, po + rb));
        }
        return classify_sep(sep);
    }
    case K_FRUSTUM: {
        Vector3d axes[27], edges[6];
        int na = 0;
        for (auto &n : s->normals) axes[na++] = n;
        for (int k = 0; k < 4; k++) edges[k] = s->corners[4 + k] - s->corners[k];
        edges[4] = s->R.col(1);
        edges[5] = s->R.col(2);
        for (int i = 0; i < 3; i++) {
            axes[na++] = Vector3d::Unit(i);
            for (auto &e : edges) axes[na++] = Vector3d::Unit(i).cross(e);
        }
        double sep = -1e300;
        for (int ai = 0; ai < na; ai++) {
            Vector3d L = axes[ai];
            const double n = L.norm();
            if (n < 1e-9) continue;
            L /= n;
            double lo = 1e300, hi = -1e300;
            for (auto &p : s->corners) {
                lo = std::min(lo, L.dot(p));
                hi = std::max(hi, L.dot(p));
            }
            sep = std::max(sep, sep_axis(L, cc, h, lo, hi));
        }
        return classify_sep(sep);
    }
    }
    return 0;
}

static Vector3d cell_center(const occ_map_t *map, const uint32_t k[3], unsigned level)
{
    const double res = oracle_user_resolution((double)map->cfg.resolution_m);
    const double half = std::ldexp(1.0, map->cfg.depth_levels - 1);
    const double side = std::ldexp(1.0, (int)level);
    Vector3d c;
    for (int i = 0; i < 3; i++) {
        const double base = (double)(k[i] & ~((1u << level) - 1u));
        c[i] = (base - half + side / 2) * res;
    }
    return c;
}

extern "C" int oracle_q_cell(const oracle_q_shape_t *s, const occ_map_t *map, occ_key_t key,
                             unsigned level)
{
    const double h = std::ldexp(1.0, (int)level) * oracle_user_resolution((double)map->cfg.resolution_m) / 2;
    return cube_test(s, cell_center(map, key.k, level), h);
}

static uint64_t interleave(const uint32_t k[3])
{
    uint64_t c = 0;
    for (int b = 0; b < 21; b++) {
        for (int i = 0; i < 3; i++) {
            c |= (uint64_t)((k[i] >> b) & 1u) << (3 * b + i);
        }
    }
    return c;
}

static unsigned voxel_state_bit(const occ_map_t *map, const uint32_t k[3])
{
    occ_key_t key;
    key.k[0] = k[0];
    key.k[1] = k[1];
    key.k[2] = k[2];
    occ_node_info_t info;
    if (occ_map_read_key(map, key, 0, &info) != OCC_OK) return 0;
    switch (info.state) {
    case OCC_STATE_OCCUPIED: return OCC_PRED_OCCUPIED;
    case OCC_STATE_FREE: return OCC_PRED_FREE;
    default: return OCC_PRED_UNKNOWN;
    }
}

// Range of cell indices at `level` overlapping [mn - eps, mx + eps], clipped to the map.
static bool cell_range(const occ_map_t *map, const oracle_q_shape *s, unsigned level,
                       int64_t lo[3], int64_t hi[3])
{
    const double res = oracle_user_resolution((double)map->cfg.resolution_m);
    const double side = std::ldexp(1.0, (int)level) * res;
    const int64_t half = (int64_t)1 << (map->cfg.depth_levels - 1);
    const int64_t ncell = ((int64_t)1 << map->cfg.depth_levels) >> level;
    for (int i = 0; i < 3; i++) {
        lo[i] = (int64_t)std::floor((s->mn[i] - 2 * ORACLE_Q_EPS + half * res) / side) - 1;
        hi[i] = (int64_t)std::floor((s->mx[i] + 2 * ORACLE_Q_EPS + half * res) / side) + 1;
        lo[i] = std::max<int64_t>(lo[i], 0);
        hi[i] = std::min<int64_t>(hi[i], ncell - 1);
        if (lo[i] > hi[i]) return false;
    }
    return true;
}

extern "C" size_t oracle_q_collect(const occ_map_t *map, const oracle_q_shape_t *s,
                                   unsigned states, unsigned level, uint64_t *codes,
                                   uint8_t *ambiguous, size_t cap)
{
    int64_t lo[3], hi[3];
    if (!cell_range(map, s, level, lo, hi)) return 0;
    std::vector<std::pair<uint64_t, uint8_t>> found;
    const uint32_t side = 1u << level;
    for (int64_t z = lo[2]; z <= hi[2]; z++) {
        for (int64_t y = lo[1]; y <= hi[1]; y++) {
            for (int64_t x = lo[0]; x <= hi[0]; x++) {
                const uint32_t k[3] = {(uint32_t)x << level, (uint32_t)y << level,
                                       (uint32_t)z << level};
                occ_key_t key;
                key.k[0] = k[0];
                key.k[1] = k[1];
                key.k[2] = k[2];
                const int g = oracle_q_cell(s, map, key, level);
                if (g == 0) continue;
                bool match = false;
                for (uint32_t dz = 0; dz < side && !match; dz++) {
                    for (uint32_t dy = 0; dy < side && !match; dy++) {
                        for (uint32_t dx = 0; dx < side && !match; dx++) {
                            const uint32_t v[3] = {k[0] + dx, k[1] + dy, k[2] + dz};
                            match = (voxel_state_bit(map, v) & states) != 0u;
                        }
                    }
                }
                if (match) found.emplace_back(interleave(k), g < 0 ? 1 : 0);
            }
        }
    }
    std::sort(found.begin(), found.end());
    for (size_t i = 0; i < found.size() && i < cap; i++) {
        codes[i] = found[i].first;
        ambiguous[i] = found[i].second;
    }
    return found.size();
}

extern "C" void oracle_q_count(const occ_map_t *map, const oracle_q_shape_t *s,
                               uint64_t counts[3], uint64_t *ambiguous)
{
    counts[0] = counts[1] = counts[2] = 0;
    *ambiguous = 0;
    int64_t lo[3], hi[3];
    if (!cell_range(map, s, 0, lo, hi)) return;
    for (int64_t z = lo[2]; z <= hi[2]; z++) {
        for (int64_t y = lo[1]; y <= hi[1]; y++) {
            for (int64_t x = lo[0]; x <= hi[0]; x++) {
                occ_key_t key;
                key.k[0] = (uint32_t)x;
                key.k[1] = (uint32_t)y;
                key.k[2] = (uint32_t)z;
                const int g = oracle_q_cell(s, map, key, 0);
                if (g == 0) continue;
                if (g < 0) {
                    (*ambiguous)++;
                    continue;
                }
                const unsigned b = voxel_state_bit(map, key.k);
                counts[b == OCC_PRED_OCCUPIED ? 0 : (b == OCC_PRED_FREE ? 1 : 2)]++;
            }
        }
    }
}

extern "C" double oracle_q_nearest_d2(const occ_map_t *map, const double p[3], unsigned states)
{
    const uint32_t n = 1u << map->cfg.depth_levels;
    const double h = oracle_user_resolution((double)map->cfg.resolution_m) / 2;
    double best = -1;
    const Vector3d pp = v3(p);
    for (uint32_t z = 0; z < n; z++) {
        for (uint32_t y = 0; y < n; y++) {
            for (uint32_t x = 0; x < n; x++) {
                const uint32_t k[3] = {x, y, z};
                if ((voxel_state_bit(map, k) & states) == 0u) continue;
                const Vector3d c = cell_center(map, k, 0);
                const Eigen::AlignedBox3d box(c - Vector3d::Constant(h), c + Vector3d::Constant(h));
                const double d = box.exteriorDistance(pp);
                if (best < 0 || d * d < best) best = d * d;
            }
        }
    }
    return best;
}

// ---- OctoMap ------------------------------------------------------------------------------------
struct oracle_q_octo {
    octomap::OcTree *tree = nullptr;
};

extern "C" oracle_q_octo_t *oracle_q_octo_load(const char *path)
{
    const std::string p(path);
    octomap::OcTree *t = nullptr;
    if (p.size() > 3 && p.compare(p.size() - 3, 3, ".bt") == 0) {
        t = new octomap::OcTree(0.1);
        if (!t->readBinary(p)) {
            delete t;
            return nullptr;
        }
    } else {
        octomap::AbstractOcTree *a = octomap::AbstractOcTree::read(p);
        t = dynamic_cast<octomap::OcTree *>(a);
        if (t == nullptr) {
            delete a;
            return nullptr;
        }
    }
    auto *o = new oracle_q_octo;
    o->tree = t;
    return o;
}

extern "C" oracle_q_octo_t *oracle_q_octo_random(uint64_t seed, double res_m)
{
    std::mt19937_64 rng(seed);
    auto r = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
    auto *t = new octomap::OcTree(oracle_user_resolution(res_m));
    const int half = 32; /* voxels: the scene spans [-32, 32) per axis */
    auto box = [&](int size, bool occupied) {
        const int x0 = r(-half, half - size), y0 = r(-half, half - size), z0 = r(-half, half - size);
        for (int x = x0; x < x0 + size; x++)
            for (int y = y0; y < y0 + size; y++)
                for (int z = z0; z < z0 + size; z++) {
                    const octomap::OcTreeKey k((octomap::key_type)(32768 + x), (octomap::key_type)(32768 + y),
                                               (octomap::key_type)(32768 + z));
                    t->updateNode(k, occupied, true);
                }
    };
    for (int i = 0; i < 40; i++) box(r(4, 20), false);
    for (int i = 0; i < 150; i++) box(r(2, 5), true);
    for (int i = 0; i < 2000; i++) box(1, true);
    t->updateInnerOccupancy();
    t->prune();
    auto *o = new oracle_q_octo;
    o->tree = t;
    return o;
}

extern "C" void oracle_q_octo_free(oracle_q_octo_t *o)
{
    if (o != nullptr) {
        delete o->tree;
        delete o;
    }
}

extern "C" double oracle_q_octo_resolution(const oracle_q_octo_t *o) { return o->tree->getResolution(); }
extern "C" size_t oracle_q_octo_leaves(const oracle_q_octo_t *o) { return o->tree->getNumLeafNodes(); }

extern "C" void oracle_q_octo_bbox(const oracle_q_octo_t *o, double mn[3], double mx[3])
{
    double x0, y0, z0, x1, y1, z1;
    o->tree->getMetricMin(x0, y0, z0);
    o->tree->getMetricMax(x1, y1, z1);
    mn[0] = x0;
    mn[1] = y0;
    mn[2] = z0;
    mx[0] = x1;
    mx[1] = y1;
    mx[2] = z1;
}

extern "C" occ_err_t oracle_q_octo_copy(const oracle_q_octo_t *o, occ_map_t *map,
                                        size_t *state_mismatch)
{
    *state_mismatch = 0;
    octomap::OcTree *t = o->tree;
    for (auto it = t->begin_leafs(), end = t->end_leafs(); it != end; ++it) {
        const octomap::OcTreeKey k = it.getKey();
        occ_key_t key;
        key.k[0] = k[0];
        key.k[1] = k[1];
        key.k[2] = k[2];
        const unsigned level = 16u - it.getDepth();
        const occ_err_t e = occ_map_set_key(map, key, level, it->getLogOdds());
        if (e != OCC_OK) return e;
    }
    for (auto it = t->begin_leafs(), end = t->end_leafs(); it != end; ++it) {
        const octomap::OcTreeKey k = it.getKey();
        occ_key_t key;
        key.k[0] = k[0];
        key.k[1] = k[1];
        key.k[2] = k[2];
        occ_node_info_t info;
        if (occ_map_read_key(map, key, 0, &info) != OCC_OK) {
            (*state_mismatch)++;
            continue;
        }
        const bool occ = t->isNodeOccupied(*it);
        if (occ != (info.state == OCC_STATE_OCCUPIED) || info.state == OCC_STATE_UNKNOWN) {
            (*state_mismatch)++;
        }
    }
    return OCC_OK;
}

extern "C" bool oracle_q_octo_cast(const oracle_q_octo_t *o, const float origin[3],
                                   const float dir[3], bool ignore_unknown, double max_range,
                                   float end[3])
{
    octomap::point3d e;
    const bool hit = o->tree->castRay(octomap::point3d(origin[0], origin[1], origin[2]),
                                      octomap::point3d(dir[0], dir[1], dir[2]), e,
                                      ignore_unknown, max_range);
    end[0] = e.x();
    end[1] = e.y();
    end[2] = e.z();
    return hit;
}

extern "C" int oracle_q_octo_search(const oracle_q_octo_t *o, const float p[3])
{
    const octomap::OcTreeNode *n = o->tree->search((double)p[0], (double)p[1], (double)p[2]);
    if (n == nullptr) return -1;
    return o->tree->isNodeOccupied(n) ? 1 : 0;
}

// ---- random scenes --------------------------------------------------------------------------------
extern "C" occ_err_t oracle_q_random_map(occ_map_t *map, uint64_t seed, unsigned n_voxels)
{
    uint64_t st = seed * 2862933555777941757ull + 3037000493ull;
    auto rnd = [&](uint32_t n) -> uint32_t {
        st ^= st << 13;
        st ^= st >> 7;
        st ^= st << 17;
        return (uint32_t)(st % n);
    };
    const uint32_t n = 1u << map->cfg.depth_levels;
    const uint32_t lo = n / 4, span = n / 2;
    auto rkey = [&](unsigned level) {
        occ_key_t k;
        for (int i = 0; i < 3; i++) k.k[i] = (lo + rnd(span)) & ~((1u << level) - 1u);
        return k;
    };
    occ_err_t e = OCC_OK;
    for (int i = 0; i < 24 && e == OCC_OK; i++) { // free blocks
        e = occ_map_set_key(map, rkey(1 + rnd(3)), 0, -1.5f);
        if (e == OCC_OK) {
            const unsigned lv = 1 + rnd(3);
            e = occ_map_set_key(map, rkey(lv), lv, -1.2f - 0.1f * (float)rnd(5));
        }
    }
    for (int i = 0; i < 6 && e == OCC_OK; i++) { // occupied blocks
        const unsigned lv = 1 + rnd(2);
        e = occ_map_set_key(map, rkey(lv), lv, 2.0f);
    }
    for (unsigned i = 0; i < n_voxels && e == OCC_OK; i++) { // scattered voxels
        const occ_key_t k = rkey(0);
        const unsigned reps = 1 + rnd(3);
        const bool hit = rnd(3) == 0;
        for (unsigned r = 0; r < reps && e == OCC_OK; r++) {
            e = occ_map_update_key(map, k, hit ? 0.85f : -0.4f);
        }
    }
    for (int i = 0; i < 6 && e == OCC_OK; i++) { // unknown holes
        const unsigned lv = rnd(3);
        e = occ_map_forget_key(map, rkey(lv), lv);
    }
    return e;
}

extern "C" void oracle_q_bounds(const oracle_q_shape_t *s, double mn[3], double mx[3])
{
    for (int i = 0; i < 3; i++) {
        mn[i] = s->mn[i];
        mx[i] = s->mx[i];
    }
}

extern "C" void oracle_q_gain(const occ_map_t *map, const oracle_q_shape_t *s, unsigned level,
                              uint64_t *definite, uint64_t *ambiguous)
{
    *definite = *ambiguous = 0;
    int64_t lo[3], hi[3];
    if (!cell_range(map, s, level, lo, hi)) return;
    const uint32_t side = 1u << level;
    for (int64_t z = lo[2]; z <= hi[2]; z++) {
        for (int64_t y = lo[1]; y <= hi[1]; y++) {
            for (int64_t x = lo[0]; x <= hi[0]; x++) {
                occ_key_t key;
                key.k[0] = (uint32_t)x << level;
                key.k[1] = (uint32_t)y << level;
                key.k[2] = (uint32_t)z << level;
                const int g = oracle_q_cell(s, map, key, level);
                if (g == 0) continue;
                bool all_unobserved = true;
                for (uint32_t d = 0; d < side * side * side && all_unobserved; d++) {
                    occ_key_t v = key;
                    v.k[0] += d % side;
                    v.k[1] += (d / side) % side;
                    v.k[2] += d / (side * side);
                    occ_node_info_t info;
                    all_unobserved = occ_map_read_key(map, v, 0, &info) == OCC_OK && !info.observed;
                }
                if (!all_unobserved) continue;
                if (g < 0) (*ambiguous)++;
                else (*definite)++;
            }
        }
    }
}
