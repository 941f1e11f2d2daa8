/* SPDX-License-Identifier: BSD-3-Clause */
/* run_state.c - the state `occmap run`'s two threads share: the clock offset, frame lists. */
#include <stdlib.h>

#include "run.h"

static const char *const source_names[RUN_SOURCES] = {"depth", "mavlink_ranges", "can_ranges"};

bool run_source_on(const run_opts_t *o, int src)
{
    switch (src) {
    case RUN_SRC_DEPTH:
        return o->depth_dir != NULL;
    case RUN_SRC_MAVLINK:
        return o->mavlink_ranges;
    case RUN_SRC_CAN:
        return o->can != NULL && o->n_can_mounts > 0u;
    default:
        return false;
    }
}

const char *run_source_name(int src)
{
    return src >= 0 && src < RUN_SOURCES ? source_names[src] : "?";
}

bool run_state_offset(const run_state_t *st, int64_t *offset_us, const char **source)
{
    if (st->ts.valid) {
        *offset_us = st->ts.offset_us;
        *source = "timesync";
        return true;
    }
    if (st->have_arrival) {
        *offset_us = st->arrival_offset_us;
        *source = "arrival";
        return true;
    }
    *offset_us = 0;
    *source = "none";
    return false;
}

bool run_list_push(run_list_t *l, size_t idx, uint32_t version, const occ_pose_t *pose)
{
    if (l->n == l->cap) {
        const size_t cap = l->cap == 0u ? 64u : 2u * l->cap;
        size_t *const i = realloc(l->idx, cap * sizeof *i);
        if (i == NULL) {
            return false;
        }
        l->idx = i;
        uint32_t *const v = realloc(l->version, cap * sizeof *v);
        if (v == NULL) {
            return false;
        }
        l->version = v;
        occ_pose_t *const p = realloc(l->pose, cap * sizeof *p);
        if (p == NULL) {
            return false;
        }
        l->pose = p;
        l->cap = cap;
    }
    l->idx[l->n] = idx;
    l->version[l->n] = version;
    l->pose[l->n] = pose != NULL ? *pose : occ_pose_identity();
    l->n++;
    return true;
}

void run_list_free(run_list_t *l)
{
    free(l->idx);
    free(l->version);
    free(l->pose);
    l->idx = NULL;
    l->version = NULL;
    l->pose = NULL;
    l->n = l->cap = 0;
}

static int cmp_u32(const void *a, const void *b)
{
    const uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

double run_percentile_u32(const uint32_t *v, size_t n, double p)
{
    if (n == 0u) {
        return 0.0;
    }
    uint32_t *const s = malloc(n * sizeof *s);
    if (s == NULL) {
        return 0.0;
    }
    for (size_t i = 0; i < n; i++) {
        s[i] = v[i];
    }
    qsort(s, n, sizeof *s, cmp_u32);
    size_t k = (size_t)(p * (double)(n - 1u) + 0.5);
    k = k >= n ? n - 1u : k;
    const double r = (double)s[k];
    free(s);
    return r;
}
