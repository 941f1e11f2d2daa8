// SPDX-License-Identifier: BSD-3-Clause
// oracle_stats.cpp - OctoMap's own statistics of a tree (see oracle_stats.h).
#include "oracle_stats.h"

#include <octomap/OcTree.h>

#include <sstream>
#include <string>

static void stats_of(const octomap::OcTree &t, oracle_stats_t *out)
{
    *out = oracle_stats_t();
    out->resolution_m = t.getResolution();
    out->nodes = t.size();
    out->leaf_nodes = t.getNumLeafNodes();
    for (octomap::OcTree::leaf_iterator it = t.begin_leafs(), end = t.end_leafs(); it != end;
         ++it) {
        const double s = it.getSize();
        if (t.isNodeOccupied(*it)) {
            out->occupied_leaves++;
            out->occupied_volume_m3 += s * s * s;
        } else {
            out->free_leaves++;
            out->free_volume_m3 += s * s * s;
        }
    }
}

extern "C" bool oracle_stats_bt(const uint8_t *data, size_t len, oracle_stats_t *out)
{
    std::istringstream s(std::string(reinterpret_cast<const char *>(data), len));
    octomap::OcTree t(0.1);
    if (!t.readBinary(s)) {
        return false;
    }
    t.prune(); /* files may hold prunable children; occmap prunes on load, as OctoMap can */
    stats_of(t, out);
    return true;
}
