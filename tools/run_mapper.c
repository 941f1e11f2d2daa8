/* SPDX-License-Identifier: BSD-3-Clause */
/* run_mapper.c - the mapping thread of `occmap run`: releases each depth frame at its time,
 * finds its pose in the history (on the autopilot's clock), integrates it as the map's one
 * writer, and never stops for memory: evict, then the nearest part of the frame, then count. */
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cli.h"
#include "run.h"
#include "run_camera.h"
#include "run_ranges.h"
#include "occmap/occ_port.h"
#include "occmap/host/occ_file.h"

static void sleep_us(uint64_t us)
{
    struct timespec ts;
    ts.tv_sec = (time_t)(us / 1000000u);
    ts.tv_nsec = (long)(us % 1000000u) * 1000L;
    (void)nanosleep(&ts, NULL);
}

/* Recorded timing: wait until the autopilot clock (local + offset) reaches the frame's stamp.
 * Returns the local time the frame was due (earlier than now when the mapping is behind); fast
 * replay: now. 0 when asked to stop. */
static uint64_t wait_release(run_mapper_t *m, const run_frame_t *f)
{
    for (;;) {
        if (m->st->stop) {
            return 0;
        }
        const uint64_t now = occ_port_clock_us();
        if (m->opt->replay_speed == 0u) {
            return now;
        }
        int64_t off = 0;
        const char *src = NULL;
        (void)pthread_mutex_lock(&m->st->lock);
        const bool known = run_state_offset(m->st, &off, &src);
        (void)pthread_mutex_unlock(&m->st->lock);
        const int64_t release = (int64_t)f->remote_us - off;
        if (known && (int64_t)now >= release) {
            return release > 0 ? (uint64_t)release : now;
        }
        run_ranges_service(m);
        const int64_t wait = known ? release - (int64_t)now : 10000;
        sleep_us(wait > 10000 ? 10000u : wait < 0 ? 0u : (uint64_t)wait);
    }
}

/* The pose at the frame's stamp once the history reaches past it, or the refusal after
 * --pose-timeout-ms without such a pose (since release; in fast mode since the last pose). */
static occ_err_t wait_pose(run_mapper_t *m, const run_frame_t *f, uint64_t released,
                           occ_pose_t *pose, occ_pose_refusal_t *why)
{
    const uint64_t timeout = (uint64_t)m->opt->pose_timeout_ms * 1000u;
    for (;;) {
        uint64_t oldest = 0, newest = 0;
        const uint64_t now = occ_port_clock_us();
        (void)pthread_mutex_lock(&m->st->lock);
        const bool any = occ_pose_history_span(&m->st->hist, &oldest, &newest) == OCC_OK;
        const uint64_t last_rx = m->st->last_pose_local_us;
        const uint64_t since = m->opt->replay_speed == 0u && last_rx > released ? last_rx : released;
        /* fast replay waits for the first pose however long it takes (the streams start when
         * the autopilot answers), then gives up after a timeout without a new pose */
        const bool wait_first = m->opt->replay_speed == 0u && !any;
        const bool give_up = m->st->stop || (!wait_first && now - since > timeout);
        occ_err_t e = OCC_ERR_TIME;
        if ((any && newest >= f->remote_us) || give_up) {
            e = occ_pose_history_at(&m->st->hist, f->remote_us, pose, why);
        }
        (void)pthread_mutex_unlock(&m->st->lock);
        if (m->st->stop) {
            return OCC_ERR_STATE; /* ending: the frame is neither integrated nor dropped */
        }
        if ((any && newest >= f->remote_us) || give_up) {
            return e;
        }
        run_ranges_service(m);
        sleep_us(2000);
    }
}

static int cmp_u16(const void *a, const void *b)
{
    const uint16_t x = *(const uint16_t *)a, y = *(const uint16_t *)b;
    return (x > y) - (x < y);
}

/* The raw value at or below which `keep` of the frame's valid pixels (on the step grid) lie. */
static uint16_t nearest_cutoff(const uint16_t *px, uint32_t w, uint32_t h, uint32_t step,
                               uint16_t *tmp, double keep)
{
    size_t n = 0;
    for (uint32_t v = 0; v < h; v += step) {
        for (uint32_t u = 0; u < w; u += step) {
            if (px[(size_t)v * w + u] != 0u) {
                tmp[n++] = px[(size_t)v * w + u];
            }
        }
    }
    if (n == 0u) {
        return 0;
    }
    qsort(tmp, n, sizeof *tmp, cmp_u16);
    const size_t k = (size_t)((double)n * keep);
    return tmp[k > 0u ? k - 1u : 0u];
}

typedef struct {
    uint16_t *px, *part, *tmp;
    uint32_t w, h;
    void *scratch;
    size_t scratch_bytes;
} frame_buf_t;

/* The depth integration's parameters: --depth-method (simple by default). */
static occ_insert_params_t depth_params(const run_mapper_t *m)
{
    occ_insert_params_t ip = occ_insert_params_default();
    ip.method = m->opt->depth_projective ? OCC_INSERT_PROJECTIVE : OCC_INSERT_SIMPLE;
    return ip;
}

/* One write call: the frame (or its pixels up to `cutoff`, 0 = all) with automatic eviction. */
static occ_err_t insert(run_mapper_t *m, occ_map_t *map, frame_buf_t *b,
                        const occ_pose_t *map_from_cam, uint16_t cutoff, occ_depth_result_t *r)
{
    const uint16_t *src = b->px;
    if (cutoff != 0u) {
        const size_t n = (size_t)b->w * b->h;
        for (size_t i = 0; i < n; i++) {
            b->part[i] = b->px[i] <= cutoff ? b->px[i] : 0u;
        }
        src = b->part;
    }
    const occ_depth_image_t img = {src, OCC_DEPTH_U16, b->w, b->h, (size_t)b->w * 2u,
                                   m->cam->depth_scale_m};
    occ_insert_params_t ip = depth_params(m);
    ip.auto_evict = &m->policy;
    occ_evict_out_t ev;
    (void)pthread_mutex_lock(&m->st->lock);
    ev = m->st->evict;
    (void)pthread_mutex_unlock(&m->st->lock);
    ip.auto_evict_state = &ev;
    occ_err_t e = occ_map_insert_depth(map, &img, &m->cam->params, map_from_cam, &ip,
                                       b->scratch, b->scratch_bytes, r);
    if (e == OCC_ERR_NOMEM && ip.method == OCC_INSERT_PROJECTIVE) {
        /* The projective integrator does not evict by itself: make room (a quarter of the
         * arena, robot-centric) and try once more. */
        occ_map_stats_t s;
        occ_map_pool_stats(map, &s);
        (void)occ_map_evict(map, &map_from_cam->p, &m->policy, s.leaf_capacity / 4u, &ev);
        e = occ_map_insert_depth(map, &img, &m->cam->params, map_from_cam, &ip, b->scratch,
                                 b->scratch_bytes, r);
    }
    (void)pthread_mutex_lock(&m->st->lock);
    m->st->evict = ev;
    (void)pthread_mutex_unlock(&m->st->lock);
    return e;
}

/* The never-stop rule: the whole frame, else its nearest 1/2, 1/4, 1/8, 1/16. */
static occ_err_t integrate(run_mapper_t *m, occ_map_t *map, frame_buf_t *b,
                           const occ_pose_t *map_from_cam, bool *partial, size_t *points)
{
    occ_depth_result_t r;
    memset(&r, 0, sizeof r);
    occ_err_t e = insert(m, map, b, map_from_cam, 0, &r);
    double keep = 0.5;
    *partial = false;
    while (e == OCC_ERR_NOMEM && keep > 0.05) {
        const uint16_t cut = nearest_cutoff(b->px, b->w, b->h, m->opt->stride, b->tmp, keep);
        if (cut == 0u) {
            break;
        }
        e = insert(m, map, b, map_from_cam, cut, &r);
        *partial = true;
        keep *= 0.5;
    }
    *points = r.points;
    return e;
}

static bool grow(frame_buf_t *b, uint32_t w, uint32_t h, size_t scratch_bytes)
{
    if (b->w == w && b->h == h && b->scratch != NULL) {
        return true;
    }
    free(b->part);
    free(b->tmp);
    free(b->scratch);
    b->part = malloc((size_t)w * h * 2u);
    b->tmp = malloc((size_t)w * h * 2u);
    b->scratch = malloc(scratch_bytes);
    b->scratch_bytes = scratch_bytes;
    b->w = w;
    b->h = h;
    return b->part != NULL && b->tmp != NULL && b->scratch != NULL;
}

/* The frame's pixels from the camera and the scratch for its size. OCC_OK or the camera's
 * error. */
static occ_err_t load(run_mapper_t *m, const run_frame_t *f, frame_buf_t *b)
{
    uint32_t w = 0, h = 0;
    free(b->px);
    b->px = NULL;
    const occ_err_t e = m->cam->pixels(m->cam->ctx, f, &b->px, &w, &h);
    if (e != OCC_OK) {
        return e;
    }
    const occ_insert_params_t ip = depth_params(m);
    const size_t need = occ_depth_scratch_bytes(m->guard->map, w, h, m->opt->stride,
                                                m->opt->depth_max_m, &ip);
    return need > 0u && grow(b, w, h, need) ? OCC_OK : OCC_ERR_NOMEM;
}

static void record(run_mapper_t *m, const run_frame_t *f, int drop, bool partial, size_t points,
                   uint64_t t0, const occ_pose_t *map_from_cam)
{
    const uint64_t now = occ_port_clock_us();
    run_state_t *const st = m->st;
    occ_map_stats_t pool;
    occ_map_pool_stats(m->guard->map, &pool); /* the writer's thread: nothing changes it now */
    (void)pthread_mutex_lock(&st->lock);
    st->pool = pool;
    run_map_counters_t *const c = &st->mc;
    c->frames_done++;
    if (drop >= 0) {
        c->dropped[drop]++;
        (void)run_list_push(&st->dropped, f->index, 0, NULL);
    } else {
        c->integrated++;
        c->partial += partial ? 1u : 0u;
        c->points += points;
        st->last_sample_local_us[RUN_SRC_DEPTH] = now;
        /* inside the write section: the version write_end publishes holds this frame */
        (void)run_list_push(&st->integrated, f->index, run_write_next_version(m->guard),
                            map_from_cam);
        if (c->n_integrate == c->cap_integrate) {
            const size_t cap = c->cap_integrate == 0u ? 1024u : 2u * c->cap_integrate;
            uint32_t *const p = realloc(c->integrate_us, cap * sizeof *p);
            if (p != NULL) {
                c->integrate_us = p;
                c->cap_integrate = cap;
            }
        }
        if (c->n_integrate < c->cap_integrate) {
            const uint64_t dt = now - t0;
            c->integrate_us[c->n_integrate++] = dt > UINT32_MAX ? UINT32_MAX : (uint32_t)dt;
        }
    }
    (void)pthread_mutex_unlock(&st->lock);
}

static int refusal_reason(occ_pose_refusal_t why)
{
    switch (why) {
    case OCC_POSE_EMPTY:
        return RUN_DROP_EMPTY;
    case OCC_POSE_TOO_OLD:
        return RUN_DROP_TOO_OLD;
    case OCC_POSE_TOO_NEW:
        return RUN_DROP_TOO_NEW;
    case OCC_POSE_GAP:
        return RUN_DROP_GAP;
    case OCC_POSE_OK:
    default:
        return RUN_DROP_ERROR;
    }
}

/* One frame from release to the counters. */
static void do_frame(run_mapper_t *m, const run_frame_t *f, frame_buf_t *b)
{
    const uint64_t released = wait_release(m, f);
    if (released == 0u) {
        return;
    }
    if (occ_port_clock_us() - released > (uint64_t)m->opt->max_lag_ms * 1000u) {
        record(m, f, RUN_DROP_LATE, false, 0, released, NULL); /* behind the camera: newer frames wait */
        return;
    }
    occ_pose_t map_from_body;
    occ_pose_refusal_t why = OCC_POSE_OK;
    const occ_err_t pe = wait_pose(m, f, released, &map_from_body, &why);
    if (pe == OCC_ERR_STATE) {
        return;
    }
    if (pe != OCC_OK) {
        record(m, f, refusal_reason(why), false, 0, released, NULL);
        return;
    }
    if (load(m, f, b) != OCC_OK) {
        record(m, f, RUN_DROP_ERROR, false, 0, occ_port_clock_us(), NULL);
        return;
    }
    const uint64_t t0 = occ_port_clock_us(); /* integrate time: the write section, not the PNG */
    const occ_pose_t map_from_cam = occ_pose_compose(&map_from_body, &m->cam->body_from_camera);
    bool partial = false;
    size_t points = 0;
    occ_map_t *const map = run_write_begin(m->guard);
    const occ_err_t e = integrate(m, map, b, &map_from_cam, &partial, &points);
    const int drop = e == OCC_OK ? -1 : e == OCC_ERR_NOMEM ? RUN_DROP_NOMEM : RUN_DROP_ERROR;
    record(m, f, drop, partial, points, t0, &map_from_cam);
    run_write_end(m->guard);
}

int run_save(const run_opts_t *o, const occ_map_t *map)
{
    char msg[256] = "";
    const occ_err_t e = occ_file_save(o->out_path, map, msg, sizeof msg);
    if (e != OCC_OK) {
        cli_error("run", "cannot save %s: %s (%s)", o->out_path, msg, occ_err_str(e));
        return 1;
    }
    return 0;
}

/* --save-every: the writer saves between frames (readers may read meanwhile; no one writes). */
static void maybe_save(run_mapper_t *m, uint64_t *next_save)
{
    if (m->opt->out_path == NULL || m->opt->save_every_s <= 0.0f) {
        return;
    }
    const uint64_t now = occ_port_clock_us();
    if (now < *next_save) {
        return;
    }
    *next_save = now + (uint64_t)(m->opt->save_every_s * 1e6f);
    const int r = run_save(m->opt, m->guard->map);
    (void)pthread_mutex_lock(&m->st->lock);
    m->st->mc.saves += r == 0 ? 1u : 0u;
    m->st->mc.save_errors += r == 0 ? 0u : 1u;
    (void)pthread_mutex_unlock(&m->st->lock);
}

void *run_mapper_main(void *arg)
{
    run_mapper_t *const m = arg;
    frame_buf_t b;
    memset(&b, 0, sizeof b);
    uint64_t next_save = occ_port_clock_us() + (uint64_t)(m->opt->save_every_s * 1e6f);
    run_frame_t f;
    while (m->cam != NULL && m->cam->next(m->cam->ctx, &m->st->stop, &f)) {
        do_frame(m, &f, &b);
        run_ranges_service(m);
        maybe_save(m, &next_save);
    }
    (void)pthread_mutex_lock(&m->st->lock);
    m->st->mc.done = true; /* the depth directory is replayed (--exit-after-depth) */
    (void)pthread_mutex_unlock(&m->st->lock);
    while (!m->st->stop) { /* range messages and saves until the end */
        run_ranges_service(m);
        maybe_save(m, &next_save);
        sleep_us(5000);
    }
    run_ranges_finish(m); /* what the link queued before it stopped: integrated or counted */
    free(b.px);
    free(b.part);
    free(b.tmp);
    free(b.scratch);
    return NULL;
}
