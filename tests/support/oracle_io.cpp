// SPDX-License-Identifier: BSD-3-Clause
// oracle_io.cpp - OctoMap as the reference for the file tests (see oracle_io.h).
#include "oracle_res.hpp"
#include "oracle_io.h"

#include <octomap/ColorOcTree.h>
#include <octomap/OcTree.h>
#include <octomap/OcTreeStamped.h>
#include <octomap/ScanGraph.h>
#include <octomap/octomap.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>

using octomap::OcTreeKey;

struct oracle_io {
    oracle_io_kind_t kind;
    octomap::OcTree *oc;
    octomap::ColorOcTree *color;
    octomap::OcTreeStamped *stamped;
};

template <class F> static auto visit(const oracle_io *t, F f) -> decltype(f(t->oc))
{
    if (t->kind == ORACLE_COLOR) {
        return f(t->color);
    }
    if (t->kind == ORACLE_STAMPED) {
        return f(t->stamped);
    }
    return f(t->oc);
}

static oracle_io *wrap(octomap::AbstractOcTree *a)
{
    if (a == nullptr) {
        return nullptr;
    }
    oracle_io *t = new oracle_io();
    t->oc = dynamic_cast<octomap::OcTree *>(a);
    t->color = dynamic_cast<octomap::ColorOcTree *>(a);
    t->stamped = dynamic_cast<octomap::OcTreeStamped *>(a);
    t->kind = t->color ? ORACLE_COLOR : t->stamped ? ORACLE_STAMPED : ORACLE_OCTREE;
    if (!t->oc && !t->color && !t->stamped) {
        delete a;
        delete t;
        return nullptr;
    }
    return t;
}

extern "C" oracle_io_t *oracle_io_new(oracle_io_kind_t kind, double res)
{
    if (kind == ORACLE_COLOR) {
        return wrap(new octomap::ColorOcTree(oracle_user_resolution(res)));
    }
    if (kind == ORACLE_STAMPED) {
        return wrap(new octomap::OcTreeStamped(oracle_user_resolution(res)));
    }
    return wrap(new octomap::OcTree(oracle_user_resolution(res)));
}

extern "C" void oracle_io_free(oracle_io_t *t)
{
    if (t == nullptr) {
        return;
    }
    visit(t, [](auto *p) { delete p; return 0; });
    delete t;
}

extern "C" oracle_io_t *oracle_io_read_bt(const uint8_t *data, size_t len)
{
    std::istringstream s(std::string(reinterpret_cast<const char *>(data), len));
    octomap::OcTree *oc = new octomap::OcTree(0.1);
    if (!oc->readBinary(s)) {
        delete oc;
        return nullptr;
    }
    return wrap(oc);
}

extern "C" oracle_io_t *oracle_io_read_ot(const uint8_t *data, size_t len)
{
    std::istringstream s(std::string(reinterpret_cast<const char *>(data), len));
    return wrap(octomap::AbstractOcTree::read(s));
}

static uint8_t *copy_out(const std::string &str, size_t *len)
{
    uint8_t *out = static_cast<uint8_t *>(malloc(str.size() + 1));
    memcpy(out, str.data(), str.size());
    *len = str.size();
    return out;
}

extern "C" uint8_t *oracle_io_write_bt(oracle_io_t *t, size_t *len)
{
    std::ostringstream s;
    visit(t, [&](auto *p) { return p->writeBinary(s); });
    return copy_out(s.str(), len);
}

extern "C" uint8_t *oracle_io_write_ot(const oracle_io_t *t, size_t *len)
{
    std::ostringstream s;
    visit(t, [&](auto *p) { return p->write(s); });
    return copy_out(s.str(), len);
}

extern "C" oracle_io_t *oracle_io_read_bt_file(const char *path)
{
    octomap::OcTree *oc = new octomap::OcTree(0.1);
    if (!oc->readBinary(std::string(path))) {
        delete oc;
        return nullptr;
    }
    return wrap(oc);
}

extern "C" bool oracle_io_write_bt_file(oracle_io_t *t, const char *path)
{
    return visit(t, [&](auto *p) { return p->writeBinary(std::string(path)); });
}

extern "C" void oracle_io_prune(oracle_io_t *t)
{
    visit(t, [](auto *p) { p->prune(); return 0; });
}

extern "C" size_t oracle_io_size(const oracle_io_t *t)
{
    return visit(t, [](auto *p) { return p->size(); });
}

extern "C" double oracle_io_resolution(const oracle_io_t *t)
{
    return visit(t, [](auto *p) { return p->getResolution(); });
}

extern "C" void oracle_io_update(oracle_io_t *t, uint32_t kx, uint32_t ky, uint32_t kz, float d)
{
    const OcTreeKey k((octomap::key_type)kx, (octomap::key_type)ky, (octomap::key_type)kz);
    visit(t, [&](auto *p) { p->updateNode(k, d); return 0; });
    if (t->kind == ORACLE_COLOR) {
        t->color->setNodeColor(k, (uint8_t)kx, (uint8_t)ky, (uint8_t)kz);
    }
}

extern "C" void oracle_io_set(oracle_io_t *t, uint32_t kx, uint32_t ky, uint32_t kz, float lo)
{
    const OcTreeKey k((octomap::key_type)kx, (octomap::key_type)ky, (octomap::key_type)kz);
    visit(t, [&](auto *p) { p->setNodeValue(k, lo); return 0; });
}

extern "C" bool oracle_io_insert_graph(oracle_io_t *t, const char *path, unsigned max_scans,
                                       double max_range_m)
{
    std::ifstream f(path, std::ios_base::binary);
    if (!f.is_open()) {
        return false;
    }
    octomap::ScanGraph g;
    g.readBinary(f);
    unsigned n = 0;
    for (auto it = g.begin(); it != g.end() && n < max_scans; ++it, ++n) {
        visit(t, [&](auto *p) { p->insertPointCloud(**it, max_range_m); return 0; });
    }
    return n > 0;
}

extern "C" size_t oracle_io_for_each_leaf(const oracle_io_t *t, oracle_io_leaf_fn fn, void *ctx)
{
    return visit(t, [&](auto *p) {
        size_t n = 0;
        for (auto it = p->begin_leafs(), end = p->end_leafs(); it != end; ++it) {
            const OcTreeKey k = it.getKey();
            const unsigned level = 16u - it.getDepth();
            const uint32_t mask = ~((1u << level) - 1u);
            const uint32_t key[3] = {k[0] & mask, k[1] & mask, k[2] & mask};
            fn(ctx, key, level, it->getLogOdds());
            n++;
        }
        return n;
    });
}

extern "C" bool oracle_io_search(const oracle_io_t *t, const uint32_t key[3], unsigned level,
                                 unsigned *found_level, float *logodds, bool *has_children)
{
    return visit(t, [&](auto *p) {
        // Walk down by hand: search() hides the depth at which it stopped.
        auto *node = p->getRoot();
        if (node == nullptr) {
            return false;
        }
        const OcTreeKey k((octomap::key_type)key[0], (octomap::key_type)key[1],
                          (octomap::key_type)key[2]);
        unsigned lv = 16;
        while (lv > level && p->nodeHasChildren(node)) {
            const unsigned bit = lv - 1;
            const unsigned slot = ((k[0] >> bit) & 1u) | (((k[1] >> bit) & 1u) << 1) |
                                  (((k[2] >> bit) & 1u) << 2);
            if (!p->nodeChildExists(node, slot)) {
                return false;
            }
            node = p->getNodeChild(node, slot);
            lv--;
        }
        *found_level = lv;
        *logodds = node->getLogOdds();
        *has_children = p->nodeHasChildren(node);
        return true;
    });
}

namespace {
struct side {
    const oracle_io_t *other;
    float tol;
    bool ok;
    long double volume;
    std::string why;
};
}  // namespace

static void check_leaf(void *ctx, const uint32_t key[3], unsigned level, float lo)
{
    side *s = static_cast<side *>(ctx);
    s->volume += std::ldexp(1.0L, (int)(3 * level));
    if (!s->ok) {
        return;
    }
    unsigned fl = 0;
    float v = 0;
    bool ch = false;
    if (!oracle_io_search(s->other, key, level, &fl, &v, &ch)) {
        s->ok = false;
        char buf[160];
        snprintf(buf, sizeof buf, "leaf (%u,%u,%u) level %u missing in the other tree", key[0],
                 key[1], key[2], level);
        s->why = buf;
        return;
    }
    if (!ch && std::fabs(v - lo) > s->tol) {
        s->ok = false;
        char buf[160];
        snprintf(buf, sizeof buf, "leaf (%u,%u,%u) level %u: %.6f vs %.6f", key[0], key[1],
                 key[2], level, (double)lo, (double)v);
        s->why = buf;
    }
}

extern "C" bool oracle_io_equivalent(const oracle_io_t *a, const oracle_io_t *b, float tol,
                                     char *why, size_t why_len)
{
    side sa{b, tol, true, 0, ""}, sb{a, tol, true, 0, ""};
    oracle_io_for_each_leaf(a, check_leaf, &sa);
    oracle_io_for_each_leaf(b, check_leaf, &sb);
    std::string w;
    if (!sa.ok) {
        w = "a->b: " + sa.why;
    } else if (!sb.ok) {
        w = "b->a: " + sb.why;
    } else if (sa.volume != sb.volume) {
        w = "known volumes differ";
    }
    if (why != nullptr && why_len > 0) {
        snprintf(why, why_len, "%s", w.c_str());
    }
    return w.empty();
}

extern "C" void oracle_io_insert_cloud(oracle_io_t *t, const float *xyz, size_t n,
                                       const float origin[3], double max_range_m, bool discretize)
{
    octomap::Pointcloud pc;
    pc.reserve(n);
    for (size_t i = 0; i < n; i++) {
        pc.push_back(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
    }
    const octomap::point3d o(origin[0], origin[1], origin[2]);
    visit(t, [&](auto *p) { p->insertPointCloud(pc, o, max_range_m, false, discretize); return 0; });
}
