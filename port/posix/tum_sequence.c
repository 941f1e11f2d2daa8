/* SPDX-License-Identifier: BSD-3-Clause */
/* tum_sequence.c - TUM RGB-D sequence directories: depth.txt, groundtruth.txt, and depth frames
 * posed by the interpolating pose history. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "occmap/host/occ_tum.h"

occ_depth_camera_t occ_depth_camera_tum_fr1(void)
{
    const occ_depth_camera_t c = {517.3f, 516.5f, 318.6f, 255.3f, 5000.0f};
    return c;
}

static void line_msg(char *msg, size_t len, const char *path, unsigned long line,
                     const char *what)
{
    if (msg != NULL && len > 0u) {
        if (line > 0u) {
            (void)snprintf(msg, len, "%s: line %lu: %s", path, line, what);
        } else {
            (void)snprintf(msg, len, "%s: %s", path, what);
        }
    }
}

/* A growing array of `size`-byte records: room for one more, or NULL (out of memory). */
static void *grow(void **arr, size_t *cap, size_t n, size_t size)
{
    if (n == *cap) {
        const size_t nc = *cap == 0u ? 256u : *cap * 2u;
        void *const g = realloc(*arr, nc * size);
        if (g == NULL) {
            return NULL;
        }
        *arr = g;
        *cap = nc;
    }
    return (unsigned char *)*arr + n * size;
}

/* Line parser: fills the record `rec` from `line`; false if malformed. */
typedef bool (*parse_fn)(const char *line, void *rec);

/* Every non-comment line of `path` through `parse` into a malloc'd array (times strictly
 * increasing: each record starts with its uint64_t t_us). */
static occ_err_t read_lines(const char *path, parse_fn parse, size_t size, const char *expect,
                            void **out, size_t *n_out, char *msg, size_t msg_len)
{
    FILE *const f = fopen(path, "r");
    if (f == NULL) {
        line_msg(msg, msg_len, path, 0u, strerror(errno));
        return OCC_ERR_IO;
    }
    void *arr = NULL;
    size_t n = 0, cap = 0;
    occ_err_t e = OCC_OK;
    char line[1024];
    unsigned long lineno = 0;
    uint64_t last_t = 0;
    while (e == OCC_OK && fgets(line, sizeof line, f) != NULL) {
        lineno++;
        if (line[0] == '#' || line[0] == '\n' || line[0] == '\r') {
            continue;
        }
        void *const rec = grow(&arr, &cap, n, size);
        if (rec == NULL) {
            e = OCC_ERR_NOMEM;
            break;
        }
        uint64_t t = 0;
        if (!parse(line, rec) || (memcpy(&t, rec, sizeof t), n > 0u && t <= last_t)) {
            line_msg(msg, msg_len, path, lineno, expect);
            e = OCC_ERR_FORMAT;
            break;
        }
        last_t = t;
        n++;
    }
    (void)fclose(f);
    if (e != OCC_OK) {
        free(arr);
        return e;
    }
    *out = arr;
    *n_out = n;
    return OCC_OK;
}

static bool seconds_to_us(double s, uint64_t *t_us)
{
    if (!isfinite(s) || s < 0.0 || s > 1.8e13) {
        return false;
    }
    *t_us = (uint64_t)llround(s * 1e6);
    return true;
}

static bool parse_depth(const char *line, void *rec)
{
    occ_tum_depth_entry_t *const e = rec;
    double s;
    char tail;
    return sscanf(line, "%lf %95s %c", &s, e->file, &tail) == 2 && seconds_to_us(s, &e->t_us);
}

static bool parse_pose(const char *line, void *rec)
{
    occ_pose_sample_t *const p = rec;
    double s;
    float t[3], q[4];
    char tail;
    if (sscanf(line, "%lf %f %f %f %f %f %f %f %c", &s, &t[0], &t[1], &t[2], &q[0], &q[1], &q[2],
               &q[3], &tail) != 8 ||
        !seconds_to_us(s, &p->t_us)) {
        return false;
    }
    p->pose.p = (occ_vec3_t){t[0], t[1], t[2]};
    p->pose.q = (occ_quat_t){q[3], q[0], q[1], q[2]}; /* file order x y z w */
    return occ_quat_normalize(p->pose.q, &p->pose.q) == OCC_OK && occ_pose_check(&p->pose) == OCC_OK;
}

occ_err_t occ_tum_read_depth_list(const char *path, occ_tum_depth_entry_t **entries, size_t *n,
                                  char *msg, size_t msg_len)
{
    if (path == NULL || entries == NULL || n == NULL) {
        return OCC_ERR_ARG;
    }
    void *arr = NULL;
    const occ_err_t e = read_lines(path, parse_depth, sizeof **entries,
                                   "expected 'timestamp file' with increasing times", &arr, n,
                                   msg, msg_len);
    *entries = arr;
    return e;
}

occ_err_t occ_tum_read_groundtruth(const char *path, occ_pose_sample_t **samples, size_t *n,
                                   char *msg, size_t msg_len)
{
    if (path == NULL || samples == NULL || n == NULL) {
        return OCC_ERR_ARG;
    }
    void *arr = NULL;
    const occ_err_t e = read_lines(path, parse_pose, sizeof **samples,
                                   "expected 'timestamp tx ty tz qx qy qz qw' with increasing "
                                   "times and a unit quaternion",
                                   &arr, n, msg, msg_len);
    *samples = arr;
    return e;
}

occ_err_t occ_tum_history_fill(occ_pose_history_t *h, const occ_pose_sample_t *samples, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        const occ_err_t e = occ_pose_history_push(h, samples[i].t_us, &samples[i].pose);
        if (e != OCC_OK) {
            return e;
        }
    }
    return OCC_OK;
}

/* The ground truth of `dir` as a history over *storage (malloc'd, the caller frees it). */
static occ_err_t load_history(const char *dir, occ_pose_history_t *h,
                              occ_pose_sample_t **storage, char *msg, size_t msg_len)
{
    char path[4096];
    (void)snprintf(path, sizeof path, "%s/groundtruth.txt", dir);
    size_t n = 0;
    occ_err_t e = occ_tum_read_groundtruth(path, storage, &n, msg, msg_len);
    if (e == OCC_OK && n < 2u) {
        line_msg(msg, msg_len, path, 0u, "fewer than two poses");
        e = OCC_ERR_FORMAT;
    }
    const occ_pose_history_cfg_t cfg = {OCC_TUM_MAX_GAP_US, 0u};
    if (e == OCC_OK) {
        e = occ_pose_history_init(h, *storage, n, &cfg);
    }
    return e == OCC_OK ? occ_tum_history_fill(h, *storage, n) : e;
}

typedef struct {
    occ_scan_frame_t *frames;
    size_t n, cap, dropped;
} frame_list_t;

/* One depth.txt entry: its frame appended, or skipped (no PNG), or dropped (no pose). */
static occ_err_t add_entry(const char *dir, const occ_tum_depth_entry_t *en,
                           occ_pose_history_t *h, const occ_depth_camera_t *cam, unsigned stride,
                           frame_list_t *fl, char *msg, size_t msg_len)
{
    char png_path[4096];
    (void)snprintf(png_path, sizeof png_path, "%s/%s", dir, en->file);
    FILE *const probe = fopen(png_path, "rb");
    if (probe == NULL) {
        return OCC_OK; /* frame not in this copy of the data set */
    }
    (void)fclose(probe);
    occ_pose_t pose;
    if (occ_pose_history_at(h, en->t_us, &pose, NULL) != OCC_OK) {
        fl->dropped++;
        return OCC_OK;
    }
    void *const slot = grow((void **)&fl->frames, &fl->cap, fl->n, sizeof *fl->frames);
    if (slot == NULL) {
        return OCC_ERR_NOMEM;
    }
    const float t[3] = {pose.p.x, pose.p.y, pose.p.z};
    const float q[4] = {pose.q.w, pose.q.x, pose.q.y, pose.q.z};
    const occ_err_t e = occ_depth_read_png(png_path, cam, t, q, stride, &fl->frames[fl->n], msg,
                                           msg_len);
    fl->n += e == OCC_OK ? 1u : 0u;
    return e;
}

occ_err_t occ_depth_read_tum_sequence(const char *dir, const occ_depth_camera_t *cam,
                                      unsigned stride, size_t max_frames,
                                      occ_scan_frame_t **frames, size_t *n_frames,
                                      size_t *n_dropped, char *msg, size_t msg_len)
{
    if (dir == NULL || cam == NULL || frames == NULL || n_frames == NULL || n_dropped == NULL) {
        return OCC_ERR_ARG;
    }
    *frames = NULL;
    *n_frames = 0;
    *n_dropped = 0;
    char path[4096];
    (void)snprintf(path, sizeof path, "%s/depth.txt", dir);
    occ_tum_depth_entry_t *list = NULL;
    size_t n_list = 0;
    occ_pose_sample_t *storage = NULL;
    occ_pose_history_t h;
    occ_err_t e = occ_tum_read_depth_list(path, &list, &n_list, msg, msg_len);
    if (e == OCC_OK) {
        e = load_history(dir, &h, &storage, msg, msg_len);
    }
    frame_list_t fl = {NULL, 0, 0, 0};
    for (size_t i = 0; e == OCC_OK && i < n_list && (max_frames == 0u || fl.n < max_frames); i++) {
        e = add_entry(dir, &list[i], &h, cam, stride, &fl, msg, msg_len);
    }
    free(list);
    free(storage);
    if (e == OCC_OK && fl.n == 0u) {
        line_msg(msg, msg_len, path, 0u, "no depth frame with a pose was found");
        e = OCC_ERR_IO;
    }
    if (e != OCC_OK) {
        occ_scan_frames_free(fl.frames, fl.n);
        return e;
    }
    *frames = fl.frames;
    *n_frames = fl.n;
    *n_dropped = fl.dropped;
    return OCC_OK;
}
