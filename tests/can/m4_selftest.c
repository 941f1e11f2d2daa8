/* SPDX-License-Identifier: BSD-3-Clause */
/* m4_selftest.c - the core's behaviour on an emulated Cortex-M4F (qemu mps2-an386, semihosting):
 * map init / update / read / check / clear on a static arena, pool exhaustion, the sector module
 * against a hand-built wall, and the DroneCAN encoder against the golden bytes of
 * ../shared/notes/autopilot-protocols.md (checked on the host with pydronecan). The exit status
 * is the number of failed checks (qemu passes it to make). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "occmap/occmap.h"
#include "occmap/occ_dronecan.h"
#include "occmap/occ_sectors.h"

static unsigned checks, failed;

static void check(int ok, const char *what)
{
    checks++;
    if (!ok) {
        failed++;
        printf("FAIL %s\n", what);
    }
}

static uint8_t arena[512u * 1024u];
static uint8_t tiny_arena[OCC_ARENA_BYTES(20, 2)];
static occ_map_t map;
static occ_sectors_t sectors;

static occ_can_frame_t frames[8];
static unsigned n_frames;

static occ_err_t cap_tx(void *user, const occ_can_frame_t *f)
{
    (void)user;
    if (n_frames >= 8u) {
        return OCC_ERR_NOMEM;
    }
    frames[n_frames++] = *f;
    return OCC_OK;
}

static void test_dronecan(void)
{
    const occ_can_iface_t iface = {cap_tx, NULL, NULL};
    const occ_dronecan_proximity_t m = {1, OCC_PROX_GOOD, 0, 45.0f, 0.0f, 3.5f};
    uint8_t p[8];
    (void)occ_dronecan_encode_proximity(&m, p);
    n_frames = 0;
    check(occ_dronecan_send_transfer(&iface, occ_dronecan_msg_id(31, 21910, 100),
                                     OCC_DRONECAN_PROXIMITY_SIG, 0, p, 8, NULL) == OCC_OK,
          "proximity send");
    const uint8_t f0[8] = {0x49, 0x6b, 0x01, 0x40, 0xa0, 0x51, 0x00, 0x80};
    const uint8_t f1[4] = {0x00, 0x00, 0x43, 0x60};
    check(n_frames == 2u && frames[0].id == 0x1F559664u && frames[0].len == 8u &&
              memcmp(frames[0].data, f0, 8) == 0 && frames[1].len == 4u &&
              memcmp(frames[1].data, f1, 4) == 0,
          "Proximity golden frames (note: 49 6b 01 40 a0 51 00 80 / 00 00 43 60)");
    const occ_dronecan_node_status_t st = {1, 0, 0, 0, 0};
    uint8_t s[7];
    (void)occ_dronecan_encode_node_status(&st, s);
    n_frames = 0;
    (void)occ_dronecan_send_transfer(&iface, occ_dronecan_msg_id(31, 341, 100),
                                     OCC_DRONECAN_NODESTATUS_SIG, 0, s, 7, NULL);
    const uint8_t g[8] = {0x01, 0, 0, 0, 0, 0, 0, 0xc0};
    check(n_frames == 1u && frames[0].id == 0x1F015564u && memcmp(frames[0].data, g, 8) == 0,
          "NodeStatus golden frame");
    check(occ_float16_from_float(65504.0f) == 0x7BFFu && occ_float16_from_float(INFINITY) == 0x7BFFu &&
              occ_float16_from_float(5.9604644775390625e-08f) == 0x0001u &&
              occ_float16_from_float(1.00048828125f) == 0x3C01u &&
              occ_float16_from_float(0.1f) == 0x2E66u,
          "float16 edge cases (FPU subnormal path)");
    unsigned bad = 0;
    for (uint32_t h = 0; h < 0x7C00u; h++) {
        if (occ_float16_from_float(occ_float16_to_float((uint16_t)h)) != h) {
            bad++;
        }
    }
    check(bad == 0u, "float16 round trip of every finite positive half");
    const uint8_t digits[] = "123456789";
    check(occ_dronecan_crc16(0xFFFF, digits, 9) == 0x29B1u, "CRC-16-CCITT check value");
}

static void test_map(void)
{
    occ_map_config_t cfg = occ_map_config_default();
    check(occ_map_init(&map, &cfg, arena, sizeof arena) == OCC_OK, "map init");
    const occ_vec3_t p = {1.23f, -4.56f, 0.78f};
    check(occ_map_state_at(&map, p) == OCC_STATE_UNKNOWN, "unobserved reads UNKNOWN");
    check(occ_map_update(&map, p, cfg.hit) == OCC_OK, "update hit");
    check(occ_map_state_at(&map, p) == OCC_STATE_OCCUPIED, "hit reads OCCUPIED");
    occ_node_info_t info;
    check(occ_map_read(&map, p, 0, &info) == OCC_OK && info.observed &&
              fabsf(info.logodds - cfg.hit) < 0.002f,
          "read back the hit log-odds (fixed point)");
    for (int i = 0; i < 3; i++) {
        (void)occ_map_update(&map, p, cfg.miss);
    }
    check(occ_map_state_at(&map, p) == OCC_STATE_FREE, "three misses make it FREE");
    /* A full 8x8x8 block of hits prunes to uniform nodes; the coarse read sees OCCUPIED. */
    for (int x = 0; x < 8; x++) {
        for (int y = 0; y < 8; y++) {
            for (int z = 0; z < 8; z++) {
                const occ_vec3_t q = {0.05f + 0.1f * (float)x, 0.05f + 0.1f * (float)y,
                                      0.05f + 0.1f * (float)z};
                (void)occ_map_update(&map, q, 2.0f);
            }
        }
    }
    const occ_vec3_t c = {0.05f, 0.05f, 0.05f};
    check(occ_map_read(&map, c, 3, &info) == OCC_OK && info.state == OCC_STATE_OCCUPIED &&
              (info.flags & OCC_NODE_UNIFORM) != 0u,
          "8x8x8 block pruned to one uniform level-3 node");
    check(occ_map_check(&map) == OCC_OK, "occ_map_check after updates");
    occ_map_stats_t st;
    occ_map_stats(&map, &st);
    check(st.occupied_voxels == 512u && st.free_voxels == 1u, "stats: 512 occupied, 1 free voxel");
    occ_map_clear(&map);
    occ_map_pool_stats(&map, &st);
    check(st.inner_used == 0u && st.leaf_used == 0u, "clear returns every block");
    const occ_vec3_t out = {1e9f, 0.0f, 0.0f};
    check(occ_map_update(&map, out, 1.0f) == OCC_ERR_RANGE, "outside the map: OCC_ERR_RANGE");

    /* A tiny arena runs out: NOMEM, counted, and the map unchanged. */
    occ_map_t small;
    check(occ_map_init(&small, &cfg, tiny_arena, sizeof tiny_arena) == OCC_OK, "tiny map init");
    unsigned ok = 0, nomem = 0;
    for (int i = 0; i < 40; i++) {
        const occ_vec3_t q = {(float)i * 7.3f, (float)i * -3.1f, 1.0f};
        const occ_err_t e = occ_map_update(&small, q, 1.0f);
        ok += e == OCC_OK;
        nomem += e == OCC_ERR_NOMEM;
    }
    check(nomem > 0u && ok > 0u && small.oom_count == nomem && occ_map_check(&small) == OCC_OK,
          "pool exhaustion is OCC_ERR_NOMEM and the map stays consistent");
}

static void test_sectors(void)
{
    occ_map_config_t cfg = occ_map_config_default();
    (void)occ_map_init(&map, &cfg, arena, sizeof arena);
    /* Observed free disc of radius 4 m in the layer z in [0, 0.1), a wall at y = 3.0 .. 3.1. */
    for (int y = -40; y < 40; y++) {
        for (int x = -40; x < 40; x++) {
            const occ_vec3_t q = {((float)x + 0.5f) * 0.1f, ((float)y + 0.5f) * 0.1f, 0.05f};
            const int wall = y == 30 && x >= -15 && x < 15;
            if (wall || q.x * q.x + q.y * q.y < 16.0f) {
                (void)occ_map_update(&map, q, wall ? 3.0f : -3.0f);
            }
        }
    }
    occ_sectors_config_t sc = occ_sectors_config_default();
    sc.band_below_m = 0.04f;
    sc.band_above_m = 0.04f;
    const occ_vec3_t up5cm = {0.0f, 0.0f, -0.05f};
    occ_pose_t pose;
    check(occ_pose_from_ned(up5cm, occ_quat_identity(), &pose) == OCC_OK, /* facing north */
          "pose from NED");
    check(occ_sectors_compute(&map, &pose, &sc, &sectors) == OCC_OK && sectors.n == 72u,
          "sectors compute");
    check(sectors.distance_cm[0] >= 299u && sectors.distance_cm[0] <= 300u,
          "sector 0 (north) sees the wall at 3.0 m");
    check(sectors.distance_cm[36] == OCC_SECTORS_UNKNOWN, "sector 36 (south) ends in unknown space");
    printf("m4-selftest: sectors 0/4/36: %u %u %u cm, %u nodes read\n", sectors.distance_cm[0],
           sectors.distance_cm[4], sectors.distance_cm[36], (unsigned)sectors.nodes_read);
}

int main(void)
{
    printf("m4-selftest: Cortex-M4F under qemu, semihosting\n");
    test_dronecan();
    test_map();
    test_sectors();
    printf("m4-selftest: %u checks, %u failed\n", checks, failed);
    return failed > 255u ? 255 : (int)failed;
}
