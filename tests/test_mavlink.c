/* test_mavlink.c - the MAVLink parser, encoders, decoders and feed state machine.
 * References: frames pymavlink encoded (build/mavlink/py_frames.*, tools/mav_golden.py), what
 * pymavlink reads in a real ArduSub tlog (build/mavlink/tlog_ref.txt, tools/mav_tlog_ref.py),
 * and hand-built corrupt frames. */
#define _XOPEN_SOURCE 700 /* posix_openpt for the serial test */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <fcntl.h>
#include <unistd.h>

#include "occmap/occ_mavlink.h"
#include "occmap/occ_port.h"
#include "ardupilotmega/mavlink.h"

#define TLOG "../shared/data/mavlink/ardusub_2023-04-18_11-03-34.tlog"
#define TLOG_REF "build/mavlink/tlog_ref.txt"
#define PY_BIN "build/mavlink/py_frames.bin"
#define PY_TXT "build/mavlink/py_frames.txt"

static unsigned seed;

static bool feq(double a, double b)
{
    return !(a < b) && !(a > b);
}

/* Float read back from a "%.9g" text equals the float32 on the wire, bit for bit (NaN = NaN). */
static bool f32eq(float got, const char *txt)
{
    const float want = strtof(txt, NULL);
    if (isnan(want)) {
        return isnan(got);
    }
    return feq((double)got, (double)want);
}

static size_t parse_all(occ_mav_parser_t *p, const uint8_t *b, size_t n, occ_mav_result_t *last,
                        occ_mav_frame_t *fr)
{
    size_t frames = 0;
    for (size_t i = 0; i < n; i++) {
        const occ_mav_result_t r = occ_mav_parser_push(p, b[i], fr);
        if (r != OCC_MAV_NONE && r != OCC_MAV_JUNK) {
            frames++;
            if (last != NULL) {
                *last = r;
            }
        }
    }
    return frames;
}

/* ---- encoder and parser round trip ------------------------------------------------------------- */

static void test_obstacle_roundtrip(void **state)
{
    (void)state;
    occ_mav_sender_t tx = {7, 196, 254};
    occ_mav_obstacle_distance_t m, d;
    memset(&m, 0, sizeof m);
    m.time_usec = 0x0102030405060708ull;
    m.sensor_type = 0;
    for (unsigned i = 0; i < 72; i++) {
        m.distances[i] = (uint16_t)(i * 31u + 20u);
    }
    m.distances[5] = UINT16_MAX;
    m.increment = 0;
    m.min_distance = 20;
    m.max_distance = 2000;
    m.increment_f = 5.0f;
    m.angle_offset = -2.5f;
    m.frame = 12;
    uint8_t buf[OCC_MAV_FRAME_MAX];
    const size_t n = occ_mav_encode_obstacle_distance(&tx, &m, buf, sizeof buf);
    assert_int_equal(n, 179); /* 10 + 167 + 2: nothing to trim (frame = 12 last) */
    assert_int_equal(buf[0], 0xFD);
    assert_int_equal(buf[4], 254);
    assert_int_equal(tx.seq, 255);
    assert_int_equal(occ_mav_encode_obstacle_distance(&tx, &m, buf, 100), 0);
    assert_int_equal(tx.seq, 255);
    occ_mav_parser_t p;
    occ_mav_parser_init(&p);
    occ_mav_frame_t fr;
    occ_mav_result_t r = OCC_MAV_NONE;
    assert_int_equal(parse_all(&p, buf, n, &r, &fr), 1);
    assert_int_equal(r, OCC_MAV_OK);
    assert_int_equal(fr.msgid, 330);
    assert_int_equal(fr.sysid, 7);
    assert_int_equal(fr.compid, 196);
    assert_int_equal(fr.seq, 254);
    assert_int_equal(occ_mav_decode_obstacle_distance(&fr, &d), OCC_OK);
    assert_true(d.time_usec == m.time_usec);
    assert_memory_equal(d.distances, m.distances, sizeof m.distances);
    assert_int_equal(d.min_distance, 20);
    assert_int_equal(d.max_distance, 2000);
    assert_true(feq((double)d.increment_f, 5.0) && feq((double)d.angle_offset, -2.5));
    assert_int_equal(d.frame, 12);
    occ_mav_attitude_t att;
    assert_int_equal(occ_mav_decode_attitude(&fr, &att), OCC_ERR_ARG);
    /* Trimmed: frame 0 and offsets 0 -> the extension bytes vanish from the wire. */
    m.frame = 0;
    m.angle_offset = 0.0f;
    m.increment_f = 0.0f;
    const size_t n2 = occ_mav_encode_obstacle_distance(&tx, &m, buf, sizeof buf);
    assert_true(n2 < n);
    assert_int_equal(parse_all(&p, buf, n2, &r, &fr), 1);
    assert_int_equal(r, OCC_MAV_OK);
    assert_int_equal(occ_mav_decode_obstacle_distance(&fr, &d), OCC_OK);
    assert_int_equal(d.frame, 0);
    assert_memory_equal(d.distances, m.distances, sizeof m.distances);
    assert_int_equal(p.counters.frames_ok, 2);
    /* Message info comes from the generated table. */
    uint8_t extra, lo, hi;
    assert_true(occ_mav_msg_info(330, &extra, &lo, &hi));
    assert_int_equal(extra, 23);
    assert_int_equal(lo, 158);
    assert_int_equal(hi, 167);
    assert_false(occ_mav_msg_info(0xFFFFFF, &extra, &lo, &hi));
}

/* ---- frames pymavlink encoded --------------------------------------------------------------------- */

static uint8_t *read_file(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    if (f == NULL) {
        return NULL;
    }
    fseek(f, 0, SEEK_END);
    const long len = ftell(f);
    fseek(f, 0, SEEK_SET);
    uint8_t *b = malloc((size_t)len + 1u);
    assert_non_null(b);
    assert_int_equal(fread(b, 1, (size_t)len, f), (size_t)len);
    fclose(f);
    *n = (size_t)len;
    return b;
}

static void test_pymavlink_frames(void **state)
{
    (void)state;
    size_t n = 0;
    uint8_t *bin = read_file(PY_BIN, &n);
    FILE *txt = fopen(PY_TXT, "r");
    if (bin == NULL || txt == NULL) {
        printf("SKIP: %s / %s missing (made by `make test-build` with tools/mav_golden.py)\n",
               PY_BIN, PY_TXT);
        free(bin);
        if (txt != NULL) {
            fclose(txt);
        }
        skip();
    }
    occ_mav_parser_t p;
    occ_mav_parser_init(&p);
    char line[2048];
    size_t at = 0;
    unsigned frames = 0;
    while (fgets(line, sizeof line, txt) != NULL) {
        char *tok[64];
        int nt = 0;
        for (char *s = strtok(line, " \n"); s != NULL && nt < 64; s = strtok(NULL, " \n")) {
            tok[nt++] = s;
        }
        assert_true(nt >= 6);
        occ_mav_frame_t fr;
        occ_mav_result_t r = OCC_MAV_NONE;
        while (at < n && r == OCC_MAV_NONE) {
            r = occ_mav_parser_push(&p, bin[at++], &fr);
        }
        assert_int_equal(r, OCC_MAV_OK);
        frames++;
        assert_int_equal(fr.msgid, strtoul(tok[0], NULL, 10));
        assert_int_equal(fr.version, strtoul(tok[1], NULL, 10));
        assert_int_equal(fr.sysid, strtoul(tok[2], NULL, 10));
        assert_int_equal(fr.compid, strtoul(tok[3], NULL, 10));
        assert_int_equal(fr.seq, strtoul(tok[4], NULL, 10));
        assert_int_equal(fr.is_signed ? 1 : 0, strtoul(tok[5], NULL, 10));
        char **v = tok + 6;
        switch (fr.msgid) {
        case 32: {
            occ_mav_local_position_ned_t m;
            assert_int_equal(occ_mav_decode_local_position_ned(&fr, &m), OCC_OK);
            assert_int_equal(m.time_boot_ms, strtoul(v[0], NULL, 10));
            assert_true(f32eq(m.x, v[1]) && f32eq(m.y, v[2]) && f32eq(m.z, v[3]));
            assert_true(f32eq(m.vx, v[4]) && f32eq(m.vy, v[5]) && f32eq(m.vz, v[6]));
            break;
        }
        case 30: {
            occ_mav_attitude_t m;
            assert_int_equal(occ_mav_decode_attitude(&fr, &m), OCC_OK);
            assert_int_equal(m.time_boot_ms, strtoul(v[0], NULL, 10));
            assert_true(f32eq(m.roll, v[1]) && f32eq(m.pitch, v[2]) && f32eq(m.yaw, v[3]));
            assert_true(f32eq(m.rollspeed, v[4]) && f32eq(m.pitchspeed, v[5]) &&
                        f32eq(m.yawspeed, v[6]));
            break;
        }
        case 31: {
            occ_mav_attitude_quaternion_t m;
            assert_int_equal(occ_mav_decode_attitude_quaternion(&fr, &m), OCC_OK);
            assert_int_equal(m.time_boot_ms, strtoul(v[0], NULL, 10));
            for (int i = 0; i < 4; i++) {
                assert_true(f32eq(m.q[i], v[1 + i]));
            }
            assert_true(f32eq(m.rollspeed, v[5]) && f32eq(m.yawspeed, v[7]));
            break;
        }
        case 331: {
            occ_mav_odometry_t m;
            assert_int_equal(occ_mav_decode_odometry(&fr, &m), OCC_OK);
            assert_true(m.time_usec == strtoull(v[0], NULL, 10));
            assert_int_equal(m.frame_id, strtoul(v[1], NULL, 10));
            assert_int_equal(m.child_frame_id, strtoul(v[2], NULL, 10));
            assert_true(f32eq(m.x, v[3]) && f32eq(m.y, v[4]) && f32eq(m.z, v[5]));
            for (int i = 0; i < 4; i++) {
                assert_true(f32eq(m.q[i], v[6 + i]));
            }
            assert_true(f32eq(m.vx, v[10]) && f32eq(m.vy, v[11]) && f32eq(m.vz, v[12]));
            break;
        }
        case 132: {
            occ_mav_distance_sensor_t m;
            assert_int_equal(occ_mav_decode_distance_sensor(&fr, &m), OCC_OK);
            assert_int_equal(m.time_boot_ms, strtoul(v[0], NULL, 10));
            assert_int_equal(m.min_distance, strtoul(v[1], NULL, 10));
            assert_int_equal(m.max_distance, strtoul(v[2], NULL, 10));
            assert_int_equal(m.current_distance, strtoul(v[3], NULL, 10));
            assert_int_equal(m.type, strtoul(v[4], NULL, 10));
            assert_int_equal(m.id, strtoul(v[5], NULL, 10));
            assert_int_equal(m.orientation, strtoul(v[6], NULL, 10));
            assert_int_equal(m.covariance, strtoul(v[7], NULL, 10));
            assert_true(f32eq(m.horizontal_fov, v[8]) && f32eq(m.vertical_fov, v[9]));
            for (int i = 0; i < 4; i++) {
                assert_true(f32eq(m.quaternion[i], v[10 + i]));
            }
            assert_int_equal(m.signal_quality, strtoul(v[14], NULL, 10));
            break;
        }
        case 0: {
            occ_mav_heartbeat_t m;
            assert_int_equal(occ_mav_decode_heartbeat(&fr, &m), OCC_OK);
            assert_int_equal(m.custom_mode, strtoul(v[0], NULL, 10));
            assert_int_equal(m.type, strtoul(v[1], NULL, 10));
            assert_int_equal(m.autopilot, strtoul(v[2], NULL, 10));
            assert_int_equal(m.base_mode, strtoul(v[3], NULL, 10));
            assert_int_equal(m.system_status, strtoul(v[4], NULL, 10));
            assert_int_equal(m.mavlink_version, strtoul(v[5], NULL, 10));
            break;
        }
        default:
            fail_msg("unexpected msgid %u", (unsigned)fr.msgid);
        }
    }
    assert_true(frames >= 40);
    assert_int_equal(at, n);
    assert_int_equal(p.counters.frames_ok, frames);
    assert_int_equal(p.counters.bad_crc + p.counters.bad_len + p.counters.junk_bytes, 0);
    fclose(txt);
    free(bin);
}

/* ---- corrupt input ---------------------------------------------------------------------------------- */

/* A valid MAVLink 2 ATTITUDE frame. */
static size_t attitude_frame(occ_mav_sender_t *tx, float yaw, uint8_t *buf)
{
    mavlink_attitude_t a;
    memset(&a, 0, sizeof a);
    a.time_boot_ms = 1000;
    a.yaw = yaw;
    a.roll = 0.1f;
    return occ_mav_finalize(tx, MAVLINK_MSG_ID_ATTITUDE, (const uint8_t *)&a, sizeof a, buf,
                            OCC_MAV_FRAME_MAX);
}

/* Recompute the CRC of a hand-edited MAVLink 2 frame (header+payload of `len`). */
static void fix_crc_v2(uint8_t *b, uint8_t crc_extra)
{
    uint16_t crc = 0xFFFF;
    for (size_t i = 1; i < 10u + b[1]; i++) {
        crc_accumulate(b[i], &crc);
    }
    crc_accumulate(crc_extra, &crc);
    b[10 + b[1]] = (uint8_t)(crc & 0xFF);
    b[11 + b[1]] = (uint8_t)(crc >> 8);
}

static void test_corrupt_frames(void **state)
{
    (void)state;
    occ_mav_sender_t tx = {1, 1, 0};
    occ_mav_parser_t p;
    occ_mav_parser_init(&p);
    uint8_t good[OCC_MAV_FRAME_MAX], b[2 * OCC_MAV_FRAME_MAX];
    const size_t ng = attitude_frame(&tx, 1.0f, good);
    assert_true(ng > 12);
    occ_mav_result_t r;
    occ_mav_frame_t fr;

    /* Bad CRC: one payload bit flipped. */
    memcpy(b, good, ng);
    b[12] ^= 0x10;
    assert_int_equal(parse_all(&p, b, ng, &r, &fr), 1);
    assert_int_equal(r, OCC_MAV_BAD_CRC);
    assert_int_equal(fr.msgid, 30);
    assert_int_equal(p.counters.bad_crc, 1);
    /* The next good frame parses. */
    assert_int_equal(parse_all(&p, good, ng, &r, &fr), 1);
    assert_int_equal(r, OCC_MAV_OK);

    /* Wrong length: MAVLink 2 payload longer than ATTITUDE's 28 bytes (CRC made valid). */
    memset(b, 0, sizeof b);
    memcpy(b, good, 10);
    b[1] = 40;
    for (int i = 0; i < 40; i++) {
        b[10 + i] = (uint8_t)(i + 1);
    }
    fix_crc_v2(b, 39);
    assert_int_equal(parse_all(&p, b, 52, &r, &fr), 1);
    assert_int_equal(r, OCC_MAV_BAD_LEN);
    assert_int_equal(p.counters.bad_len, 1);
    /* MAVLink 1 frame shorter than the message (v1 cannot trim). */
    {
        uint8_t v1[64];
        v1[0] = 0xFE;
        v1[1] = 10;
        v1[2] = 0;
        v1[3] = 1;
        v1[4] = 1;
        v1[5] = 30;
        memset(v1 + 6, 0x11, 10);
        uint16_t crc = 0xFFFF;
        for (int i = 1; i < 16; i++) {
            crc_accumulate(v1[i], &crc);
        }
        crc_accumulate(39, &crc);
        v1[16] = (uint8_t)crc;
        v1[17] = (uint8_t)(crc >> 8);
        assert_int_equal(parse_all(&p, v1, 18, &r, &fr), 1);
        assert_int_equal(r, OCC_MAV_BAD_LEN);
        assert_int_equal(p.counters.bad_len, 2);
    }

    /* Truncated: a frame cut short, then good frames: the cut frame swallows the start of the
     * next one (bad CRC), and the parser is back in step within a frame. */
    memcpy(b, good, ng / 2);
    size_t nb = ng / 2;
    for (int k = 0; k < 3; k++) {
        memcpy(b + nb, good, ng);
        nb += ng;
    }
    const uint32_t ok0 = p.counters.frames_ok, bad0 = p.counters.bad_crc;
    parse_all(&p, b, nb, &r, &fr);
    assert_int_equal(p.counters.bad_crc, bad0 + 1);
    assert_true(p.counters.frames_ok >= ok0 + 1);
    assert_int_equal(r, OCC_MAV_OK);

    /* Unknown message id (CRC cannot be checked). */
    memcpy(b, good, ng);
    b[7] = 0x34;
    b[8] = 0x12;
    b[9] = 0x00;
    assert_int_equal(parse_all(&p, b, ng, &r, &fr), 1);
    assert_int_equal(r, OCC_MAV_UNKNOWN);
    assert_int_equal(fr.msgid, 0x1234);
    assert_int_equal(p.counters.unknown_id, 1);

    /* Unknown incompat flags. */
    memcpy(b, good, ng);
    b[2] = 0x02;
    assert_int_equal(parse_all(&p, b, ng, &r, &fr), 1);
    assert_int_equal(r, OCC_MAV_BAD_FLAGS);
    assert_int_equal(p.counters.bad_flags, 1);

    /* Junk between frames is counted byte by byte. */
    const uint8_t junk[5] = {0x00, 0x11, 0x22, 0x33, 0x44};
    const uint32_t j0 = p.counters.junk_bytes;
    assert_int_equal(parse_all(&p, junk, 5, NULL, NULL), 0);
    assert_int_equal(p.counters.junk_bytes, j0 + 5);

    /* Random bytes: never a crash; 280 zero bytes later the parser is idle and reads frames. */
    srand(seed);
    for (int round = 0; round < 200; round++) {
        uint8_t rnd[600];
        for (size_t i = 0; i < sizeof rnd; i++) {
            rnd[i] = (uint8_t)(rand() % 8 == 0 ? 0xFD : rand());
        }
        parse_all(&p, rnd, sizeof rnd, NULL, NULL);
        uint8_t zeros[OCC_MAV_FRAME_MAX];
        memset(zeros, 0, sizeof zeros);
        parse_all(&p, zeros, sizeof zeros, NULL, NULL);
        const uint32_t ok1 = p.counters.frames_ok;
        assert_int_equal(parse_all(&p, good, ng, &r, &fr), 1);
        assert_int_equal(r, OCC_MAV_OK);
        assert_int_equal(p.counters.frames_ok, ok1 + 1);
    }
    const occ_mav_counters_t *c = &p.counters;
    printf("corrupt: ok %u bad_crc %u bad_len %u unknown %u bad_flags %u junk %u bytes %llu\n",
           c->frames_ok, c->bad_crc, c->bad_len, c->unknown_id, c->bad_flags, c->junk_bytes,
           (unsigned long long)c->bytes);
    assert_true(c->bad_crc > 10);
}

/* ---- the real tlog -------------------------------------------------------------------------------- */

#define MAX_ID 65536u
static uint32_t tl_ok[MAX_ID], tl_bad[MAX_ID];

static void test_tlog(void **state)
{
    (void)state;
    FILE *ref = fopen(TLOG_REF, "r");
    FILE *log = fopen(TLOG, "rb");
    char line[512];
    if (ref == NULL || log == NULL || fgets(line, sizeof line, ref) == NULL ||
        strncmp(line, "SKIP", 4) == 0) {
        printf("SKIP: needs %s and %s (from tools/mav_tlog_ref.py)\n", TLOG, TLOG_REF);
        if (ref != NULL) {
            fclose(ref);
        }
        if (log != NULL) {
            fclose(log);
        }
        skip();
    }
    rewind(ref);
    static occ_mav_parser_t p;
    occ_mav_parser_init(&p);
    memset(tl_ok, 0, sizeof tl_ok);
    memset(tl_bad, 0, sizeof tl_bad);
    unsigned n_ds = 0, n_ds_checked = 0, n_records = 0;
    /* Read like pymavlink's mavlogfile: an 8-byte timestamp, then bytes until a frame ends. */
    for (;;) {
        uint8_t ts[8];
        if (fread(ts, 1, 8, log) != 8) {
            break;
        }
        n_records++;
        occ_mav_result_t r = OCC_MAV_NONE;
        occ_mav_frame_t fr;
        int ch;
        while (r == OCC_MAV_NONE && (ch = fgetc(log)) != EOF) {
            r = occ_mav_parser_push(&p, (uint8_t)ch, &fr);
        }
        if (r == OCC_MAV_NONE) {
            break;
        }
        assert_int_not_equal(r, OCC_MAV_JUNK);
        assert_true(fr.msgid < MAX_ID);
        if (r == OCC_MAV_OK) {
            tl_ok[fr.msgid]++;
        } else if (r == OCC_MAV_BAD_CRC) {
            tl_bad[fr.msgid]++;
        } else {
            fail_msg("tlog record %u: result %d msgid %u", n_records, r, (unsigned)fr.msgid);
        }
        if (r == OCC_MAV_OK && fr.msgid == OCC_MAV_MSG_DISTANCE_SENSOR) {
            n_ds++;
            /* The next "ds" line of the reference must hold exactly these fields. */
            occ_mav_distance_sensor_t m;
            assert_int_equal(occ_mav_decode_distance_sensor(&fr, &m), OCC_OK);
            do {
                assert_non_null(fgets(line, sizeof line, ref));
            } while (strncmp(line, "ds ", 3) != 0);
            char *v[20];
            int nv = 0;
            for (char *s = strtok(line + 3, " \n"); s != NULL && nv < 20; s = strtok(NULL, " \n")) {
                v[nv++] = s;
            }
            assert_int_equal(nv, 15);
            assert_int_equal(m.time_boot_ms, strtoul(v[0], NULL, 10));
            assert_int_equal(m.min_distance, strtoul(v[1], NULL, 10));
            assert_int_equal(m.max_distance, strtoul(v[2], NULL, 10));
            assert_int_equal(m.current_distance, strtoul(v[3], NULL, 10));
            assert_int_equal(m.type, strtoul(v[4], NULL, 10));
            assert_int_equal(m.id, strtoul(v[5], NULL, 10));
            assert_int_equal(m.orientation, strtoul(v[6], NULL, 10));
            assert_int_equal(m.covariance, strtoul(v[7], NULL, 10));
            assert_true(f32eq(m.horizontal_fov, v[8]));
            assert_true(f32eq(m.vertical_fov, v[9]));
            for (int i = 0; i < 4; i++) {
                assert_true(f32eq(m.quaternion[i], v[10 + i]));
            }
            assert_int_equal(m.signal_quality, strtoul(v[14], NULL, 10));
            n_ds_checked++;
        }
    }
    fclose(log);
    /* Per-id counts. */
    rewind(ref);
    unsigned ids = 0;
    unsigned long tot_ok = 0, tot_bad = 0;
    while (fgets(line, sizeof line, ref) != NULL) {
        unsigned id, ok, bad;
        if (sscanf(line, "count %u %u %u", &id, &ok, &bad) == 3) {
            assert_true(id < MAX_ID);
            if (tl_ok[id] != ok || tl_bad[id] != bad) {
                fail_msg("msgid %u: C %u ok %u bad, pymavlink %u ok %u bad", id, tl_ok[id],
                         tl_bad[id], ok, bad);
            }
            tl_ok[id] = tl_bad[id] = 0;
            ids++;
            tot_ok += ok;
            tot_bad += bad;
        } else if (strncmp(line, "unknown", 7) == 0) {
            fail_msg("pymavlink saw unknown ids: %s", line);
        }
    }
    fclose(ref);
    for (unsigned id = 0; id < MAX_ID; id++) {
        if (tl_ok[id] != 0u || tl_bad[id] != 0u) {
            fail_msg("msgid %u seen by C only (%u ok %u bad)", id, tl_ok[id], tl_bad[id]);
        }
    }
    printf("tlog: %u records, %u message ids, %lu good frames, %lu bad CRC, %u DISTANCE_SENSOR "
           "(all fields equal pymavlink's)\n", n_records, ids, tot_ok, tot_bad, n_ds_checked);
    assert_int_equal(n_ds, n_ds_checked);
    assert_true(n_ds > 0);
}

/* ---- the feed state machine ---------------------------------------------------------------------- */

static uint8_t arena[1u << 20];

static size_t pose_frames(occ_mav_sender_t *ap, float n, float e, float d, float yaw, uint8_t *buf)
{
    mavlink_local_position_ned_t lp;
    memset(&lp, 0, sizeof lp);
    lp.x = n;
    lp.y = e;
    lp.z = d;
    size_t len = occ_mav_finalize(ap, MAVLINK_MSG_ID_LOCAL_POSITION_NED, (const uint8_t *)&lp,
                                  sizeof lp, buf, OCC_MAV_FRAME_MAX);
    len += attitude_frame(ap, yaw, buf + len);
    return len;
}

/* A HEARTBEAT as `tx` (type, autopilot: 2, 3 = an ArduPilot quad; 6, 8 = a GCS). */
static size_t heartbeat_frame(occ_mav_sender_t *tx, uint8_t type, uint8_t autopilot, uint8_t *buf)
{
    const occ_mav_heartbeat_t hb = {0, type, autopilot, 0, 4, 3};
    return occ_mav_encode_heartbeat(tx, &hb, buf, OCC_MAV_FRAME_MAX);
}

static size_t ack_frame(occ_mav_sender_t *tx, uint8_t result, uint8_t *buf)
{
    occ_mav_command_ack_t a;
    memset(&a, 0, sizeof a);
    a.command = OCC_MAV_CMD_SET_MESSAGE_INTERVAL;
    a.result = result;
    a.target_system = 1;
    a.target_component = 196;
    return occ_mav_encode_command_ack(tx, &a, buf, OCC_MAV_FRAME_MAX);
}

typedef struct {
    unsigned hb, obst, req;
    occ_mav_obstacle_distance_t last;
    occ_mav_command_long_t reqs[16]; /* the first 16 SET_MESSAGE_INTERVAL commands */
} sink_t;

static void drain(occ_mav_feed_t *f, const occ_map_t *map, uint64_t now, sink_t *s)
{
    uint8_t out[OCC_MAV_FRAME_MAX];
    size_t n;
    while ((n = occ_mav_feed_poll(f, map, now, out, sizeof out)) > 0) {
        occ_mav_parser_t p;
        occ_mav_parser_init(&p);
        occ_mav_result_t r = OCC_MAV_NONE;
        occ_mav_frame_t fr;
        assert_int_equal(parse_all(&p, out, n, &r, &fr), 1);
        assert_int_equal(r, OCC_MAV_OK);
        assert_int_equal(fr.sysid, 1);
        assert_int_equal(fr.compid, 196);
        if (fr.msgid == 0) {
            occ_mav_heartbeat_t hb;
            assert_int_equal(occ_mav_decode_heartbeat(&fr, &hb), OCC_OK);
            assert_int_equal(hb.type, 18);
            assert_int_equal(hb.autopilot, 8);
            s->hb++;
        } else if (fr.msgid == OCC_MAV_MSG_COMMAND_LONG) {
            occ_mav_command_long_t c;
            assert_int_equal(occ_mav_decode_command_long(&fr, &c), OCC_OK);
            assert_int_equal(c.command, OCC_MAV_CMD_SET_MESSAGE_INTERVAL);
            if (s->req < 16u) {
                s->reqs[s->req] = c;
            }
            s->req++;
        } else {
            assert_int_equal(fr.msgid, 330);
            assert_int_equal(occ_mav_decode_obstacle_distance(&fr, &s->last), OCC_OK);
            s->obst++;
        }
    }
}

static void test_feed(void **state)
{
    (void)state;
    occ_map_t map;
    occ_map_config_t mc = occ_map_config_default();
    assert_int_equal(occ_map_init(&map, &mc, arena, sizeof arena), OCC_OK);
    /* Free space around the origin with a wall 1.5 m north (ENU y in [1.5, 1.6)). */
    for (int i = 0; i < 8; i++) {
        occ_vec3_t v = {(i & 1) ? 0.05f : -0.05f, (i & 2) ? 0.05f : -0.05f,
                        (i & 4) ? 0.05f : -0.05f};
        occ_key_t k;
        assert_int_equal(occ_map_key(&map, v, &k), OCC_OK);
        assert_int_equal(occ_map_set_key(&map, k, 8, -2.0f), OCC_OK);
    }
    for (float x = -3.0f; x < 3.0f; x += 0.1f) {
        for (float z = -0.6f; z < 0.6f; z += 0.1f) {
            occ_vec3_t v = {x, 1.55f, z};
            assert_int_equal(occ_map_update(&map, v, 2.0f), OCC_OK);
        }
    }
    occ_mav_feed_config_t cfg = occ_mav_feed_config_default();
    static occ_mav_feed_t feed;
    assert_int_equal(occ_mav_feed_init(&feed, &cfg), OCC_OK);
    occ_mav_sender_t ap = {1, 1, 0};
    uint8_t in[2 * OCC_MAV_FRAME_MAX];
    sink_t s;
    memset(&s, 0, sizeof s);
    /* No pose yet: heartbeats only. */
    uint64_t t = 1000000;
    for (int i = 0; i < 25; i++, t += 50000) {
        drain(&feed, &map, t, &s);
    }
    assert_int_equal(s.obst, 0);
    assert_int_equal(s.hb, 2); /* t = 1.0 s and 2.0 s */
    assert_int_equal(s.req, 0); /* no autopilot yet */
    assert_true(feed.counters.stale_skips >= 10);
    /* Poses before the autopilot's HEARTBEAT are not taken; after it they are. */
    size_t nin = pose_frames(&ap, 0.0f, 0.0f, 0.0f, 0.0f, in);
    occ_mav_feed_rx(&feed, in, nin, t);
    assert_int_equal(feed.counters.positions_rx, 0);
    assert_int_equal(feed.counters.foreign_rx, 2);
    nin = heartbeat_frame(&ap, 2, 3, in);
    occ_mav_feed_rx(&feed, in, nin, t);
    assert_true(feed.have_autopilot && feed.ap_sysid == 1 && feed.ap_compid == 1);
    /* Poses at 20 Hz for 2 s: 10 Hz obstacle messages. Facing north (NED yaw 0). */
    const unsigned hb0 = s.hb;
    for (int i = 0; i < 40; i++, t += 50000) {
        const size_t n = pose_frames(&ap, 0.0f, 0.0f, 0.0f, 0.0f, in);
        occ_mav_feed_rx(&feed, in, n, t);
        drain(&feed, &map, t, &s);
    }
    assert_true(s.obst >= 19 && s.obst <= 21);
    assert_int_equal(s.hb - hb0, 2);
    assert_int_equal(s.last.frame, 12);
    assert_true(feq((double)s.last.increment_f, 5.0));
    assert_int_equal(s.last.increment, 5);
    assert_int_equal(s.last.min_distance, 20);
    assert_int_equal(s.last.max_distance, 2000);
    assert_true(feq((double)s.last.angle_offset, -20.0)); /* element 4 looks straight ahead */
    /* Wall 1.5 m straight ahead. */
    assert_int_equal(s.last.distances[4], 150);
    assert_int_equal(s.last.distances[40], 2001); /* observed free behind: max + 1 */
    /* The same numbers as occ_sectors_compute for the same pose. */
    static occ_sectors_t ref;
    occ_pose_t pose = occ_pose_from_ned(0.0f, 0.0f, 0.0f, 0.0f);
    assert_int_equal(occ_sectors_compute(&map, &pose, &cfg.sectors, &ref), OCC_OK);
    assert_memory_equal(ref.distance_cm, s.last.distances, 72 * sizeof(uint16_t));
    /* Facing east (NED yaw +90 deg): the wall is on the left, body 270 deg = element 58. */
    for (int i = 0; i < 4; i++, t += 50000) {
        const size_t n = pose_frames(&ap, 0.0f, 0.0f, 0.0f, (float)(M_PI / 2.0), in);
        occ_mav_feed_rx(&feed, in, n, t);
        drain(&feed, &map, t, &s);
    }
    assert_int_equal(s.last.distances[58], 150);
    /* Poses stop: messages stop within the 300 ms timeout, heartbeats go on. */
    const uint64_t t_last_pose = t - 50000;
    const unsigned ob = s.obst, hb1 = s.hb;
    unsigned after = 0;
    for (int i = 0; i < 60; i++, t += 50000) {
        const unsigned before = s.obst;
        drain(&feed, &map, t, &s);
        if (s.obst > before) {
            assert_true(t - t_last_pose <= 300000);
            after++;
        }
    }
    assert_true(after <= 3);
    assert_true(s.obst - ob <= 3);
    assert_true(s.hb - hb1 >= 2);
    /* Our own frames echoed back are ignored; ODOMETRY revives the feed. */
    occ_mav_sender_t self = {1, 196, 0};
    size_t n = pose_frames(&self, 0.0f, 0.0f, 0.0f, 0.0f, in);
    occ_mav_feed_rx(&feed, in, n, t);
    const unsigned ob2 = s.obst;
    drain(&feed, &map, t, &s);
    t += 100000;
    drain(&feed, &map, t, &s);
    assert_int_equal(s.obst, ob2);
    mavlink_odometry_t od;
    memset(&od, 0, sizeof od);
    od.frame_id = 1;
    od.q[0] = cosf(0.25f * (float)M_PI); /* yaw 90 deg about down: facing east */
    od.q[3] = sinf(0.25f * (float)M_PI);
    n = occ_mav_finalize(&ap, MAVLINK_MSG_ID_ODOMETRY, (const uint8_t *)&od, MAVLINK_MSG_ID_ODOMETRY_LEN, in,
                         sizeof in);
    occ_mav_feed_rx(&feed, in, n, t);
    t += 100000;
    drain(&feed, &map, t, &s);
    assert_int_equal(s.obst, ob2 + 1);
    assert_int_equal(s.last.distances[58], 150);
    /* The ODOMETRY pose in the map frame: NED heading east = ENU yaw 0. */
    occ_pose_t pz;
    assert_true(occ_mav_feed_pose(&feed, t, &pz));
    assert_true(fabsf(pz.yaw_rad) < 1e-5f);
    /* PX4 needs all 72 elements covered. */
    occ_mav_feed_config_t c2 = cfg;
    c2.autopilot = OCC_AUTOPILOT_PX4;
    c2.sectors.n_sectors = 8;
    c2.sectors.increment_deg = 10.0f;
    assert_int_equal(occ_mav_feed_init(&feed, &c2), OCC_ERR_ARG);
    c2.sectors.n_sectors = 72;
    c2.sectors.increment_deg = 5.0f;
    assert_int_equal(occ_mav_feed_init(&feed, &c2), OCC_OK);
    c2.period_us = 0;
    assert_int_equal(occ_mav_feed_init(&feed, &c2), OCC_ERR_ARG);
    printf("feed: %u heartbeats, %u OBSTACLE_DISTANCE\n", s.hb, s.obst);
}

/* ---- the feed as ArduPilot reads it ---------------------------------------------------------------- */

/* ArduPilot's OBSTACLE_DISTANCE handler as documented (AP_Proximity_MAV, PRX1_TYPE = 2): reset
 * the 8 faces of 45 deg centred on 0, 45, ..., 315; walk the elements in order, skipping 0,
 * UINT16_MAX, < min and > max; keep the nearest valid element of the current face and write
 * the face each time a valid element's face differs from the previous one. face_m < 0: no
 * obstacle. */
static void ardupilot_faces(const occ_mav_obstacle_distance_t *m, double face_m[8])
{
    for (int f = 0; f < 8; f++) {
        face_m[f] = -1.0;
    }
    const double inc = m->increment_f > 0.0f ? (double)m->increment_f : (double)m->increment;
    int prev = -1;
    double best = 0.0;
    for (int i = 0; i < 72; i++) {
        const uint16_t d = m->distances[i];
        if (d == 0u || d == UINT16_MAX || d < m->min_distance || d > m->max_distance) {
            continue;
        }
        const double angle = fmod(fmod((double)i * inc + (double)m->angle_offset, 360.0) + 360.0,
                                  360.0);
        const int face = (int)(fmod(angle + 22.5, 360.0) / 45.0) % 8;
        if (prev >= 0 && face != prev) {
            face_m[prev] = best;
            prev = -1;
        }
        const double dm = (double)d * 0.01;
        if (prev < 0 || dm < best) {
            best = dm;
        }
        prev = face;
    }
    if (prev >= 0) {
        face_m[prev] = best;
    }
}

/* A map of free space (the eight level-8 nodes around the origin, 25.6 m cubes). */
static void free_map(occ_map_t *map)
{
    occ_map_config_t mc = occ_map_config_default();
    assert_int_equal(occ_map_init(map, &mc, arena, sizeof arena), OCC_OK);
    for (int i = 0; i < 8; i++) {
        occ_vec3_t v = {(i & 1) ? 0.05f : -0.05f, (i & 2) ? 0.05f : -0.05f,
                        (i & 4) ? 0.05f : -0.05f};
        occ_key_t k;
        assert_int_equal(occ_map_key(map, v, &k), OCC_OK);
        assert_int_equal(occ_map_set_key(map, k, 8, -2.0f), OCC_OK);
    }
}

/* A post (one voxel column, z -0.45..0.45) at body angle b_deg, range r_m from a vehicle at the
 * origin facing north; returns its distance, worked out from the voxel's square in double. */
static double post(occ_map_t *map, double b_deg, double r_m)
{
    const double res = (double)map->cfg.resolution_m;
    const double x = r_m * sin(b_deg * M_PI / 180.0), y = r_m * cos(b_deg * M_PI / 180.0);
    for (double z = -0.45; z < 0.5; z += 0.1) {
        const occ_vec3_t v = {(float)x, (float)y, (float)z};
        assert_int_equal(occ_map_update(map, v, 2.0f), OCC_OK);
    }
    const double x0 = floor(x / res) * res, y0 = floor(y / res) * res;
    const double qx = x0 > 0.0 ? x0 : (x0 + res < 0.0 ? x0 + res : 0.0);
    const double qy = y0 > 0.0 ? y0 : (y0 + res < 0.0 ? y0 + res : 0.0);
    return sqrt(qx * qx + qy * qy);
}

/* One OBSTACLE_DISTANCE of a feed with `cfg` for the autopilot (1, 1) at NED (n, e, d, yaw). */
static occ_mav_obstacle_distance_t feed_once(const occ_mav_feed_config_t *cfg,
                                             const occ_map_t *map, float n, float e, float d,
                                             float yaw)
{
    static occ_mav_feed_t feed;
    assert_int_equal(occ_mav_feed_init(&feed, cfg), OCC_OK);
    occ_mav_sender_t ap = {1, 1, 0};
    uint8_t in[3 * OCC_MAV_FRAME_MAX];
    size_t len = heartbeat_frame(&ap, 2, 3, in);
    len += pose_frames(&ap, n, e, d, yaw, in + len);
    occ_mav_feed_rx(&feed, in, len, 1000000);
    sink_t s;
    memset(&s, 0, sizeof s);
    drain(&feed, map, 1000000, &s);
    assert_int_equal(s.obst, 1);
    return s.last;
}

/* Every face ArduPilot computes from our message is the nearest obstacle in its 45 degrees;
 * faces without one read "no obstacle" (free elements are max + 1, dropped by its range check).
 * The forward face holds two posts, the near one at 10 deg, a far one at 345 deg: with
 * angle_offset 0 (the old default) ArduPilot's forward face is the far one (elements 68-71
 * overwrite 0-4), the 1.96 m instead of 1.16 m. */
static void test_feed_ardupilot_faces(void **state)
{
    (void)state;
    occ_map_t map;
    free_map(&map);
    const double near0 = post(&map, 10.0, 1.2), far0 = post(&map, 345.0, 2.0);
    const double d2 = post(&map, 100.0, 1.5), d5 = post(&map, 225.0, 0.8);
    assert_true(near0 < far0 - 0.5);
    occ_mav_feed_config_t cfg = occ_mav_feed_config_default();
    assert_true(feq((double)cfg.sectors.angle_offset_deg, -20.0));
    cfg.sectors.max_distance_cm = 500;
    const occ_mav_obstacle_distance_t m = feed_once(&cfg, &map, 0.0f, 0.0f, 0.0f, 0.0f);
    double face[8];
    ardupilot_faces(&m, face);
    const double want[8] = {near0, -1.0, d2, -1.0, -1.0, d5, -1.0, -1.0};
    for (int f = 0; f < 8; f++) {
        printf("face %d: ardupilot %.2f m, nearest in the map %.3f m\n", f, face[f], want[f]);
        if (want[f] < 0.0) {
            assert_true(face[f] < 0.0);
        } else {
            assert_true(fabs(face[f] - want[f]) <= 0.011);
        }
    }
    unsigned free_elems = 0;
    for (int i = 0; i < 72; i++) {
        free_elems += m.distances[i] == 501u ? 1u : 0u;
        assert_true(m.distances[i] != 0u && m.distances[i] != 500u);
    }
    assert_true(free_elems > 50u);
    /* The old offset: ArduPilot's forward face reads the far post. */
    cfg.sectors.angle_offset_deg = 0.0f;
    const occ_mav_obstacle_distance_t m0 = feed_once(&cfg, &map, 0.0f, 0.0f, 0.0f, 0.0f);
    ardupilot_faces(&m0, face);
    assert_true(fabs(face[0] - far0) <= 0.011);
    /* Free as max_distance (the old encoding) would be an obstacle at 5 m in every face. */
    occ_mav_obstacle_distance_t old = m;
    for (int i = 0; i < 72; i++) {
        old.distances[i] = old.distances[i] == 501u ? 500u : old.distances[i];
    }
    ardupilot_faces(&old, face);
    assert_true(fabs(face[1] - 5.0) < 1e-9);
}

/* The vehicle standing on a floor can arm: no face nearer than 0.6 m (ArduPilot's arming check). */
static void test_feed_floor_arming(void **state)
{
    (void)state;
    occ_map_t map;
    free_map(&map);
    for (float x = -4.95f; x < 5.0f; x += 0.1f) {
        for (float y = -4.95f; y < 5.0f; y += 0.1f) {
            const occ_vec3_t v = {x, y, -0.05f}; /* floor voxels z -0.1..0 */
            assert_int_equal(occ_map_update(&map, v, 2.0f), OCC_OK);
        }
    }
    const double d_post = post(&map, 45.0, 2.0);
    occ_mav_feed_config_t cfg = occ_mav_feed_config_default();
    cfg.sectors.max_distance_cm = 400;
    /* Standing 5 cm above the floor (NED down -0.05), heading 30 deg. */
    occ_mav_obstacle_distance_t m = feed_once(&cfg, &map, 0.0f, 0.0f, -0.05f, 0.0f);
    double face[8];
    ardupilot_faces(&m, face);
    for (int f = 0; f < 8; f++) {
        assert_true(face[f] < 0.0 || face[f] > 0.6);
    }
    assert_true(fabs(face[1] - d_post) <= 0.011);
    /* Hovering 0.4 m over it: the same. */
    m = feed_once(&cfg, &map, 0.0f, 0.0f, -0.4f, 0.0f);
    ardupilot_faces(&m, face);
    for (int f = 0; f < 8; f++) {
        assert_true(face[f] < 0.0 || face[f] > 0.6);
    }
    /* Without the ground rule the floor is at 0.2 m (min_distance) in every face. */
    cfg.sectors.ignore_ground = false;
    m = feed_once(&cfg, &map, 0.0f, 0.0f, -0.05f, 0.0f);
    ardupilot_faces(&m, face);
    for (int f = 0; f < 8; f++) {
        assert_true(fabs(face[f] - 0.2) < 1e-9);
    }
}

/* Unknown space: UINT16_MAX by default (ArduPilot: a face of only unknown = no obstacle); with
 * unknown_as_distance its distance (an obstacle both autopilots respect). */
static void test_feed_unknown_encoding(void **state)
{
    (void)state;
    occ_map_t map;
    occ_map_config_t mc = occ_map_config_default();
    assert_int_equal(occ_map_init(&map, &mc, arena, sizeof arena), OCC_OK);
    /* Free only north of the vehicle (y >= 0): the south half is never observed. */
    for (float x = -2.95f; x < 3.0f; x += 0.1f) {
        for (float y = -0.05f; y < 3.0f; y += 0.1f) {
            for (float z = -0.45f; z < 0.5f; z += 0.1f) {
                const occ_vec3_t v = {x, y, z};
                assert_int_equal(occ_map_update(&map, v, -2.0f), OCC_OK);
            }
        }
    }
    occ_mav_feed_config_t cfg = occ_mav_feed_config_default();
    cfg.sectors.max_distance_cm = 250;
    occ_mav_obstacle_distance_t m = feed_once(&cfg, &map, 0.05f, 0.05f, 0.0f, 0.0f);
    double face[8];
    ardupilot_faces(&m, face);
    assert_int_equal(m.distances[40], UINT16_MAX); /* behind: unknown 10 cm away */
    assert_true(face[4] < 0.0);                     /* ArduPilot: no obstacle behind */
    assert_true(face[0] < 0.0);                     /* ahead: observed free */
    cfg.sectors.unknown_as_distance = true;
    m = feed_once(&cfg, &map, 0.05f, 0.05f, 0.0f, 0.0f);
    ardupilot_faces(&m, face);
    assert_int_equal(m.distances[40], 20); /* 0.1 m, clamped to min_distance */
    assert_true(fabs(face[4] - 0.2) < 1e-9);
    assert_true(face[0] < 0.0);
}

/* The autopilot: named by its HEARTBEAT (not a GCS's, not a companion's) or by the config;
 * poses from other systems or components are ignored. */
static void test_feed_sysid(void **state)
{
    (void)state;
    occ_map_t map;
    free_map(&map);
    occ_mav_feed_config_t cfg = occ_mav_feed_config_default();
    static occ_mav_feed_t feed;
    assert_int_equal(occ_mav_feed_init(&feed, &cfg), OCC_OK);
    occ_mav_sender_t gcs = {255, 190, 0}, companion = {7, 197, 0}, ap = {7, 1, 0};
    occ_mav_sender_t other = {2, 1, 0}, ap_other_comp = {7, 2, 0};
    uint8_t in[3 * OCC_MAV_FRAME_MAX];
    size_t n = heartbeat_frame(&gcs, 6, 8, in);
    n += heartbeat_frame(&companion, 18, 8, in + n);
    occ_mav_feed_rx(&feed, in, n, 1000000);
    assert_false(feed.have_autopilot);
    n = heartbeat_frame(&ap, 2, 3, in);
    occ_mav_feed_rx(&feed, in, n, 1000000);
    assert_true(feed.have_autopilot && feed.ap_sysid == 7 && feed.ap_compid == 1);
    n = heartbeat_frame(&other, 2, 12, in); /* a second autopilot does not take over */
    occ_mav_feed_rx(&feed, in, n, 1000000);
    assert_int_equal(feed.ap_sysid, 7);
    sink_t s;
    memset(&s, 0, sizeof s);
    uint64_t t = 1000000;
    for (int i = 0; i < 10; i++, t += 50000) {
        n = pose_frames(&other, 0.0f, 0.0f, 0.0f, 0.0f, in);
        n += pose_frames(&ap_other_comp, 0.0f, 0.0f, 0.0f, 0.0f, in + n);
        occ_mav_feed_rx(&feed, in, n, t);
        drain(&feed, &map, t, &s);
    }
    assert_int_equal(s.obst, 0);
    assert_int_equal(feed.counters.positions_rx + feed.counters.attitudes_rx, 0);
    assert_int_equal(feed.counters.foreign_rx, 40);
    n = pose_frames(&ap, 0.0f, 0.0f, 0.0f, 0.0f, in);
    occ_mav_feed_rx(&feed, in, n, t);
    drain(&feed, &map, t, &s);
    assert_int_equal(s.obst, 1);
    /* Given sysid and compid: no HEARTBEAT needed, others' ignored. */
    cfg.autopilot_sysid = 9;
    cfg.autopilot_compid = 3;
    assert_int_equal(occ_mav_feed_init(&feed, &cfg), OCC_OK);
    occ_mav_sender_t ap9 = {9, 3, 0};
    n = heartbeat_frame(&ap, 2, 3, in);
    n += pose_frames(&ap, 0.0f, 0.0f, 0.0f, 0.0f, in + n);
    occ_mav_feed_rx(&feed, in, n, t);
    assert_int_equal(feed.ap_sysid, 9);
    assert_int_equal(feed.counters.positions_rx, 0);
    n = pose_frames(&ap9, 0.0f, 0.0f, 0.0f, 0.0f, in);
    occ_mav_feed_rx(&feed, in, n, t);
    assert_int_equal(feed.counters.positions_rx, 1);
    assert_int_equal(feed.counters.attitudes_rx, 1);
}

static bool is_request(const occ_mav_command_long_t *c, uint32_t msgid)
{
    return c->target_system == 7u && c->target_component == 1u &&
           c->command == OCC_MAV_CMD_SET_MESSAGE_INTERVAL &&
           feq((double)c->param[0], (double)msgid) && feq((double)c->param[1], 50000.0);
}

/* SET_MESSAGE_INTERVAL for LOCAL_POSITION_NED and ATTITUDE: sent once the autopilot is known,
 * every second until the streams arrive, again when they stop; refusals counted. */
static void test_feed_requests(void **state)
{
    (void)state;
    occ_map_t map;
    free_map(&map);
    occ_mav_feed_config_t cfg = occ_mav_feed_config_default();
    static occ_mav_feed_t feed;
    assert_int_equal(occ_mav_feed_init(&feed, &cfg), OCC_OK);
    occ_mav_sender_t ap = {7, 1, 0}, other = {2, 1, 0};
    uint8_t in[3 * OCC_MAV_FRAME_MAX];
    sink_t s;
    memset(&s, 0, sizeof s);
    uint64_t t = 1000000;
    drain(&feed, &map, t, &s);
    assert_int_equal(s.req, 0); /* nobody to ask yet */
    size_t n = heartbeat_frame(&ap, 2, 3, in);
    occ_mav_feed_rx(&feed, in, n, t);
    drain(&feed, &map, t, &s);
    assert_int_equal(s.req, 2);
    assert_true(is_request(&s.reqs[0], 32) && is_request(&s.reqs[1], 30));
    /* Refused, then accepted; an ACK from another system is not ours. */
    n = ack_frame(&ap, 2, in);
    n += ack_frame(&other, 4, in + n);
    n += ack_frame(&ap, 0, in + n);
    occ_mav_feed_rx(&feed, in, n, t);
    assert_int_equal(feed.counters.request_refusals, 1);
    assert_int_equal(feed.counters.last_refusal_result, 2);
    assert_int_equal(feed.counters.request_acks, 1);
    /* Nothing arrives: asked again every second. */
    for (int i = 0; i < 20; i++) {
        t += 50000;
        drain(&feed, &map, t, &s);
    }
    assert_int_equal(s.req, 4);
    assert_true(is_request(&s.reqs[2], 32) && is_request(&s.reqs[3], 30));
    /* Poses at 20 Hz for 3 s: no more requests. */
    for (int i = 0; i < 60; i++) {
        t += 50000;
        n = pose_frames(&ap, 0.0f, 0.0f, 0.0f, 0.0f, in);
        occ_mav_feed_rx(&feed, in, n, t);
        drain(&feed, &map, t, &s);
    }
    assert_int_equal(s.req, 4);
    assert_true(s.obst >= 28);
    /* Only the attitude stops: only ATTITUDE is asked for. */
    mavlink_local_position_ned_t lp;
    memset(&lp, 0, sizeof lp);
    for (int i = 0; i < 30; i++) {
        t += 50000;
        n = occ_mav_finalize(&ap, MAVLINK_MSG_ID_LOCAL_POSITION_NED, (const uint8_t *)&lp,
                             sizeof lp, in, sizeof in);
        occ_mav_feed_rx(&feed, in, n, t);
        drain(&feed, &map, t, &s);
    }
    assert_true(s.req >= 5 && s.req <= 6);
    assert_true(is_request(&s.reqs[4], 30));
    /* Everything stops (the autopilot rebooted): both asked for again, every second. */
    const unsigned r0 = s.req;
    for (int i = 0; i < 40; i++) {
        t += 50000;
        drain(&feed, &map, t, &s);
    }
    assert_true(s.req >= r0 + 2);
    assert_true(is_request(&s.reqs[s.req - 2], 32) && is_request(&s.reqs[s.req - 1], 30));
    assert_int_equal(feed.counters.requests_tx, s.req);
    /* pose_interval_us 0: never asks. */
    cfg.pose_interval_us = 0;
    assert_int_equal(occ_mav_feed_init(&feed, &cfg), OCC_OK);
    memset(&s, 0, sizeof s);
    n = heartbeat_frame(&ap, 2, 3, in);
    occ_mav_feed_rx(&feed, in, n, t);
    for (int i = 0; i < 40; i++) {
        t += 50000;
        drain(&feed, &map, t, &s);
    }
    assert_int_equal(s.req, 0);
    cfg.pose_interval_us = 50000;
    cfg.request_period_us = 0;
    assert_int_equal(occ_mav_feed_init(&feed, &cfg), OCC_ERR_ARG);
}

/* The termios serial link over a pseudo-terminal: frames both ways, non-blocking reads. */
static void test_serial_pty(void **state)
{
    (void)state;
    const int master = posix_openpt(O_RDWR | O_NOCTTY);
    if (master < 0 || grantpt(master) != 0 || unlockpt(master) != 0 || ptsname(master) == NULL) {
        printf("SKIP: no pseudo-terminals here\n");
        if (master >= 0) {
            close(master);
        }
        skip();
    }
    char name[128];
    snprintf(name, sizeof name, "%s", ptsname(master));
    occ_link_t link;
    char msg[128];
    assert_int_equal(occ_link_serial_open(&link, name, 12345, msg, sizeof msg), OCC_ERR_ARG);
    assert_int_equal(occ_link_serial_open(&link, "/nonexistent/tty", 57600, msg, sizeof msg),
                     OCC_ERR_IO);
    assert_int_equal(occ_link_serial_open(&link, name, 921600, msg, sizeof msg), OCC_OK);
    uint8_t buf[OCC_MAV_FRAME_MAX];
    size_t n = 0;
    assert_int_equal(occ_link_read(&link, buf, sizeof buf, &n), OCC_OK); /* nothing: no block */
    assert_int_equal(n, 0);
    /* Autopilot -> us. */
    occ_mav_sender_t ap = {1, 1, 0};
    uint8_t frame[OCC_MAV_FRAME_MAX];
    const size_t nf = attitude_frame(&ap, 0.5f, frame);
    assert_int_equal(write(master, frame, nf), (ssize_t)nf);
    occ_mav_parser_t p;
    occ_mav_parser_init(&p);
    size_t got = 0;
    for (int i = 0; i < 50 && got < nf; i++) {
        (void)occ_link_wait(&link, 20000);
        assert_int_equal(occ_link_read(&link, buf, sizeof buf, &n), OCC_OK);
        parse_all(&p, buf, n, NULL, NULL);
        got += n;
    }
    assert_int_equal(got, nf);
    assert_int_equal(p.counters.frames_ok, 1);
    /* Us -> autopilot. */
    occ_mav_sender_t us = {1, 196, 0};
    occ_mav_heartbeat_t hb = {0, 18, 8, 0, 4, 3};
    const size_t nh = occ_mav_encode_heartbeat(&us, &hb, frame, sizeof frame);
    assert_int_equal(occ_link_write(&link, frame, nh), OCC_OK);
    occ_mav_parser_init(&p);
    got = 0;
    for (int i = 0; i < 50 && got < nh; i++) {
        const ssize_t r = read(master, buf, sizeof buf);
        if (r > 0) {
            parse_all(&p, buf, (size_t)r, NULL, NULL);
            got += (size_t)r;
        }
    }
    assert_int_equal(got, nh);
    assert_int_equal(p.counters.frames_ok, 1);
    assert_true(link.tx_bytes == nh && link.rx_bytes == nf);
    occ_link_close(&link);
    close(master);
}

static void test_quat_yaw(void **state)
{
    (void)state;
    for (int i = -8; i <= 8; i++) {
        const float yaw = (float)i * 0.39f;
        const float q[4] = {cosf(yaw / 2.0f), 0.0f, 0.0f, sinf(yaw / 2.0f)};
        float roll, pitch;
        const float got = occ_mav_quat_yaw(q, &roll, &pitch);
        float d = got - yaw;
        d = atan2f(sinf(d), cosf(d));
        assert_true(fabsf(d) < 1e-5f);
        assert_true(fabsf(roll) < 1e-6f && fabsf(pitch) < 1e-6f);
    }
}

int main(void)
{
    const char *env = getenv("OCC_SEED");
    seed = env != NULL ? (unsigned)strtoul(env, NULL, 0) : 4242u;
    printf("test_mavlink: OCC_SEED=%u\n", seed);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_obstacle_roundtrip),
        cmocka_unit_test(test_pymavlink_frames),
        cmocka_unit_test(test_corrupt_frames),
        cmocka_unit_test(test_tlog),
        cmocka_unit_test(test_quat_yaw),
        cmocka_unit_test(test_serial_pty),
        cmocka_unit_test(test_feed),
        cmocka_unit_test(test_feed_ardupilot_faces),
        cmocka_unit_test(test_feed_floor_arming),
        cmocka_unit_test(test_feed_unknown_encoding),
        cmocka_unit_test(test_feed_sysid),
        cmocka_unit_test(test_feed_requests),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
