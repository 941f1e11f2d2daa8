/* SPDX-License-Identifier: BSD-3-Clause */
/* iotest.c - helpers shared by the file tests (see iotest.h). */
#include "iotest.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

uint8_t *iotest_read_file(const char *const path, size_t *const len)
{
    FILE *const f = fopen(path, "rb");
    if (f == NULL) {
        return NULL;
    }
    (void)fseek(f, 0, SEEK_END);
    const long n = ftell(f);
    (void)fseek(f, 0, SEEK_SET);
    uint8_t *const buf = (uint8_t *)malloc((size_t)n + 1u);
    if (buf == NULL || fread(buf, 1u, (size_t)n, f) != (size_t)n) {
        free(buf);
        (void)fclose(f);
        return NULL;
    }
    (void)fclose(f);
    *len = (size_t)n;
    return buf;
}

static uint64_t mix(uint64_t h, const void *const p, const size_t n)
{
    const uint8_t *const b = (const uint8_t *)p;
    for (size_t i = 0; i < n; i++) {
        h = (h ^ b[i]) * 1099511628211ull;
    }
    return h;
}

uint64_t iotest_map_digest(const occ_map_t *const map)
{
    uint64_t h = 1469598103934665603ull;
    occ_walk_t w;
    occ_walk_node_t n;
    occ_walk_begin(&w, map);
    while (occ_walk_next(&w, &n)) {
        h = mix(h, n.key.k, sizeof n.key.k);
        h = mix(h, &n.level, 1u);
        h = mix(h, &n.value, sizeof n.value);
        h = mix(h, &n.flags, 1u);
        const uint8_t c = n.has_children ? 1u : 0u;
        h = mix(h, &c, 1u);
    }
    h = mix(h, &map->inner.used, sizeof map->inner.used);
    h = mix(h, &map->leaf.used, sizeof map->leaf.used);
    const float c[7] = {map->cfg.resolution_m, map->cfg.hit, map->cfg.miss, map->cfg.clamp_min,
                        map->cfg.clamp_max, map->cfg.free_max, map->cfg.occupied_min};
    h = mix(h, c, sizeof c);
    h = mix(h, &map->cfg.depth_levels, 1u);
    return h;
}

static float logodds(const double p)
{
    return (float)log(p / (1.0 - p));
}

occ_map_config_t iotest_octomap_cfg(void)
{
    occ_map_config_t c = occ_map_config_default();
    c.hit = logodds(0.7);
    c.miss = logodds(0.4);
    c.clamp_min = logodds(0.1192);
    c.clamp_max = logodds(0.971);
    return c;
}

void *iotest_load(occ_map_t *const map, const uint8_t *const buf, const size_t len,
                  const size_t extra, occ_err_t *const err, occ_io_info_t *const info)
{
    occ_io_info_t local;
    occ_io_info_t *const inf = info != NULL ? info : &local;
    const occ_map_config_t cfg = iotest_octomap_cfg();
    *err = occ_io_probe(buf, len, &cfg, inf);
    if (*err != OCC_OK) {
        return NULL;
    }
    const size_t bytes = inf->arena_bytes_needed + extra;
    void *const arena = malloc(bytes);
    *err = occ_io_load(map, &cfg, arena, bytes, buf, len, inf);
    if (*err != OCC_OK) {
        free(arena);
        return NULL;
    }
    return arena;
}

uint8_t *iotest_write(const occ_map_t *const map, const occ_format_t fmt, size_t *const len)
{
    size_t n = 0u;
    if (occ_io_write(map, fmt, NULL, NULL, &n) != OCC_OK) {
        return NULL;
    }
    occ_io_buf_t b;
    b.data = (uint8_t *)malloc(n + 1u);
    b.cap = n;
    b.len = 0u;
    size_t n2 = 0u;
    if (occ_io_write(map, fmt, occ_io_buf_write, &b, &n2) != OCC_OK || n2 != n || b.len != n) {
        free(b.data);
        return NULL;
    }
    *len = n;
    return b.data;
}

typedef struct {
    const occ_map_t *map;
    const oracle_io_t *t;
    float tol;
    bool ok;
    long double volume;
    char *why;
    size_t why_len;
} eq_ctx_t;

static void fail(eq_ctx_t *const c, const char *const what, const uint32_t *const key,
                 const unsigned level, const double a, const double b)
{
    if (c->ok && c->why != NULL) {
        (void)snprintf(c->why, c->why_len, "%s at (%u,%u,%u) level %u: %.6f vs %.6f", what,
                       (unsigned)key[0], (unsigned)key[1], (unsigned)key[2], level, a, b);
    }
    c->ok = false;
}

static void oracle_leaf(void *const ctx, const uint32_t key[3], const unsigned level,
                        const float logodds)
{
    eq_ctx_t *const c = (eq_ctx_t *)ctx;
    c->volume += ldexpl(1.0L, (int)(3u * level));
    occ_key_t k;
    memcpy(k.k, key, sizeof k.k);
    occ_node_info_t ni;
    if (occ_map_read_key(c->map, k, level, &ni) != OCC_OK || !ni.observed) {
        fail(c, "OctoMap leaf unobserved in occmap", key, level, (double)logodds, 0.0);
        return;
    }
    if ((ni.flags & OCC_NODE_UNIFORM) != 0u && fabsf(ni.logodds - logodds) > c->tol) {
        fail(c, "value differs", key, level, (double)logodds, (double)ni.logodds);
    }
}

bool iotest_equivalent(const occ_map_t *const map, const oracle_io_t *const t, const float tol,
                       char *const why, const size_t why_len)
{
    eq_ctx_t c = {map, t, tol, true, 0.0L, why, why_len};
    if (why != NULL && why_len > 0u) {
        why[0] = '\0';
    }
    oracle_io_for_each_leaf(t, oracle_leaf, &c);
    long double vol = 0.0L;
    occ_walk_t w;
    occ_walk_node_t n;
    occ_walk_begin(&w, map);
    while (occ_walk_next(&w, &n)) {
        if (n.has_children || !n.observed) {
            continue;
        }
        vol += ldexpl(1.0L, (int)(3u * n.level));
        unsigned fl = 0u;
        float v = 0.0f;
        bool ch = false;
        if (!oracle_io_search(t, n.key.k, n.level, &fl, &v, &ch)) {
            fail(&c, "occmap leaf missing in OctoMap", n.key.k, n.level,
                 (double)occ_value_to_logodds(n.value), 0.0);
            break;
        }
        if (!ch && fabsf(v - occ_value_to_logodds(n.value)) > tol) {
            fail(&c, "value differs", n.key.k, n.level, (double)occ_value_to_logodds(n.value),
                 (double)v);
            break;
        }
    }
    if (c.ok && (vol < c.volume || c.volume < vol)) {
        if (why != NULL) {
            (void)snprintf(why, why_len, "known volumes differ: %.0Lf vs %.0Lf voxels", vol,
                           c.volume);
        }
        c.ok = false;
    }
    return c.ok;
}
