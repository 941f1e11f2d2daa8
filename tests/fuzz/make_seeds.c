/* SPDX-License-Identifier: BSD-3-Clause */
/* make_seeds.c - the fuzz seed corpus: small crops of real maps (geb079.bt, and the shared
 * .ot when present) written as .bt, .ot and .occ. usage: make_seeds OUTDIR */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "occmap/occmap.h"
#include "occmap/host/occ_file.h"

static uint8_t crop_arena[1u << 20];

/* Copy the observed leaves of `src` whose first voxel lies in [lo, lo + size) into `dst`. */
static void crop(const occ_map_t *src, occ_map_t *dst, const uint32_t lo[3], uint32_t size)
{
    occ_walk_t w;
    occ_walk_node_t n;
    occ_walk_begin(&w, src);
    while (occ_walk_next(&w, &n)) {
        int inside = 1;
        for (int a = 0; a < 3; a++) {
            inside = inside && n.key.k[a] >= lo[a] && n.key.k[a] < lo[a] + size;
        }
        if (!n.has_children && n.observed && inside) {
            (void)occ_map_set_key(dst, n.key, n.level, occ_value_to_logodds(n.value));
        }
    }
}

static void emit(const char *in, const char *outdir, const char *name, const uint32_t lo[3],
                 uint32_t size)
{
    occ_map_t src, dst;
    void *arena = NULL;
    char msg[256];
    if (occ_file_load_alloc(in, NULL, &src, 0u, &arena, NULL, msg, sizeof msg) != OCC_OK) {
        fprintf(stderr, "make_seeds: %s (skipped)\n", msg);
        return;
    }
    occ_map_init(&dst, &src.cfg, crop_arena, sizeof crop_arena);
    uint32_t at[3] = {lo[0], lo[1], lo[2]};
    if (lo[0] == 0u) {  /* anchor the box at the 2000th voxel-level leaf of the map */
        occ_walk_t w;
        occ_walk_node_t n;
        unsigned seen = 0u;
        occ_walk_begin(&w, &src);
        while (occ_walk_next(&w, &n)) {
            if (n.level == 0u && ++seen == 2000u) {
                for (int a = 0; a < 3; a++) {
                    at[a] = n.key.k[a] - size / 2u;
                }
                break;
            }
        }
    }
    crop(&src, &dst, at, size);
    const char *ext[3] = {"bt", "ot", "occ"};
    for (int i = 0; i < 3; i++) {
        char path[512];
        snprintf(path, sizeof path, "%s/%s/%s.%s", outdir, ext[i], name, ext[i]);
        if (occ_file_save(path, &dst, msg, sizeof msg) != OCC_OK) {
            fprintf(stderr, "make_seeds: %s\n", msg);
            exit(1);
        }
    }
    free(arena);
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: make_seeds OUTDIR\n");
        return 2;
    }
    const uint32_t g1[3] = {32768u - 64u, 32768u - 64u, 32768u - 8u};
    const uint32_t g2[3] = {32768u + 64u, 32768u - 32u, 32768u - 8u};
    emit("/usr/share/doc/liboctomap-dev/examples/data/geb079.bt", argv[1], "geb079_a", g1, 32u);
    emit("/usr/share/doc/liboctomap-dev/examples/data/geb079.bt", argv[1], "geb079_b", g2, 16u);
    const uint32_t f1[3] = {0u, 0u, 0u};
    emit("../shared/data/maps/fr_079_t1_model.ot", argv[1], "fr079", f1, 16u);
    return 0;
}
