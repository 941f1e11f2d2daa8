/* SPDX-License-Identifier: BSD-3-Clause */
/* test_mavlink_ranges.c - MAVLink range messages as beams (occ_mavlink_ranges.h).
 * Frames are built by pymavlink (tools/mav_ranges_golden.py -> build/mavlink/ranges_frames.*),
 * decoded by our parser and translator; each case's beams were worked out by hand: body FLU for
 * sensor mounts and body-frame elements (x forward, y left, z up), ENU for north-aligned ones. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "occmap/occ_mavlink_ranges.h"

#define RF_BIN "build/mavlink/ranges_frames.bin"
#define RF_TXT "build/mavlink/ranges_frames.txt"
#define OWN_SYS 1u
#define OWN_COMP 196u
#define DEG 0.017453292519943295

typedef struct {
    int j;                 /* (documentation) element index */
    double x, y, z, d;     /* direction (body FLU or ENU) and distance */
} want_beam_t;

typedef struct {
    const char *label;
    occ_err_t err;
    size_t n;
    occ_mav_beam_frame_t frame;
    double min_m, max_m, cone;
    bool valid;
    unsigned unknown;
    want_beam_t b[4];
} want_t;

#define C45 0.70710678118654752
#define DS(lbl, x, y, z) {lbl, OCC_OK, 1, OCC_MAV_BEAMS_BODY, 0.2, 10.005, 0, true, 0, {{0, x, y, z, 2.5}}}
#define BAD(lbl, e) {lbl, e, 0, OCC_MAV_BEAMS_BODY, 0, 0, 0, false, 0, {{0, 0, 0, 0, 0}}}

/* In the order tools/mav_ranges_golden.py writes them. */
static const want_t wants[] = {
    DS("ds_yaw0", 1, 0, 0),          /* forward */
    DS("ds_yaw45", C45, -C45, 0),    /* MAVLink yaw is clockwise seen from above: right-forward */
    DS("ds_yaw90", 0, -1, 0),        /* right (PX4 and ArduPilot; common.xml's text says left) */
    DS("ds_yaw135", -C45, -C45, 0),
    DS("ds_yaw180", -1, 0, 0),
    DS("ds_yaw225", -C45, C45, 0),
    DS("ds_yaw270", 0, 1, 0),        /* left */
    DS("ds_yaw315", C45, C45, 0),
    DS("ds_roll180", 1, 0, 0),       /* the beam stays forward (the mount flips: test_mount_axes) */
    DS("ds_pitch180", -1, 0, 0),     /* backward */
    DS("ds_pitch90", 0, 0, 1),       /* up */
    DS("ds_pitch270", 0, 0, -1),     /* down */
    DS("ds_pitch315", C45, 0, -C45), /* pitch -45: forward and down */
    DS("ds_custom_yaw90", 0, -1, 0), /* quaternion (c45, 0, 0, s45) FRD: right */
    DS("ds_custom_pitch_m30", 0.86602540378, 0, -0.5), /* 2 x pitch -30 FRD: forward, down */
    BAD("ds_custom_zero", OCC_ERR_FORMAT),
    BAD("ds_orient41", OCC_ERR_UNSUPPORTED),
    {"ds_sq1", OCC_OK, 1, OCC_MAV_BEAMS_BODY, 0.2, 10.005, 0, false, 0, {{0, 0, 0, -1, 2.5}}},
    DS("ds_sq100", 0, 0, -1),
    BAD("ds_sq101", OCC_ERR_FORMAT),
    {"ds_fov", OCC_OK, 1, OCC_MAV_BEAMS_BODY, 0.2, 10.005, 0.15, true, 0, {{0, 0, 0, -1, 2.5}}},
    {"ds_fov_v", OCC_OK, 1, OCC_MAV_BEAMS_BODY, 0.2, 10.005, 0.2, true, 0, {{0, 0, 0, -1, 2.5}}},
    BAD("ds_fov_nan", OCC_ERR_FORMAT),
    BAD("ds_min_eq_max", OCC_ERR_FORMAT),
    {"ds_at_max", OCC_OK, 1, OCC_MAV_BEAMS_BODY, 0.2, 10.005, 0, true, 0, {{0, 1, 0, 0, 10.0}}},
    {"ds_past_max", OCC_OK, 1, OCC_MAV_BEAMS_BODY, 0.2, 10.005, 0, true, 0, {{0, 1, 0, 0, 10.01}}},
    BAD("ds_own", OCC_ERR_ARG),
    {"ds_v1", OCC_OK, 1, OCC_MAV_BEAMS_BODY, 0.3, 40.005, 0, true, 0, {{0, 0, 0, -1, 12.34}}},
    /* Body FRD, increment_f 5, offset -20: bearings -20, 0, 90 (right), 270 (left, max + 1). */
    {"od_body", OCC_OK, 4, OCC_MAV_BEAMS_BODY, 0.2, 20.005, 0, true, 68,
     {{0, 0.93969262, 0.34202014, 0, 3.0}, {4, 1, 0, 0, 1.5}, {22, 0, -1, 0, 5.0},
      {58, 0, 1, 0, 20.01}}},
    /* Frame 0 (north aligned), increment 10: north, east, west in ENU. */
    {"od_global", OCC_OK, 3, OCC_MAV_BEAMS_NORTH, 0.2, 20.005, 0, true, 69,
     {{0, 0, 1, 0, 4.0}, {9, 1, 0, 0, 9.0}, {27, -1, 0, 0, 19.99}}},
    /* LOCAL_NED, increment_f -5 wins over increment 10: element 1 at 5 deg west of north. */
    {"od_local_ned_ccw", OCC_OK, 1, OCC_MAV_BEAMS_NORTH, 0.2, 20.005, 0, true, 71,
     {{1, -0.08715574, 0.99619470, 0, 7.0}}},
    BAD("od_frame8", OCC_ERR_UNSUPPORTED),
    BAD("od_inc0", OCC_ERR_FORMAT),
    {"od_all_unknown", OCC_OK, 0, OCC_MAV_BEAMS_BODY, 0, 0, 0, true, 72, {{0, 0, 0, 0, 0}}},
    BAD("od_own", OCC_ERR_ARG),
    /* FRD (3, 4, 0): forward 3, right 4. */
    {"o3_body", OCC_OK, 1, OCC_MAV_BEAMS_BODY, 0.5, 30, 0, true, 0, {{0, 0.6, -0.8, 0, 5.0}}},
    {"o3_down", OCC_OK, 1, OCC_MAV_BEAMS_BODY, 0.5, 30, 0, true, 0, {{0, 0, 0, -1, 2.0}}},
    BAD("o3_local_ned", OCC_ERR_UNSUPPORTED),
    BAD("o3_origin", OCC_ERR_FORMAT),
    BAD("o3_max_le_min", OCC_ERR_FORMAT),
    BAD("heartbeat", OCC_ERR_UNSUPPORTED),
};
#define N_WANTS (sizeof wants / sizeof wants[0])

static bool near(double got, double want, double tol)
{
    return fabs(got - want) <= tol;
}

static void check_vec(occ_vec3_t v, double x, double y, double z, const char *what)
{
    if (!near(v.x, x, 1e-5) || !near(v.y, y, 1e-5) || !near(v.z, z, 1e-5)) {
        fail_msg("%s: got (%.6f %.6f %.6f), want (%.6f %.6f %.6f)", what, (double)v.x,
                 (double)v.y, (double)v.z, x, y, z);
    }
}

static void check_case(const want_t *w, occ_err_t e, const occ_mav_beams_t *b)
{
    if (e != w->err) {
        fail_msg("%s: error %d, want %d", w->label, e, w->err);
    }
    if (e != OCC_OK) {
        return;
    }
    assert_int_equal(b->n, w->n);
    assert_int_equal(b->frame, w->frame);
    assert_int_equal(b->unknown_elements, w->unknown);
    for (size_t i = 0; i < b->n; i++) {
        const occ_range_beam_t *const r = &b->beam[i];
        /* Body FLU (or ENU for north beams): the mount applied to the beam's direction. */
        const occ_vec3_t dir = occ_pose_rotate(&b->mount, r->dir);
        check_vec(dir, w->b[i].x, w->b[i].y, w->b[i].z, w->label);
        assert_true(near(r->distance_m, w->b[i].d, 1e-5));
        assert_true(near(r->min_m, w->min_m, 1e-6) && near(r->max_m, w->max_m, 1e-5));
        assert_true(near(r->cone_half_rad, w->cone, 1e-7));
        assert_int_equal(r->valid, w->valid);
    }
}

static void test_pymavlink_range_frames(void **state)
{
    (void)state;
    FILE *bin = fopen(RF_BIN, "rb");
    FILE *txt = fopen(RF_TXT, "r");
    if (bin == NULL || txt == NULL) {
        printf("SKIP: %s / %s missing (made by `make test-build`, tools/mav_ranges_golden.py)\n",
               RF_BIN, RF_TXT);
        if (bin != NULL) {
            fclose(bin);
        }
        if (txt != NULL) {
            fclose(txt);
        }
        skip();
    }
    occ_mav_parser_t p;
    occ_mav_parser_init(&p);
    occ_mav_ranges_t rx;
    assert_int_equal(occ_mav_ranges_init(&rx, OWN_SYS, OWN_COMP), OCC_OK);
    static occ_mav_beams_t beams;
    char label[64];
    unsigned msgid, sysid, compid, n_ok = 0;
    size_t k = 0;
    while (fscanf(txt, "%63s %u %u %u", label, &msgid, &sysid, &compid) == 4) {
        assert_true(k < N_WANTS);
        assert_string_equal(label, wants[k].label);
        occ_mav_frame_t fr;
        occ_mav_result_t r = OCC_MAV_NONE;
        int ch;
        while (r == OCC_MAV_NONE && (ch = fgetc(bin)) != EOF) {
            r = occ_mav_parser_push(&p, (uint8_t)ch, &fr);
        }
        assert_int_equal(r, OCC_MAV_OK);
        assert_int_equal(fr.msgid, msgid);
        assert_int_equal(fr.sysid, sysid);
        assert_int_equal(fr.compid, compid);
        const occ_err_t e = occ_mav_ranges_decode(&rx, &fr, &beams);
        check_case(&wants[k], e, &beams);
        if (e == OCC_OK) {
            n_ok++;
            assert_int_equal(beams.sysid, sysid);
            assert_int_equal(beams.compid, compid);
            /* The message's own stamp: time_boot_ms x 1000, or time_usec. */
            const uint64_t t = strcmp(label, "ds_v1") == 0 ? 99000u
                               : msgid == 132u             ? 123456000u
                               : msgid == 330u             ? 777u
                                                           : 4242000u;
            assert_true(beams.time_us == t);
            assert_int_equal(beams.sensor_id, msgid == 132u ? (k == N_WANTS - 14u ? 2 : 3) : 0);
        }
        k++;
    }
    fclose(bin);
    fclose(txt);
    assert_int_equal(k, N_WANTS);
    const occ_mav_ranges_counters_t *c = &rx.counters;
    assert_int_equal(c->translated, n_ok);
    assert_int_equal(c->translated, 28);
    assert_int_equal(c->own_refused, 2);
    assert_int_equal(c->malformed, 7);
    assert_int_equal(c->unsupported, 3);
    assert_int_equal(c->other_msgs, 1);
    assert_int_equal(c->invalid_readings, 1);
    assert_int_equal(c->unknown_elements, 68 + 69 + 71 + 72);
    printf("pymavlink range frames: %zu cases, %u translated\n", k, n_ok);
}

/* The mount's other axes, by hand (FLU): roll 180 turns the sensor's up to down and left to
 * right; pitch 270 (down) turns the sensor's up to forward; yaw 90 its left to forward. */
static void test_mount_axes(void **state)
{
    (void)state;
    const occ_vec3_t up = {0, 0, 1}, left = {0, 1, 0};
    occ_pose_t m;
    assert_int_equal(occ_mav_sensor_mount(8, NULL, &m), OCC_OK);
    check_vec(occ_pose_rotate(&m, up), 0, 0, -1, "roll180 up");
    check_vec(occ_pose_rotate(&m, left), 0, -1, 0, "roll180 left");
    assert_int_equal(occ_mav_sensor_mount(OCC_MAV_SENSOR_ROTATION_PITCH_270, NULL, &m), OCC_OK);
    check_vec(occ_pose_rotate(&m, up), 1, 0, 0, "pitch270 up");
    assert_int_equal(occ_mav_sensor_mount(2, NULL, &m), OCC_OK);
    check_vec(occ_pose_rotate(&m, left), 1, 0, 0, "yaw90 left");
    check_vec(m.p, 0, 0, 0, "no offset");
    /* 26 = pitch 180 then yaw 90 (R = Rz Ry Rx, ArduPilot's order): forward -> FRD (0, -1, 0)
     * = left in FLU; 36 = roll 90, pitch 180, yaw 90: forward -> FRD (0, -1, 0) too, and the
     * sensor's up (FRD (0, 0, -1)) -> Rx: (0, 1, 0) -> Ry: (0, 1, 0) -> Rz: (-1, 0, 0), back. */
    const occ_vec3_t fwd = {1, 0, 0};
    assert_int_equal(occ_mav_sensor_mount(26, NULL, &m), OCC_OK);
    check_vec(occ_pose_rotate(&m, fwd), 0, 1, 0, "pitch180 yaw90");
    assert_int_equal(occ_mav_sensor_mount(36, NULL, &m), OCC_OK);
    check_vec(occ_pose_rotate(&m, fwd), 0, 1, 0, "roll90 pitch180 yaw90");
    check_vec(occ_pose_rotate(&m, up), -1, 0, 0, "roll90 pitch180 yaw90 up");
    /* Every fixed rotation gives a unit quaternion; 41..99 and 101.. are refused. */
    for (unsigned o = 0; o < 256u; o++) {
        const occ_err_t e = occ_mav_sensor_mount((uint8_t)o, NULL, &m);
        if (o <= 40u) {
            assert_int_equal(e, OCC_OK);
            assert_int_equal(occ_pose_check(&m), OCC_OK);
        } else {
            assert_int_equal(e, o == 100u ? OCC_ERR_ARG : OCC_ERR_UNSUPPORTED);
        }
    }
    const float nan_q[4] = {NAN, 0, 0, 0};
    assert_int_equal(occ_mav_sensor_mount(100, nan_q, &m), OCC_ERR_FORMAT);
    assert_int_equal(occ_mav_sensor_mount(0, NULL, NULL), OCC_ERR_ARG);
}

/* Beams in the map: hand-computed vehicle poses through occ_pose_from_ned(). */
static void test_sensor_pose(void **state)
{
    (void)state;
    occ_mav_beams_t b;
    memset(&b, 0, sizeof b);
    b.frame = OCC_MAV_BEAMS_BODY;
    occ_pose_t body, sensor;
    /* NED (10, 20, -5) heading east, level: ENU (20, 10, 5); a right-facing sensor (yaw 90)
     * looks south, so its 2.5 m reading lands at (20, 7.5, 5). */
    const occ_vec3_t ned = {10, 20, -5};
    assert_int_equal(occ_pose_from_ned(ned, occ_quat_from_euler(0, 0, (float)(90 * DEG)), &body),
                     OCC_OK);
    assert_int_equal(occ_mav_sensor_mount(2, NULL, &b.mount), OCC_OK);
    assert_int_equal(occ_mav_beams_sensor_pose(&b, &body, &sensor), OCC_OK);
    const occ_vec3_t reading = {2.5f, 0, 0};
    check_vec(occ_pose_apply(&sensor, reading), 20, 7.5, 5, "right sensor, heading east");
    /* Heading north, nose up 30 deg: the down sonar looks forward-down, NED (0.5, 0, 0.866)
     * per metre = ENU (0, 0.5, -0.866). */
    assert_int_equal(occ_pose_from_ned(ned, occ_quat_from_euler(0, (float)(30 * DEG), 0), &body),
                     OCC_OK);
    assert_int_equal(occ_mav_sensor_mount(OCC_MAV_SENSOR_ROTATION_PITCH_270, NULL, &b.mount),
                     OCC_OK);
    assert_int_equal(occ_mav_beams_sensor_pose(&b, &body, &sensor), OCC_OK);
    const occ_vec3_t one = {1, 0, 0};
    check_vec(occ_pose_rotate(&sensor, one), 0, 0.5, -0.86602540, "down sonar, nose up 30");
    /* North beams ignore the vehicle's attitude: north stays north at the vehicle's position. */
    b.frame = OCC_MAV_BEAMS_NORTH;
    b.mount = occ_pose_identity();
    assert_int_equal(occ_mav_beams_sensor_pose(&b, &body, &sensor), OCC_OK);
    const occ_vec3_t north = {0, 4, 0};
    check_vec(occ_pose_apply(&sensor, north), 20, 14, 5, "north beam");
    /* Refusals. */
    occ_pose_t bad = body;
    bad.q.w = NAN;
    assert_int_equal(occ_mav_beams_sensor_pose(&b, &bad, &sensor), OCC_ERR_ARG);
    assert_int_equal(occ_mav_beams_sensor_pose(NULL, &body, &sensor), OCC_ERR_ARG);
    assert_int_equal(occ_mav_beams_sensor_pose(&b, NULL, &sensor), OCC_ERR_ARG);
    assert_int_equal(occ_mav_beams_sensor_pose(&b, &body, NULL), OCC_ERR_ARG);
    occ_mav_ranges_t rx;
    occ_mav_frame_t fr;
    memset(&fr, 0, sizeof fr);
    assert_int_equal(occ_mav_ranges_init(NULL, 1, 1), OCC_ERR_ARG);
    assert_int_equal(occ_mav_ranges_init(&rx, 1, 1), OCC_OK);
    assert_int_equal(occ_mav_ranges_decode(&rx, NULL, &b), OCC_ERR_ARG);
    assert_int_equal(occ_mav_ranges_decode(&rx, &fr, NULL), OCC_ERR_ARG);
    assert_int_equal(occ_mav_ranges_decode(NULL, &fr, &b), OCC_ERR_ARG);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pymavlink_range_frames),
        cmocka_unit_test(test_mount_axes),
        cmocka_unit_test(test_sensor_pose),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
