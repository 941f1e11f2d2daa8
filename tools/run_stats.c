/* SPDX-License-Identifier: BSD-3-Clause */
/* run_stats.c - `occmap run`'s telemetry: the config line, one JSON line a second, the final
 * line (--stats FILE, default stderr). */
#include <stdlib.h>
#include <string.h>

#include "run_link.h"
#include "run_can.h"
#include "run_ranges.h"

static const char *const drop_names[RUN_DROP_REASONS] = {
    "no_pose_yet", "no_pose_too_old", "no_pose_too_new", "no_pose_gap", "nomem", "error", "late"};

static void print_sectors(FILE *f, const occ_sectors_config_t *s)
{
    fprintf(f, "\"sectors\": {\"n\": %u, \"increment_deg\": %.9g, \"angle_offset_deg\": %.9g, "
            "\"min_cm\": %u, \"max_cm\": %u, \"band_below_m\": %.9g, \"band_above_m\": %.9g, "
            "\"ignore_ground\": %s, \"ground_clearance_m\": %.9g, \"unknown_as_distance\": %s, "
            "\"map_ned\": %s}", s->n_sectors, (double)s->increment_deg,
            (double)s->angle_offset_deg, s->min_distance_cm, s->max_distance_cm,
            (double)s->band_below_m, (double)s->band_above_m, s->ignore_ground ? "true" : "false",
            (double)s->ground_clearance_m, s->unknown_as_distance ? "true" : "false",
            s->map_ned ? "true" : "false");
}

static void print_depth(FILE *f, const run_opts_t *o, const run_depth_t *d)
{
    if (d == NULL) {
        fprintf(f, "\"depth\": null");
        return;
    }
    const occ_pinhole_t *const c = &d->params.intrinsics;
    const occ_pose_t *const b = &d->body_from_camera;
    fprintf(f, "\"depth\": {\"dir\": \"%s\", \"frames_listed\": %zu, \"frames_present\": %zu, "
            "\"stride\": %u, \"method\": \"%s\", \"intrinsics\": [%.9g, %.9g, %.9g, %.9g], "
            "\"depth_scale_m\": %.9g, \"min_range_m\": %.9g, \"max_range_m\": %.9g, "
            "\"mount\": [%.9g, %.9g, %.9g, %.9g, %.9g, %.9g], "
            "\"body_from_camera\": [%.9g, %.9g, %.9g, %.9g, %.9g, %.9g, %.9g], "
            "\"replay_speed\": %u, \"t_ref_rule\": \"first depth.txt time - 1 s\"}",
            d->dir, d->n_listed, d->n, d->params.pixel_step,
            o->depth_projective ? "projective" : "simple", (double)c->fx, (double)c->fy,
            (double)c->cx, (double)c->cy, (double)d->depth_scale_m, (double)d->params.min_range_m,
            (double)d->params.max_range_m, (double)o->mount[0], (double)o->mount[1],
            (double)o->mount[2], (double)o->mount[3], (double)o->mount[4], (double)o->mount[5],
            (double)b->p.x, (double)b->p.y, (double)b->p.z, (double)b->q.w, (double)b->q.x,
            (double)b->q.y, (double)b->q.z, o->replay_speed);
}

/* --3d and --can: on or off, the bus, the node id, each range sensor's mount (body FLU <- sensor:
 * id, x, y, z, qw, qx, qy, qz, min_m, max_m). */
static void print_can(FILE *f, const run_opts_t *o)
{
    fprintf(f, ", \"obstacle_3d\": %s, \"can\": %s%s%s, \"can_node_id\": %u, \"can_mounts\": [",
            o->obstacle_3d ? "true" : "false", o->can != NULL ? "\"" : "",
            o->can != NULL ? o->can : "null", o->can != NULL ? "\"" : "", o->can_node_id);
    for (size_t i = 0; i < o->n_can_mounts; i++) {
        const occ_dronecan_range_mount_t *const m = &o->can_mounts[i];
        const occ_pose_t *const p = &m->body_from_sensor;
        fprintf(f, "%s[%u, %.9g, %.9g, %.9g, %.9g, %.9g, %.9g, %.9g, %.9g, %.9g]",
                i > 0u ? ", " : "", m->sensor_id, (double)p->p.x, (double)p->p.y, (double)p->p.z,
                (double)p->q.w, (double)p->q.x, (double)p->q.y, (double)p->q.z, (double)m->min_m,
                (double)m->max_m);
    }
    fprintf(f, "]");
}

void run_stats_config(run_link_t *l)
{
    const run_opts_t *const o = l->opt;
    FILE *const f = l->stats;
    fprintf(f, "{\"config\": {\"res\": %.9g, \"arena_bytes\": %zu, \"evict\": \"robot\", "
            "\"keep_radius_m\": %.9g, \"rate_hz\": %.9g, \"pose_rate_hz\": %.9g, "
            "\"pose_timeout_ms\": %u, \"sensor_timeout_ms\": %u, \"max_lag_ms\": %u, "
            "\"target\": [%u, %u], "
            "\"ids\": [%u, %u], \"prior_map\": %s%s%s, ", (double)l->guard->map->cfg.resolution_m,
            o->arena_bytes, (double)o->keep_radius_m, (double)o->fa.rate_hz,
            (double)o->pose_rate_hz, o->pose_timeout_ms, o->sensor_timeout_ms, o->max_lag_ms, o->target_sysid,
            o->target_compid, o->sysid, o->compid, o->fa.map_path != NULL ? "\"" : "",
            o->fa.map_path != NULL ? o->fa.map_path : "null", o->fa.map_path != NULL ? "\"" : "");
    print_depth(f, o, l->depth);
    fprintf(f, ", ");
    print_sectors(f, &l->feed->cfg.sectors);
    print_can(f, o);
    fprintf(f, "}}\n");
    fflush(f);
}

/* p50 / p99 / max of n microsecond values, as milliseconds. */
static void print_ms3(FILE *f, const char *name, const uint32_t *v, size_t n)
{
    fprintf(f, "\"%s\": {\"n\": %zu, \"p50\": %.3f, \"p99\": %.3f, \"max\": %.3f}", name, n,
            run_percentile_u32(v, n, 0.5) / 1000.0, run_percentile_u32(v, n, 0.99) / 1000.0,
            run_percentile_u32(v, n, 1.0) / 1000.0);
}

/* The feed period's jitter: |interval - period| per pair of OBSTACLE_DISTANCE. */
static void print_feed(FILE *f, run_link_t *l)
{
    const occ_mav_feed_counters_t *const c = &l->feed->counters;
    const uint32_t period = l->feed->cfg.period_us;
    uint32_t *const j = malloc((l->ft.n + 1u) * sizeof *j);
    for (size_t i = 0; j != NULL && i < l->ft.n; i++) {
        const uint32_t d = l->ft.interval_us[i];
        j[i] = d > period ? d - period : period - d;
    }
    fprintf(f, "\"feed\": {\"sent\": %u, \"stale_skips\": %u, \"sector_errors\": %u, "
            "\"heartbeats\": %u, \"statustexts\": %u, \"period_ms\": %.3f, ", c->obstacle_tx,
            c->stale_skips, c->sector_errors, c->heartbeat_tx, l->statustexts,
            (double)period / 1000.0);
    print_ms3(f, "jitter_ms", j, j != NULL ? l->ft.n : 0u);
    fprintf(f, ", \"requests_tx\": %u, \"request_acks\": %u, \"request_refusals\": %u}",
            c->requests_tx, c->request_acks, c->request_refusals);
    free(j);
}

static void print_mapping(FILE *f, const run_state_t *st)
{
    const run_map_counters_t *const c = &st->mc;
    fprintf(f, "\"frames\": {\"done\": %llu, \"integrated\": %llu, \"partial\": %llu, \"dropped\": {",
            (unsigned long long)c->frames_done, (unsigned long long)c->integrated,
            (unsigned long long)c->partial);
    for (unsigned i = 0; i < RUN_DROP_REASONS; i++) {
        fprintf(f, "%s\"%s\": %llu", i > 0u ? ", " : "", drop_names[i],
                (unsigned long long)c->dropped[i]);
    }
    fprintf(f, "}, \"points\": %llu}, ", (unsigned long long)c->points);
    print_ms3(f, "integrate_ms", c->integrate_us, c->n_integrate);
    fprintf(f, ", \"arena\": {\"bytes\": %zu, \"used\": %zu, \"peak\": %zu, \"oom\": %u}, "
            "\"evictions\": %llu, \"blocks_evicted\": %llu, \"saves\": %llu, \"save_errors\": %llu",
            st->pool.arena_bytes, st->pool.bytes_used, st->pool.bytes_peak, st->pool.oom_count,
            (unsigned long long)st->evict.evictions, (unsigned long long)st->evict.blocks_freed,
            (unsigned long long)c->saves, (unsigned long long)c->save_errors);
}

/* The age of each configured input's newest integrated sample (ms; -1: none yet). */
static void print_inputs(FILE *f, const run_link_t *l, uint64_t now)
{
    fprintf(f, ", \"sensor_age_ms\": {");
    bool first = true;
    for (int s = 0; s < RUN_SOURCES; s++) {
        if (run_source_on(l->opt, s)) {
            const uint64_t t = l->st->last_sample_local_us[s];
            fprintf(f, "%s\"%s\": %.3f", first ? "" : ", ", run_source_name(s),
                    t == 0u ? -1.0 : t >= now ? 0.0 : (double)(now - t) / 1000.0);
            first = false;
        }
    }
    fprintf(f, "}");
}

static void print_clock(FILE *f, run_link_t *l, uint64_t now)
{
    const run_state_t *const st = l->st;
    int64_t off = 0;
    const char *src = "none";
    const bool known = run_state_offset(st, &off, &src);
    const double age = st->last_pose_local_us != 0u ? (double)(now - st->last_pose_local_us) / 1000.0 : -1.0;
    fprintf(f, ", \"pose_age_ms\": %.3f, \"poses\": {\"rx\": %u, \"foreign\": %u, \"bad\": %u, "
            "\"unpaired\": %u, \"in_history\": %zu}, \"clock\": {\"offset_us\": %lld, "
            "\"known\": %s, \"source\": \"%s\", \"rtt_us\": %u, \"timesync_replies\": %u}",
            age, l->prx.counters.poses, l->prx.counters.foreign, l->prx.counters.bad,
            l->prx.counters.unpaired, occ_pose_history_count(&st->hist), (long long)off,
            known ? "true" : "false", src, st->ts.rtt_us, st->ts.accepted);
}

void run_stats_line(run_link_t *l, uint64_t now, const char *key, bool map_check_ok)
{
    FILE *const f = l->stats;
    const char *const status = !l->ever_sent ? "boot" : l->stale ? "stale" : "active";
    fprintf(f, "{%s%s%s\"t_s\": %.3f, \"status\": \"%s\", \"stale_input\": %s%s%s, "
            "\"version\": %u, ", key != NULL ? "\"" : "", key != NULL ? key : "",
            key != NULL ? "\": {" : "", (double)(now - l->t0) / 1e6, status,
            l->stale ? "\"" : "", l->stale ? l->stale_why : "null", l->stale ? "\"" : "",
            run_read_version(l->guard));
    (void)pthread_mutex_lock(&l->st->lock);
    print_mapping(f, l->st);
    print_inputs(f, l, now);
    print_clock(f, l, now);
    fprintf(f, ", ");
    run_ranges_print(f, l->st->ranges, &l->ranges_tr);
    (void)pthread_mutex_unlock(&l->st->lock);
    fprintf(f, ", ");
    print_feed(f, l);
    if (l->can != NULL) {
        fprintf(f, ", ");
        run_can_print(f, l->can);
    }
    if (l->nearest != NULL) {
        fprintf(f, ", \"obstacle_3d_sent\": %llu", (unsigned long long)l->sent_3d);
    }
    fprintf(f, ", \"link\": {\"rx_bytes\": %llu, \"tx_dropped\": %u, \"bad_crc\": %u}",
            (unsigned long long)l->link->rx_bytes, l->link->tx_dropped,
            l->feed->parser.counters.bad_crc);
    if (key != NULL) {
        fprintf(f, ", \"map_check\": \"%s\"}", map_check_ok ? "ok" : "FAILED");
    }
    fprintf(f, "}\n");
    fflush(f);
}
