// SPDX-License-Identifier: BSD-3-Clause
// oracle_rays.cpp - OctoMap 1.9.7 (Debian liboctomap) as the reference for ray keys and point-cloud
// integration. extern "C" API for the C tests (tests/support/oracle_rays.h).
#include <octomap/OcTree.h>
#include <octomap/octomap.h>

#include <cstddef>
#include <cstdint>

#include "oracle_res.hpp"
#include "oracle_rays.h"

using octomap::OcTree;
using octomap::OcTreeKey;
using octomap::point3d;

extern "C" int oracle_ray_keys(double res, const float o[3], const float e[3], uint32_t *keys,
                               size_t cap, size_t *n)
{
    static OcTree *tree = nullptr;
    const double user_res = oracle_user_resolution(res);
    if (tree == nullptr || tree->getResolution() != user_res) {
        delete tree;
        tree = new OcTree(user_res);
    }
    static octomap::KeyRay ray;
    const bool ok = tree->computeRayKeys(point3d(o[0], o[1], o[2]), point3d(e[0], e[1], e[2]), ray);
    *n = ray.size();
    size_t i = 0;
    for (auto it = ray.begin(); it != ray.end() && i < cap; ++it, ++i) {
        keys[3 * i] = (*it)[0];
        keys[3 * i + 1] = (*it)[1];
        keys[3 * i + 2] = (*it)[2];
    }
    return ok ? 1 : 0;
}

extern "C" void oracle_ray_free_static(void) {}

extern "C" void *oracle_ins_new(double res)
{
    return new OcTree(oracle_user_resolution(res));
}

extern "C" void oracle_ins_delete(void *t)
{
    delete static_cast<OcTree *>(t);
}

extern "C" void oracle_ins_cloud(void *t, const float *xyz, size_t n, const float origin[3],
                                 double max_range, int discretize)
{
    octomap::Pointcloud pc;
    pc.reserve(n);
    for (size_t i = 0; i < n; i++) {
        pc.push_back(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
    }
    static_cast<OcTree *>(t)->insertPointCloud(pc, point3d(origin[0], origin[1], origin[2]),
                                               max_range, false, discretize != 0);
}

extern "C" size_t oracle_ins_leaves(void *t, uint32_t *keys, uint8_t *levels, float *logodds,
                                    size_t cap)
{
    OcTree *const tree = static_cast<OcTree *>(t);
    size_t i = 0;
    for (auto it = tree->begin_leafs(); it != tree->end_leafs(); ++it) {
        if (i < cap) {
            const OcTreeKey k = it.getKey();
            const unsigned level = tree->getTreeDepth() - it.getDepth();
            const unsigned mask = ~((1u << level) - 1u);
            keys[3 * i] = k[0] & mask;
            keys[3 * i + 1] = k[1] & mask;
            keys[3 * i + 2] = k[2] & mask;
            levels[i] = (uint8_t)level;
            logodds[i] = it->getLogOdds();
        }
        i++;
    }
    return i;
}

extern "C" int oracle_ins_search(void *t, const uint32_t key[3], float *logodds, unsigned *level)
{
    OcTree *const tree = static_cast<OcTree *>(t);
    const OcTreeKey k((octomap::key_type)key[0], (octomap::key_type)key[1],
                      (octomap::key_type)key[2]);
    // search() returns the deepest node on the path (a pruned ancestor answers for its voxels).
    unsigned depth = 0;
    octomap::OcTreeNode *node = tree->getRoot();
    if (node == nullptr) {
        return 0;
    }
    while (depth < tree->getTreeDepth() && tree->nodeHasChildren(node)) {
        const unsigned pos = octomap::computeChildIdx(k, (int)(tree->getTreeDepth() - 1 - depth));
        if (!tree->nodeChildExists(node, pos)) {
            return 0;
        }
        node = tree->getNodeChild(node, pos);
        depth++;
    }
    *logodds = node->getLogOdds();
    *level = tree->getTreeDepth() - depth;
    return 1;
}

extern "C" size_t oracle_ins_memory(void *t)
{
    return static_cast<OcTree *>(t)->memoryUsage();
}
