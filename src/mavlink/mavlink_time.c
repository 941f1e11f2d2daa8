/* SPDX-License-Identifier: BSD-3-Clause */
/* mavlink_time.c - TIMESYNC and STATUSTEXT codecs and the clock-offset filter
 * (occ_mavlink_run.h). */
#include "occmap/occ_mavlink_run.h"
#include "mavlink_internal.h"

#include <string.h>

#include "ardupilotmega/mavlink.h"

size_t occ_mav_encode_timesync(occ_mav_sender_t *tx, const occ_mav_timesync_t *m, uint8_t *out,
                               size_t cap)
{
    if (tx == NULL || m == NULL || out == NULL) {
        return 0;
    }
    mavlink_timesync_t s;
    memset(&s, 0, sizeof s);
    s.tc1 = m->tc1;
    s.ts1 = m->ts1;
    return occ_mav_finalize(tx, MAVLINK_MSG_ID_TIMESYNC, (const uint8_t *)&s,
                            MAVLINK_MSG_ID_TIMESYNC_LEN, out, cap);
}

occ_err_t occ_mav_decode_timesync(const occ_mav_frame_t *f, occ_mav_timesync_t *out)
{
    mavlink_timesync_t s;
    if (out == NULL || !occi_mav_load(f, MAVLINK_MSG_ID_TIMESYNC, &s, sizeof s)) {
        return OCC_ERR_ARG;
    }
    out->tc1 = s.tc1;
    out->ts1 = s.ts1;
    return OCC_OK;
}

size_t occ_mav_encode_statustext(occ_mav_sender_t *tx, uint8_t severity, const char *text,
                                 uint8_t *out, size_t cap)
{
    if (tx == NULL || text == NULL || out == NULL) {
        return 0;
    }
    mavlink_statustext_t s;
    memset(&s, 0, sizeof s);
    s.severity = severity;
    for (size_t i = 0; i < sizeof s.text && text[i] != '\0'; i++) {
        s.text[i] = text[i];
    }
    return occ_mav_finalize(tx, MAVLINK_MSG_ID_STATUSTEXT, (const uint8_t *)&s,
                            MAVLINK_MSG_ID_STATUSTEXT_LEN, out, cap);
}

occ_err_t occ_timesync_init(occ_timesync_t *ts, uint32_t max_rtt_us)
{
    if (ts == NULL || max_rtt_us == 0u) {
        return OCC_ERR_ARG;
    }
    memset(ts, 0, sizeof *ts);
    ts->priv.max_rtt_us = max_rtt_us;
    return OCC_OK;
}

occ_mav_timesync_t occ_timesync_request(uint64_t now_us)
{
    occ_mav_timesync_t m;
    m.tc1 = 0;
    m.ts1 = (int64_t)(now_us * 1000u);
    return m;
}

occ_err_t occ_timesync_take(occ_timesync_t *ts, const occ_mav_timesync_t *reply, uint64_t now_us)
{
    if (ts == NULL || reply == NULL) {
        return OCC_ERR_ARG;
    }
    const int64_t now = (int64_t)now_us;
    const int64_t sent = reply->ts1 / 1000;
    if (reply->tc1 <= 0 || reply->ts1 <= 0 || sent > now || now - sent > (int64_t)ts->priv.max_rtt_us) {
        ts->refused++;
        return OCC_ERR_TIME;
    }
    const uint32_t rtt = (uint32_t)(now - sent);
    /* tc1 - (sent + now) / 2, kept exact: (2 tc1 - sent - now) / 2 in integer us. */
    const int64_t off2 = 2 * (reply->tc1 / 1000) - sent - now;
    const int64_t off = off2 >= 0 ? off2 / 2 : -((-off2 + 1) / 2);
    ts->priv.off[ts->priv.next] = off;
    ts->priv.rtt[ts->priv.next] = rtt;
    ts->priv.next = (ts->priv.next + 1u) % OCC_TIMESYNC_WINDOW;
    ts->priv.n = ts->priv.n < OCC_TIMESYNC_WINDOW ? ts->priv.n + 1u : OCC_TIMESYNC_WINDOW;
    uint32_t best = 0;
    for (uint32_t i = 1; i < ts->priv.n; i++) {
        if (ts->priv.rtt[i] < ts->priv.rtt[best]) {
            best = i;
        }
    }
    ts->offset_us = ts->priv.off[best];
    ts->rtt_us = ts->priv.rtt[best];
    ts->valid = true;
    ts->accepted++;
    return OCC_OK;
}
