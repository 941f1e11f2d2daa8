// SPDX-License-Identifier: BSD-3-Clause
// oracle_ranges.cpp - OctoMap 1.9.7's insertRay() for the range-beam tests (oracle_ranges.h).
#include <octomap/OcTree.h>

#include <cstddef>

#include "oracle_ranges.h"

using octomap::OcTree;
using octomap::point3d;

extern "C" void oracle_ins_ray(void *t, const float origin[3], const float end[3],
                               double max_range)
{
    static_cast<OcTree *>(t)->insertRay(point3d(origin[0], origin[1], origin[2]),
                                        point3d(end[0], end[1], end[2]), max_range, false);
}

extern "C" void oracle_ins_volume(void *t, size_t *voxels, size_t *occupied)
{
    OcTree *const tree = static_cast<OcTree *>(t);
    *voxels = 0;
    *occupied = 0;
    const unsigned depth = tree->getTreeDepth();
    for (auto it = tree->begin_leafs(), end = tree->end_leafs(); it != end; ++it) {
        const size_t n = (size_t)1 << (3u * (depth - it.getDepth()));
        *voxels += n;
        *occupied += tree->isNodeOccupied(*it) ? n : 0u;
    }
}
