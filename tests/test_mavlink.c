/* SPDX-License-Identifier: BSD-3-Clause */
/* test_mavlink.c - the MAVLink parser, encoders and decoders, and the serial link (the feed state
 * machine: test_mavlink_feed.c).
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
#include "occmap/host/occ_link_posix.h"
#include "ardupilotmega/mavlink.h"
#include "support/mav_frames.h"

#define TLOG "../shared/data/mavlink/ardusub_2023-04-18_11-03-34.tlog"
#define TLOG_REF "build/mavlink/tlog_ref.txt"
#define PY_BIN "build/mavlink/py_frames.bin"
#define PY_TXT "build/mavlink/py_frames.txt"

static unsigned seed;


/* Float read back from a "%.9g" text equals the float32 on the wire, bit for bit (NaN = NaN). */
static bool f32eq(float got, const char *txt)
{
    const float want = strtof(txt, NULL);
    if (isnan(want)) {
        return isnan(got);
    }
    return feq((double)got, (double)want);
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
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
