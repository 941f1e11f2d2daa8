/* SPDX-License-Identifier: BSD-3-Clause */
/* scan_graph.c - OctoMap's binary ScanGraph reader (scans with 6-D poses). */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "occmap/host/occ_scan.h"

typedef struct {
    const unsigned char *p;
    size_t len, off;
    char *msg;
    size_t msg_len;
    const char *path;
} rd_t;

static occ_err_t fail(rd_t *r, const char *what)
{
    if (r->msg != NULL && r->msg_len > 0u) {
        (void)snprintf(r->msg, r->msg_len, "%s: byte %zu: %s", r->path, r->off, what);
    }
    return OCC_ERR_FORMAT;
}

static bool get(rd_t *r, void *dst, size_t n)
{
    if (r->len - r->off < n) {
        return false;
    }
    memcpy(dst, r->p + r->off, n);
    r->off += n;
    return true;
}

/* i32 count + count doubles. */
static occ_err_t get_vec(rd_t *r, int32_t want, double *v, const char *what)
{
    int32_t dim;
    if (!get(r, &dim, 4u)) {
        return fail(r, what);
    }
    if (dim != want) {
        r->off -= 4u;
        return fail(r, "bad vector dimension");
    }
    for (int32_t i = 0; i < want; i++) {
        if (!get(r, &v[i], 8u)) {
            return fail(r, what);
        }
        if (!isfinite(v[i])) {
            r->off -= 8u;
            return fail(r, "non-finite number");
        }
    }
    return OCC_OK;
}

static occ_err_t get_pose(rd_t *r, double t[3], double q[4])
{
    occ_err_t e = get_vec(r, 3, t, "truncated pose translation");
    if (e == OCC_OK) {
        e = get_vec(r, 4, q, "truncated pose rotation");
    }
    return e;
}

void occ_scan_frames_free(occ_scan_frame_t *frames, size_t n)
{
    if (frames == NULL) {
        return;
    }
    for (size_t i = 0; i < n; i++) {
        free(frames[i].points);
    }
    free(frames);
}

/* p' = R(q) p + t, q = (w, x, y, z) normalized here. */
static occ_vec3_t transform(const double t[3], const double q[4], const double p[3])
{
    const double n = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    const double w = q[0] / n, x = q[1] / n, y = q[2] / n, z = q[3] / n;
    const double r[3][3] = {
        {1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
        {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
        {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)},
    };
    occ_vec3_t o;
    o.x = (float)(r[0][0] * p[0] + r[0][1] * p[1] + r[0][2] * p[2] + t[0]);
    o.y = (float)(r[1][0] * p[0] + r[1][1] * p[1] + r[1][2] * p[2] + t[1]);
    o.z = (float)(r[2][0] * p[0] + r[2][1] * p[1] + r[2][2] * p[2] + t[2]);
    return o;
}

/* A node's np points, stored at pts_off before its pose: read them now that the pose is known,
 * into f->points in the map frame. On error nothing stays allocated. */
static occ_err_t read_points(rd_t *r, size_t pts_off, uint32_t np, const double t[3],
                             const double q[4], occ_scan_frame_t *f)
{
    f->points = malloc((np > 0u ? np : 1u) * sizeof *f->points);
    if (f->points == NULL) {
        return OCC_ERR_NOMEM;
    }
    const size_t end_off = r->off;
    r->off = pts_off;
    for (uint32_t i = 0; i < np; i++) {
        double v[3];
        const occ_err_t e = get_vec(r, 3, v, "truncated point");
        if (e != OCC_OK) {
            free(f->points);
            f->points = NULL;
            return e;
        }
        f->points[i] = transform(t, q, v);
    }
    r->off = end_off;
    f->n_points = np;
    return OCC_OK;
}

static void set_pose(occ_scan_frame_t *f, const double t[3], const double q[4], uint32_t id)
{
    f->origin.x = (float)t[0];
    f->origin.y = (float)t[1];
    f->origin.z = (float)t[2];
    for (unsigned i = 0; i < 3u; i++) {
        f->pose_t[i] = (float)t[i];
    }
    for (unsigned i = 0; i < 4u; i++) {
        f->pose_q[i] = (float)q[i];
    }
    (void)snprintf(f->name, sizeof f->name, "node %u", (unsigned)id);
}

/* One node: point count, the points, then the pose they are in, then the node id. */
static occ_err_t read_node(rd_t *r, occ_scan_frame_t *f, uint32_t *id)
{
    uint32_t np;
    if (!get(r, &np, 4u)) {
        return fail(r, "truncated point count");
    }
    if ((size_t)np > (r->len - r->off) / 28u) {
        r->off -= 4u;
        return fail(r, "point count larger than the file");
    }
    const size_t pts_off = r->off;
    r->off += (size_t)np * 28u; /* points are transformed once the pose is known */
    double t[3], q[4];
    occ_err_t e = get_pose(r, t, q);
    if (e != OCC_OK) {
        return e;
    }
    if (!get(r, id, 4u)) {
        return fail(r, "truncated node id");
    }
    e = read_points(r, pts_off, np, t, q, f);
    if (e == OCC_OK) {
        set_pose(f, t, q, *id);
    }
    return e;
}

static bool has_id(const uint32_t *ids, uint32_t n, uint32_t id)
{
    for (uint32_t i = 0; i < n; i++) {
        if (ids[i] == id) {
            return true;
        }
    }
    return false;
}

/* The edges (checked, then dropped: a map needs only the nodes) and the end of the file. */
static occ_err_t read_edges(rd_t *r, const uint32_t *ids, uint32_t n_nodes)
{
    uint32_t n_edges;
    if (!get(r, &n_edges, 4u)) {
        return fail(r, "truncated edge count");
    }
    if ((size_t)n_edges > (r->len - r->off) / 80u) {
        r->off -= 4u;
        return fail(r, "edge count larger than the file");
    }
    for (uint32_t k = 0; k < n_edges; k++) {
        uint32_t a, b;
        double t[3], q[4], w;
        const size_t at = r->off;
        if (!get(r, &a, 4u) || !get(r, &b, 4u)) {
            return fail(r, "truncated edge");
        }
        if (!has_id(ids, n_nodes, a) || !has_id(ids, n_nodes, b)) {
            r->off = at;
            return fail(r, "edge names a node that does not exist");
        }
        const occ_err_t e = get_pose(r, t, q);
        if (e != OCC_OK) {
            return e;
        }
        if (!get(r, &w, 8u)) {
            return fail(r, "truncated edge weight");
        }
    }
    return r->off == r->len ? OCC_OK : fail(r, "trailing bytes after the last edge");
}

static occ_err_t parse(rd_t *r, occ_scan_frame_t **frames_out, size_t *n_out)
{
    uint32_t n_nodes;
    if (!get(r, &n_nodes, 4u)) {
        return fail(r, "truncated node count");
    }
    /* Each node takes at least 4 + 64 + 4 bytes: reject absurd counts before allocating. */
    if ((size_t)n_nodes > (r->len - r->off) / 72u) {
        r->off -= 4u;
        return fail(r, "node count larger than the file");
    }
    occ_scan_frame_t *const fr = calloc(n_nodes > 0u ? n_nodes : 1u, sizeof *fr);
    uint32_t *const ids = calloc(n_nodes > 0u ? n_nodes : 1u, sizeof *ids);
    if (fr == NULL || ids == NULL) {
        free(fr);
        free(ids);
        return OCC_ERR_NOMEM;
    }
    occ_err_t e = OCC_OK;
    size_t done = 0;
    for (; done < n_nodes && e == OCC_OK; done++) {
        e = read_node(r, &fr[done], &ids[done]);
    }
    if (e == OCC_OK) {
        e = read_edges(r, ids, n_nodes);
    }
    free(ids);
    if (e != OCC_OK) {
        occ_scan_frames_free(fr, done);
        return e;
    }
    *frames_out = fr;
    *n_out = n_nodes;
    return OCC_OK;
}

occ_err_t occ_scan_read_graph(const char *path, occ_scan_frame_t **frames, size_t *n_frames,
                              char *msg, size_t msg_len)
{
    if (path == NULL || frames == NULL || n_frames == NULL) {
        return OCC_ERR_ARG;
    }
    *frames = NULL;
    *n_frames = 0;
    FILE *const f = fopen(path, "rb");
    if (f == NULL) {
        if (msg != NULL && msg_len > 0u) {
            (void)snprintf(msg, msg_len, "%s: %s", path, strerror(errno));
        }
        return OCC_ERR_IO;
    }
    size_t cap = 1u << 16, len = 0;
    unsigned char *buf = malloc(cap);
    occ_err_t e = buf != NULL ? OCC_OK : OCC_ERR_NOMEM;
    while (e == OCC_OK) {
        if (len == cap) {
            unsigned char *const g = realloc(buf, cap * 2u);
            if (g == NULL) {
                e = OCC_ERR_NOMEM;
                break;
            }
            buf = g;
            cap *= 2u;
        }
        const size_t got = fread(buf + len, 1u, cap - len, f);
        len += got;
        if (got == 0u) {
            if (ferror(f)) {
                if (msg != NULL && msg_len > 0u) {
                    (void)snprintf(msg, msg_len, "%s: read error", path);
                }
                e = OCC_ERR_IO;
            }
            break;
        }
    }
    (void)fclose(f);
    if (e == OCC_OK) {
        rd_t r = {buf, len, 0u, msg, msg_len, path};
        e = parse(&r, frames, n_frames);
    }
    free(buf);
    return e;
}
