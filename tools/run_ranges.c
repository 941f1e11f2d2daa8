/* SPDX-License-Identifier: BSD-3-Clause */
/* run_ranges.c - range messages from other components into `occmap run`'s map (run_ranges.h). */
#include <stdlib.h>
#include <string.h>

#include "run_ranges.h"
#include "occmap/occ_port.h"

static bool is_range_msg(uint32_t id)
{
    return id == OCC_MAV_MSG_DISTANCE_SENSOR || id == OCC_MAV_MSG_OBSTACLE_DISTANCE ||
           id == OCC_MAV_MSG_OBSTACLE_DISTANCE_3D;
}

bool run_ranges_take(run_state_t *st, run_ranges_t *r, occ_mav_ranges_t *tr,
                     const occ_mav_frame_t *f, uint64_t now)
{
    if (!is_range_msg(f->msgid)) {
        return false;
    }
    static occ_mav_beams_t b; /* link thread only */
    if (occ_mav_ranges_decode(tr, f, &b) == OCC_OK) { /* else counted by the translator */
        run_ranges_queue(st, r, &b, now, RUN_SRC_MAVLINK);
    }
    return true;
}

/* A MAVLink reading's own stamp (autopilot us) is a time on the autopilot's clock: TIMESYNC
 * answered, and mapped to our clock through its offset (as the poses) it lies at most `window`
 * before the arrival `now` and not after it (beyond the offset's error, rtt / 2, and the
 * millisecond of time_boot_ms). Caller holds st->lock. */
static bool own_stamp_ok(const run_state_t *st, uint64_t own_us, uint64_t now, uint64_t window)
{
    if (!st->ts.valid || own_us == 0u || own_us > (uint64_t)INT64_MAX) {
        return false;
    }
    const int64_t local = (int64_t)own_us - st->ts.offset_us;
    const int64_t slack = (int64_t)st->ts.rtt_us / 2 + 2000;
    return local <= (int64_t)now + slack && local >= (int64_t)now - (int64_t)window;
}

void run_ranges_queue(run_state_t *st, run_ranges_t *r, const occ_mav_beams_t *beams,
                      uint64_t now, int source)
{
    static run_range_msg_t m; /* link thread only */
    m.beams = *beams;
    m.source = source;
    (void)pthread_mutex_lock(&st->lock);
    int64_t off = 0;
    const char *src = NULL;
    if (!run_state_offset(st, &off, &src)) {
        r->no_clock++;
    } else if (r->n == RUN_RANGES_QUEUE) {
        r->queue_full++;
    } else {
        const bool own = source == RUN_SRC_MAVLINK &&
                         own_stamp_ok(st, beams->time_us, now, r->own_window_us);
        m.local_us = now;
        m.remote_us = own ? beams->time_us : (uint64_t)((int64_t)now + off);
        r->stamped_own += own ? 1u : 0u;
        r->stamped_arrival += own ? 0u : 1u;
        r->q[(r->head + r->n) % RUN_RANGES_QUEUE] = m;
        r->n++;
        r->queued++;
    }
    (void)pthread_mutex_unlock(&st->lock);
}

/* The oldest queued message and its pose once the history reaches past its time; false when
 * there is none ready. *why: 0 pose found, 1 no pose (given up). Caller holds st->lock. */
static bool pop_ready(run_mapper_t *m, run_range_msg_t *out, occ_pose_t *pose, int *why)
{
    run_ranges_t *const r = m->st->ranges;
    if (r->n == 0u) {
        return false;
    }
    const run_range_msg_t *const h = &r->q[r->head];
    uint64_t oldest = 0, newest = 0;
    const bool any = occ_pose_history_span(&m->st->hist, &oldest, &newest) == OCC_OK;
    const bool late = occ_port_clock_us() - h->local_us > (uint64_t)m->opt->pose_timeout_ms * 1000u;
    if (!(any && newest >= h->remote_us) && !late) {
        return false;
    }
    *out = *h;
    r->head = (r->head + 1u) % RUN_RANGES_QUEUE;
    r->n--;
    *why = occ_pose_history_at(&m->st->hist, out->remote_us, pose, NULL) == OCC_OK ? 0 : 1;
    return true;
}

/* One message into the map (a write section). */
static occ_err_t insert(run_mapper_t *m, const run_range_msg_t *msg, const occ_pose_t *map_from_body,
                        void **scratch, size_t *cap)
{
    occ_pose_t map_from_sensor;
    if (occ_mav_beams_sensor_pose(&msg->beams, map_from_body, &map_from_sensor) != OCC_OK) {
        return OCC_ERR_ARG;
    }
    occ_insert_params_t ip = occ_insert_params_default();
    const size_t need = occ_ranges_scratch_bytes(m->guard->map, msg->beams.beam, msg->beams.n, &ip);
    if (need > *cap) {
        free(*scratch);
        *scratch = malloc(need);
        *cap = *scratch != NULL ? need : 0u;
    }
    if (*scratch == NULL) {
        return OCC_ERR_NOMEM;
    }
    occ_evict_out_t ev;
    ip.auto_evict = &m->policy;
    ip.auto_evict_state = &ev;
    occ_map_t *const map = run_write_begin(m->guard);
    (void)pthread_mutex_lock(&m->st->lock);
    ev = m->st->evict;
    (void)pthread_mutex_unlock(&m->st->lock);
    const occ_err_t e = occ_map_insert_ranges(map, &map_from_sensor, msg->beams.beam,
                                              msg->beams.n, &ip, *scratch, *cap, NULL);
    (void)pthread_mutex_lock(&m->st->lock);
    m->st->evict = ev;
    if (e == OCC_OK) {
        m->st->last_sample_local_us[msg->source] = occ_port_clock_us();
        m->st->ranges->integrated++;
        occ_map_pool_stats(map, &m->st->pool);
    }
    (void)pthread_mutex_unlock(&m->st->lock);
    run_write_end(m->guard);
    return e;
}

void run_ranges_service(run_mapper_t *m)
{
    static void *scratch; /* mapping thread only; kept for the run */
    static size_t cap;
    for (;;) {
        run_range_msg_t msg;
        occ_pose_t pose;
        int why = 1;
        (void)pthread_mutex_lock(&m->st->lock);
        const bool ready = pop_ready(m, &msg, &pose, &why);
        if (ready && why != 0) {
            m->st->ranges->no_pose++;
        }
        (void)pthread_mutex_unlock(&m->st->lock);
        if (!ready) {
            return;
        }
        if (why == 0) {
            const occ_err_t e = insert(m, &msg, &pose, &scratch, &cap);
            if (e != OCC_OK) {
                (void)pthread_mutex_lock(&m->st->lock);
                m->st->ranges->nomem += e == OCC_ERR_NOMEM ? 1u : 0u;
                m->st->ranges->errors += e == OCC_ERR_NOMEM ? 0u : 1u;
                (void)pthread_mutex_unlock(&m->st->lock);
            }
        }
    }
}

void run_ranges_print(FILE *f, const run_ranges_t *r, const occ_mav_ranges_t *tr)
{
    const occ_mav_ranges_counters_t *const c = &tr->counters;
    fprintf(f, "\"ranges\": {\"translated\": %u, \"queued\": %llu, \"stamped\": {\"own\": %llu, "
            "\"arrival\": %llu}, \"integrated\": %llu, "
            "\"dropped\": {\"no_pose\": %llu, \"no_clock\": %llu, \"queue_full\": %llu, "
            "\"nomem\": %llu, \"error\": %llu}, \"own_refused\": %u, \"malformed\": %u, "
            "\"unsupported\": %u}", c->translated, (unsigned long long)r->queued,
            (unsigned long long)r->stamped_own, (unsigned long long)r->stamped_arrival,
            (unsigned long long)r->integrated, (unsigned long long)r->no_pose,
            (unsigned long long)r->no_clock, (unsigned long long)r->queue_full,
            (unsigned long long)r->nomem, (unsigned long long)r->errors, c->own_refused,
            c->malformed, c->unsupported);
}

void run_ranges_finish(run_mapper_t *m)
{
    run_ranges_service(m);
    (void)pthread_mutex_lock(&m->st->lock);
    run_ranges_t *const r = m->st->ranges;
    r->no_pose += r->n;
    r->n = 0;
    (void)pthread_mutex_unlock(&m->st->lock);
}
