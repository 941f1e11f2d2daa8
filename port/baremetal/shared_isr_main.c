/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * shared_isr_main.c - one writer, one interrupt reader on a shared map (issue 20), on qemu's
 * mps2-an386 (Cortex-M4F, semihosting). main() is the writer: it integrates a synthetic moving
 * scan per version in a small arena with eviction, and records the answers of a probe set on its
 * own map before each version goes out (write section). SysTick, re-armed with a pseudo-random
 * period after each interrupt, preempts the writer anywhere (mid-insert, mid-eviction,
 * mid-publish copy) and is the reader: it opens a view, answers the probes (voxel states, a
 * sphere check, a ray cast), compares them with the record of the view's version and closes the
 * view. The exit status is the number of failures (mismatches, refused views, failed checks);
 * the interrupt's worst-case time is printed in SysTick ticks of qemu's 25 MHz clock; run with
 * -icount shift=0 (port/shared_m4.mk) a tick is 40 guest instructions (not a real M4's cycles:
 * no wait states or pipeline).
 * Own vector table and reset code (the image does not link startup_m4.c: SysTick is ours).
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "occmap/occmap.h"

#define N_PROBES 24u
#define MAX_VERSIONS 160u
#define N_POINTS 300u

typedef struct {
    uint8_t state[N_PROBES];
    uint8_t sphere;
    uint8_t ray_hit;
    uint32_t ray_key[3];
} answers_t;

static uint8_t arena[OCC_ARENA_BYTES(1500, 6000)];
static uint8_t shmem[OCC_SHARED_BYTES(sizeof arena)];
static occ_map_t map;
static answers_t record[MAX_VERSIONS + 1u];
static occ_vec3_t cloud[N_POINTS];
static uint8_t scratch[256u * 1024u];

static volatile uint32_t isr_runs, isr_fail, isr_worst_ticks, isr_versions, isr_last_version;
static uint32_t rng = 12345u;

#define SYST_CSR (*(volatile uint32_t *)0xE000E010u)
#define SYST_RVR (*(volatile uint32_t *)0xE000E014u)
#define SYST_CVR (*(volatile uint32_t *)0xE000E018u)

static uint32_t next_rand(void)
{
    rng = rng * 1664525u + 1013904223u;
    return rng >> 8;
}

static occ_vec3_t v3(float x, float y, float z)
{
    occ_vec3_t v = {x, y, z};
    return v;
}

static occ_vec3_t probe(unsigned i)
{
    return v3(-3.0f + 0.5f * (float)i, 1.0f + 0.1f * (float)(i % 5u), 0.45f);
}

static void answer(const occ_map_t *m, answers_t *out)
{
    memset(out, 0, sizeof *out);
    for (unsigned i = 0; i < N_PROBES; i++) {
        out->state[i] = (uint8_t)occ_map_state_at(m, probe(i));
    }
    occ_collision_t c;
    const occ_err_t e = occ_collide_sphere(m, v3(0.0f, 1.5f, 0.5f), 0.8f, OCC_UNKNOWN_SAFE, &c);
    out->sphere = (uint8_t)((e != OCC_OK ? 1u : 0u) | (c.safe ? 2u : 0u) | (c.outside ? 4u : 0u));
    occ_ray_result_t r;
    (void)occ_cast_ray(m, v3(-4.0f, 0.0f, 0.45f), v3(1.0f, 0.6f, 0.0f), true, 10.0f, &r);
    out->ray_hit = (uint8_t)(r.hit ? 1u : 0u);
    memcpy(out->ray_key, r.key.k, sizeof out->ray_key);
}

/* The reader: runs to completion inside the interrupt (one core: the writer is stopped). */
void shared_isr_systick(void);
void shared_isr_systick(void)
{
    const uint32_t t0 = SYST_CVR;
    occ_view_t v;
    if (occ_read_begin(&map, 0u, &v) != OCC_OK) {
        isr_fail++;
    } else {
        answers_t got;
        answer(occ_view_map(&v), &got);
        if (v.version > MAX_VERSIONS || memcmp(&got, &record[v.version], sizeof got) != 0) {
            isr_fail++;
        }
        if (v.version < isr_last_version) {
            isr_fail++; /* a newer view never shows an older version */
        }
        isr_versions += v.version != isr_last_version ? 1u : 0u;
        isr_last_version = v.version;
        occ_read_end(&map, &v);
    }
    const uint32_t t1 = SYST_CVR;
    /* SysTick counts down; the period is reloaded at zero, so a wrap adds the reload value. */
    const uint32_t dt = t0 >= t1 ? t0 - t1 : t0 + (SYST_RVR + 1u) - t1;
    if (dt > isr_worst_ticks) {
        isr_worst_ticks = dt;
    }
    isr_runs++;
    SYST_RVR = 5000u + next_rand() % 30000u; /* next preemption at a pseudo-random point */
}

/* One synthetic scan: a wall and a floor patch seen from a sensor moving along x. */
static void make_scan(unsigned k, occ_vec3_t *origin)
{
    const float ox = -2.0f + 0.15f * (float)(k % 40u);
    *origin = v3(ox, 0.0f, 0.5f);
    for (unsigned i = 0; i < N_POINTS; i++) {
        const float u = (float)(next_rand() % 1000u) / 1000.0f;
        const float w = (float)(next_rand() % 1000u) / 1000.0f;
        cloud[i] = i % 3u == 0u ? v3(ox - 1.5f + 3.0f * u, 1.0f + 2.0f * w, 0.0f)
                                : v3(ox - 2.0f + 4.0f * u, 3.0f + 0.2f * (float)(k % 7u), 1.5f * w);
    }
}

static unsigned write_versions(void)
{
    static occ_insert_params_t ip; /* static: the writer's frame stays small */
    static occ_evict_policy_t pol;
    static occ_evict_out_t ev;
    ip = occ_insert_params_default();
    pol = occ_evict_policy_default();
    pol.keep_radius_m = 2.0f;
    occ_evict_out_init(&ev);
    ip.auto_evict = &pol;
    ip.auto_evict_state = &ev;
    unsigned fails = 0;
    for (uint32_t v = 1; v <= MAX_VERSIONS; v++) {
        occ_vec3_t o;
        make_scan(v, &o);
        fails += occ_map_write_begin(&map) != OCC_OK ? 1u : 0u;
        (void)occ_map_evict(&map, &o, &pol, 800u, &ev);
        const occ_err_t e = occ_map_insert_cloud(&map, &o, cloud, N_POINTS, &ip, scratch,
                                                 sizeof scratch, NULL);
        fails += e != OCC_OK && e != OCC_ERR_NOMEM ? 1u : 0u;
        if (v % 50u == 49u) {
            occ_map_clear(&map);
        }
        fails += occ_map_version(&map) != v ? 1u : 0u; /* every scan changes the map */
        answer(&map, &record[v]); /* before the version is published */
        fails += occ_map_write_end(&map) != OCC_OK ? 1u : 0u;
        fails += occ_map_version(&map) != v ? 1u : 0u;
    }
    printf("shared-isr: evictions %lu\n", (unsigned long)ev.evictions);
    return fails;
}

int main(void)
{
    const occ_map_config_t cfg = occ_map_config_default();
    if (occ_map_init(&map, &cfg, arena, sizeof arena) != OCC_OK ||
        occ_shared_bytes(&map, 1u) > sizeof shmem) {
        return 90;
    }
    answer(&map, &record[0]);
    if (occ_map_share(&map, shmem, sizeof shmem, 1u) != OCC_OK) {
        return 91;
    }
    SYST_RVR = 30000u;
    SYST_CVR = 0u;
    SYST_CSR = 7u; /* processor clock, interrupt on, enabled */
    const unsigned wfail = write_versions();
    SYST_CSR = 0u;
    const unsigned check_fail = occ_map_check(&map) != OCC_OK ? 1u : 0u;
    static occ_shared_info_t info;
    (void)occ_shared_info(&map, &info);
    printf("shared-isr: %u versions, %lu interrupts (reader), %lu version changes seen, %lu "
           "mismatches or refused views, %lu publishes, %lu deferred, writer failures %u, "
           "map check %s\n",
           MAX_VERSIONS, (unsigned long)isr_runs, (unsigned long)isr_versions,
           (unsigned long)isr_fail, (unsigned long)info.publishes, (unsigned long)info.deferred,
           wfail, check_fail == 0u ? "ok" : "FAILED");
    printf("shared-isr: interrupt (view + %u lookups + sphere + ray + compare) worst case %lu "
           "SysTick ticks = %lu instructions under qemu -icount shift=0 (40 per tick)\n",
           N_PROBES, (unsigned long)isr_worst_ticks, (unsigned long)(isr_worst_ticks * 40u));
    const unsigned total = (unsigned)isr_fail + wfail + check_fail + (isr_runs < 20u ? 1u : 0u);
    return total > 99u ? 99 : (int)total;
}

/* ---- reset and vectors (this image's own: SysTick is the reader) --------------------------- */
extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss, _estack;
extern void initialise_monitor_handles(void);
void shared_isr_reset(void);
void shared_isr_fault(void);
void shared_isr_idle(void);

void shared_isr_idle(void)
{
}

void shared_isr_fault(void)
{
    exit(100);
}

void shared_isr_reset(void)
{
    volatile uint32_t *const cpacr = (volatile uint32_t *)0xE000ED88u;
    *cpacr |= 0xFu << 20; /* FPU on before any float instruction */
    __asm__ volatile("dsb\n\tisb" ::: "memory");
    const uint32_t *src = &_sidata;
    for (uint32_t *dst = &_sdata; dst < &_edata;) {
        *dst++ = *src++;
    }
    for (uint32_t *dst = &_sbss; dst < &_ebss;) {
        *dst++ = 0u;
    }
    initialise_monitor_handles();
    exit(main());
}

typedef void (*vector_t)(void);
typedef struct {
    uint32_t *initial_sp;
    vector_t handlers[15];
} vectors_t;

/* SP, then Reset, NMI, HardFault, MemManage, BusFault, UsageFault, 4 reserved, SVCall,
 * DebugMon, reserved, PendSV, SysTick. */
__attribute__((section(".isr_vector"), used)) const vectors_t shared_isr_vectors = {
    &_estack,
    {shared_isr_reset, shared_isr_fault, shared_isr_fault, shared_isr_fault, shared_isr_fault,
     shared_isr_fault, 0, 0, 0, 0, shared_isr_idle, shared_isr_idle, 0, shared_isr_idle,
     shared_isr_systick}};
