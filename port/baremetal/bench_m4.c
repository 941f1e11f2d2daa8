/* SPDX-License-Identifier: BSD-3-Clause */
/* bench_m4.c - instructions per call on an emulated Cortex-M4F (`make bench-m4`): qemu's
 * mps2-an386 with -icount shift=0 advances virtual time by one nanosecond per instruction; the
 * CMSDK dual timer (free-running, 32 bits) is read before and after each call, and the ticks are
 * turned into instructions with a calibration loop of known length. The map is a crop of OctoMap's
 * geb079 (0.08 m), embedded in flash (build/fw/geb079_crop.c) and loaded with occ_io_load into a
 * static arena. Inputs (points, scans, depth frames) are made before the timed calls.
 * Prints one line per call kind: median / max / mean instructions over a few hundred calls.
 * The exit status is non-zero when a call fails (the numbers would not mean anything). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "occmap/occmap.h"
#include "occmap/occ_depth.h"
#include "occmap/occ_evict.h"
#include "occmap/occ_query.h"
#include "occmap/occ_sectors.h"

extern const unsigned char occ_bench_map[];
extern const size_t occ_bench_map_len;
extern const float occ_bench_box_min[3];
extern const float occ_bench_box_max[3];

#define BENCH_ARENA_BYTES (1024u * 1024u)
#define BENCH_SCRATCH_BYTES (192u * 1024u)
#define N_CALLS 300u
#define N_SCANS 16u
#define SCAN_RAYS 64u
#define SCAN_RANGE_M 8.0f
#define TOF_SIDE 8u
#define TOF_RANGE_M 4.0f

/* CMSDK APB dual timer 1 on mps2-an386: Load, Value, Control (enable | 32-bit, free-running). */
#define DUALTIMER_LOAD (*(volatile uint32_t *)0x40002000u)
#define DUALTIMER_VALUE (*(volatile uint32_t *)0x40002004u)
#define DUALTIMER_CONTROL (*(volatile uint32_t *)0x40002008u)

static uint8_t arena[BENCH_ARENA_BYTES];
static uint8_t scratch[BENCH_SCRATCH_BYTES];
static occ_map_t map;
static occ_vec3_t pts[N_CALLS], dirs[N_CALLS];
static occ_vec3_t scan_origin[N_SCANS], scan_end[N_SCANS][SCAN_RAYS];
static float tof_depth[N_SCANS][TOF_SIDE * TOF_SIDE];
static occ_pose_t tof_pose[N_SCANS];
static occ_sectors_t sectors;
static occ_sectors_config_t sectors_cfg;
static occ_quat_t yaws[N_CALLS];
static occ_evict_out_t evict_out;
static uint32_t ticks[N_CALLS];
static unsigned failures;
static uint32_t rng = 12345u;

static float uniform(float lo, float hi)
{
    rng = rng * 1664525u + 1013904223u;
    return lo + (hi - lo) * (float)(rng >> 8) / 16777216.0f;
}

static uint32_t timer_now(void)
{
    return DUALTIMER_VALUE; /* counts down */
}

static void expect(occ_err_t e, const char *what)
{
    if (e != OCC_OK) {
        failures++;
        printf("FAIL bench-m4: %s: %s\n", what, occ_err_str(e));
    }
}

static void load_map(void)
{
    occ_io_info_t info;
    expect(occ_io_load(&map, NULL, arena, sizeof arena, occ_bench_map, occ_bench_map_len, &info),
           "occ_io_load");
}

/* ---- the timed calls: one per kind, argument = call index ------------------------------------ */
static void op_empty(unsigned i)
{
    (void)i;
}

static void op_load(unsigned i)
{
    (void)i;
    load_map();
}

static void op_lookup(unsigned i)
{
    if (occ_map_state_at(&map, pts[i]) > OCC_STATE_OCCUPIED) {
        failures++;
    }
}

static void op_sphere(unsigned i)
{
    occ_collision_t c;
    expect(occ_collide_sphere(&map, pts[i], 0.5f, OCC_UNKNOWN_UNSAFE, &c), "collide_sphere");
}

static void op_capsule(unsigned i)
{
    const occ_vec3_t b = {pts[i].x + dirs[i].x, pts[i].y + dirs[i].y, pts[i].z + dirs[i].z};
    occ_collision_t c;
    expect(occ_collide_capsule(&map, pts[i], b, 0.3f, OCC_UNKNOWN_UNSAFE, &c), "collide_capsule");
}

static void op_ray(unsigned i)
{
    occ_ray_result_t r;
    expect(occ_cast_ray(&map, pts[i], dirs[i], true, 10.0f, &r), "cast_ray");
}

static void op_sectors(unsigned i)
{
    occ_pose_t pose;
    pose.p = pts[i];
    pose.q = yaws[i];
    expect(occ_sectors_compute(&map, &pose, &sectors_cfg, &sectors), "sectors_compute");
}

static void op_scan(unsigned i)
{
    occ_insert_params_t p = occ_insert_params_default();
    p.max_range_m = SCAN_RANGE_M;
    occ_insert_result_t r;
    const unsigned s = i % N_SCANS;
    expect(occ_map_insert_cloud(&map, &scan_origin[s], scan_end[s], SCAN_RAYS, &p, scratch,
                                sizeof scratch, &r),
           "insert_cloud (64 rays)");
}

static const occ_depth_params_t tof_params = {{9.6569f, 9.6569f, 3.5f, 3.5f}, 0.02f, TOF_RANGE_M, 1u};

static void op_tof(unsigned i)
{
    const unsigned s = i % N_SCANS;
    const occ_depth_image_t img = {tof_depth[s], OCC_DEPTH_F32, TOF_SIDE, TOF_SIDE,
                                   TOF_SIDE * sizeof(float), 1.0f};
    occ_insert_params_t p = occ_insert_params_default();
    occ_depth_result_t r;
    expect(occ_map_insert_depth(&map, &img, &tof_params, &tof_pose[s], &p, scratch, sizeof scratch,
                                &r),
           "insert_depth (8x8)");
}

static occ_evict_policy_t evict_policy;
static occ_vec3_t evict_center;

static void op_evict(unsigned i)
{
    (void)i;
    expect(occ_map_evict(&map, &evict_center, &evict_policy, 1000000u, &evict_out), "map_evict");
}

/* ---- inputs ---------------------------------------------------------------------------------- */
static void make_inputs(void)
{
    for (unsigned i = 0; i < N_CALLS; i++) {
        pts[i].x = uniform(occ_bench_box_min[0] + 0.5f, occ_bench_box_max[0] - 0.5f);
        pts[i].y = uniform(occ_bench_box_min[1] + 0.5f, occ_bench_box_max[1] - 0.5f);
        pts[i].z = uniform(0.5f, 2.0f);
        const float a = uniform(-3.14159f, 3.14159f);
        dirs[i].x = cosf(a);
        dirs[i].y = sinf(a);
        dirs[i].z = uniform(-0.1f, 0.1f);
        yaws[i] = occ_quat_from_euler(0.0f, 0.0f, uniform(-3.14159f, 3.14159f));
    }
    sectors_cfg = occ_sectors_config_default();
    /* 64-ray horizontal scans and 8x8 time-of-flight frames, cast against the loaded map. */
    const occ_quat_t body_from_optical = {0.5f, -0.5f, 0.5f, -0.5f}; /* z fwd, x right, y down */
    for (unsigned s = 0; s < N_SCANS; s++) {
        const occ_vec3_t o = pts[s];
        scan_origin[s] = o;
        for (unsigned k = 0; k < SCAN_RAYS; k++) {
            const float a = 6.2831853f * (float)k / (float)SCAN_RAYS;
            const occ_vec3_t d = {cosf(a), sinf(a), 0.0f};
            occ_ray_result_t r;
            const bool hit = occ_cast_ray(&map, o, d, true, SCAN_RANGE_M, &r) == OCC_OK && r.hit;
            const float t = hit ? sqrtf((r.end.x - o.x) * (r.end.x - o.x) +
                                        (r.end.y - o.y) * (r.end.y - o.y))
                                : SCAN_RANGE_M + 0.5f; /* no return: beyond max range */
            scan_end[s][k].x = o.x + t * d.x;
            scan_end[s][k].y = o.y + t * d.y;
            scan_end[s][k].z = o.z;
        }
        const occ_pose_t yaw = {o, occ_quat_from_euler(0.0f, 0.0f, uniform(-3.14159f, 3.14159f))};
        const occ_pose_t opt = {{0.0f, 0.0f, 0.0f}, body_from_optical};
        tof_pose[s] = occ_pose_compose(&yaw, &opt);
        for (unsigned v = 0; v < TOF_SIDE; v++) {
            for (unsigned u = 0; u < TOF_SIDE; u++) {
                const occ_vec3_t c = {((float)u - 3.5f) / 9.6569f, ((float)v - 3.5f) / 9.6569f, 1.0f};
                const float n = sqrtf(c.x * c.x + c.y * c.y + 1.0f);
                occ_ray_result_t r;
                const occ_vec3_t dm = occ_pose_rotate(&tof_pose[s], c);
                float d = INFINITY;
                if (occ_cast_ray(&map, o, dm, true, TOF_RANGE_M, &r) == OCC_OK && r.hit) {
                    const float dx = r.end.x - o.x, dy = r.end.y - o.y, dz = r.end.z - o.z;
                    d = sqrtf(dx * dx + dy * dy + dz * dz) / n;
                }
                tof_depth[s][v * TOF_SIDE + u] = d;
            }
        }
    }
    const occ_vec3_t fwd = occ_pose_rotate(&tof_pose[0], (occ_vec3_t){0.0f, 0.0f, 1.0f});
    if (fabsf(fwd.z) > 1e-3f) {
        failures++;
        printf("FAIL bench-m4: the camera's optical axis is not horizontal\n");
    }
    evict_policy = occ_evict_policy_default();
    evict_policy.keep_radius_m = 2.0f;
    evict_policy.budget_blocks = 64u;
    evict_center.x = 0.5f * (occ_bench_box_min[0] + occ_bench_box_max[0]);
    evict_center.y = 0.5f * (occ_bench_box_min[1] + occ_bench_box_max[1]);
    evict_center.z = 1.0f;
}

/* ---- measuring -------------------------------------------------------------------------------- */
static float insn_per_tick;
static float overhead_ticks;

static void calibrate(void)
{
    DUALTIMER_CONTROL = 0u;
    DUALTIMER_LOAD = 0xFFFFFFFFu;
    DUALTIMER_CONTROL = 0x82u;
    uint32_t n = 1000000u;
    const uint32_t t0 = timer_now();
    __asm__ volatile("1: subs %0, %0, #1\n\tbne 1b" : "+r"(n) : : "cc"); /* 2 instructions a turn */
    const uint32_t t1 = timer_now();
    insn_per_tick = 2000000.0f / (float)(t0 - t1);
}

static void sort_u32(uint32_t *a, unsigned n)
{
    for (unsigned i = 1; i < n; i++) {
        const uint32_t x = a[i];
        unsigned j = i;
        while (j > 0u && a[j - 1u] > x) {
            a[j] = a[j - 1u];
            j--;
        }
        a[j] = x;
    }
}

static void run(const char *name, void (*op)(unsigned), unsigned n, const char *work)
{
    for (unsigned i = 0; i < n; i++) {
        if (op == op_evict && evict_out.exhausted) {
            load_map(); /* a fresh map to evict from (not timed) */
            occ_evict_out_init(&evict_out);
        }
        const uint32_t t0 = timer_now();
        op(i);
        const uint32_t t1 = timer_now();
        ticks[i] = t0 - t1;
    }
    double sum = 0.0;
    for (unsigned i = 0; i < n; i++) {
        sum += (double)ticks[i];
    }
    sort_u32(ticks, n);
    if (op == op_empty) {
        overhead_ticks = (float)ticks[n / 2u];
        printf("(subtracted: timer reads + the indirect call, %.0f instructions)\n",
               (double)(overhead_ticks * insn_per_tick));
        return;
    }
    const float med = ((float)ticks[n / 2u] - overhead_ticks) * insn_per_tick;
    const float max = ((float)ticks[n - 1u] - overhead_ticks) * insn_per_tick;
    const float mean = ((float)(sum / (double)n) - overhead_ticks) * insn_per_tick;
    printf("%-34s %5u %10lu %10lu %10lu  %s\n", name, n, (unsigned long)(med + 0.5f),
           (unsigned long)(max + 0.5f), (unsigned long)(mean + 0.5f), work);
}

int main(void)
{
    calibrate();
    load_map();
    occ_map_stats_t st;
    occ_map_pool_stats(&map, &st);
    make_inputs();
    occ_insert_params_t ip = occ_insert_params_default();
    ip.max_range_m = SCAN_RANGE_M;
    size_t scan_scratch = 0; /* the largest of the scans' own bounds */
    for (unsigned s = 0; s < N_SCANS; s++) {
        const size_t b = occ_insert_scratch_bytes_scan(&map, &scan_origin[s], scan_end[s],
                                                       SCAN_RAYS, &ip);
        scan_scratch = b > scan_scratch ? b : scan_scratch;
    }
    ip.max_range_m = 0.0f;
    const size_t tof_scratch = occ_depth_scratch_bytes(&map, TOF_SIDE, TOF_SIDE, 1u, TOF_RANGE_M, &ip);
    printf("== bench-m4: instructions per call on Cortex-M4F (qemu mps2-an386, -icount shift=0; "
           "timer: %.1f instructions per tick, so +-%.0f per call)\n",
           (double)insn_per_tick, (double)insn_per_tick);
    printf("map: geb079 crop (%.1f %.1f %.1f) .. (%.1f %.1f %.1f) m, 0.08 m, %lu-byte snapshot in "
           "flash; arena %u KB, %lu inner + %lu leaf blocks used (%lu bytes) after load; scratch "
           "%u KB static (bounds: 64-ray scan %lu B, 8x8 frame %lu B)\n",
           (double)occ_bench_box_min[0], (double)occ_bench_box_min[1], (double)occ_bench_box_min[2],
           (double)occ_bench_box_max[0], (double)occ_bench_box_max[1], (double)occ_bench_box_max[2],
           (unsigned long)occ_bench_map_len, BENCH_ARENA_BYTES / 1024u,
           (unsigned long)st.inner_used, (unsigned long)st.leaf_used,
           (unsigned long)OCC_ARENA_BYTES(st.inner_used, st.leaf_used),
           BENCH_SCRATCH_BYTES / 1024u, (unsigned long)scan_scratch, (unsigned long)tof_scratch);
    if (scan_scratch > sizeof scratch || tof_scratch > sizeof scratch) {
        printf("FAIL bench-m4: scratch too small\n");
        return 1;
    }
    printf("%-34s %5s %10s %10s %10s  %s\n", "call", "calls", "median", "max", "mean", "work");
    run("(timer read + indirect call)", op_empty, N_CALLS, "");
    run("occ_map_state_at (point lookup)", op_lookup, N_CALLS, "one descent");
    run("occ_collide_sphere r 0.5 m", op_sphere, N_CALLS, "unknown unsafe");
    run("occ_collide_capsule 1 m, r 0.3 m", op_capsule, N_CALLS, "unknown unsafe");
    run("occ_cast_ray 10 m", op_ray, N_CALLS, "0.08 m voxels, unknown ignored");
    run("occ_sectors_compute 72 sectors", op_sectors, N_CALLS, "default config");
    run("occ_map_insert_cloud 64 rays", op_scan, N_CALLS, "8 m range, 360 deg fan");
    run("occ_map_insert_depth 8x8 ToF", op_tof, N_CALLS, "4 m range, 45 deg FoV");
    occ_map_pool_stats(&map, &st);
    printf("after the scans and frames: %lu inner + %lu leaf blocks (%lu bytes)\n",
           (unsigned long)st.inner_used, (unsigned long)st.leaf_used,
           (unsigned long)OCC_ARENA_BYTES(st.inner_used, st.leaf_used));
    run("occ_io_load (the crop)", op_load, 5u, "the snapshot above");
    run("occ_map_evict slice (64 blocks)", op_evict, N_CALLS, "keep 2 m, reload when exhausted");
    printf("bench-m4: %s\n", failures == 0u ? "all calls returned OCC_OK" : "FAILED calls");
    return failures == 0u ? 0 : 1;
}
