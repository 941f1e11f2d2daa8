/* SPDX-License-Identifier: BSD-3-Clause */
/* crop_map.c - host helper of `make bench-m4`: the part of a map inside an axis-aligned box,
 * as a snapshot (.occ) small enough for a microcontroller's RAM. Every childless node (voxel or
 * pruned uniform node) whose cube meets the box is copied whole with its log-odds, so pruned
 * nodes on the border stay pruned (the crop may reach up to one such node past the box).
 *
 * usage: crop_map IN OUT XMIN YMIN ZMIN XMAX YMAX ZMAX     (metres, map frame)
 * Prints the crop's size. Host only (POSIX file helpers). */
#include <stdio.h>
#include <stdlib.h>

#include "occmap/occmap.h"
#include "occmap/host/occ_file.h"

static int meets_box(const occ_map_t *m, const occ_walk_node_t *n, const float lo[3],
                     const float hi[3])
{
    const occ_vec3_t c = occ_map_key_center(m, n->key, n->level);
    const float h = 0.5f * occ_map_node_size(m, n->level);
    const float cc[3] = {c.x, c.y, c.z};
    for (int i = 0; i < 3; i++) {
        if (cc[i] + h < lo[i] || cc[i] - h > hi[i]) {
            return 0;
        }
    }
    return 1;
}

int main(int argc, char **argv)
{
    if (argc != 9) {
        fprintf(stderr, "usage: crop_map IN OUT XMIN YMIN ZMIN XMAX YMAX ZMAX\n");
        return 2;
    }
    float lo[3], hi[3];
    for (int i = 0; i < 3; i++) {
        lo[i] = strtof(argv[3 + i], NULL);
        hi[i] = strtof(argv[6 + i], NULL);
    }
    char msg[256];
    occ_map_t full, crop;
    void *arena_full = NULL;
    occ_io_info_t info;
    if (occ_file_load_alloc(argv[1], NULL, &full, 0, &arena_full, &info, msg, sizeof msg) !=
        OCC_OK) {
        fprintf(stderr, "crop_map: %s\n", msg);
        return 1;
    }
    const size_t cap = info.arena_bytes_needed;
    void *arena_crop = malloc(cap);
    if (arena_crop == NULL || occ_map_init(&crop, &full.cfg, arena_crop, cap) != OCC_OK) {
        fprintf(stderr, "crop_map: no memory for the crop\n");
        return 1;
    }
    occ_walk_t w;
    occ_walk_node_t n;
    unsigned long copied = 0;
    occ_walk_begin(&w, &full);
    while (occ_walk_next(&w, &n)) {
        if (!meets_box(&full, &n, lo, hi)) {
            occ_walk_skip_children(&w);
        } else if (!n.has_children) {
            if (occ_map_set_key(&crop, n.key, n.level, occ_value_to_logodds(n.value)) != OCC_OK) {
                fprintf(stderr, "crop_map: set_key failed\n");
                return 1;
            }
            copied++;
        }
    }
    if (occ_walk_status(&w) != OCC_OK || occ_map_check(&crop) != OCC_OK ||
        occ_file_save(argv[2], &crop, msg, sizeof msg) != OCC_OK) {
        fprintf(stderr, "crop_map: %s\n", msg);
        return 1;
    }
    occ_map_stats_t st;
    occ_map_pool_stats(&crop, &st);
    printf("crop_map: %s -> %s: %lu nodes in (%.2f %.2f %.2f) .. (%.2f %.2f %.2f) m, "
           "%u inner + %u leaf blocks\n",
           argv[1], argv[2], copied, (double)lo[0], (double)lo[1], (double)lo[2], (double)hi[0],
           (double)hi[1], (double)hi[2], (unsigned)st.inner_used, (unsigned)st.leaf_used);
    free(arena_crop);
    free(arena_full);
    return 0;
}
