/* SPDX-License-Identifier: BSD-3-Clause */
/* tlog_ranges.c - a log's range readings into a map with the log's own poses (occ_tlog.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "ardupilotmega/mavlink.h"
#include "occmap/host/occ_tlog_ranges.h"

#define EARTH_RADIUS_M 6378137.0
#define DEG_E7_TO_RAD (3.14159265358979323846 / 180.0 * 1e-7)

occ_tlog_ranges_config_t occ_tlog_ranges_config_default(void)
{
    occ_tlog_ranges_config_t c;
    memset(&c, 0, sizeof c);
    c.autopilot_sysid = 1;
    c.autopilot_compid = OCC_MAV_COMP_ID_AUTOPILOT1;
    c.own_sysid = 1;
    c.own_compid = OCC_MAV_COMP_ID_OBSTACLE_AVOIDANCE;
    c.max_gap_us = 1000000u;
    c.max_extrapolate_us = 200000u;
    return c;
}

/* The vehicle's latest position (NED, metres) while pass 1 walks the log. */
typedef struct {
    bool have_local, have_global, have_origin;
    occ_vec3_t local_ned, global_ned;
    int32_t lat0, lon0;
} position_t;

static void take_global(position_t *pos, const occ_mav_frame_t *f, occ_tlog_ranges_stats_t *st)
{
    mavlink_global_position_int_t g;
    memset(&g, 0, sizeof g);
    memcpy(&g, f->payload, f->len < sizeof g ? f->len : sizeof g);
    if (g.lat == 0 && g.lon == 0) {
        st->no_horizontal_fix = true; /* ArduPilot's "no position estimate" */
        pos->global_ned.x = 0.0f;
        pos->global_ned.y = 0.0f;
    } else {
        if (!pos->have_origin) {
            pos->lat0 = g.lat;
            pos->lon0 = g.lon;
            pos->have_origin = true;
        }
        const double lat0 = (double)pos->lat0 * DEG_E7_TO_RAD;
        pos->global_ned.x = (float)((double)(g.lat - pos->lat0) * DEG_E7_TO_RAD * EARTH_RADIUS_M);
        pos->global_ned.y = (float)((double)(g.lon - pos->lon0) * DEG_E7_TO_RAD * EARTH_RADIUS_M *
                                    cos(lat0));
    }
    pos->global_ned.z = -(float)g.relative_alt * 0.001f;
    pos->have_global = true;
}

/* Poses of the autopilot's frames; true when f was an ATTITUDE that made *pose. */
static bool pose_of(position_t *pos, const occ_mav_frame_t *f, occ_tlog_ranges_stats_t *st,
                    occ_pose_t *pose)
{
    occ_mav_local_position_ned_t lp;
    occ_mav_attitude_t att;
    if (occ_mav_decode_local_position_ned(f, &lp) == OCC_OK) {
        pos->local_ned = (occ_vec3_t){lp.x, lp.y, lp.z};
        pos->have_local = true;
        st->positions++;
    } else if (f->msgid == MAVLINK_MSG_ID_GLOBAL_POSITION_INT) {
        take_global(pos, f, st);
        st->positions++;
    } else if (occ_mav_decode_attitude(f, &att) == OCC_OK) {
        st->attitudes++;
        if (!pos->have_local && !pos->have_global) {
            return false;
        }
        st->position_source = pos->have_local ? 32u : 33u;
        const occ_vec3_t ned = pos->have_local ? pos->local_ned : pos->global_ned;
        return occ_pose_from_ned(ned, occ_quat_from_euler(att.roll, att.pitch, att.yaw), pose) ==
               OCC_OK;
    }
    return false;
}

/* Pass 1: every pose of the log, in order, into a malloc'ed array. */
static occ_err_t read_poses(const char *path, const occ_tlog_ranges_config_t *cfg,
                            occ_pose_sample_t **out, size_t *n, occ_tlog_ranges_stats_t *st,
                            char *msg, size_t msg_len)
{
    occ_tlog_t t;
    occ_err_t e = occ_tlog_open(&t, path, msg, msg_len);
    if (e != OCC_OK) {
        return e;
    }
    position_t pos;
    memset(&pos, 0, sizeof pos);
    size_t cap = 0;
    uint64_t stamp;
    occ_mav_frame_t f;
    while (e == OCC_OK && occ_tlog_next(&t, &stamp, &f)) {
        occ_pose_t pose;
        if (f.sysid != cfg->autopilot_sysid || f.compid != cfg->autopilot_compid ||
            !pose_of(&pos, &f, st, &pose) || (*n > 0u && stamp <= (*out)[*n - 1u].t_us)) {
            continue;
        }
        if (*n == cap) {
            cap = cap > 0u ? 2u * cap : 1024u;
            occ_pose_sample_t *const grown = realloc(*out, cap * sizeof **out);
            e = grown != NULL ? OCC_OK : OCC_ERR_NOMEM;
            *out = grown != NULL ? grown : *out;
        }
        if (e == OCC_OK) {
            (*out)[(*n)++] = (occ_pose_sample_t){stamp, pose};
        }
    }
    e = (e == OCC_OK && t.io_error) ? OCC_ERR_IO : e;
    occ_tlog_close(&t);
    return e;
}

static occ_err_t make_history(occ_pose_history_t *h, occ_pose_sample_t **ring,
                              const occ_pose_sample_t *samples, size_t n,
                              const occ_tlog_ranges_config_t *cfg)
{
    *ring = malloc((n > 2u ? n : 2u) * sizeof **ring);
    if (*ring == NULL) {
        return OCC_ERR_NOMEM;
    }
    const occ_pose_history_cfg_t hc = {cfg->max_gap_us, cfg->max_extrapolate_us};
    occ_err_t e = occ_pose_history_init(h, *ring, n > 2u ? n : 2u, &hc);
    for (size_t i = 0; e == OCC_OK && i < n; i++) {
        e = occ_pose_history_push(h, samples[i].t_us, &samples[i].pose);
    }
    return e;
}

/* Pass 2 state: the translator, the history, the insert's scratch. */
typedef struct {
    occ_map_t *map;
    const occ_insert_params_t *params;
    occ_mav_ranges_t rx;
    occ_pose_history_t hist;
    occ_mav_beams_t beams;
    void *scratch;
    size_t scratch_len;
    occ_tlog_beams_fn on_beams;
    void *user;
} pass2_t;

static void add_result(occ_ranges_result_t *sum, const occ_ranges_result_t *r)
{
    sum->beams_hit += r->beams_hit;
    sum->beams_no_return += r->beams_no_return;
    sum->beams_invalid += r->beams_invalid;
    sum->beams_too_close += r->beams_too_close;
    sum->beams_bad += r->beams_bad;
    sum->rays += r->rays;
    sum->insert.points_integrated += r->insert.points_integrated;
    sum->insert.points_skipped += r->insert.points_skipped;
    sum->insert.voxel_visits += r->insert.voxel_visits;
    sum->insert.voxels_updated += r->insert.voxels_updated;
}

/* Scratch for these beams (occ_ranges_scratch_bytes), grown when a message needs more. */
static bool fit_scratch(pass2_t *s)
{
    const size_t need = occ_ranges_scratch_bytes(s->map, s->beams.beam, s->beams.n, s->params);
    if (need <= s->scratch_len) {
        return true;
    }
    void *const grown = realloc(s->scratch, need);
    if (grown == NULL) {
        return false;
    }
    s->scratch = grown;
    s->scratch_len = need;
    return true;
}

/* One range frame at its stamp: refused (counted) or integrated. Only NOMEM/IO stop the log. */
static occ_err_t one_reading(pass2_t *s, uint64_t stamp, const occ_mav_frame_t *f,
                             occ_tlog_ranges_stats_t *st)
{
    if (occ_mav_ranges_decode(&s->rx, f, &s->beams) != OCC_OK) {
        return OCC_OK; /* not a range message, ours, or malformed: counted in rx */
    }
    st->range_msgs++;
    occ_pose_t body, sensor;
    if (occ_pose_history_at(&s->hist, stamp, &body, NULL) != OCC_OK ||
        occ_mav_beams_sensor_pose(&s->beams, &body, &sensor) != OCC_OK) {
        st->no_pose++;
        return OCC_OK;
    }
    if (!fit_scratch(s)) {
        return OCC_ERR_NOMEM;
    }
    occ_ranges_result_t r;
    const occ_err_t e = occ_map_insert_ranges(s->map, &sensor, s->beams.beam, s->beams.n,
                                              s->params, s->scratch, s->scratch_len, &r);
    if (e == OCC_ERR_NOMEM) {
        return e;
    }
    if (e != OCC_OK) {
        st->insert_errors++;
        return OCC_OK;
    }
    add_result(&st->sum, &r);
    st->integrated++;
    st->t_first_us = st->integrated == 1u ? stamp : st->t_first_us;
    st->t_last_us = stamp;
    if (s->on_beams != NULL) {
        s->on_beams(s->user, stamp, &s->beams, &sensor);
    }
    return OCC_OK;
}

static occ_err_t integrate_readings(pass2_t *s, const char *path, occ_tlog_ranges_stats_t *st,
                                    char *msg, size_t msg_len)
{
    occ_tlog_t t;
    occ_err_t e = occ_tlog_open(&t, path, msg, msg_len);
    uint64_t stamp;
    occ_mav_frame_t f;
    while (e == OCC_OK && occ_tlog_next(&t, &stamp, &f)) {
        e = one_reading(s, stamp, &f, st);
    }
    if (e == OCC_OK) {
        e = t.io_error ? OCC_ERR_IO : OCC_OK;
        st->records = t.records;
        st->frames_ok = t.frames_ok;
        st->frames_bad = t.frames_bad;
    }
    occ_tlog_close(&t);
    return e;
}

occ_err_t occ_tlog_integrate_ranges(occ_map_t *map, const char *path,
                                    const occ_tlog_ranges_config_t *cfg,
                                    const occ_insert_params_t *params, occ_tlog_beams_fn on_beams,
                                    void *user, occ_tlog_ranges_stats_t *st, char *msg,
                                    size_t msg_len)
{
    if (map == NULL || path == NULL || cfg == NULL || params == NULL || st == NULL) {
        return OCC_ERR_ARG;
    }
    memset(st, 0, sizeof *st);
    occ_pose_sample_t *samples = NULL, *ring = NULL;
    size_t n = 0;
    pass2_t *const s = calloc(1, sizeof *s); /* ~2 KB of beams: off the stack */
    occ_err_t e = s != NULL ? read_poses(path, cfg, &samples, &n, st, msg, msg_len) : OCC_ERR_NOMEM;
    st->poses = (uint32_t)n;
    if (e == OCC_OK) {
        e = make_history(&s->hist, &ring, samples, n, cfg);
    }
    if (e == OCC_OK) {
        s->map = map;
        s->params = params;
        s->on_beams = on_beams;
        s->user = user;
        (void)occ_mav_ranges_init(&s->rx, cfg->own_sysid, cfg->own_compid);
        e = integrate_readings(s, path, st, msg, msg_len);
        st->tr = s->rx.counters;
    }
    if (s != NULL) {
        free(s->scratch);
    }
    free(s);
    free(ring);
    free(samples);
    return e;
}
