/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * shared.c - `make bench` step for the shared map (issue 20, occ_shared.h). The writer replays
 * the real TUM frames and scan.dat (tests/support/shared_replay.h: eviction in a small arena)
 * in three configurations, interleaved round by round on fresh maps:
 *   plain   - the single-threaded map (never shared)
 *   shared  - the same map shared, no reader running (the publish copy per scan is the cost)
 *   readers - shared, with 4 reader threads each opening a view, answering the probe set
 *             (states, sphere and capsule checks, ray casts, sectors) and closing it, at
 *             50 Hz each (the top of an avoidance loop's 10-50 Hz; a reader spinning flat out
 *             measures only how many cores the machine has: readers never block the writer,
 *             but on a shared 2-core box they take its CPU)
 * and prints the writer's median time per scan (median over rounds, with min-max of the round
 * medians), the ratios against plain (target <= 1.20), and the readers' latency while the
 * writer runs: occ_read_begin alone and a whole view (begin + probes + end), median, p99, max.
 * Usage: shared [rounds (5)] [scans per run (100)] [arena MiB (8)] [reader Hz (50)]
 */
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "occmap/occmap.h"
#include "support/shared_replay.h"

#define N_READERS 4u
#define MAX_SAMPLES 200000u

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double quantile(double *v, size_t n, double q)
{
    if (n == 0u) {
        return 0.0;
    }
    qsort(v, n, sizeof *v, cmp_double);
    size_t i = (size_t)(q * (double)(n - 1u) + 0.5);
    return v[i < n ? i : n - 1u];
}

typedef struct {
    occ_map_t *map;
    unsigned slot;
    double *begin_s, *view_s;
    size_t n;
    occ_sectors_t sec;
} reader_t;

static unsigned stop_flag;
static long reader_period_ns = 20000000; /* 50 Hz per reader: an avoidance loop's top rate */

static void *reader_main(void *arg)
{
    reader_t *const r = arg;
    sr_answers_t a;
    const struct timespec pause = {0, reader_period_ns};
    while (__atomic_load_n(&stop_flag, __ATOMIC_ACQUIRE) == 0u) {
        occ_view_t v;
        const double t0 = now_s();
        if (occ_read_begin(r->map, r->slot, &v) != OCC_OK) {
            break;
        }
        const double t1 = now_s();
        sr_answer(occ_view_map(&v), SR_Q_ALL, &r->sec, &a);
        occ_read_end(r->map, &v);
        const double t2 = now_s();
        if (r->n < MAX_SAMPLES) {
            r->begin_s[r->n] = t1 - t0;
            r->view_s[r->n] = t2 - t0;
            r->n++;
        }
        nanosleep(&pause, NULL);
    }
    return NULL;
}

enum { PLAIN, SHARED, READERS, N_CONF };
static const char *const conf_name[N_CONF] = {"plain", "shared", "readers"};

/* One run: a fresh map, `scans` scans; the median writer time per scan (seconds). */
static double run(int conf, size_t scans, size_t arena_bytes, reader_t *rd, size_t *copied)
{
    sr_writer_t w;
    if (!sr_writer_init(&w, 8u, 16u)) {
        exit(77);
    }
    uint8_t *const arena = malloc(arena_bytes);
    occ_map_t map;
    const occ_map_config_t cfg = occ_map_config_default();
    (void)occ_map_init(&map, &cfg, arena, arena_bytes);
    uint8_t *shmem = NULL;
    if (conf != PLAIN) {
        const size_t need = occ_shared_bytes(&map, N_READERS);
        shmem = malloc(need);
        (void)occ_map_share(&map, shmem, need, N_READERS);
    }
    pthread_t th[N_READERS];
    __atomic_store_n(&stop_flag, 0u, __ATOMIC_RELEASE);
    if (conf == READERS) {
        for (unsigned i = 0; i < N_READERS; i++) {
            rd[i].map = &map;
            rd[i].slot = i;
            pthread_create(&th[i], NULL, reader_main, &rd[i]);
        }
    }
    double *const t = malloc(scans * sizeof *t);
    for (size_t k = 0; k < scans; k++) {
        const double t0 = now_s();
        (void)sr_writer_step(&w, &map);
        t[k] = now_s() - t0;
    }
    __atomic_store_n(&stop_flag, 1u, __ATOMIC_RELEASE);
    if (conf == READERS) {
        for (unsigned i = 0; i < N_READERS; i++) {
            pthread_join(th[i], NULL);
        }
    }
    occ_shared_info_t info;
    if (conf != PLAIN && occ_shared_info(&map, &info) == OCC_OK) {
        *copied = info.copied_bytes_last;
    }
    const double med = quantile(t, scans, 0.5);
    free(t);
    free(shmem);
    free(arena);
    sr_writer_free(&w);
    return med;
}

int main(int argc, char **argv)
{
    const unsigned rounds = argc > 1 ? (unsigned)atoi(argv[1]) : 5u;
    const size_t scans = argc > 2 ? (size_t)atoi(argv[2]) : 100u;
    const size_t arena_bytes = (argc > 3 ? (size_t)atoi(argv[3]) : 8u) << 20;
    if (argc > 4 && atoi(argv[4]) > 0) {
        reader_period_ns = 1000000000L / atoi(argv[4]);
    }
    static reader_t rd[N_READERS];
    for (unsigned i = 0; i < N_READERS; i++) {
        rd[i].begin_s = malloc(MAX_SAMPLES * sizeof(double));
        rd[i].view_s = malloc(MAX_SAMPLES * sizeof(double));
    }
    double med[N_CONF][64];
    size_t copied = 0;
    for (unsigned r = 0; r < rounds && r < 64u; r++) {
        for (int j = 0; j < N_CONF; j++) {
            const int c = (j + (int)r) % N_CONF; /* rotate the order: no config always first */
            med[c][r] = run(c, scans, arena_bytes, rd, &copied);
        }
    }
    printf("shared bench: writer, %zu TUM/scan.dat scans per run in %zu MiB with eviction, %u "
           "interleaved rounds (median of round medians, [min-max]); readers at %ld Hz each\n",
           scans, arena_bytes >> 20, rounds, 1000000000L / reader_period_ns);
    double m[N_CONF];
    for (int c = 0; c < N_CONF; c++) {
        double v[64];
        memcpy(v, med[c], rounds * sizeof(double));
        const double lo = quantile(v, rounds, 0.0), hi = quantile(v, rounds, 1.0);
        m[c] = quantile(v, rounds, 0.5);
        printf("  %-8s %8.3f ms/scan [%.3f-%.3f]  x%.3f vs plain\n", conf_name[c], 1e3 * m[c],
               1e3 * lo, 1e3 * hi, m[c] / m[PLAIN]);
    }
    printf("  last publish copied %zu bytes\n", copied);
    double *b = malloc(N_READERS * MAX_SAMPLES * sizeof(double));
    double *vw = malloc(N_READERS * MAX_SAMPLES * sizeof(double));
    size_t n = 0;
    for (unsigned i = 0; i < N_READERS; i++) { /* every readers round's samples */
        memcpy(b + n, rd[i].begin_s, rd[i].n * sizeof(double));
        memcpy(vw + n, rd[i].view_s, rd[i].n * sizeof(double));
        n += rd[i].n;
    }
    const double b50 = quantile(b, n, 0.5), b99 = quantile(b, n, 0.99), bmax = quantile(b, n, 1.0);
    const double v50 = quantile(vw, n, 0.5), v99 = quantile(vw, n, 0.99),
                 vmax = quantile(vw, n, 1.0);
    printf("  readers (%zu views while the writer ran): occ_read_begin median %.2f us, "
           "p99 %.2f us, max %.2f us; whole view (probe set incl. 2 sector updates) median "
           "%.1f us, p99 %.1f us, max %.1f us\n",
           n, 1e6 * b50, 1e6 * b99, 1e6 * bmax, 1e6 * v50, 1e6 * v99, 1e6 * vmax);
    printf("  writer slowdown: shared x%.3f, with readers x%.3f (target <= 1.20)\n",
           m[SHARED] / m[PLAIN], m[READERS] / m[PLAIN]);
    free(b);
    free(vw);
    return 0;
}
