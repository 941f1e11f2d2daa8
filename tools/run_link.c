/* SPDX-License-Identifier: BSD-3-Clause */
/* run_link.c - `occmap run`'s link thread (see run_link.h). */
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "run_can.h"
#include "run_link.h"
#include "run_ranges.h"
#include "occmap/occ_port.h"

static void send_frame(run_link_t *l, const uint8_t *out, size_t n)
{
    if (n > 0u) {
        (void)occ_link_write(l->link, out, n);
    }
}

/* A pose on the autopilot's clock into the history; its arrival bounds the clock offset. */
static void take_pose(run_link_t *l, const occ_pose_sample_t *s, uint64_t now)
{
    run_state_t *const st = l->st;
    (void)pthread_mutex_lock(&st->lock);
    if (occ_pose_history_push(&st->hist, s->t_us, &s->pose) == OCC_OK) {
        st->last_pose_local_us = now;
    }
    const int64_t off = (int64_t)s->t_us - (int64_t)now; /* remote - local - link delay */
    if (!st->have_arrival || off > st->arrival_offset_us) {
        st->arrival_offset_us = off;
        st->have_arrival = true;
    }
    (void)pthread_mutex_unlock(&st->lock);
}

static void take_timesync(run_link_t *l, const occ_mav_frame_t *f, uint64_t now)
{
    occ_mav_timesync_t m;
    if (occ_mav_decode_timesync(f, &m) != OCC_OK) {
        return;
    }
    if (m.tc1 == 0) { /* the autopilot asks us: answer with our clock */
        const occ_mav_timesync_t r = {(int64_t)(now * 1000u), m.ts1};
        uint8_t out[OCC_MAV_FRAME_MAX];
        send_frame(l, out, occ_mav_encode_timesync(&l->tx, &r, out, sizeof out));
        return;
    }
    (void)pthread_mutex_lock(&l->st->lock);
    (void)occ_timesync_take(&l->st->ts, &m, now);
    (void)pthread_mutex_unlock(&l->st->lock);
}

static void take_frame(run_link_t *l, const occ_mav_frame_t *f, uint64_t now)
{
    if (f->sysid == l->opt->sysid && f->compid == l->opt->compid) {
        return; /* our own echo */
    }
    occ_pose_sample_t s;
    if (occ_mav_pose_rx_take(&l->prx, f, &s)) {
        take_pose(l, &s, now);
    } else if (l->opt->mavlink_ranges &&
               run_ranges_take(l->st, l->st->ranges, &l->ranges_tr, f, now)) {
        return;
    } else if (f->msgid == OCC_MAV_MSG_TIMESYNC && f->sysid == l->opt->target_sysid &&
               f->compid == l->opt->target_compid) {
        take_timesync(l, f, now);
    }
}

/* Everything waiting on the link: the feed's parser and ours see the same bytes. */
static int drain(run_link_t *l, uint64_t now)
{
    uint8_t buf[2048];
    size_t n = 0;
    do {
        if (occ_link_read(l->link, buf, sizeof buf, &n) != OCC_OK) {
            cli_error("run", "read failed");
            return 1;
        }
        occ_mav_feed_rx(l->feed, buf, n, now);
        for (size_t i = 0; i < n; i++) {
            occ_mav_frame_t f;
            if (occ_mav_parser_push(&l->parser, buf[i], &f) == OCC_MAV_OK) {
                take_frame(l, &f, now);
            }
        }
    } while (n > 0u);
    return 0;
}

/* TIMESYNC: five requests 100 ms apart to start, then one a second. */
static void poll_timesync(run_link_t *l, uint64_t now)
{
    if (now < l->next_timesync) {
        return;
    }
    l->next_timesync = now + (l->timesync_sent < 5u ? 100000u : 1000000u);
    l->timesync_sent++;
    const occ_mav_timesync_t q = occ_timesync_request(now);
    uint8_t out[OCC_MAV_FRAME_MAX];
    send_frame(l, out, occ_mav_encode_timesync(&l->tx, &q, out, sizeof out));
}

/* Every configured input integrated a sample within --sensor-timeout-ms (none configured:
 * fresh); else *stale names the first that did not. */
static bool sensors_fresh(run_link_t *l, uint64_t now, const char **stale)
{
    const uint64_t timeout = (uint64_t)l->opt->sensor_timeout_ms * 1000u;
    uint64_t last[RUN_SOURCES];
    (void)pthread_mutex_lock(&l->st->lock);
    memcpy(last, l->st->last_sample_local_us, sizeof last);
    (void)pthread_mutex_unlock(&l->st->lock);
    for (int s = 0; s < RUN_SOURCES; s++) {
        /* last may be after `now` (integrated since the loop read the clock): fresh, not a
         * huge unsigned age */
        const bool fresh = last[s] != 0u && (last[s] >= now || now - last[s] <= timeout);
        if (run_source_on(l->opt, s) && !fresh) {
            *stale = run_source_name(s);
            return false;
        }
    }
    return true;
}

static void statustext(run_link_t *l, uint8_t severity, const char *text)
{
    uint8_t out[OCC_MAV_FRAME_MAX];
    send_frame(l, out, occ_mav_encode_statustext(&l->tx, severity, text, out, sizeof out));
    l->statustexts++;
    fprintf(stderr, "occmap run: STATUSTEXT %s\n", text);
}

/* Stale pose or sensors: the feed skips its periods (no map / stale pose); one STATUSTEXT when
 * it starts (after we had been sending) and one when it ends; HEARTBEAT says which. */
static bool update_status(run_link_t *l, uint64_t now)
{
    const bool pose_ok = occ_mav_feed_pose(l->feed, now, NULL);
    const char *input = NULL;
    const bool sens_ok = sensors_fresh(l, now, &input);
    const bool stale = !pose_ok || !sens_ok;
    if (stale && !l->stale && l->ever_sent) {
        l->stale_why = !pose_ok ? "pose" : input;
        fprintf(stderr, "occmap run: stale input: %s\n", l->stale_why);
        statustext(l, OCC_MAV_SEVERITY_WARNING, !pose_ok ? "occmap: pose stale, obstacle data stopped"
                                                         : "occmap: sensors stale, obstacle data stopped");
    } else if (!stale && l->stale && l->ever_sent) {
        statustext(l, OCC_MAV_SEVERITY_INFO, "occmap: obstacle data resumed");
    }
    l->stale = stale && l->ever_sent;
    occ_mav_feed_set_status(l->feed, !l->ever_sent ? OCC_MAV_STATE_BOOT
                                     : l->stale    ? OCC_MAV_STATE_CRITICAL
                                                   : OCC_MAV_STATE_ACTIVE);
    return sens_ok;
}

static void note_period(run_feed_timing_t *t, uint64_t now)
{
    if (t->sent > 0u) {
        if (t->n == t->cap) {
            const size_t cap = t->cap == 0u ? 256u : 2u * t->cap;
            uint32_t *const p = realloc(t->interval_us, cap * sizeof *p);
            if (p != NULL) {
                t->interval_us = p;
                t->cap = cap;
            }
        }
        if (t->n < t->cap) {
            const uint64_t d = now - t->last_us;
            t->interval_us[t->n++] = d > UINT32_MAX ? UINT32_MAX : (uint32_t)d;
        }
    }
    t->sent++;
    t->last_us = now;
}

static void print_list(FILE *f, const run_list_t *l, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        fprintf(f, "%s%zu", i > 0u ? ", " : "", l->idx[i]);
    }
}

/* The camera poses the listed frames were integrated with: [x, y, z, qw, qx, qy, qz] each. */
static void print_poses(FILE *f, const run_list_t *l, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        const occ_pose_t *const p = &l->pose[i];
        fprintf(f, "%s[%.9g, %.9g, %.9g, %.9g, %.9g, %.9g, %.9g]", i > 0u ? ", " : "",
                (double)p->p.x, (double)p->p.y, (double)p->p.z, (double)p->q.w, (double)p->q.x,
                (double)p->q.y, (double)p->q.z);
    }
}

/* Drop the first n entries of a list. */
static void list_shift(run_list_t *l, size_t n)
{
    memmove(l->idx, l->idx + n, (l->n - n) * sizeof *l->idx);
    memmove(l->version, l->version + n, (l->n - n) * sizeof *l->version);
    memmove(l->pose, l->pose + n, (l->n - n) * sizeof *l->pose);
    l->n -= n;
}

/* --3d: the points sent with this line, "], \"obstacles_3d\": [[id, x, y, z], ...". */
static void log_3d(FILE *o, const run_3d_t *r)
{
    const run_3d_side_t *const side[2] = {&r->above, &r->below};
    fprintf(o, "], \"obstacles_3d_err\": %d, \"obstacles_3d\": [", (int)r->err);
    bool first = true;
    for (unsigned id = 0; id < 2u; id++) {
        if (side[id]->found) {
            fprintf(o, "%s[%u, %.9g, %.9g, %.9g]", first ? "" : ", ", id,
                    (double)side[id]->frd_m.x, (double)side[id]->frd_m.y,
                    (double)side[id]->frd_m.z);
            first = false;
        }
    }
}

/* One feed-log line for the OBSTACLE_DISTANCE in `out`, sent at `now` from view version v. */
static void log_obstacle(run_link_t *l, const uint8_t *out, size_t len, uint64_t now, uint32_t v)
{
    occ_mav_parser_t p;
    occ_mav_frame_t f;
    occ_mav_obstacle_distance_t m;
    occ_mav_parser_init(&p);
    occ_mav_result_t r = OCC_MAV_NONE;
    for (size_t i = 0; i < len && r == OCC_MAV_NONE; i++) {
        r = occ_mav_parser_push(&p, out[i], &f);
    }
    occ_pose_t pose = occ_pose_identity();
    (void)occ_mav_feed_pose(l->feed, now, &pose);
    if (r != OCC_MAV_OK || occ_mav_decode_obstacle_distance(&f, &m) != OCC_OK) {
        return;
    }
    FILE *const o = l->feed_log;
    run_state_t *const st = l->st;
    (void)pthread_mutex_lock(&st->lock);
    size_t n_int = 0;
    while (n_int < st->integrated.n && st->integrated.version[n_int] <= v) {
        n_int++;
    }
    fprintf(o, "{\"time_usec\": %llu, \"seq\": %llu, \"version\": %u, \"frames\": [",
            (unsigned long long)m.time_usec, (unsigned long long)l->od_seq, v);
    print_list(o, &st->integrated, n_int);
    fprintf(o, "], \"frame_poses\": [");
    print_poses(o, &st->integrated, n_int);
    fprintf(o, "], \"frames_dropped\": [");
    print_list(o, &st->dropped, st->dropped.n);
    list_shift(&st->integrated, n_int);
    st->dropped.n = 0;
    const uint64_t evictions = st->evict.evictions;
    (void)pthread_mutex_unlock(&st->lock);
    fprintf(o, "], \"pose\": [%.9g, %.9g, %.9g, %.9g, %.9g, %.9g, %.9g], \"distances\": [",
            (double)pose.p.x, (double)pose.p.y, (double)pose.p.z, (double)pose.q.w,
            (double)pose.q.x, (double)pose.q.y, (double)pose.q.z);
    for (unsigned i = 0; i < 72u; i++) {
        fprintf(o, "%s%u", i > 0u ? ", " : "", m.distances[i]);
    }
    if (l->nearest != NULL) {
        log_3d(o, &l->last_3d);
    }
    fprintf(o, "], \"increment_deg\": %.9g, \"angle_offset_deg\": %.9g, \"min_cm\": %u, "
            "\"max_cm\": %u, \"evictions\": %llu}\n", (double)m.increment_f,
            (double)m.angle_offset, m.min_distance, m.max_distance, (unsigned long long)evictions);
    fflush(o);
}

/* --3d: OBSTACLE_DISTANCE_3D above (id 0) and below (id 1) from the view the OBSTACLE_DISTANCE
 * in `od` (len bytes) was computed from, at the same pose, stamped with its time (one batch). */
static void send_3d(run_link_t *l, const occ_map_t *map, uint64_t now, const uint8_t *od,
                    size_t len)
{
    occ_pose_t pose;
    if (!occ_mav_feed_pose(l->feed, now, &pose)) {
        return;
    }
    const occ_sectors_config_t *const c = &l->feed->cfg.sectors;
    run_3d_nearest(map, &pose, c, l->nearest, l->nearest_cap, &l->last_3d);
    occ_mav_parser_t p;
    occ_mav_frame_t f;
    occ_mav_obstacle_distance_t m;
    occ_mav_parser_init(&p);
    occ_mav_result_t r = OCC_MAV_NONE;
    for (size_t i = 0; i < len && r == OCC_MAV_NONE; i++) {
        r = occ_mav_parser_push(&p, od[i], &f);
    }
    const uint32_t ms = r == OCC_MAV_OK && occ_mav_decode_obstacle_distance(&f, &m) == OCC_OK
                        ? (uint32_t)(m.time_usec / 1000u) : (uint32_t)(now / 1000u);
    const run_3d_side_t *const side[2] = {&l->last_3d.above, &l->last_3d.below};
    for (uint16_t id = 0; id < 2u; id++) {
        if (!side[id]->found) {
            continue;
        }
        const occ_mav_obstacle_3d_t o = {ms, 0u, OCC_MAV_FRAME_BODY_FRD, id, side[id]->frd_m.x,
                                         side[id]->frd_m.y, side[id]->frd_m.z,
                                         (float)c->min_distance_cm / 100.0f,
                                         (float)c->max_distance_cm / 100.0f};
        uint8_t out[OCC_MAV_FRAME_MAX];
        const size_t n = occ_mav_encode_obstacle_3d(&l->tx, &o, out, sizeof out);
        send_frame(l, out, n);
        l->sent_3d += n > 0u;
    }
}

/* Whatever the feed has due, from a view of the map (none while the sensors are stale). */
static void poll_feed(run_link_t *l, uint64_t now, bool map_ok)
{
    if (now < occ_mav_feed_next_due(l->feed)) {
        return;
    }
    run_view_t view;
    run_read_begin(l->guard, RUN_READER_FEED, &view);
    now = occ_port_clock_us(); /* after a wait for the writer: the time it really goes out */
    for (;;) {
        uint8_t out[OCC_MAV_FRAME_MAX];
        const uint32_t before = l->feed->counters.obstacle_tx;
        const size_t n = occ_mav_feed_poll(l->feed, map_ok ? view.map : NULL, now, out, sizeof out);
        if (n == 0u) {
            break;
        }
        send_frame(l, out, n);
        if (l->feed->counters.obstacle_tx != before) {
            l->ever_sent = true;
            note_period(&l->ft, now);
            if (l->nearest != NULL) {
                send_3d(l, view.map, now, out, n);
            }
            if (l->feed_log != NULL) {
                log_obstacle(l, out, n, now, view.version);
            }
            l->od_seq++;
        }
    }
    run_read_end(l->guard, &view);
}

/* The autopilot's refusals of SET_MESSAGE_INTERVAL, logged as they come. */
static void log_requests(run_link_t *l)
{
    const occ_mav_feed_counters_t *const c = &l->feed->counters;
    if (c->request_refusals != l->refusals_logged) {
        l->refusals_logged = c->request_refusals;
        fprintf(stderr, "occmap run: the autopilot refused SET_MESSAGE_INTERVAL (MAV_RESULT %u, "
                "%u refusals); set its LOCAL_POSITION_NED / ATTITUDE rates by hand\n",
                c->last_refusal_result, c->request_refusals);
    }
}

/* --exit-after-depth: the directory is done and one more OBSTACLE_DISTANCE went out (or the
 * sensors went stale, so none will). */
static bool depth_finished(run_link_t *l, uint64_t now)
{
    if (!l->opt->exit_after_depth) {
        return false;
    }
    if (!l->done_seen) {
        (void)pthread_mutex_lock(&l->st->lock);
        l->done_seen = l->st->mc.done;
        (void)pthread_mutex_unlock(&l->st->lock);
        l->done_sent = l->ft.sent;
        l->done_us = now;
        return false;
    }
    return l->ft.sent > l->done_sent ||
           now - l->done_us > (uint64_t)l->opt->sensor_timeout_ms * 1000u;
}

static void wait_next(run_link_t *l, uint64_t now)
{
    uint64_t due = occ_mav_feed_next_due(l->feed);
    due = l->next_timesync < due ? l->next_timesync : due;
    due = l->next_stats < due ? l->next_stats : due;
    uint64_t wait = due > now ? due - now : 0u;
    const uint64_t most = l->can != NULL ? 2000u : 20000u; /* the CAN bus is polled */
    wait = wait > most ? most : wait;
    if (wait > 0u) {
        (void)occ_link_wait(l->link, wait);
    }
}

int run_link_loop(run_link_t *l)
{
    const uint64_t t_end = feed_args_end_us(&l->opt->fa, l->t0);
    while (!feed_stop_requested()) {
        const uint64_t now = occ_port_clock_us();
        if (now >= t_end || depth_finished(l, now)) {
            break;
        }
        if (drain(l, now) != 0) {
            return 1;
        }
        poll_timesync(l, now);
        const bool map_ok = update_status(l, now);
        poll_feed(l, now, map_ok);
        if (l->can != NULL) {
            run_can_poll(l, l->can, occ_port_clock_us(), map_ok);
        }
        log_requests(l);
        if (now >= l->next_stats) {
            l->next_stats += 1000000u;
            run_stats_line(l, now, NULL, true);
        }
        wait_next(l, occ_port_clock_us());
    }
    return 0;
}
