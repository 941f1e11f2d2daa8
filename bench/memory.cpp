// SPDX-License-Identifier: BSD-3-Clause
// bench/memory.cpp - memory per stored voxel: occmap vs OctoMap for the same content.
//
// Content 1: the endpoints of OctoMap's real scan.dat marked occupied (updateNode(key, true) in
// both, occmap configured with OctoMap's exact sensor model so both hold the same values).
// Content 2: the same scan integrated by OctoMap with free space (insertPointCloud from the
// origin, as octomap's tools do), then copied leaf by leaf into occmap (occ_map_set_key at the
// leaf's level), so both hold the same tree; this is the "407,411 nodes at 0.1 m" case.
// For each resolution (0.1 m, 0.05 m): nodes, leaves, bytes, bytes per node and per leaf, and
// the ratio occmap / OctoMap memoryUsage(). Endpoint insertion time: median of 5 runs each.
// The table row (bench_rows.hpp, issue 22) is the scan+free tree at 0.05 m: id
// memory/scan.dat/0.05/16bit, or .../8bit when built against a library with OCC_VALUE_BITS 8
// (build/bench/memory8, `make bench-memory` runs both). The byte counts are the pool blocks in
// use (occ_map_stats bytes_used) vs OctoMap's memoryUsage(); no repetitions (sizes are exact).
// Usage: memory SCAN.dat OUT.json [ROWS.json]
#include <octomap/OcTree.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "../tests/support/oracle_res.hpp"
#include "bench_rows.hpp"
#include "occmap/occmap.h"
#include "occmap/host/occ_scan.h"

namespace {

const int kReps = 5;

double median(std::vector<double> v)
{
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

double now_s()
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

struct Row {
    std::string content;
    double res;
    uint64_t occ_nodes, occ_leaves, occ_bytes, occ_leaf_blocks;
    uint64_t om_nodes, om_leaves, om_bytes;
    double occ_insert_ms, om_insert_ms;  // < 0: not measured
};

occ_map_config_t config_like(const octomap::OcTree &t, double res)
{
    occ_map_config_t c = occ_map_config_default();
    c.resolution_m = static_cast<float>(res);
    c.depth_levels = 16;
    c.hit = t.getProbHitLog();
    c.miss = t.getProbMissLog();
    c.clamp_min = t.getClampingThresMinLog();
    c.clamp_max = t.getClampingThresMaxLog();
    c.free_max = c.occupied_min = t.getOccupancyThresLog();
    return c;
}

bool insert_endpoints_occ(occ_map_t *m, const std::vector<occ_vec3_t> &pts)
{
    for (const occ_vec3_t &p : pts) {
        occ_key_t k;
        if (occ_map_key(m, p, &k) != OCC_OK || occ_map_observe_key(m, k, true) != OCC_OK) {
            return false;
        }
    }
    return true;
}

void insert_endpoints_om(octomap::OcTree &t, const std::vector<occ_vec3_t> &pts)
{
    for (const occ_vec3_t &p : pts) {
        t.updateNode(octomap::point3d(p.x, p.y, p.z), true);
    }
}

void fill_row(Row &r, const occ_map_t *m, const octomap::OcTree &t)
{
    occ_map_stats_t st;
    occ_map_stats(m, &st);
    r.occ_nodes = st.nodes;
    r.occ_leaves = st.leaf_nodes;
    r.occ_bytes = st.bytes_used;
    r.occ_leaf_blocks = st.leaf_used;
    r.om_nodes = t.size();
    r.om_leaves = t.getNumLeafNodes();
    r.om_bytes = t.memoryUsage();
}

// The table's row: the scan+free tree at 0.05 m, occmap's pool bytes vs OctoMap's memoryUsage().
bool write_rows(const char *path, const std::vector<Row> &rows)
{
    const bool compact = OCC_VALUE_BITS == 8;
    const double goal = compact ? 0.10 : 0.174;
    std::vector<BenchRow> out;
    for (const Row &r : rows) {
        if (r.content != "scan+free" || r.res > 0.075) {
            continue;
        }
        BenchRow b;
        b.id = std::string("memory/scan.dat/0.05/") + (compact ? "8bit" : "16bit");
        b.work = std::string("map memory, scan.dat 0.05 m with free space (OctoMap's tree copied), ") +
                 (compact ? "8-bit" : "16-bit") + " values, leaf block " +
                 std::to_string(OCC_LEAF_BLOCK_BYTES) + " B, inner block " +
                 std::to_string(OCC_INNER_BLOCK_BYTES) + " B";
        b.unit = "MB";
        b.octomap = static_cast<double>(r.om_bytes) / 1e6;
        b.occmap = static_cast<double>(r.occ_bytes) / 1e6;
        b.ratio = b.ratio_min = b.ratio_max = b.octomap / b.occmap;
        b.reps = 1;
        b.target = compact ? "occmap <= 10% of OctoMap" : "occmap <= 17.4% of OctoMap";
        b.met = static_cast<double>(r.occ_bytes) <= goal * static_cast<double>(r.om_bytes);
        // Same tree: the 16-bit copy keeps every OctoMap leaf; the 8-bit one may prune siblings
        // whose values round to the same step, so it is compared by leaf count only.
        b.equal = r.occ_leaves == r.om_leaves ? "yes" : "no";
        out.push_back(b);
    }
    return !out.empty() && bench_rows_write(path, out);
}

}  // namespace

int main(int argc, char **argv)
{
    if (argc != 3 && argc != 4) {
        std::fprintf(stderr, "usage: %s SCAN.dat OUT.json [ROWS.json]\n", argv[0]);
        return 2;
    }
    occ_vec3_t *raw = nullptr;
    size_t n = 0;
    char msg[256] = "";
    if (occ_scan_read_xyz(argv[1], &raw, &n, msg, sizeof msg) != OCC_OK) {
        std::fprintf(stderr, "memory: cannot read %s: %s\n", argv[1], msg);
        return 1;
    }
    const std::vector<occ_vec3_t> pts(raw, raw + n);
    std::free(raw);
    const size_t arena_bytes = static_cast<size_t>(256) << 20;
    std::vector<uint8_t> arena(arena_bytes);
    std::vector<Row> rows;
    for (const float res_f : {0.1f, 0.05f}) {
        // OctoMap gets the decimal a user writes for occmap's float (OcTree(0.1) for 0.1f): the
        // resolution occmap's keys use, so both cut space at the same places.
        const double res = oracle_user_resolution(static_cast<double>(res_f));
        // ---- content 1: endpoints only ----
        Row r{"endpoints", res, 0, 0, 0, 0, 0, 0, 0, -1.0, -1.0};
        std::vector<double> t_occ, t_om;
        occ_map_t m;
        for (int rep = 0; rep < kReps; rep++) {
            octomap::OcTree t(res);
            const occ_map_config_t cfg = config_like(t, res);
            if (occ_map_init(&m, &cfg, arena.data(), arena.size()) != OCC_OK) {
                std::fprintf(stderr, "memory: occ_map_init failed\n");
                return 1;
            }
            double t0 = now_s();
            if (!insert_endpoints_occ(&m, pts)) {
                std::fprintf(stderr, "memory: occmap insertion failed\n");
                return 1;
            }
            t_occ.push_back((now_s() - t0) * 1e3);
            t0 = now_s();
            insert_endpoints_om(t, pts);
            t_om.push_back((now_s() - t0) * 1e3);
            if (rep == kReps - 1) {
                fill_row(r, &m, t);
            }
        }
        r.occ_insert_ms = median(t_occ);
        r.om_insert_ms = median(t_om);
        rows.push_back(r);
        // ---- content 2: OctoMap's integration with free space, copied into occmap ----
        Row r2{"scan+free", res, 0, 0, 0, 0, 0, 0, 0, -1.0, -1.0};
        octomap::OcTree t(res);
        octomap::Pointcloud cloud;
        for (const occ_vec3_t &p : pts) {
            cloud.push_back(p.x, p.y, p.z);
        }
        t.insertPointCloud(cloud, octomap::point3d(0, 0, 0));
        const occ_map_config_t cfg = config_like(t, res);
        if (occ_map_init(&m, &cfg, arena.data(), arena.size()) != OCC_OK) {
            return 1;
        }
        const unsigned depth = t.getTreeDepth();
        for (octomap::OcTree::leaf_iterator it = t.begin_leafs(), end = t.end_leafs(); it != end; ++it) {
            const unsigned level = depth - it.getDepth();
            const octomap::OcTreeKey k = it.getKey();
            occ_key_t key;
            for (unsigned i = 0; i < 3; i++) {
                key.k[i] = static_cast<uint32_t>(k[i]) & ~((1u << level) - 1u);
            }
            if (occ_map_set_key(&m, key, level, it->getLogOdds()) != OCC_OK) {
                std::fprintf(stderr, "memory: occ_map_set_key failed\n");
                return 1;
            }
        }
        if (occ_map_check(&m) != OCC_OK) {
            std::fprintf(stderr, "memory: occ_map_check failed\n");
            return 1;
        }
        fill_row(r2, &m, t);
        rows.push_back(r2);
    }

    std::printf("%-10s %5s | %9s %9s %10s %7s %7s | %9s %9s %10s %7s %7s | %6s %6s | %9s %9s\n",
                "content", "res", "occ nodes", "leaves", "bytes", "B/node", "B/leaf", "om nodes",
                "leaves", "bytes", "B/node", "B/leaf", "ratio", "floor", "occ ms", "om ms");
    std::string json = "{\"bench\":\"memory\",\"reps\":" + std::to_string(kReps) +
                       ",\"points\":" + std::to_string(pts.size()) + ",\"rows\":[";
    for (size_t i = 0; i < rows.size(); i++) {
        const Row &r = rows[i];
        const double ratio = static_cast<double>(r.occ_bytes) / static_cast<double>(r.om_bytes);
        // The least any layout with this build's values in blocks of 8 siblings addressed by
        // uint32 indices can use for this tree: one leaf block and one index per split level-1 node.
        const double floor_ratio =
            static_cast<double>(r.occ_leaf_blocks * (OCC_LEAF_BLOCK_BYTES + 4u)) / static_cast<double>(r.om_bytes);
        std::printf("%-10s %5.2f | %9llu %9llu %10llu %7.2f %7.2f | %9llu %9llu %10llu %7.2f %7.2f "
                    "| %5.1f%% %5.1f%% | %9s %9s\n",
                    r.content.c_str(), r.res, (unsigned long long)r.occ_nodes,
                    (unsigned long long)r.occ_leaves, (unsigned long long)r.occ_bytes,
                    static_cast<double>(r.occ_bytes) / static_cast<double>(r.occ_nodes),
                    static_cast<double>(r.occ_bytes) / static_cast<double>(r.occ_leaves),
                    (unsigned long long)r.om_nodes, (unsigned long long)r.om_leaves,
                    (unsigned long long)r.om_bytes,
                    static_cast<double>(r.om_bytes) / static_cast<double>(r.om_nodes),
                    static_cast<double>(r.om_bytes) / static_cast<double>(r.om_leaves),
                    100.0 * ratio, 100.0 * floor_ratio,
                    r.occ_insert_ms < 0 ? "-" : std::to_string(r.occ_insert_ms).substr(0, 7).c_str(),
                    r.om_insert_ms < 0 ? "-" : std::to_string(r.om_insert_ms).substr(0, 7).c_str());
        char buf[768];
        std::snprintf(buf, sizeof buf,
                      "%s{\"content\":\"%s\",\"resolution_m\":%.3f,\"occmap\":{\"nodes\":%llu,"
                      "\"leaf_nodes\":%llu,\"memory_bytes\":%llu,\"bytes_per_node\":%.3f,"
                      "\"bytes_per_leaf\":%.3f%s},\"octomap\":{\"nodes\":%llu,\"leaf_nodes\":%llu,"
                      "\"memory_bytes\":%llu,\"bytes_per_node\":%.3f,\"bytes_per_leaf\":%.3f%s},"
                      "\"memory_ratio\":%.5f,\"layout_floor_ratio\":%.5f}",
                      i ? "," : "", r.content.c_str(), r.res, (unsigned long long)r.occ_nodes,
                      (unsigned long long)r.occ_leaves, (unsigned long long)r.occ_bytes,
                      static_cast<double>(r.occ_bytes) / static_cast<double>(r.occ_nodes),
                      static_cast<double>(r.occ_bytes) / static_cast<double>(r.occ_leaves),
                      r.occ_insert_ms < 0 ? "" : (",\"insert_ms_median\":" + std::to_string(r.occ_insert_ms)).c_str(),
                      (unsigned long long)r.om_nodes, (unsigned long long)r.om_leaves,
                      (unsigned long long)r.om_bytes,
                      static_cast<double>(r.om_bytes) / static_cast<double>(r.om_nodes),
                      static_cast<double>(r.om_bytes) / static_cast<double>(r.om_leaves),
                      r.om_insert_ms < 0 ? "" : (",\"insert_ms_median\":" + std::to_string(r.om_insert_ms)).c_str(),
                      ratio, floor_ratio);
        json += buf;
    }
    json += "]}\n";
    std::printf("ratio = occmap bytes_used / OctoMap memoryUsage() for the same tree; target <= 10%%.\n"
                "floor = split level-1 nodes x (leaf block + 4 B index) / memoryUsage(): no layout "
                "with these values in 8-sibling blocks and uint32 indices goes below it.\n"
                "Insert times: median of %d runs, endpoints only.\n", kReps);
    std::printf("value mode: %d-bit, leaf block %u B, inner block %u B\n", OCC_VALUE_BITS,
                static_cast<unsigned>(OCC_LEAF_BLOCK_BYTES), static_cast<unsigned>(OCC_INNER_BLOCK_BYTES));
    if (argc == 4 && !write_rows(argv[3], rows)) {
        std::fprintf(stderr, "memory: cannot write %s\n", argv[3]);
        return 1;
    }
    FILE *f = std::fopen(argv[2], "w");
    if (f == nullptr || std::fputs(json.c_str(), f) < 0 || std::fclose(f) != 0) {
        std::fprintf(stderr, "memory: cannot write %s\n", argv[2]);
        return 1;
    }
    return 0;
}
