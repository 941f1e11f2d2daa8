/* SPDX-License-Identifier: BSD-3-Clause */
/* occ_tlog.h - MAVLink telemetry logs (.tlog, as QGroundControl, MAVProxy and pymavlink write
 * them) on a POSIX host (port/posix/tlog.c; the range readings of a log into a map:
 * occ_tlog_ranges.h).
 *
 * A .tlog is repeated [8-byte big-endian microseconds since the Unix epoch: when the logging
 * ground station received the frame][one MAVLink 1 or 2 frame]. The stamp is the only clock
 * every message of a log shares: a message's own time_boot_ms is its sender's clock, and in
 * the ArduSub log of ../shared the sonar's DISTANCE_SENSOR (compid 194, a companion computer)
 * runs 1.1 s behind the autopilot's (compid 1) ATTITUDE. So poses and readings are matched on
 * the log stamp. It includes the link's delay and batching (the sonar's frames arrive in
 * bursts up to ~0.3 s late): fine for a slow vehicle, stated, not hidden.
 */
#ifndef OCC_TLOG_H_INCLUDED
#define OCC_TLOG_H_INCLUDED

#include <stdio.h>

#include "occmap/occmap.h"
#include "occmap/occ_mavlink.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- reader ------------------------------------------------------------------------------- */
typedef struct {
    uint64_t records;        /* stamps read */
    uint64_t frames_ok;      /* frames the parser accepted (OCC_MAV_OK) */
    uint64_t frames_bad;     /* records whose frame failed (bad CRC, unknown id, ...): skipped */
    bool truncated;          /* the file ended inside a record */
    bool io_error;           /* a read failed */
    FILE *file_;             /* private */
    occ_mav_parser_t parser_;
} occ_tlog_t;

/* Open a log. OCC_ERR_IO (cannot open; `msg` says why). */
occ_err_t occ_tlog_open(occ_tlog_t *t, const char *path, char *msg, size_t msg_len);
/* The next good frame and its stamp; false at the end of the file (or on a read error:
 * io_error). Bad frames are counted and skipped, like pymavlink's robust parsing. The frame
 * points into *t and stays valid until the next call. O(frame). */
bool occ_tlog_next(occ_tlog_t *t, uint64_t *stamp_us, occ_mav_frame_t *frame);
void occ_tlog_close(occ_tlog_t *t);

#ifdef __cplusplus
}
#endif
#endif
