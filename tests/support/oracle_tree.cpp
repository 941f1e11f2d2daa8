// SPDX-License-Identifier: BSD-3-Clause
// oracle_tree.cpp - octomap::OcTree behind the C API of oracle_tree.h (test/bench reference).
#include "oracle_res.hpp"
#include "oracle_tree.h"

#include <octomap/OcTree.h>

#include <new>

struct oracle_tree {
    explicit oracle_tree(double res) : tree(oracle_user_resolution(res)) {}
    octomap::OcTree tree;
};

static octomap::OcTreeKey make_key(uint32_t kx, uint32_t ky, uint32_t kz)
{
    return octomap::OcTreeKey(static_cast<octomap::key_type>(kx),
                              static_cast<octomap::key_type>(ky),
                              static_cast<octomap::key_type>(kz));
}

extern "C" {

oracle_tree_t *oracle_tree_new(double resolution_m)
{
    return new (std::nothrow) oracle_tree(resolution_m);
}

void oracle_tree_free(oracle_tree_t *t)
{
    delete t;
}

void oracle_tree_clear(oracle_tree_t *t)
{
    t->tree.clear();
}

void oracle_tree_params(const oracle_tree_t *t, float *hit, float *miss, float *clamp_min,
                        float *clamp_max, float *occ_thres)
{
    *hit = t->tree.getProbHitLog();
    *miss = t->tree.getProbMissLog();
    *clamp_min = t->tree.getClampingThresMinLog();
    *clamp_max = t->tree.getClampingThresMaxLog();
    *occ_thres = t->tree.getOccupancyThresLog();
}

void oracle_tree_update_key(oracle_tree_t *t, uint32_t kx, uint32_t ky, uint32_t kz,
                            bool occupied)
{
    t->tree.updateNode(make_key(kx, ky, kz), occupied);
}

void oracle_tree_update_key_logodds(oracle_tree_t *t, uint32_t kx, uint32_t ky, uint32_t kz,
                                    float delta)
{
    t->tree.updateNode(make_key(kx, ky, kz), delta);
}

bool oracle_tree_coord_to_key(const oracle_tree_t *t, double x, double y, double z,
                              uint32_t key[3])
{
    octomap::OcTreeKey k;
    if (!t->tree.coordToKeyChecked(x, y, z, k)) {
        return false;
    }
    for (unsigned i = 0; i < 3; i++) {
        key[i] = k[i];
    }
    return true;
}

size_t oracle_tree_size(const oracle_tree_t *t)
{
    return t->tree.size();
}

size_t oracle_tree_memory_usage(const oracle_tree_t *t)
{
    return t->tree.memoryUsage();
}

size_t oracle_tree_num_leaf_nodes(const oracle_tree_t *t)
{
    return t->tree.getNumLeafNodes();
}

void oracle_tree_leaf_counts(const oracle_tree_t *t, uint64_t *occupied, uint64_t *free_)
{
    uint64_t o = 0, f = 0;
    for (octomap::OcTree::leaf_iterator it = t->tree.begin_leafs(), end = t->tree.end_leafs();
         it != end; ++it) {
        if (t->tree.isNodeOccupied(*it)) {
            o++;
        } else {
            f++;
        }
    }
    *occupied = o;
    *free_ = f;
}

size_t oracle_tree_for_each_leaf(const oracle_tree_t *t, oracle_tree_leaf_fn fn, void *ctx)
{
    size_t n = 0;
    const unsigned max_depth = t->tree.getTreeDepth();
    for (octomap::OcTree::leaf_iterator it = t->tree.begin_leafs(), end = t->tree.end_leafs();
         it != end; ++it) {
        const unsigned level = max_depth - it.getDepth();
        const octomap::OcTreeKey k = it.getKey();
        uint32_t key[3];
        for (unsigned i = 0; i < 3; i++) {
            key[i] = static_cast<uint32_t>(k[i]) & ~((1u << level) - 1u);
        }
        fn(ctx, key, level, it->getLogOdds(), t->tree.isNodeOccupied(*it));
        n++;
    }
    return n;
}

bool oracle_tree_search(const oracle_tree_t *t, const uint32_t key[3], unsigned level,
                        unsigned *found_level, float *logodds, bool *has_children)
{
    const unsigned max_depth = t->tree.getTreeDepth();
    const octomap::OcTreeKey k = make_key(key[0], key[1], key[2]);
    // Descend by hand so the level of the node found is known (search() hides it).
    const octomap::OcTreeNode *node = t->tree.getRoot();
    if (node == nullptr) {
        return false;
    }
    unsigned depth = 0;
    while (depth < max_depth - level && t->tree.nodeHasChildren(node)) {
        const unsigned bit = max_depth - 1u - depth;
        unsigned pos = 0;
        for (unsigned i = 0; i < 3; i++) {
            if ((k[i] >> bit) & 1u) {
                pos |= 1u << i;
            }
        }
        if (!t->tree.nodeChildExists(node, pos)) {
            return false;
        }
        node = t->tree.getNodeChild(node, pos);
        depth++;
    }
    *found_level = max_depth - depth;
    *logodds = node->getLogOdds();
    *has_children = t->tree.nodeHasChildren(node);
    return true;
}

}  // extern "C"
