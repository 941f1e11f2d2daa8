/* SPDX-License-Identifier: BSD-3-Clause */
/* test_dronecan_range.c - uavcan.equipment.range_sensor.Measurement in: transfers built by
 * pydronecan (tests/can/range_frames.py -> build/can/range_frames.txt) reassembled and decoded
 * field for field, reading types to beams through the mount table, broken transfers dropped
 * and counted, and one reading integrated into a map (hand-computed voxels). */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "occmap/occmap.h"
#include "occmap/occ_dronecan.h"
#include "occmap/occ_ranges.h"
#include "support/leak_check.h"

#define FRAMES_FILE "build/can/range_frames.txt"
#define MAX_CASES 512u
#define MAX_FRAMES 8u

typedef struct {
    unsigned src, tid;
    unsigned long long usec;
    unsigned sensor;
    int rpy[3];
    int defined;
    double fov, range;
    unsigned stype, rtype;
    occ_can_frame_t frames[MAX_FRAMES];
    size_t n_frames;
} case_t;

static case_t cases[MAX_CASES];
static size_t n_cases;
static occ_dronecan_range_mount_t mounts[2];
static occ_dronecan_range_rx_t rx;

/* Sensor 3 looks down (the sensor's +x is body -z: a quarter turn about y), 0.2..40 m;
 * sensor 4 looks forward from 0.1 m ahead, 0.1..10 m. Sensor 9 has no mount. */
static void make_mounts(void)
{
    const occ_vec3_t y = {0, 1, 0};
    mounts[0].sensor_id = 3;
    mounts[0].body_from_sensor = occ_pose_identity();
    assert_int_equal(occ_quat_from_axis_angle(y, 1.5707963f, &mounts[0].body_from_sensor.q), OCC_OK);
    mounts[0].min_m = 0.2f;
    mounts[0].max_m = 40.0f;
    mounts[1].sensor_id = 4;
    mounts[1].body_from_sensor = occ_pose_identity();
    mounts[1].body_from_sensor.p.x = 0.1f;
    mounts[1].min_m = 0.1f;
    mounts[1].max_m = 10.0f;
}

static bool parse_frame(const char *tok, occ_can_frame_t *f)
{
    unsigned long id;
    char hex[2 * OCC_CAN_MAX_DATA + 1];
    if (sscanf(tok, "%lx:%128s", &id, hex) != 2 || strlen(hex) % 2u != 0u) {
        return false;
    }
    memset(f, 0, sizeof *f);
    f->id = (uint32_t)id;
    f->flags = OCC_CAN_FLAG_EXT;
    f->len = (uint8_t)(strlen(hex) / 2u);
    for (size_t i = 0; i < f->len; i++) {
        unsigned b;
        if (sscanf(hex + 2u * i, "%2x", &b) != 1) {
            return false;
        }
        f->data[i] = (uint8_t)b;
    }
    return true;
}

static bool parse_line(char *line, case_t *c)
{
    char *bar = strchr(line, '|');
    if (bar == NULL) {
        return false;
    }
    *bar = '\0';
    char fov[64], range[64];
    if (sscanf(line, "%u %u %llu %u %d %d %d %d %63s %u %u %63s", &c->src, &c->tid, &c->usec,
               &c->sensor, &c->rpy[0], &c->rpy[1], &c->rpy[2], &c->defined, fov, &c->stype,
               &c->rtype, range) != 12) {
        return false;
    }
    c->fov = strtod(fov, NULL);
    c->range = strtod(range, NULL);
    c->n_frames = 0;
    for (char *tok = strtok(bar + 1, " \n"); tok != NULL; tok = strtok(NULL, " \n")) {
        if (c->n_frames == MAX_FRAMES || !parse_frame(tok, &c->frames[c->n_frames++])) {
            return false;
        }
    }
    return c->n_frames > 0u;
}

static int load(void **state)
{
    (void)state;
    make_mounts();
    FILE *f = fopen(FRAMES_FILE, "r");
    n_cases = 0;
    if (f == NULL) {
        return 0;
    }
    static char line[4096];
    while (fgets(line, sizeof line, f) != NULL && n_cases < MAX_CASES) {
        if (line[0] != '#') {
            assert_true(parse_line(line, &cases[n_cases]));
            n_cases++;
        }
    }
    fclose(f);
    return 0;
}

static bool have_cases(void)
{
    if (n_cases == 0u) {
        printf("SKIP: %s missing (made by tests/can/range_frames.py; run make test-build)\n",
               FRAMES_FILE);
        return false;
    }
    return true;
}

/* Feed a case's frames; the reading when the last one completed it. */
static bool feed(const case_t *c, uint64_t t_us, occ_dronecan_range_reading_t *r)
{
    bool got = false;
    for (size_t i = 0; i < c->n_frames; i++) {
        assert_false(got);
        assert_int_equal(occ_dronecan_range_rx_frame(&rx, &c->frames[i], t_us, r, &got), OCC_OK);
    }
    return got;
}

/* Bit-equal floats, or both NaN (the exact comparison -Wfloat-equal would refuse). */
static bool same(float a, float b)
{
    return memcmp(&a, &b, sizeof a) == 0 || (isnan(a) && isnan(b));
}

static void assert_beam(const case_t *c, const occ_dronecan_range_reading_t *r)
{
    const occ_dronecan_range_mount_t *m = c->sensor == 3u ? &mounts[0] : &mounts[1];
    assert_ptr_equal(r->mount, m);
    assert_true(same(r->beam.dir.x, 1.0f) && same(r->beam.dir.y, 0.0f) && same(r->beam.dir.z, 0.0f));
    assert_true(same(r->beam.min_m, m->min_m) && same(r->beam.max_m, m->max_m));
    const bool fov_ok = isfinite(c->fov) && c->fov >= 0.0 && c->fov <= 2.0 * (double)OCC_RANGES_CONE_MAX_RAD;
    const bool reading = c->rtype == OCC_DRONECAN_RANGE_VALID || c->rtype == OCC_DRONECAN_RANGE_TOO_FAR;
    assert_int_equal(r->beam.valid, fov_ok && reading);
    if (r->beam.valid) {
        assert_true(same(r->beam.cone_half_rad, (float)(c->fov / 2.0)));
        const float want = c->rtype == OCC_DRONECAN_RANGE_TOO_FAR ? m->max_m : (float)c->range;
        assert_true(same(r->beam.distance_m, want));
    }
}

static void test_pydronecan_frames(void **state)
{
    (void)state;
    if (!have_cases()) {
        skip();
    }
    assert_int_equal(occ_dronecan_range_rx_init(&rx, mounts, 2), OCC_OK);
    size_t known = 0, unknown = 0, valid = 0;
    for (size_t i = 0; i < n_cases; i++) {
        const case_t *c = &cases[i];
        occ_dronecan_range_reading_t r;
        const bool got = feed(c, 1000u * i, &r);
        assert_int_equal(got, c->sensor == 3u || c->sensor == 4u);
        if (!got) {
            unknown++;
            continue;
        }
        known++;
        assert_int_equal(r.src_node, c->src);
        assert_true(r.msg.timestamp_us == c->usec);
        assert_int_equal(r.msg.sensor_id, c->sensor);
        for (unsigned a = 0; a < 3u; a++) {
            assert_true(r.msg.orientation_rpy[a] == c->rpy[a]);
        }
        assert_int_equal(r.msg.orientation_defined, c->defined != 0);
        assert_true(same(r.msg.field_of_view_rad, (float)c->fov));
        assert_true(same(r.msg.range_m, (float)c->range));
        assert_int_equal(r.msg.sensor_type, c->stype);
        assert_int_equal(r.msg.reading_type, c->rtype);
        assert_beam(c, &r);
        valid += r.beam.valid ? 1u : 0u;
    }
    printf("  %zu pydronecan transfers: %zu readings (%zu valid beams), %zu unknown sensor\n",
           n_cases, known, valid, unknown);
    assert_int_equal(rx.readings, known);
    assert_int_equal(rx.unknown_sensor, unknown);
    assert_int_equal(rx.crc_errors + rx.sequence_errors + rx.bad_payload, 0);
    assert_true(known > 50u && valid > 20u && unknown > 5u);
}

static void test_broken_transfers(void **state)
{
    (void)state;
    if (!have_cases()) {
        skip();
    }
    assert_int_equal(occ_dronecan_range_rx_init(&rx, mounts, 2), OCC_OK);
    case_t c = cases[0];
    assert_int_equal(c.n_frames, 3);
    occ_dronecan_range_reading_t r;
    c.frames[1].data[2] ^= 0x04u; /* a payload bit */
    assert_false(feed(&c, 0, &r));
    assert_int_equal(rx.crc_errors, 1);
    c = cases[0];
    c.frames[1] = c.frames[2]; /* the middle frame lost: the end frame's toggle is wrong */
    c.n_frames = 2;
    assert_false(feed(&c, 0, &r));
    assert_int_equal(rx.sequence_errors, 1);
    assert_false(feed(&(case_t){.frames = {cases[0].frames[2]}, .n_frames = 1}, 0, &r));
    assert_int_equal(rx.sequence_errors, 2); /* an end frame of no transfer */
    bool got = false;
    for (size_t i = 0; i < 3u; i++) { /* too slow: the end arrives after the timeout */
        const uint64_t t = i == 2u ? OCC_DRONECAN_RANGE_RX_TIMEOUT_US + 1u : 0u;
        assert_int_equal(occ_dronecan_range_rx_frame(&rx, &cases[0].frames[i], t, &r, &got), OCC_OK);
    }
    assert_false(got);
    assert_int_equal(rx.sequence_errors, 3);
    /* two sources interleaved frame by frame both complete */
    const case_t *a = &cases[0], *b = &cases[10];
    assert_true(a->src != b->src && a->n_frames == 3u && b->n_frames == 3u);
    size_t done = 0;
    for (size_t i = 0; i < 3u; i++) {
        assert_int_equal(occ_dronecan_range_rx_frame(&rx, &a->frames[i], 5, &r, &got), OCC_OK);
        done += got ? 1u : 0u;
        assert_int_equal(occ_dronecan_range_rx_frame(&rx, &b->frames[i], 5, &r, &got), OCC_OK);
        done += got ? 1u : 0u;
    }
    assert_int_equal(done, 1); /* b's sensor 255 has no mount: decoded, counted, dropped */
    assert_int_equal(rx.readings, 1);
    assert_int_equal(rx.unknown_sensor, 1);
    /* not ours: another type, a service frame, a standard id, an error report */
    occ_can_frame_t other = cases[0].frames[0];
    other.id ^= 1u << 8;
    const uint32_t frames = rx.frames;
    assert_int_equal(occ_dronecan_range_rx_frame(&rx, &other, 0, &r, &got), OCC_OK);
    other = cases[0].frames[0];
    other.id |= 0x80u;
    assert_int_equal(occ_dronecan_range_rx_frame(&rx, &other, 0, &r, &got), OCC_OK);
    other.flags = OCC_CAN_FLAG_ERR | OCC_CAN_FLAG_EXT;
    assert_int_equal(occ_dronecan_range_rx_frame(&rx, &other, 0, &r, &got), OCC_OK);
    assert_int_equal(rx.frames, frames);
    assert_int_equal(occ_dronecan_range_rx_frame(NULL, &other, 0, &r, &got), OCC_ERR_ARG);
    assert_int_equal(occ_dronecan_range_rx_frame(&rx, NULL, 0, &r, &got), OCC_ERR_ARG);
}

static void test_decode_and_mount_errors(void **state)
{
    (void)state;
    uint8_t p[OCC_DRONECAN_RANGE_BYTES + 1u] = {0};
    occ_dronecan_range_t m;
    assert_int_equal(occ_dronecan_decode_range(p, OCC_DRONECAN_RANGE_BYTES - 1u, &m), OCC_ERR_FORMAT);
    assert_int_equal(occ_dronecan_decode_range(p, OCC_DRONECAN_RANGE_BYTES + 1u, &m), OCC_ERR_FORMAT);
    assert_int_equal(occ_dronecan_decode_range(NULL, OCC_DRONECAN_RANGE_BYTES, &m), OCC_ERR_ARG);
    assert_int_equal(occ_dronecan_decode_range(p, OCC_DRONECAN_RANGE_BYTES, &m), OCC_OK);
    occ_range_beam_t b;
    const occ_dronecan_range_mount_t *mt = NULL;
    m.sensor_id = 9;
    assert_int_equal(occ_dronecan_range_beam(&m, mounts, 2, &b, &mt), OCC_ERR_UNSUPPORTED);
    assert_null(mt);
    assert_int_equal(occ_dronecan_range_beam(NULL, mounts, 2, &b, &mt), OCC_ERR_ARG);
    occ_dronecan_range_mount_t bad[2] = {mounts[0], mounts[1]};
    bad[1].sensor_id = bad[0].sensor_id;
    assert_int_equal(occ_dronecan_range_rx_init(&rx, bad, 2), OCC_ERR_ARG); /* listed twice */
    bad[1] = mounts[1];
    bad[1].max_m = bad[1].min_m;
    assert_int_equal(occ_dronecan_range_rx_init(&rx, bad, 2), OCC_ERR_ARG);
    bad[1] = mounts[1];
    bad[1].body_from_sensor.q.w = 2.0f;
    assert_int_equal(occ_dronecan_range_rx_init(&rx, bad, 2), OCC_ERR_ARG);
    assert_int_equal(occ_dronecan_range_rx_init(&rx, NULL, 1), OCC_ERR_ARG);
    assert_int_equal(occ_dronecan_range_rx_init(&rx, NULL, 0), OCC_OK);
}

static void test_reading_into_map(void **state)
{
    (void)state;
    if (!have_cases()) {
        skip();
    }
    /* Case 0: sensor 3 (down), VALID, 2.5 m. The vehicle level at (0.05, 0.05, 3.05): the
     * floor hit at z = 0.55 (voxel 5 above z = 0), z = 0.65 .. 3.05 free. */
    static uint8_t arena[1u << 20], scratch[OCC_RANGES_SCRATCH_BYTES(1, 1, 402)];
    occ_map_t map;
    occ_map_config_t cfg = occ_map_config_default();
    cfg.resolution_m = 0.1f;
    assert_int_equal(occ_map_init(&map, &cfg, arena, sizeof arena), OCC_OK);
    assert_int_equal(occ_dronecan_range_rx_init(&rx, mounts, 2), OCC_OK);
    occ_dronecan_range_reading_t r;
    assert_true(feed(&cases[0], 0, &r));
    occ_pose_t map_from_body = occ_pose_identity();
    map_from_body.p = (occ_vec3_t){0.05f, 0.05f, 3.05f};
    const occ_pose_t map_from_sensor = occ_pose_compose(&map_from_body, &r.mount->body_from_sensor);
    const occ_insert_params_t p = occ_insert_params_default();
    occ_ranges_result_t res;
    assert_int_equal(occ_map_insert_ranges(&map, &map_from_sensor, &r.beam, 1, &p, scratch,
                                           sizeof scratch, &res),
                     OCC_OK);
    assert_int_equal(res.beams_hit, 1);
    assert_int_equal(res.insert.voxels_updated, 26); /* z voxels 5 .. 30 */
    assert_int_equal(occ_map_state_at(&map, (occ_vec3_t){0.05f, 0.05f, 0.55f}), OCC_STATE_OCCUPIED);
    assert_int_equal(occ_map_state_at(&map, (occ_vec3_t){0.05f, 0.05f, 0.65f}), OCC_STATE_FREE);
    assert_int_equal(occ_map_state_at(&map, (occ_vec3_t){0.05f, 0.05f, 3.05f}), OCC_STATE_FREE);
    assert_int_equal(occ_map_state_at(&map, (occ_vec3_t){0.05f, 0.05f, 0.45f}), OCC_STATE_UNKNOWN);
    assert_int_equal(leak_check(&map), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pydronecan_frames),
        cmocka_unit_test(test_broken_transfers),
        cmocka_unit_test(test_decode_and_mount_errors),
        cmocka_unit_test(test_reading_into_map),
    };
    return cmocka_run_group_tests(tests, load, NULL);
}
