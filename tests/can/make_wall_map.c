/* SPDX-License-Identifier: BSD-3-Clause */
/* make_wall_map.c - a small known map for the can-feed tests: observed free space in a disc of
 * radius 5 m around the origin (z in [-0.6, 0.6] m), and an occupied wall 3 m north of the origin
 * (map y = 3.0 .. 3.1, x in [-2, 2]). usage: make_wall_map OUT.occ|OUT.bt */
#include <stdio.h>
#include <stdlib.h>

#include "occmap/host/occ_file.h"

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: make_wall_map OUT\n");
        return 2;
    }
    const size_t arena_bytes = 32u << 20;
    void *arena = malloc(arena_bytes);
    occ_map_t map;
    occ_map_config_t cfg = occ_map_config_default(); /* 0.1 m, depth 16 */
    if (arena == NULL || occ_map_init(&map, &cfg, arena, arena_bytes) != OCC_OK) {
        fprintf(stderr, "make_wall_map: init failed\n");
        return 1;
    }
    unsigned long n_free = 0, n_occ = 0;
    for (int iz = -6; iz < 6; iz++) {
        for (int iy = -50; iy < 50; iy++) {
            for (int ix = -50; ix < 50; ix++) {
                const occ_vec3_t p = {((float)ix + 0.5f) * 0.1f, ((float)iy + 0.5f) * 0.1f,
                                      ((float)iz + 0.5f) * 0.1f};
                const bool wall = iy == 30 && ix >= -20 && ix < 20;
                if (!wall && p.x * p.x + p.y * p.y > 25.0f) {
                    continue;
                }
                if (occ_map_update(&map, p, wall ? 3.0f : -3.0f) != OCC_OK) {
                    fprintf(stderr, "make_wall_map: update failed\n");
                    return 1;
                }
                if (wall) {
                    n_occ++;
                } else {
                    n_free++;
                }
            }
        }
    }
    char msg[200] = "";
    if (occ_file_save(argv[1], &map, msg, sizeof msg) != OCC_OK) {
        fprintf(stderr, "make_wall_map: save failed: %s\n", msg);
        return 1;
    }
    printf("make_wall_map: %s: %lu free, %lu occupied voxels\n", argv[1], n_free, n_occ);
    free(arena);
    return 0;
}
