// SPDX-License-Identifier: BSD-3-Clause
// oracle_geom.cpp - OctoMap 1.9.7's coordToKeyChecked / keyToCoord for the geometry tests.
#include <octomap/OcTree.h>

#include "oracle_geom.h"
#include "oracle_res.hpp"

static octomap::OcTree &tree_for(float res_f)
{
    static octomap::OcTree *tree = nullptr;
    const double res = oracle_user_resolution(static_cast<double>(res_f));
    if (tree == nullptr || tree->getResolution() != res) {
        delete tree;
        tree = new octomap::OcTree(res);
    }
    return *tree;
}

extern "C" double oracle_geom_user_res(double res)
{
    return oracle_user_resolution(res);
}

extern "C" int oracle_geom_key(float res_f, float x, float y, float z, uint32_t key[3])
{
    octomap::OcTreeKey k;
    if (!tree_for(res_f).coordToKeyChecked(octomap::point3d(x, y, z), k)) {
        return 0;
    }
    for (int i = 0; i < 3; i++) {
        key[i] = k[i];
    }
    return 1;
}

extern "C" void oracle_geom_center(float res_f, const uint32_t key[3], unsigned level, float out[3])
{
    octomap::OcTree &t = tree_for(res_f);
    const unsigned depth = 16u - level;
    for (int i = 0; i < 3; i++) {
        const octomap::key_type k = static_cast<octomap::key_type>(key[i]);
        out[i] = static_cast<float>(t.keyToCoord(k, depth));
    }
}
