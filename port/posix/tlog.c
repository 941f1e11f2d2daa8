/* SPDX-License-Identifier: BSD-3-Clause */
/* tlog.c - reading MAVLink telemetry logs (see occ_tlog.h). */
#include <stdarg.h>
#include <string.h>

#include "occmap/host/occ_tlog.h"

occ_err_t occ_tlog_open(occ_tlog_t *t, const char *path, char *msg, size_t msg_len)
{
    if (t == NULL || path == NULL) {
        return OCC_ERR_ARG;
    }
    memset(t, 0, sizeof *t);
    occ_mav_parser_init(&t->parser_);
    t->file_ = fopen(path, "rb");
    if (t->file_ == NULL) {
        if (msg != NULL && msg_len > 0u) {
            (void)snprintf(msg, msg_len, "cannot open %s", path);
        }
        return OCC_ERR_IO;
    }
    return OCC_OK;
}

static uint64_t be64(const uint8_t b[8])
{
    uint64_t v = 0;
    for (unsigned i = 0; i < 8u; i++) {
        v = (v << 8) | b[i];
    }
    return v;
}

/* One record: its stamp, then bytes into the parser until a frame ends. */
static bool read_record(occ_tlog_t *t, uint64_t *stamp_us, occ_mav_frame_t *frame,
                        occ_mav_result_t *r)
{
    uint8_t ts[8];
    const size_t got = fread(ts, 1, sizeof ts, t->file_);
    if (got != sizeof ts) {
        t->truncated = got != 0u;
        t->io_error = ferror(t->file_) != 0;
        return false;
    }
    t->records++;
    *stamp_us = be64(ts);
    *r = OCC_MAV_NONE;
    int ch;
    while (*r == OCC_MAV_NONE || *r == OCC_MAV_JUNK) {
        if ((ch = fgetc(t->file_)) == EOF) {
            t->truncated = true;
            t->io_error = ferror(t->file_) != 0;
            return false;
        }
        *r = occ_mav_parser_push(&t->parser_, (uint8_t)ch, frame);
    }
    return true;
}

bool occ_tlog_next(occ_tlog_t *t, uint64_t *stamp_us, occ_mav_frame_t *frame)
{
    if (t == NULL || t->file_ == NULL || stamp_us == NULL || frame == NULL) {
        return false;
    }
    occ_mav_result_t r;
    while (read_record(t, stamp_us, frame, &r)) {
        if (r == OCC_MAV_OK) {
            t->frames_ok++;
            return true;
        }
        t->frames_bad++;
    }
    return false;
}

void occ_tlog_close(occ_tlog_t *t)
{
    if (t != NULL && t->file_ != NULL) {
        fclose(t->file_);
        t->file_ = NULL;
    }
}
