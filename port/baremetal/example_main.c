/* SPDX-License-Identifier: BSD-3-Clause */
/* example_main.c - an example flight-controller image: a static arena, a built-in test cloud
 * (a room of 8 x 6 m seen from its middle) integrated with occ_map_insert_cloud(), and a main loop
 * that publishes the obstacles as DroneCAN Proximity (8 sectors, 10 Hz) plus NodeStatus through a
 * stub CAN driver (a 32-frame software queue in front of 3 mailboxes). It runs under qemu
 * (mps2-an386, semihosting) for 3 simulated seconds and checks what reached the "bus". */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "occmap/occmap.h"
#include "occmap/occ_dronecan.h"
#include "occmap/occ_sectors.h"
#include "occ_bm_can.h"

#define ARENA_BYTES (96u * 1024u)    /* what a 192 KB STM32F4 can spare */
#define SCRATCH_BYTES (32u * 1024u)
#define N_RAYS 720u
#define TXQ 32u

static uint8_t arena[ARENA_BYTES];
static uint8_t scratch[SCRATCH_BYTES];
static occ_map_t map;
static occ_dronecan_node_t node;
static occ_vec3_t pts[16];
static occ_map_stats_t st;

/* ---- The stub driver: strong definitions replace the weak hooks ------------------------------ */
static occ_can_frame_t txq[TXQ];
static uint32_t txq_n;
static uint64_t sim_us;
static uint32_t bus_frames, bus_prox, bus_status, bad_readings;

occ_err_t occ_bm_can_tx(const occ_can_frame_t *frame)
{
    if (txq_n >= TXQ) {
        return OCC_ERR_NOMEM;
    }
    txq[txq_n++] = *frame;
    return OCC_OK;
}

uint32_t occ_bm_can_tx_space(void)
{
    return TXQ - txq_n;
}

uint64_t occ_bm_micros(void)
{
    return sim_us;
}

/* What the mailboxes put on the wire since the last tick: count and sanity-check it. */
static void bus_tick(void)
{
    for (uint32_t i = 0; i < txq_n; i++) {
        const occ_can_frame_t *f = &txq[i];
        const uint32_t dt = (f->id >> 8) & 0xFFFFu;
        bus_frames++;
        if (dt == OCC_DRONECAN_NODESTATUS_ID) {
            bus_status++;
        } else if (dt == OCC_DRONECAN_PROXIMITY_ID && (f->data[f->len - 1u] & 0x80u) != 0u &&
                   i + 1u < txq_n) {
            /* First frame: CRC(2) + 5 payload bytes; the distance is in the second frame. */
            uint8_t p[8];
            memcpy(p, f->data + 2, 5);
            memcpy(p + 5, txq[i + 1u].data, 3);
            const float dist = occ_float16_to_float((uint16_t)occ_dronecan_get_bits(p, 48, 16));
            const unsigned type = (unsigned)occ_dronecan_get_bits(p, 8, 3);
            bus_prox++;
            if (type != OCC_PROX_GOOD || dist < 2.7f || dist > 4.6f) {
                bad_readings++;
            }
        }
    }
    txq_n = 0;
}

/* The built-in cloud: one horizontal scan of a room x in [-4, 4], y in [-3, 3] from (0, 0, z0). */
static occ_vec3_t room_point(unsigned i, float z0)
{
    const float a = (float)i * (6.28318531f / (float)N_RAYS);
    const float c = cosf(a), s = sinf(a);
    const float tx = fabsf(c) > 1e-6f ? 4.0f / fabsf(c) : 1e9f;
    const float ty = fabsf(s) > 1e-6f ? 3.0f / fabsf(s) : 1e9f;
    const float t = (tx < ty ? tx : ty) - 0.001f;
    const occ_vec3_t p = {t * c, t * s, z0};
    return p;
}

int main(void)
{
    occ_map_config_t cfg = occ_map_config_default();
    cfg.resolution_m = 0.1f;
    if (occ_map_init(&map, &cfg, arena, sizeof arena) != OCC_OK) {
        printf("example: map init failed\n");
        return 1;
    }
    const float z0 = 0.05f;
    const occ_vec3_t origin = {0.0f, 0.0f, z0};
    const occ_insert_params_t ip = occ_insert_params_default();
    size_t batch = 16;
    while (batch > 1u && occ_insert_scratch_bytes(&map, batch, 5.1f, &ip) > sizeof scratch) {
        batch--;
    }
    size_t integrated = 0;
    for (unsigned i = 0; i < N_RAYS; i += (unsigned)batch) {
        size_t n = 0;
        for (unsigned k = i; k < N_RAYS && n < batch; k++) {
            pts[n++] = room_point(k, z0);
        }
        occ_insert_result_t res;
        const occ_err_t e = occ_map_insert_cloud(&map, &origin, pts, n, &ip, scratch,
                                                 sizeof scratch, &res);
        if (e != OCC_OK) {
            printf("example: insert failed: %s\n", occ_err_str(e));
            return 1;
        }
        integrated += res.points_integrated;
    }
    occ_map_stats(&map, &st);
    printf("example: %u points in batches of %u; %lu occupied, %lu free voxels; %u of %u arena bytes\n",
           (unsigned)integrated, (unsigned)batch, (unsigned long)st.occupied_voxels,
           (unsigned long)st.free_voxels, (unsigned)st.bytes_used, (unsigned)st.arena_bytes);

    occ_dronecan_config_t ncfg = occ_dronecan_config_default();
    ncfg.node_id = 42;
    ncfg.sensor_id = 1;
    const occ_can_iface_t iface = occ_bm_can_iface();
    if (occ_dronecan_init(&node, &ncfg, &iface) != OCC_OK) {
        return 1;
    }
    occ_sectors_config_t scfg = occ_sectors_config_default();
    scfg.n_sectors = 8; /* ArduPilot keeps 8 horizontal sectors */
    scfg.increment_deg = 45.0f;
    scfg.band_below_m = 0.04f;
    scfg.band_above_m = 0.04f;
    scfg.unknown_as_distance = true;
    const occ_vec3_t start_ned = {0.0f, 0.0f, -z0}; /* level, facing north */
    occ_pose_t pose;
    if (occ_pose_from_ned(start_ned, occ_quat_identity(), &pose) != OCC_OK) {
        return 1;
    }

    /* The main loop: 3 simulated seconds at 1 kHz; the mailboxes drain every millisecond. */
    uint32_t errors = 0;
    for (sim_us = 1000000u; sim_us < 4000000u; sim_us += 1000u) {
        const occ_err_t e = occ_dronecan_poll_map(&node, occ_bm_micros(), &map, sim_us, &pose,
                                                  sim_us, &scfg);
        if (e != OCC_OK) {
            errors++;
        }
        bus_tick();
    }
    const int check = occ_map_check(&map) == OCC_OK;
    printf("example: %u frames on the bus: %u Proximity (%u off), %u NodeStatus; tx_full %u, "
           "errors %u, map check %s\n",
           (unsigned)bus_frames, (unsigned)bus_prox, (unsigned)bad_readings, (unsigned)bus_status,
           (unsigned)node.stats.tx_full, (unsigned)errors, check ? "ok" : "FAILED");
    const bool ok = check && errors == 0u && bus_prox == 30u * 8u && bad_readings == 0u &&
                    bus_status == 3u && node.stats.tx_full == 0u;
    printf("example: %s\n", ok ? "PASS" : "FAIL");
    return ok ? 0 : 1;
}
