/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * shared_isr_main.c - one writer, one interrupt reader on a shared map (issue 20), on qemu's
 * mps2-an386 (Cortex-M4F, semihosting). main() is the writer: per version it integrates a
 * slice of OctoMap's real scan.dat (every 8th point embedded at build time, port/shared_m4.mk;
 * version k takes every SCAN_STRIDE-th of those from offset k, so each version sees the whole
 * field of view) from a sensor moving around a circle, in a small arena with eviction (a slice
 * per version plus the insert's automatic eviction), and records the answers of a probe set on
 * its own map before the version goes out (write section). SysTick, re-armed with a
 * pseudo-random period after each interrupt, preempts the writer anywhere (mid-insert,
 * mid-eviction, mid-publish copy) and is the reader: it opens a view, answers the probes (voxel
 * states, sphere and capsule checks, ray casts, obstacle sectors), compares them with the
 * record of the view's version and closes the view. The exit status is the number of failures
 * (mismatches, refused views, failed checks, no eviction, too few interrupts).
 * The interrupt's worst-case time is printed in SysTick ticks of qemu's 25 MHz clock; run with
 * -icount shift=0 (port/shared_m4.mk) a tick is 40 guest instructions (not a real M4's cycles:
 * no wait states or pipeline), and as microseconds at 168 MHz taking one instruction as one
 * cycle (an estimate: flash wait states and FPU/divide latencies make a real M4 slower).
 * Own vector table and reset code (the image does not link startup_m4.c: SysTick is ours).
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "occmap/occmap.h"
#include "occmap/occ_sectors.h"

#define MAX_VERSIONS 120u
#define N_STATES 32u
#define N_SPHERES 4u
#define N_CAPSULES 4u
#define N_RAYS 2u
#define N_SECTORS 36u
#define SCAN_STRIDE 48u   /* version k inserts embedded points k % SCAN_STRIDE + j * SCAN_STRIDE */
#define CLOUD_MAX 512u
#define PATH_R 8.0f       /* the sensor's circle, metres */
#define CLOCK_MHZ 168u    /* a Cortex-M4F flight controller (STM32F4) for the microseconds */
/* The arena (360 KB; its two snapshots double that) is small enough that the eviction slice
 * each version (keep 4 m around the sensor) frees blocks all the time, large enough that a
 * scan to 5 m fits without the insert's automatic eviction. */
#define ARENA_INNER 3000u
#define ARENA_LEAF 12000u
#define RANGE_M 5.0f
#define KEEP_M 4.0f

/* The embedded points: little-endian float x, y, z triples in the sensor's frame
 * (port/baremetal/scan_subset.py + embed_bytes.py, generated into build/fw/gen). */
extern const unsigned char shared_isr_scan[];
extern const size_t shared_isr_scan_len;

typedef struct {
    uint8_t state[N_STATES];
    uint8_t sphere[N_SPHERES];     /* err + 2 * safe + 4 * outside */
    uint8_t capsule[N_CAPSULES];
    uint8_t ray_hit[N_RAYS];
    uint32_t ray_key[N_RAYS][3];
    uint16_t sector[N_SECTORS];
} answers_t;

static uint8_t arena[OCC_ARENA_BYTES(ARENA_INNER, ARENA_LEAF)];
static uint8_t shmem[OCC_SHARED_BYTES(sizeof arena)];
static occ_map_t map;
static answers_t record[MAX_VERSIONS + 1u];
static occ_vec3_t cloud[CLOUD_MAX];
static uint8_t scratch[256u * 1024u];
static occ_sectors_t isr_sec, writer_sec; /* work space: one each, the ISR's is its own */
static occ_sectors_config_t sec_cfg;

static volatile uint32_t isr_runs, isr_fail, isr_versions, isr_last_version;
/* Worst SysTick ticks of the whole interrupt, of occ_read_begin + occ_read_end and of each kind
 * of probe. */
static volatile uint32_t isr_worst_ticks, isr_worst_open_close, isr_worst_states,
    isr_worst_collide, isr_worst_rays, isr_worst_sectors;
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

/* Probe i of n: spread over the ring the sensor's path sweeps, deterministic. */
static occ_vec3_t probe(unsigned i, unsigned n)
{
    const float a = 6.2831853f * (float)i / (float)n;
    const float r = PATH_R + 3.0f * sinf(7.0f * a);
    return v3(r * cosf(a), r * sinf(a), 0.2f + 0.6f * cosf(5.0f * a));
}

static uint8_t collide_code(occ_err_t e, const occ_collision_t *c)
{
    return (uint8_t)((e != OCC_OK ? 1u : 0u) | (c->safe ? 2u : 0u) | (c->outside ? 4u : 0u));
}

static void answer_states(const occ_map_t *m, answers_t *out)
{
    for (unsigned i = 0; i < N_STATES; i++) {
        out->state[i] = (uint8_t)occ_map_state_at(m, probe(i, N_STATES));
    }
}

static void answer_collide(const occ_map_t *m, answers_t *out)
{
    occ_collision_t c;
    for (unsigned i = 0; i < N_SPHERES; i++) {
        const occ_err_t e = occ_collide_sphere(m, probe(i, N_SPHERES), 0.6f, OCC_UNKNOWN_SAFE, &c);
        out->sphere[i] = collide_code(e, &c);
    }
    for (unsigned i = 0; i < N_CAPSULES; i++) { /* 1.5 m of path ahead, along the circle */
        const occ_vec3_t a = probe(2u * i + 1u, 2u * N_CAPSULES);
        const float k = 1.5f / sqrtf(a.x * a.x + a.y * a.y);
        const occ_vec3_t b = v3(a.x - k * a.y, a.y + k * a.x, a.z);
        const occ_err_t e = occ_collide_capsule(m, a, b, 0.3f, OCC_UNKNOWN_SAFE, &c);
        out->capsule[i] = collide_code(e, &c);
    }
}

static void answer_rays(const occ_map_t *m, answers_t *out)
{
    for (unsigned i = 0; i < N_RAYS; i++) {
        const occ_vec3_t o = probe(3u * i, 3u * N_RAYS);
        occ_ray_result_t r;
        (void)occ_cast_ray(m, o, v3(-o.y, o.x, 0.05f), true, 10.0f, &r); /* along the path */
        out->ray_hit[i] = (uint8_t)(r.hit ? 1u : 0u);
        memcpy(out->ray_key[i], r.key.k, sizeof out->ray_key[i]);
    }
}

static void answer_sectors(const occ_map_t *m, occ_sectors_t *sec, answers_t *out)
{
    occ_pose_t pose = occ_pose_identity();
    pose.p = probe(1u, 5u);
    pose.p.z = 0.5f;
    (void)occ_sectors_compute(m, &pose, &sec_cfg, sec);
    memcpy(out->sector, sec->distance_cm, sizeof out->sector);
}

static void answer(const occ_map_t *m, occ_sectors_t *sec, answers_t *out)
{
    memset(out, 0, sizeof *out);
    answer_states(m, out);
    answer_collide(m, out);
    answer_rays(m, out);
    answer_sectors(m, sec, out);
}

/* SysTick ticks from t0 to t1: it counts down and reloads at zero (a wrap adds the reload). */
static uint32_t ticks(uint32_t t0, uint32_t t1)
{
    return t0 >= t1 ? t0 - t1 : t0 + (SYST_RVR + 1u) - t1;
}

static void worst(volatile uint32_t *w, uint32_t dt)
{
    if (dt > *w) {
        *w = dt;
    }
}

/* The reader: runs to completion inside the interrupt (one core: the writer is stopped). */
void shared_isr_systick(void);
void shared_isr_systick(void)
{
    const uint32_t t0 = SYST_CVR;
    occ_view_t v;
    const occ_err_t e = occ_read_begin(&map, 0u, &v);
    const uint32_t t1 = SYST_CVR;
    if (e != OCC_OK) {
        isr_fail++;
    } else {
        static answers_t got;
        memset(&got, 0, sizeof got);
        const occ_map_t *const vm = occ_view_map(&v);
        uint32_t t = SYST_CVR;
        answer_states(vm, &got);
        worst(&isr_worst_states, ticks(t, SYST_CVR));
        t = SYST_CVR;
        answer_collide(vm, &got);
        worst(&isr_worst_collide, ticks(t, SYST_CVR));
        t = SYST_CVR;
        answer_rays(vm, &got);
        worst(&isr_worst_rays, ticks(t, SYST_CVR));
        t = SYST_CVR;
        answer_sectors(vm, &isr_sec, &got);
        worst(&isr_worst_sectors, ticks(t, SYST_CVR));
        if (v.version > MAX_VERSIONS || memcmp(&got, &record[v.version], sizeof got) != 0) {
            isr_fail++;
        }
        if (v.version < isr_last_version) {
            isr_fail++; /* a newer view never shows an older version */
        }
        isr_versions += v.version != isr_last_version ? 1u : 0u;
        isr_last_version = v.version;
        const uint32_t t3 = SYST_CVR;
        occ_read_end(&map, &v);
        worst(&isr_worst_open_close, ticks(t0, t1) + ticks(t3, SYST_CVR));
    }
    worst(&isr_worst_ticks, ticks(t0, SYST_CVR));
    isr_runs++;
    /* Next preemption at a pseudo-random point, well after this interrupt's own time. */
    SYST_RVR = 10000u + 3u * isr_worst_ticks + next_rand() % 30000u;
}

static size_t scan_points(void)
{
    return shared_isr_scan_len / (3u * sizeof(float));
}

/* Version k's scan: the k-th slice of the embedded points, seen from the sensor at angle
 * 0.35 k on the circle, heading along it. */
static size_t make_scan(unsigned k, occ_vec3_t *origin)
{
    const float ang = 0.35f * (float)k;
    const float ch = cosf(ang + 1.5707963f), sh = sinf(ang + 1.5707963f);
    *origin = v3(PATH_R * cosf(ang), PATH_R * sinf(ang), 0.5f);
    size_t n = 0;
    for (size_t j = k % SCAN_STRIDE; j < scan_points() && n < CLOUD_MAX; j += SCAN_STRIDE) {
        float r[3];
        memcpy(r, shared_isr_scan + j * sizeof r, sizeof r);
        cloud[n++] = v3(origin->x + ch * r[0] - sh * r[1], origin->y + sh * r[0] + ch * r[1],
                        origin->z + r[2]);
    }
    return n;
}

static unsigned write_versions(void)
{
    static occ_insert_params_t ip; /* static: the writer's frame stays small */
    static occ_evict_policy_t pol;
    static occ_evict_out_t ev;
    ip = occ_insert_params_default();
    ip.max_range_m = RANGE_M;
    pol = occ_evict_policy_default();
    pol.keep_radius_m = KEEP_M;
    occ_evict_out_init(&ev);
    ip.auto_evict = &pol;
    ip.auto_evict_state = &ev;
    unsigned fails = 0, nomem = 0, distinct = 0;
    size_t points = 0;
    for (uint32_t v = 1; v <= MAX_VERSIONS; v++) {
        occ_vec3_t o;
        const size_t n = make_scan(v, &o);
        points += n;
        fails += occ_map_write_begin(&map) != OCC_OK ? 1u : 0u;
        (void)occ_map_evict(&map, &o, &pol, 800u, &ev);
        const occ_err_t e = occ_map_insert_cloud(&map, &o, cloud, n, &ip, scratch,
                                                 sizeof scratch, NULL);
        fails += e != OCC_OK && e != OCC_ERR_NOMEM ? 1u : 0u;
        nomem += e == OCC_ERR_NOMEM ? 1u : 0u;
        if (v % 50u == 49u) {
            occ_map_clear(&map);
        }
        fails += occ_map_version(&map) != v ? 1u : 0u; /* every scan changes the map */
        answer(&map, &writer_sec, &record[v]); /* before the version is published */
        distinct += memcmp(&record[v], &record[v - 1u], sizeof record[v]) != 0 ? 1u : 0u;
        fails += occ_map_write_end(&map) != OCC_OK ? 1u : 0u;
        fails += occ_map_version(&map) != v ? 1u : 0u;
    }
    printf("shared-isr: writer: %u versions of scan.dat (%lu of its points embedded, %lu "
           "integrated), %u with changed probe answers, %lu evictions (%lu blocks freed), %u "
           "NOMEM\n",
           MAX_VERSIONS, (unsigned long)scan_points(), (unsigned long)points, distinct,
           (unsigned long)ev.evictions, (unsigned long)ev.blocks_freed, nomem);
    if (ev.evictions == 0u) {
        printf("shared-isr: FAIL: no eviction: the arena does not make the writer free blocks\n");
        fails++;
    }
    if (distinct < MAX_VERSIONS / 2u) {
        printf("shared-isr: FAIL: the probes hardly change (%u versions): mismatches would not "
               "show\n", distinct);
        fails++;
    }
    return fails;
}

static void print_worst(const char *what, uint32_t worst_ticks)
{
    const unsigned long instr = (unsigned long)worst_ticks * 40u;
    printf("shared-isr:   %-40s %6lu ticks = %8lu instructions = %5lu.%lu us\n", what,
           (unsigned long)worst_ticks, instr, instr / CLOCK_MHZ,
           (instr % CLOCK_MHZ) * 10u / CLOCK_MHZ);
}

int main(void)
{
    const occ_map_config_t cfg = occ_map_config_default();
    sec_cfg = occ_sectors_config_default();
    sec_cfg.n_sectors = N_SECTORS;
    sec_cfg.increment_deg = 10.0f;
    sec_cfg.max_distance_cm = 600u;
    if (occ_map_init(&map, &cfg, arena, sizeof arena) != OCC_OK ||
        occ_shared_bytes(&map, 1u) > sizeof shmem || scan_points() / SCAN_STRIDE + 1u > CLOUD_MAX ||
        scan_points() < SCAN_STRIDE || occ_sectors_config_check(&sec_cfg) != OCC_OK) {
        return 90;
    }
    answer(&map, &writer_sec, &record[0]);
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
    printf("shared-isr: interrupt worst case, SysTick ticks of qemu -icount shift=0 (40 "
           "instructions each) and us at %u MHz if one instruction took one cycle (an estimate):\n",
           CLOCK_MHZ);
    print_worst("whole interrupt: view, probes, compare", isr_worst_ticks);
    print_worst("occ_read_begin + occ_read_end", isr_worst_open_close);
    print_worst("32 voxel states (occ_map_state_at)", isr_worst_states);
    print_worst("4 spheres r 0.6, 4 capsules 1.5 m r 0.3", isr_worst_collide);
    print_worst("2 ray casts to 10 m", isr_worst_rays);
    print_worst("36 sectors to 6 m (occ_sectors_compute)", isr_worst_sectors);
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
