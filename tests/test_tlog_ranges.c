/* SPDX-License-Identifier: BSD-3-Clause */
/* test_tlog_ranges.c - the real ArduSub log (../shared/data/mavlink, 919 downward sonar
 * readings) through the tlog reader, the translator, the log's poses and
 * occ_map_insert_ranges(), against what pymavlink alone says about each reading
 * (tools/mav_tlog_sonar_ref.py -> build/mavlink/sonar_ref.txt): every beam where pymavlink puts
 * it, the occupied voxels on the surface the readings imply, free space above it, none below;
 * and a small log pymavlink packed (OBSTACLE_DISTANCE, our own echo, a reading without a pose). */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "occmap/host/occ_tlog_ranges.h"
#include "occmap/occ_query.h"

#define TLOG "../shared/data/mavlink/ardusub_2023-04-18_11-03-34.tlog"
#define SONAR_REF "build/mavlink/sonar_ref.txt"
#define SYNTH "build/mavlink/synth.tlog"
#define RES 0.5f
#define ARENA_BYTES ((size_t)96 << 20)
#define MAX_READINGS 2000

typedef struct {
    uint64_t t_us;
    double d, cone, o[3], ax[3];
} reading_t;

static reading_t ref[MAX_READINGS];
static size_t n_ref, n_seen;

static size_t load_ref(void)
{
    FILE *f = fopen(SONAR_REF, "r");
    char line[256];
    size_t n = 0;
    if (f == NULL) {
        return 0;
    }
    while (fgets(line, sizeof line, f) != NULL && n < MAX_READINGS) {
        reading_t *r = &ref[n];
        unsigned long long t;
        if (sscanf(line, "r %llu %lf %lf %lf %lf %lf %lf %lf %lf", &t, &r->d, &r->cone, &r->o[0],
                   &r->o[1], &r->o[2], &r->ax[0], &r->ax[1], &r->ax[2]) == 9) {
            r->t_us = t;
            n++;
        } else {
            fail_msg("unexpected line in %s: %s", SONAR_REF, line); /* SKIP or nopose */
        }
    }
    fclose(f);
    return n;
}

/* The voxels around reading i's end (pymavlink's point, 3 x 3 x 3) and one on its axis 2 voxels
 * short of it: their log-odds before the reading (read after the previous one). */
typedef struct {
    float end[27], axis;
} probe_t;
static probe_t before;
static const occ_map_t *g_map;
static size_t n_hits_checked;

static occ_vec3_t along(const reading_t *r, double s, int k)
{
    const occ_vec3_t p = {(float)(r->o[0] + s * r->ax[0] + (k % 3 - 1) * (double)RES),
                          (float)(r->o[1] + s * r->ax[1] + (k / 3 % 3 - 1) * (double)RES),
                          (float)(r->o[2] + s * r->ax[2] + (k / 9 - 1) * (double)RES)};
    return p;
}

static float logodds_at(occ_vec3_t p)
{
    occ_node_info_t info;
    assert_int_equal(occ_map_read(g_map, p, 0, &info), OCC_OK);
    return info.logodds; /* 0 when unobserved */
}

static void read_probe(const reading_t *r, probe_t *pr)
{
    for (int k = 0; k < 27; k++) {
        pr->end[k] = logodds_at(along(r, r->d, k));
    }
    pr->axis = logodds_at(along(r, r->d - 4.0 * (double)RES, 13));
}

/* The reading just integrated: a hit (+hit, clamped) in the voxel of its end or a neighbour
 * (the C end point is pymavlink's within a centimetre), a miss on its axis short of it. */
static void check_update(const reading_t *r)
{
    probe_t now;
    read_probe(r, &now);
    const occ_map_config_t *c = &g_map->cfg;
    bool hit = false;
    for (int k = 0; k < 27; k++) {
        const float want = fminf(before.end[k] + c->hit, c->clamp_max);
        hit = hit || fabsf(now.end[k] - want) < 0.01f;
    }
    if (!hit) {
        fail_msg("reading %zu (%.2f m): no hit update around its end", n_seen, r->d);
    }
    if (fabsf(now.axis - fmaxf(before.axis + c->miss, c->clamp_min)) >= 0.01f) {
        fail_msg("reading %zu: axis voxel %.3f -> %.3f, not a miss", n_seen, (double)before.axis,
                 (double)now.axis);
    }
    n_hits_checked++;
}

/* Each integrated reading: the same stamp, distance, cone, origin and axis as pymavlink's. */
static void on_beams(void *user, uint64_t stamp_us, const occ_mav_beams_t *b,
                     const occ_pose_t *sensor)
{
    (void)user;
    assert_true(n_seen < n_ref);
    const reading_t *r = &ref[n_seen++];
    assert_true(stamp_us == r->t_us);
    assert_int_equal(b->n, 1);
    assert_true(fabs((double)b->beam[0].distance_m - r->d) < 1e-4);
    assert_true(fabs((double)b->beam[0].cone_half_rad - r->cone) < 1e-6);
    const occ_vec3_t axf = occ_pose_rotate(sensor, b->beam[0].dir);
    const double ax[3] = {axf.x, axf.y, axf.z};
    const double o[3] = {sensor->p.x, sensor->p.y, sensor->p.z};
    const double dot = ax[0] * r->ax[0] + ax[1] * r->ax[1] + ax[2] * r->ax[2];
    if (dot < cos(0.2 * 0.017453292519943295)) {
        fail_msg("reading %zu: axis (%f %f %f), pymavlink (%f %f %f)", n_seen, ax[0], ax[1],
                 ax[2], r->ax[0], r->ax[1], r->ax[2]);
    }
    assert_true(fabs(o[0] - r->o[0]) < 0.01 && fabs(o[1] - r->o[1]) < 0.01 &&
                fabs(o[2] - r->o[2]) < 0.01);
    check_update(r);
    if (n_seen < n_ref) {
        read_probe(&ref[n_seen], &before); /* the next reading's voxels, before it */
    }
}

/* Angle between v - o and the reading's axis, and |v - o|. */
static double off_axis(const reading_t *r, occ_vec3_t v, double *range)
{
    const double dx = (double)v.x - r->o[0], dy = (double)v.y - r->o[1];
    const double dz = (double)v.z - r->o[2];
    *range = sqrt(dx * dx + dy * dy + dz * dz);
    const double c = (dx * r->ax[0] + dy * r->ax[1] + dz * r->ax[2]) / (*range > 0 ? *range : 1);
    return acos(c > 1 ? 1 : (c < -1 ? -1 : c));
}

/* Some reading's cone holds the voxel centre v within `slack_m` of the reading's end (hit) or
 * short of it (free). A voxel centre is at most RES * sqrt(3) / 2 from the sampled ray that
 * updated it, so the slack is one voxel diagonal. */
static bool explained(occ_vec3_t v, bool hit)
{
    const double slack = (double)RES * 1.7320508;
    for (size_t i = 0; i < n_ref; i++) {
        double range;
        const double ang = off_axis(&ref[i], v, &range);
        if (!hit && range <= slack) {
            return true; /* the voxel the ray starts in */
        }
        if (ang > ref[i].cone + asin(fmin(1.0, slack / fmax(range, slack)))) {
            continue;
        }
        if (hit ? fabs(range - ref[i].d) <= slack : range <= ref[i].d + slack) {
            return true;
        }
    }
    return false;
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Median and quartiles of v[0..n) (sorted in place). */
static void quartiles(double *v, size_t n, double q[3])
{
    qsort(v, n, sizeof *v, cmp_double);
    q[0] = v[n / 4u];
    q[1] = v[n / 2u];
    q[2] = v[(3u * n) / 4u];
}

static double (*pts)[3];

/* Every occupied / free voxel within 60 m: explained by some reading; occupied centres into pts. */
static size_t check_voxels(const occ_map_t *map, occ_state_t want, size_t *unexplained,
                           double *deepest)
{
    occ_volume_t vol;
    const occ_vec3_t lo = {-60, -60, -60}, hi = {60, 60, 1};
    assert_int_equal(occ_volume_aabb(&vol, lo, hi), OCC_OK);
    const occ_pred_t pred = {want == OCC_STATE_OCCUPIED ? OCC_PRED_OCCUPIED : OCC_PRED_FREE, 0,
                             OCC_ITER_SPLIT};
    occ_query_iter_t it;
    assert_int_equal(occ_query_begin(&it, map, &vol, pred), OCC_OK);
    occ_query_node_t nd;
    size_t n = 0;
    *unexplained = 0;
    *deepest = 0;
    while (occ_query_next(&it, &nd)) {
        /* A pruned node (all its voxels alike) is reported whole: visit its voxels. */
        const int side = 1 << nd.level;
        for (int i = 0; i < side * side * side; i++) {
            const occ_vec3_t v = {nd.center.x + ((float)(i % side) + 0.5f) * RES - 0.5f * nd.size_m,
                                  nd.center.y + ((float)(i / side % side) + 0.5f) * RES -
                                      0.5f * nd.size_m,
                                  nd.center.z + ((float)(i / side / side) + 0.5f) * RES -
                                      0.5f * nd.size_m};
            if (!explained(v, want == OCC_STATE_OCCUPIED)) {
                ++*unexplained;
                printf("unexplained %s voxel (%.2f %.2f %.2f)\n",
                       want == OCC_STATE_OCCUPIED ? "occupied" : "free", (double)v.x, (double)v.y,
                       (double)v.z);
            }
            *deepest = fmin(*deepest, (double)v.z);
            if (want == OCC_STATE_OCCUPIED && n < 200000u) {
                pts[n][0] = (double)v.x;
                pts[n][1] = (double)v.y;
                pts[n][2] = (double)v.z;
            }
            n++;
        }
    }
    assert_int_equal(occ_query_status(&it), OCC_OK);
    return n;
}

static void test_ardusub_floor(void **state)
{
    (void)state;
    FILE *probe = fopen(TLOG, "rb");
    n_ref = load_ref();
    if (probe == NULL || n_ref == 0u) {
        printf("SKIP: needs %s and %s (tools/mav_tlog_sonar_ref.py)\n", TLOG, SONAR_REF);
        if (probe != NULL) {
            fclose(probe);
        }
        skip();
    }
    fclose(probe);
    void *arena = malloc(ARENA_BYTES);
    pts = malloc(200000u * sizeof *pts);
    assert_non_null(arena);
    assert_non_null(pts);
    occ_map_config_t cfg = occ_map_config_default();
    cfg.resolution_m = RES;
    occ_map_t map;
    assert_int_equal(occ_map_init(&map, &cfg, arena, ARENA_BYTES), OCC_OK);
    const occ_tlog_ranges_config_t tc = occ_tlog_ranges_config_default();
    const occ_insert_params_t rp = occ_insert_params_default();
    occ_tlog_ranges_stats_t st;
    char msg[256] = "";
    n_seen = 0;
    g_map = &map;
    memset(&before, 0, sizeof before); /* an empty map: every voxel unobserved (0) */
    assert_int_equal(occ_tlog_integrate_ranges(&map, TLOG, &tc, &rp, on_beams, NULL, &st, msg,
                                               sizeof msg), OCC_OK);
    /* The log as pymavlink counts it (tools/mav_tlog_ref.py): 50136 good frames, 1967 bad. */
    assert_true(st.frames_ok == 50136u && st.frames_bad == 1967u);
    assert_int_equal(st.range_msgs, 919);
    assert_int_equal(st.integrated, n_ref);
    assert_int_equal(n_seen, n_ref);
    assert_int_equal(st.no_pose + st.insert_errors, 919 - n_ref);
    assert_int_equal(st.position_source, 33); /* GLOBAL_POSITION_INT, no LOCAL_POSITION_NED */
    assert_true(st.no_horizontal_fix);
    assert_int_equal(st.tr.own_refused, 0);
    assert_int_equal(occ_map_check(&map), OCC_OK);

    size_t occ_bad, free_bad;
    double occ_deep, free_deep;
    const size_t n_occ = check_voxels(&map, OCC_STATE_OCCUPIED, &occ_bad, &occ_deep);
    const size_t n_free = check_voxels(&map, OCC_STATE_FREE, &free_bad, &free_deep);
    /* The floor under the vehicle: the level readings' hit depths (pymavlink) against the
     * occupied voxels within 2 m of their axis (the cone's axis rays; its ring lands 10 m out). */
    static double z_ref[MAX_READINGS], z_map[200000];
    size_t n_zr = 0, n_zm = 0;
    double ref_deep = 0;
    for (size_t i = 0; i < n_ref; i++) {
        const double hz = ref[i].o[2] + ref[i].d * ref[i].ax[2];
        ref_deep = fmin(ref_deep, hz);
        if (ref[i].ax[2] < -0.99) {
            z_ref[n_zr++] = hz;
        }
    }
    for (size_t i = 0; i < n_occ && i < 200000u; i++) {
        const double t = (pts[i][2] - ref[0].o[2]) / ref[0].ax[2];
        const double dx = pts[i][0] - (ref[0].o[0] + t * ref[0].ax[0]);
        const double dy = pts[i][1] - (ref[0].o[1] + t * ref[0].ax[1]);
        if (dx * dx + dy * dy < 4.0) {
            z_map[n_zm++] = pts[i][2];
        }
    }
    assert_true(n_zr > 800u && n_zm > 5u);
    double qr[3], qm[3];
    quartiles(z_ref, n_zr, qr);
    quartiles(z_map, n_zm, qm);
    printf("ardusub: %u readings integrated (%u without a pose), %zu occupied voxels (%zu off "
           "every reading's end), %zu free (%zu outside every cone)\n", st.integrated,
           st.no_pose, n_occ, occ_bad, n_free, free_bad);
    printf("ardusub: floor under the vehicle z = %.2f m (quartiles %.2f, %.2f) from %zu level "
           "readings; the map's %zu occupied voxels on their axis: %.2f m (%.2f, %.2f); "
           "deepest occupied %.2f, free %.2f, hit %.2f\n", qr[1], qr[0], qr[2], n_zr, n_zm,
           qm[1], qm[0], qm[2], occ_deep, free_deep, ref_deep);
    assert_true(n_occ > 100u);
    assert_int_equal(occ_bad, 0);   /* every hit on the surface some reading implies */
    assert_int_equal(free_bad, 0);  /* every free voxel inside some reading's cone, short of it */
    assert_true(free_deep > ref_deep - 1.0); /* nothing free below the deepest hit */
    assert_int_equal(n_hits_checked, n_ref);
    /* What stays occupied is the deep end of the readings' spread: a voxel at the median depth
     * is hit by ~10% of the readings and passed through by half of them (hit 0.85, miss -0.4).
     * The axis voxels lie within the level readings' depths, below their median. */
    assert_true(qm[2] <= qr[1] + (double)RES && qm[0] >= ref_deep - (double)RES);
    /* Straight down the first reading's axis, short of the shallowest level reading: free. */
    double shallowest = 1e9;
    for (size_t i = 0; i < n_ref; i++) {
        if (ref[i].ax[2] < -0.99) {
            shallowest = fmin(shallowest, ref[i].d);
        }
    }
    for (double s = 1.0; s < shallowest - 1.0; s += 0.25) {
        const occ_vec3_t p = {(float)(ref[0].o[0] + s * ref[0].ax[0]),
                              (float)(ref[0].o[1] + s * ref[0].ax[1]),
                              (float)(ref[0].o[2] + s * ref[0].ax[2])};
        if (occ_map_state_at(&map, p) != OCC_STATE_FREE) {
            fail_msg("%.2f m down the first reading's axis: not free", s);
        }
    }
    free(pts);
    free(arena);
}

/* A small log pymavlink packed (tools/mav_tlog_synth.py): OBSTACLE_DISTANCE in the body frame
 * from a proximity sensor, our own echo refused, a reading before the first pose refused, a
 * down sonar. The vehicle: ENU (1.05, 2.05, 3.05), heading east, level. */
static void test_synthetic_log(void **state)
{
    (void)state;
    FILE *probe = fopen(SYNTH, "rb");
    if (probe == NULL) {
        printf("SKIP: %s missing (made by `make test-build`, tools/mav_tlog_synth.py)\n", SYNTH);
        skip();
    }
    fclose(probe);
    static uint8_t arena[16u << 20];
    occ_map_config_t cfg = occ_map_config_default();
    cfg.resolution_m = 0.1f;
    occ_map_t map;
    assert_int_equal(occ_map_init(&map, &cfg, arena, sizeof arena), OCC_OK);
    const occ_tlog_ranges_config_t tc = occ_tlog_ranges_config_default();
    const occ_insert_params_t rp = occ_insert_params_default();
    occ_tlog_ranges_stats_t st;
    assert_int_equal(occ_tlog_integrate_ranges(&map, SYNTH, &tc, &rp, NULL, NULL, &st, NULL, 0),
                     OCC_OK);
    assert_int_equal(st.poses, 21);
    assert_int_equal(st.position_source, 32); /* LOCAL_POSITION_NED */
    assert_false(st.no_horizontal_fix);
    assert_int_equal(st.range_msgs, 3);       /* the own echo never becomes beams */
    assert_int_equal(st.no_pose, 1);          /* the reading before the first pose */
    assert_int_equal(st.integrated, 2);
    assert_int_equal(st.tr.own_refused, 1);
    assert_int_equal(st.tr.unknown_elements, 70);
    assert_true(st.sum.beams_hit == 2u && st.sum.beams_no_return == 1u);
    static const struct {
        float x, y, z;
        occ_state_t want;
        const char *why;
    } probes[] = {
        {5.05f, 2.05f, 3.05f, OCC_STATE_OCCUPIED, "forward (east) element, 4 m"},
        {3.05f, 2.05f, 3.05f, OCC_STATE_FREE, "short of it"},
        {2.05f, 2.05f, 3.05f, OCC_STATE_FREE, "where our own echo (1 m) would have hit"},
        {1.05f, -7.45f, 3.05f, OCC_STATE_FREE, "right (south) element, max + 1: free to 10 m"},
        {1.05f, -8.35f, 3.05f, OCC_STATE_UNKNOWN, "... and not beyond"},
        {1.05f, 2.05f, 0.55f, OCC_STATE_OCCUPIED, "down sonar, 2.5 m"},
        {1.05f, 2.05f, 1.55f, OCC_STATE_FREE, "above its hit"},
        {1.05f, 2.05f, 0.05f, OCC_STATE_UNKNOWN, "below it"},
    };
    for (size_t i = 0; i < sizeof probes / sizeof probes[0]; i++) {
        const occ_vec3_t p = {probes[i].x, probes[i].y, probes[i].z};
        if (occ_map_state_at(&map, p) != probes[i].want) {
            fail_msg("(%.2f %.2f %.2f) %s: state %d, want %d", (double)p.x, (double)p.y,
                     (double)p.z, probes[i].why, occ_map_state_at(&map, p), probes[i].want);
        }
    }
    assert_int_equal(occ_map_check(&map), OCC_OK);
    char msg[64];
    assert_int_equal(occ_tlog_integrate_ranges(&map, "build/none.tlog", &tc, &rp, NULL, NULL, &st,
                                               msg, sizeof msg), OCC_ERR_IO);
    assert_int_equal(occ_tlog_integrate_ranges(NULL, SYNTH, &tc, &rp, NULL, NULL, &st, NULL, 0),
                     OCC_ERR_ARG);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ardusub_floor),
        cmocka_unit_test(test_synthetic_log),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
