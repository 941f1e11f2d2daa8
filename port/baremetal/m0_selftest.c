/* SPDX-License-Identifier: BSD-3-Clause */
/* m0_selftest.c - the core on ARMv6-M (built for Cortex-M0+, run on qemu's microbit board:
 * Cortex-M0, 16 KB RAM, semihosting): map init / update / read / prune / stats on an 8 KB
 * arena, a ray cast and sphere checks against a hand-built block, pool exhaustion on a tiny
 * arena. Expected values are hand-computed from the block's geometry. The exit status is the
 * number of failed checks (qemu passes it to make).
 * It also measures the stack a few entry points really use (the stack below SP painted, the
 * call made, the lowest overwritten word found) and prints "stack-measured m0 NAME WRAPPER BYTES":
 * make test-m0-qemu checks them against the static call-chain bounds (tests/stack_budget.py). */
#include <math.h>
#include <stdio.h>

#include "occmap/occmap.h"
#include "occmap/occ_query.h"

static unsigned checks, failed;

static void check(int ok, const char *what)
{
    checks++;
    if (!ok) {
        failed++;
        printf("FAIL %s\n", what);
    }
}

static uint8_t arena[8u * 1024u];
static uint8_t tiny_arena[OCC_ARENA_BYTES(20, 2)];
static occ_map_t map;

/* Voxels x, y, z in [0, 8) (0 .. 0.8 m at 0.1 m) all hit: one pruned level-3 node. */
static void build_block(void)
{
    for (int x = 0; x < 8; x++) {
        for (int y = 0; y < 8; y++) {
            for (int z = 0; z < 8; z++) {
                const occ_vec3_t q = {0.05f + 0.1f * (float)x, 0.05f + 0.1f * (float)y,
                                      0.05f + 0.1f * (float)z};
                (void)occ_map_update(&map, q, 2.0f);
            }
        }
    }
}

static void test_map(void)
{
    occ_map_config_t cfg = occ_map_config_default();
    check(occ_map_init(&map, &cfg, arena, sizeof arena) == OCC_OK, "map init on an 8 KB arena");
    const occ_vec3_t p = {1.23f, -4.56f, 0.78f};
    check(occ_map_state_at(&map, p) == OCC_STATE_UNKNOWN, "unobserved reads UNKNOWN");
    check(occ_map_update(&map, p, cfg.hit) == OCC_OK, "update hit");
    occ_node_info_t info;
    check(occ_map_read(&map, p, 0, &info) == OCC_OK && info.observed &&
              fabsf(info.logodds - cfg.hit) < 0.002f,
          "read back the hit log-odds (soft-float fixed point)");
    for (int i = 0; i < 3; i++) {
        (void)occ_map_update(&map, p, cfg.miss);
    }
    check(occ_map_state_at(&map, p) == OCC_STATE_FREE, "hit + 3 misses reads FREE");
    build_block();
    const occ_vec3_t c = {0.05f, 0.05f, 0.05f};
    check(occ_map_read(&map, c, 3, &info) == OCC_OK && info.state == OCC_STATE_OCCUPIED &&
              (info.flags & OCC_NODE_UNIFORM) != 0u,
          "8x8x8 block pruned to one uniform level-3 node");
    check(occ_map_check(&map) == OCC_OK, "occ_map_check");
    occ_map_stats_t st;
    occ_map_stats(&map, &st);
    check(st.occupied_voxels == 512u && st.free_voxels == 1u, "stats: 512 occupied, 1 free");
}

static void test_queries(void)
{
    occ_ray_result_t r;
    const occ_vec3_t o = {-2.05f, 0.35f, 0.35f};
    const occ_vec3_t dx = {1.0f, 0.0f, 0.0f};
    check(occ_cast_ray(&map, o, dx, true, 0.0f, &r) == OCC_OK && r.hit && r.stop == OCC_RAY_HIT &&
              fabsf(r.end.x - 0.05f) < 1e-4f && fabsf(r.end.y - 0.35f) < 1e-4f,
          "ray along +x stops in voxel x = 0.05 m of the block");
    check(occ_cast_ray(&map, o, dx, true, 1.0f, &r) == OCC_OK && !r.hit &&
              r.stop == OCC_RAY_MAX_RANGE,
          "the same ray with a 1 m range ends before the block");
    occ_collision_t col;
    const occ_vec3_t in = {0.4f, 0.4f, 0.4f};
    check(occ_collide_sphere(&map, in, 0.1f, OCC_UNKNOWN_SAFE, &col) == OCC_OK && !col.safe &&
              col.node.state == OCC_STATE_OCCUPIED,
          "sphere inside the block: unsafe, an OCCUPIED node");
    const occ_vec3_t away = {3.0f, 3.0f, 3.0f};
    check(occ_collide_sphere(&map, away, 0.5f, OCC_UNKNOWN_SAFE, &col) == OCC_OK && col.safe,
          "sphere in unknown space, unknown safe: safe");
    check(occ_collide_sphere(&map, away, 0.5f, OCC_UNKNOWN_UNSAFE, &col) == OCC_OK && !col.safe,
          "sphere in unknown space, unknown unsafe: unsafe");
    const occ_vec3_t nan3 = {NAN, 0.0f, 0.0f};
    check(occ_collide_sphere(&map, nan3, 0.5f, OCC_UNKNOWN_SAFE, &col) == OCC_ERR_ARG && !col.safe,
          "NaN centre: OCC_ERR_ARG and reads unsafe");
}

static void test_exhaustion(void)
{
    occ_map_config_t cfg = occ_map_config_default();
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

/* ---- measured stack ---------------------------------------------------------------------------
 * No interrupts run here, so nothing but the call writes below SP. */
#define PAINT_WORDS 768u /* 3 KB: above every bound this image calls */
#define PAINT 0xA5C3E1F7u
static occ_collision_t probe_col;
static occ_ray_result_t probe_ray;

static void call_state_at(void)
{
    const occ_vec3_t q = {0.35f, 0.35f, 0.35f};
    (void)occ_map_state_at(&map, q);
}

static void call_update(void)
{
    const occ_vec3_t q = {-1.05f, 2.05f, 0.35f};
    (void)occ_map_update(&map, q, -0.4f);
}

static void call_cast_ray(void)
{
    const occ_vec3_t o = {-2.05f, 0.35f, 0.35f};
    const occ_vec3_t d = {1.0f, 0.1f, 0.05f};
    (void)occ_cast_ray(&map, o, d, true, 0.0f, &probe_ray);
}

static void call_sphere(void)
{
    const occ_vec3_t c = {0.9f, 0.4f, 0.4f};
    (void)occ_collide_sphere(&map, c, 0.2f, OCC_UNKNOWN_SAFE, &probe_col);
}

static void call_capsule(void)
{
    const occ_vec3_t a = {-0.5f, 0.4f, 0.4f}, b = {1.2f, 0.45f, 0.5f};
    (void)occ_collide_capsule(&map, a, b, 0.15f, OCC_UNKNOWN_SAFE, &probe_col);
}

static void call_check(void)
{
    (void)occ_map_check(&map);
}

/* Bytes below the caller's SP that `call` (and the call's own wrapper frame) wrote. */
static unsigned stack_used(void (*call)(void))
{
    uint32_t *sp;
    __asm__ volatile("mov %0, sp" : "=r"(sp));
    volatile uint32_t *const lo = sp - PAINT_WORDS;
    for (volatile uint32_t *p = lo; p < sp - 16; p++) { /* 64 B kept for this frame's call */
        *p = PAINT;
    }
    call();
    volatile uint32_t *p = lo;
    while (p < sp && *p == PAINT) {
        p++;
    }
    return (unsigned)((uintptr_t)sp - (uintptr_t)p);
}

static void measure_stacks(void)
{
    static const struct {
        const char *name, *wrapper; /* the wrapper's own frame is part of what is measured */
        void (*call)(void);
    } probes[] = {{"occ_map_state_at", "call_state_at", call_state_at},
                  {"occ_map_update", "call_update", call_update},
                  {"occ_cast_ray", "call_cast_ray", call_cast_ray},
                  {"occ_collide_sphere", "call_sphere", call_sphere},
                  {"occ_collide_capsule", "call_capsule", call_capsule},
                  {"occ_map_check", "call_check", call_check}};
    for (unsigned i = 0; i < sizeof probes / sizeof probes[0]; i++) {
        const unsigned used = stack_used(probes[i].call);
        check(used > 0u && used < PAINT_WORDS * 4u, "stack probe inside the painted area");
        printf("stack-measured m0 %s %s %u\n", probes[i].name, probes[i].wrapper, used);
    }
}

int main(void)
{
    printf("m0-selftest: ARMv6-M (built for Cortex-M0+) under qemu microbit, semihosting\n");
    test_map();
    test_queries();
    measure_stacks();
    test_exhaustion();
    printf("m0-selftest: %u checks, %u failed\n", checks, failed);
    return failed > 255u ? 255 : (int)failed;
}
