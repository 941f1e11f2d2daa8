// SPDX-License-Identifier: BSD-3-Clause
// bench_io.cpp - load/save times of geb079.bt (and the other formats) for occmap against
// OctoMap's readBinary/writeBinary in the same run; median of N runs; bytes per file.
#include <octomap/OcTree.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

extern "C" {
#include "occmap/occmap.h"
#include "occmap/host/occ_file.h"
}

static double now_ms()
{
    using namespace std::chrono;
    return duration<double, std::milli>(steady_clock::now().time_since_epoch()).count();
}

template <class F> static double median_ms(int runs, F f)
{
    std::vector<double> t;
    for (int i = 0; i < runs; i++) {
        const double t0 = now_ms();
        f();
        t.push_back(now_ms() - t0);
    }
    std::sort(t.begin(), t.end());
    return t[t.size() / 2];
}

static occ_err_t vec_write(void *ctx, const void *data, size_t len)
{
    auto *v = static_cast<std::vector<uint8_t> *>(ctx);
    const uint8_t *p = static_cast<const uint8_t *>(data);
    v->insert(v->end(), p, p + len);
    return OCC_OK;
}

int main(int argc, char **argv)
{
    const char *path = argc > 1 ? argv[1] : "/usr/share/doc/liboctomap-dev/examples/data/geb079.bt";
    const int runs = argc > 2 ? atoi(argv[2]) : 7;
    std::ifstream f(path, std::ios::binary);
    if (!f) {
        fprintf(stderr, "bench_io: cannot read %s\n", path);
        return 1;
    }
    std::string file((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    const uint8_t *buf = reinterpret_cast<const uint8_t *>(file.data());
    occ_io_info_t info;
    if (occ_io_probe(buf, file.size(), nullptr, &info) != OCC_OK) {
        fprintf(stderr, "bench_io: %s: %s\n", path, info.error);
        return 1;
    }
    const size_t arena_bytes = info.arena_bytes_needed + 64;
    std::vector<uint8_t> arena(arena_bytes);
    occ_map_t map;

    // Load from memory.
    const double occ_load = median_ms(runs, [&] {
        if (occ_io_load(&map, nullptr, arena.data(), arena_bytes, buf, file.size(), nullptr) != OCC_OK) {
            abort();
        }
    });
    const double om_load = median_ms(runs, [&] {
        std::istringstream s(file);
        octomap::OcTree t(0.1);
        if (!t.readBinary(s)) {
            abort();
        }
    });
    // Load from the file (read included).
    char msg[256];
    const double occ_load_file = median_ms(runs, [&] {
        if (occ_file_load(path, nullptr, &map, arena.data(), arena_bytes, msg, sizeof msg) != OCC_OK) {
            abort();
        }
    });
    const double om_load_file = median_ms(runs, [&] {
        octomap::OcTree t(0.1);
        if (!t.readBinary(std::string(path))) {
            abort();
        }
    });
    // Save to memory.
    std::vector<uint8_t> out;
    out.reserve(file.size() * 8);
    const double occ_save = median_ms(runs, [&] {
        out.clear();
        if (occ_io_write(&map, OCC_FORMAT_BT, vec_write, &out, nullptr) != OCC_OK) {
            abort();
        }
    });
    octomap::OcTree om(0.1);
    {
        std::istringstream s(file);
        om.readBinary(s);
    }
    std::string om_out;
    const double om_save = median_ms(runs, [&] {
        std::ostringstream s;
        om.writeBinary(s);
        om_out = s.str();
    });
    const bool identical = om_out.size() == out.size() && memcmp(om_out.data(), out.data(), out.size()) == 0;

    // The other formats (occmap only; OctoMap's .ot for the byte count).
    std::vector<uint8_t> ot, snap;
    const double occ_save_ot = median_ms(runs, [&] {
        ot.clear();
        occ_io_write(&map, OCC_FORMAT_OT, vec_write, &ot, nullptr);
    });
    const double occ_save_snap = median_ms(runs, [&] {
        snap.clear();
        occ_io_write(&map, OCC_FORMAT_SNAPSHOT, vec_write, &snap, nullptr);
    });
    occ_map_t m2;
    const double occ_load_ot = median_ms(runs, [&] {
        if (occ_io_load(&m2, nullptr, arena.data(), arena_bytes, ot.data(), ot.size(), nullptr) != OCC_OK) {
            abort();
        }
    });
    const double occ_load_snap = median_ms(runs, [&] {
        if (occ_io_load(&m2, nullptr, arena.data(), arena_bytes, snap.data(), snap.size(), nullptr) != OCC_OK) {
            abort();
        }
    });
    std::ostringstream oms;
    om.write(oms);
    const double om_load_ot = median_ms(runs, [&] {
        std::istringstream s(oms.str());
        delete octomap::AbstractOcTree::read(s);
    });
    // Atomic file save (temp + fsync + rename) for the record.
    const double occ_save_file = median_ms(runs, [&] {
        if (occ_file_save("/tmp/occ_bench_io.bt", &map, msg, sizeof msg) != OCC_OK) {
            abort();
        }
    });
    const double om_save_file = median_ms(runs, [&] { om.writeBinary(std::string("/tmp/occ_bench_io_om.bt")); });
    remove("/tmp/occ_bench_io.bt");
    remove("/tmp/occ_bench_io_om.bt");

    occ_map_stats_t st;
    occ_map_pool_stats(&map, &st);
    printf("== bench io: %s (%llu nodes, res %g m), median of %d runs\n", path,
           (unsigned long long)info.nodes, (double)info.resolution_m, runs);
    printf("%-34s %10s %10s %8s\n", "operation", "occmap ms", "OctoMap ms", "ratio");
    auto row = [](const char *what, double a, double b) {
        printf("%-34s %10.2f %10.2f %7.2fx\n", what, a, b, b / a);
    };
    row(".bt load (memory)", occ_load, om_load);
    row(".bt load (file, read included)", occ_load_file, om_load_file);
    row(".bt save (memory)", occ_save, om_save);
    row(".ot load (memory)", occ_load_ot, om_load_ot);
    printf("%-34s %10.2f %10.2f   (occmap: temp+fsync+rename; OctoMap: no fsync)\n",
           ".bt save (file)", occ_save_file, om_save_file);
    printf("%-34s %10.2f\n", ".ot save (memory, occmap)", occ_save_ot);
    printf("%-34s %10.2f\n", ".occ snapshot save (memory)", occ_save_snap);
    printf("%-34s %10.2f\n", ".occ snapshot load (memory)", occ_load_snap);
    printf("bytes: .bt %zu (occmap output %s OctoMap's), .ot %zu (OctoMap %zu), .occ %zu; "
           "arena %zu bytes (%u inner + %u leaf blocks) vs OctoMap memoryUsage %zu\n",
           out.size(), identical ? "identical to" : "DIFFERS from", ot.size(), oms.str().size(),
           snap.size(), st.bytes_used, (unsigned)st.inner_used, (unsigned)st.leaf_used,
           (size_t)om.memoryUsage());
    printf("bytes per node: .bt %.3f, .ot %.3f, .occ %.3f\n",
           (double)out.size() / (double)info.nodes, (double)ot.size() / (double)info.nodes,
           (double)snap.size() / (double)info.nodes);
    return identical ? 0 : 1;
}
