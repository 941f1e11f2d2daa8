/* SPDX-License-Identifier: BSD-3-Clause */
/* test_tlog_reader.c - the .tlog reader (port/posix/tlog.c): a hand-built log (big-endian
 * stamps, a corrupt frame, a truncated tail) and the real ArduSub log against pymavlink's
 * counts (build/mavlink/tlog_ref.txt, tools/mav_tlog_ref.py). */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <string.h>

#include "occmap/host/occ_tlog.h"

#define TLOG "../shared/data/mavlink/ardusub_2023-04-18_11-03-34.tlog"
#define TLOG_REF "build/mavlink/tlog_ref.txt"
#define TINY "build/mavlink/tiny.tlog"

static void put_stamp(FILE *f, uint64_t t)
{
    for (int i = 7; i >= 0; i--) {
        fputc((int)((t >> (8 * i)) & 0xFFu), f);
    }
}

static void test_tiny_log(void **state)
{
    (void)state;
    FILE *f = fopen(TINY, "wb");
    assert_non_null(f);
    occ_mav_sender_t tx = {7, 1, 0};
    const occ_mav_heartbeat_t hb = {0, 2, 3, 0, 4, 3};
    uint8_t fr[OCC_MAV_FRAME_MAX];
    const size_t n = occ_mav_encode_heartbeat(&tx, &hb, fr, sizeof fr);
    put_stamp(f, 0x0102030405060708ull);
    fwrite(fr, 1, n, f);
    put_stamp(f, 2000000u);
    fr[n - 1u] ^= 0x55u; /* CRC broken: counted, skipped */
    fwrite(fr, 1, n, f);
    fr[n - 1u] ^= 0x55u;
    put_stamp(f, 3000000u);
    fwrite(fr, 1, n, f);
    put_stamp(f, 4000000u);
    fwrite(fr, 1, n - 3u, f); /* the log ends inside a frame */
    fclose(f);
    occ_tlog_t t;
    char msg[128];
    assert_int_equal(occ_tlog_open(&t, "build/mavlink/no such.tlog", msg, sizeof msg), OCC_ERR_IO);
    assert_non_null(strstr(msg, "no such"));
    assert_int_equal(occ_tlog_open(&t, TINY, msg, sizeof msg), OCC_OK);
    uint64_t stamp;
    occ_mav_frame_t frame;
    assert_true(occ_tlog_next(&t, &stamp, &frame));
    assert_true(stamp == 0x0102030405060708ull);
    assert_int_equal(frame.msgid, 0);
    assert_int_equal(frame.sysid, 7);
    assert_true(occ_tlog_next(&t, &stamp, &frame));
    assert_true(stamp == 3000000u);
    assert_false(occ_tlog_next(&t, &stamp, &frame));
    assert_true(t.records == 4u && t.frames_ok == 2u && t.frames_bad == 1u);
    assert_true(t.truncated);
    assert_false(t.io_error);
    assert_false(occ_tlog_next(&t, &stamp, &frame));
    occ_tlog_close(&t);
    occ_tlog_close(&t); /* twice is fine */
    assert_false(occ_tlog_next(&t, &stamp, &frame));
    assert_false(occ_tlog_next(NULL, &stamp, &frame));
}

static void test_real_log_counts(void **state)
{
    (void)state;
    FILE *ref = fopen(TLOG_REF, "r");
    char line[512];
    unsigned long ok = 0, bad = 0, unknown = 0, other = 0;
    bool have_total = false;
    while (ref != NULL && fgets(line, sizeof line, ref) != NULL) {
        have_total = sscanf(line, "total %lu %lu %lu %lu", &ok, &bad, &unknown, &other) == 4 ||
                     have_total;
    }
    if (ref != NULL) {
        fclose(ref);
    }
    occ_tlog_t t;
    if (!have_total || occ_tlog_open(&t, TLOG, NULL, 0) != OCC_OK) {
        printf("SKIP: needs %s and %s (tools/mav_tlog_ref.py)\n", TLOG, TLOG_REF);
        skip();
    }
    uint64_t stamp, first = 0, last = 0;
    occ_mav_frame_t frame;
    while (occ_tlog_next(&t, &stamp, &frame)) {
        first = first == 0u ? stamp : first;
        last = stamp;
    }
    printf("tlog reader: %llu records, %llu good, %llu bad, %.1f s\n",
           (unsigned long long)t.records, (unsigned long long)t.frames_ok,
           (unsigned long long)t.frames_bad, (double)(last - first) / 1e6);
    assert_true(t.frames_ok == ok && t.frames_bad == bad + unknown + other);
    assert_true(t.records == ok + bad + unknown + other);
    assert_false(t.truncated);
    assert_false(t.io_error);
    assert_true(first > 1600000000000000ull && last > first); /* Unix-epoch microseconds */
    occ_tlog_close(&t);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_tiny_log),
        cmocka_unit_test(test_real_log_counts),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
