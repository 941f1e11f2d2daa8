/* SPDX-License-Identifier: BSD-3-Clause */
/* consumer.c - a program outside the tree that uses an installed occmap (tests/install.mk):
 * one scan of a wall 2 m ahead, then the answers worked out by hand, then a save and a load
 * through the host port (libocc_posix; not with -DCONSUMER_CORE_ONLY). Exit 0 and "consumer ok" when every answer holds. */
#include <stdio.h>
#include <stdlib.h>

#include <occmap/occmap.h>
#ifndef CONSUMER_CORE_ONLY /* built against the core only (occmap::occmap_shared): no files */
#include <occmap/host/occ_file.h>
#endif

#define N_POINTS 10
static uint8_t arena[OCC_ARENA_BYTES(256, 512)];
static uint8_t scratch[OCC_INSERT_SCRATCH_BYTES(N_POINTS, 40)];

static int check(const int ok, const char *what)
{
    if (!ok) {
        printf("consumer FAIL: %s\n", what);
    }
    return ok ? 0 : 1;
}

/* The voxel answers for the wall: x = 2.05, y = -0.45 .. 0.45 (10 voxels of 0.1 m), z = 0.05. */
static int check_wall(const occ_map_t *map)
{
    int bad = 0;
    for (int i = 0; i < N_POINTS; i++) {
        const occ_vec3_t p = {2.05f, -0.45f + 0.1f * (float)i, 0.05f};
        bad += check(occ_map_state_at(map, p) == OCC_STATE_OCCUPIED, "wall voxel occupied");
    }
    bad += check(occ_map_state_at(map, (occ_vec3_t){1.05f, 0.05f, 0.05f}) == OCC_STATE_FREE,
                 "voxel between sensor and wall free");
    bad += check(occ_map_state_at(map, (occ_vec3_t){-1.05f, 0.05f, 0.05f}) == OCC_STATE_UNKNOWN,
                 "voxel behind the sensor unknown");
    bad += check(occ_map_state_at(map, (occ_vec3_t){2.55f, 0.05f, 0.05f}) == OCC_STATE_UNKNOWN,
                 "voxel behind the wall unknown");
    occ_map_stats_t st;
    occ_map_stats(map, &st);
    bad += check(st.occupied_voxels == N_POINTS, "10 occupied voxels");
    occ_ray_result_t ray;
    const occ_err_t e = occ_cast_ray(map, (occ_vec3_t){0.05f, 0.05f, 0.05f},
                                     (occ_vec3_t){1.0f, 0.0f, 0.0f}, false, 10.0f, &ray);
    bad += check(e == OCC_OK && ray.hit && ray.end.x > 2.04f && ray.end.x < 2.06f,
                 "ray along +x hits the wall voxel centred at x = 2.05");
    return bad;
}

int main(int argc, char **argv)
{
    occ_map_t map;
    occ_map_config_t cfg = occ_map_config_default();
    cfg.resolution_m = 0.1f;
    if (occ_map_init(&map, &cfg, arena, sizeof arena) != OCC_OK) {
        printf("consumer FAIL: init\n");
        return 1;
    }
    occ_vec3_t pts[N_POINTS];
    for (int i = 0; i < N_POINTS; i++) {
        pts[i] = (occ_vec3_t){2.05f, -0.45f + 0.1f * (float)i, 0.05f};
    }
    const occ_vec3_t origin = {0.05f, 0.05f, 0.05f};
    const occ_insert_params_t ip = occ_insert_params_default();
    occ_err_t e = occ_map_insert_cloud(&map, &origin, pts, N_POINTS, &ip, scratch, sizeof scratch,
                                       NULL);
    int bad = check(e == OCC_OK, "insert_cloud") + check_wall(&map);
#ifndef CONSUMER_CORE_ONLY
    if (argc > 1) { /* the host port: save, load into a fresh arena, the same answers */
        char msg[256];
        e = occ_file_save(argv[1], &map, msg, sizeof msg);
        bad += check(e == OCC_OK, "save");
        occ_map_t loaded;
        void *arena2 = NULL;
        e = occ_file_load_alloc(argv[1], NULL, &loaded, 0u, &arena2, NULL, msg, sizeof msg);
        bad += check(e == OCC_OK, "load");
        if (e == OCC_OK) {
            bad += check_wall(&loaded);
        }
        free(arena2);
    }
#else
    (void)argv;
    bad += check(argc == 1, "no file argument for a core-only consumer");
#endif
    bad += check(occ_map_check(&map) == OCC_OK, "occ_map_check");
    if (bad == 0) {
        printf("consumer ok (%s)\n", occ_err_str(OCC_OK));
    }
    return bad == 0 ? 0 : 1;
}
