/* SPDX-License-Identifier: BSD-3-Clause */
/* shared_replay.c - see shared_replay.h. */
#include "shared_replay.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "occmap/host/occ_scan.h"

#define SR_PATH_R 30.0f

static void add_source(sr_writer_t *w, occ_vec3_t *rel, size_t n)
{
    w->rel[w->n_src] = rel;
    w->n[w->n_src] = n;
    w->max_n = n > w->max_n ? n : w->max_n;
    w->n_src++;
}

static bool load_tum(sr_writer_t *w, unsigned stride)
{
    occ_scan_frame_t *fr = NULL;
    size_t nf = 0;
    char msg[256];
    if (occ_depth_read_tum_dir(SR_TUM_DIR, stride, 0u, &fr, &nf, msg, sizeof msg) != OCC_OK) {
        return false;
    }
    for (size_t i = 0; i < nf && w->n_src < 15u; i++) {
        occ_vec3_t *rel = malloc(fr[i].n_points * sizeof *rel + 1u);
        if (rel == NULL) {
            break;
        }
        for (size_t j = 0; j < fr[i].n_points; j++) {
            rel[j].x = fr[i].points[j].x - fr[i].origin.x;
            rel[j].y = fr[i].points[j].y - fr[i].origin.y;
            rel[j].z = fr[i].points[j].z - fr[i].origin.z;
        }
        add_source(w, rel, fr[i].n_points);
    }
    occ_scan_frames_free(fr, nf);
    return w->n_src > 0u;
}

bool sr_writer_init(sr_writer_t *w, unsigned stride, size_t laser_step)
{
    memset(w, 0, sizeof *w);
    if (access(SR_TUM_DIR "/my_association.txt", R_OK) != 0 || access(SR_LASER, R_OK) != 0) {
        printf("SKIP: %s or %s absent (needs ../shared and the scan.dat rule)\n", SR_TUM_DIR,
               SR_LASER);
        return false;
    }
    if (!load_tum(w, stride)) {
        printf("SKIP: could not read the TUM frames\n");
        return false;
    }
    occ_vec3_t *pts = NULL;
    size_t np = 0;
    char msg[256];
    if (occ_scan_read_xyz(SR_LASER, &pts, &np, msg, sizeof msg) != OCC_OK) {
        printf("SKIP: could not read %s: %s\n", SR_LASER, msg);
        return false;
    }
    size_t k = 0;
    for (size_t j = 0; j < np; j += laser_step) {
        pts[k++] = pts[j];
    }
    add_source(w, pts, k);
    w->pts = malloc(w->max_n * sizeof *w->pts + 1u);
    w->ip = occ_insert_params_default();
    w->ip.max_range_m = 8.0f;
    w->pol = occ_evict_policy_default();
    w->pol.mode = OCC_EVICT_ROBOT;
    w->pol.keep_radius_m = 10.0f;
    w->pol.budget_blocks = 4096u;
    occ_evict_out_init(&w->ev);
    w->ip.auto_evict = &w->pol;
    w->ip.auto_evict_state = &w->ev;
    w->scratch_bytes = (size_t)64 << 20;
    w->scratch = malloc(w->scratch_bytes);
    return w->pts != NULL && w->scratch != NULL;
}

void sr_writer_free(sr_writer_t *w)
{
    for (size_t i = 0; i < w->n_src; i++) {
        free(w->rel[i]);
    }
    free(w->pts);
    free(w->scratch);
    memset(w, 0, sizeof *w);
}

occ_err_t sr_writer_step(sr_writer_t *w, occ_map_t *map)
{
    const size_t s = w->k % w->n_src;
    const float ang = (float)w->k * 0.35f; /* ~10 m per scan on the circle: eviction runs */
    const float cy = cosf(ang + 1.5708f), sy = sinf(ang + 1.5708f);
    w->origin.x = SR_PATH_R * cosf(ang);
    w->origin.y = SR_PATH_R * sinf(ang);
    w->origin.z = 2.0f;
    for (size_t j = 0; j < w->n[s]; j++) {
        const occ_vec3_t r = w->rel[s][j];
        w->pts[j].x = w->origin.x + cy * r.x - sy * r.y;
        w->pts[j].y = w->origin.y + sy * r.x + cy * r.y;
        w->pts[j].z = w->origin.z + r.z;
    }
    w->k++;
    (void)occ_map_evict(map, &w->origin, &w->pol, 2048u, &w->ev);
    return occ_map_insert_cloud(map, &w->origin, w->pts, w->n[s], &w->ip, w->scratch,
                                w->scratch_bytes, NULL);
}

/* A probe point: spread over the ring the path sweeps, deterministic. */
static occ_vec3_t probe_at(unsigned i, unsigned n)
{
    const float ang = 6.2832f * (float)i / (float)n;
    const float r = SR_PATH_R + 3.0f * sinf(7.0f * ang);
    occ_vec3_t p = {r * cosf(ang), r * sinf(ang), 1.0f + 1.5f * cosf(5.0f * ang)};
    return p;
}

static uint8_t collide_code(occ_err_t e, const occ_collision_t *c)
{
    const unsigned answer = (c->safe ? 1u : 0u) + 2u * (c->outside ? 1u : 0u);
    return (uint8_t)((e != OCC_OK ? 1u : 0u) + 4u * answer);
}

static void answer_collide(const occ_map_t *map, sr_answers_t *out)
{
    occ_collision_t c;
    for (unsigned i = 0; i < SR_SPHERES; i++) {
        const occ_err_t e = occ_collide_sphere(map, probe_at(i, SR_SPHERES), 0.6f,
                                               OCC_UNKNOWN_SAFE, &c);
        out->sphere[i] = collide_code(e, &c);
    }
    for (unsigned i = 0; i < SR_CAPSULES; i++) {
        const occ_vec3_t a = probe_at(i, SR_CAPSULES), b = probe_at(i + 1u, SR_CAPSULES);
        const occ_err_t e = occ_collide_capsule(map, a, b, 0.3f, OCC_UNKNOWN_SAFE, &c);
        out->capsule[i] = collide_code(e, &c);
    }
}

static void answer_rays(const occ_map_t *map, sr_answers_t *out)
{
    for (unsigned i = 0; i < SR_RAYS; i++) {
        const occ_vec3_t o = probe_at(i, SR_RAYS);
        const occ_vec3_t d = {-o.y, o.x, 0.1f}; /* along the path */
        occ_ray_result_t r;
        const occ_err_t e = occ_cast_ray(map, o, d, true, 20.0f, &r);
        out->ray[i][0] = (uint32_t)(e != OCC_OK) | (r.hit ? 2u : 0u) | ((uint32_t)r.stop << 2);
        for (unsigned a = 0; a < 3u; a++) {
            out->ray[i][1u + a] = r.key.k[a];
        }
    }
}

static void answer_sectors(const occ_map_t *map, occ_sectors_t *sec, sr_answers_t *out)
{
    const occ_sectors_config_t cfg = occ_sectors_config_default();
    for (unsigned i = 0; i < SR_SECTORS; i++) {
        occ_pose_t pose = occ_pose_identity();
        pose.p = probe_at(3u * i, 7u);
        (void)occ_sectors_compute(map, &pose, &cfg, sec);
        memcpy(out->sector[i], sec->distance_cm, sizeof out->sector[i]);
    }
}

void sr_answer(const occ_map_t *map, unsigned mask, occ_sectors_t *sec, sr_answers_t *out)
{
    memset(out, 0, sizeof *out);
    if ((mask & SR_Q_LOOKUP) != 0u) {
        for (unsigned i = 0; i < SR_POINTS; i++) {
            out->state[i] = (uint8_t)occ_map_state_at(map, probe_at(i, SR_POINTS));
        }
    }
    if ((mask & SR_Q_COLLIDE) != 0u) {
        answer_collide(map, out);
    }
    if ((mask & SR_Q_RAYS) != 0u) {
        answer_rays(map, out);
    }
    if ((mask & SR_Q_SECTORS) != 0u) {
        answer_sectors(map, sec, out);
    }
}

unsigned sr_diff(const sr_answers_t *a, const sr_answers_t *b, unsigned mask)
{
    unsigned d = 0;
    if ((mask & SR_Q_LOOKUP) != 0u) {
        for (unsigned i = 0; i < SR_POINTS; i++) {
            d += a->state[i] != b->state[i] ? 1u : 0u;
        }
    }
    if ((mask & SR_Q_COLLIDE) != 0u) {
        d += (unsigned)(memcmp(a->sphere, b->sphere, sizeof a->sphere) != 0);
        d += (unsigned)(memcmp(a->capsule, b->capsule, sizeof a->capsule) != 0);
    }
    if ((mask & SR_Q_RAYS) != 0u) {
        d += (unsigned)(memcmp(a->ray, b->ray, sizeof a->ray) != 0);
    }
    if ((mask & SR_Q_SECTORS) != 0u) {
        d += (unsigned)(memcmp(a->sector, b->sector, sizeof a->sector) != 0);
    }
    return d;
}
