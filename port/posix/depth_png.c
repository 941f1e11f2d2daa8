/* SPDX-License-Identifier: BSD-3-Clause */
/* depth_png.c - 16-bit depth PNGs (libpng) back-projected to points; TUM RGB-D directories. */
#include <errno.h>
#include <math.h>
#include <png.h>
#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "occmap/host/occ_scan.h"

occ_depth_camera_t occ_depth_camera_tum_fr2(void)
{
    const occ_depth_camera_t c = {520.9f, 521.0f, 325.1f, 249.7f, 5000.0f};
    return c;
}

typedef struct {
    jmp_buf jb;
    char why[160];
} png_err_t;

static void on_png_error(png_structp png, png_const_charp text)
{
    png_err_t *const pe = png_get_error_ptr(png);
    (void)snprintf(pe->why, sizeof pe->why, "%s", text);
    longjmp(pe->jb, 1);
}

static void on_png_warning(png_structp png, png_const_charp text)
{
    (void)png;
    (void)text;
}

static void set_msg(char *msg, size_t len, const char *path, long off, const char *what)
{
    if (msg != NULL && len > 0u) {
        if (off >= 0) {
            (void)snprintf(msg, len, "%s: byte %ld: %s", path, off, what);
        } else {
            (void)snprintf(msg, len, "%s: %s", path, what);
        }
    }
}

/* Everything libpng touches lives here so that longjmp leaves no indeterminate locals. */
typedef struct {
    FILE *f;
    png_structp png;
    png_infop info;
    uint16_t *pix;
    occ_vec3_t *pts;
    png_bytep *rows;
    png_err_t pe;
} png_job_t;

/* A cleared job with its file open; OCC_ERR_IO (and `msg`) when the file cannot be opened. */
static occ_err_t job_open(png_job_t *const j, const char *path, char *msg, size_t msg_len)
{
    memset(j, 0, sizeof *j);
    j->f = fopen(path, "rb");
    if (j->f == NULL) {
        set_msg(msg, msg_len, path, -1, strerror(errno));
        return OCC_ERR_IO;
    }
    return OCC_OK;
}

static occ_err_t decode(png_job_t *const j, const char *path, uint32_t *w_out, uint32_t *h_out,
                        char *msg, size_t msg_len)
{
    unsigned char sig[8];
    if (fread(sig, 1, 8, j->f) != 8u || png_sig_cmp(sig, 0, 8) != 0) {
        set_msg(msg, msg_len, path, 0, "not a PNG file");
        return OCC_ERR_FORMAT;
    }
    j->png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &j->pe, on_png_error, on_png_warning);
    if (j->png == NULL) {
        return OCC_ERR_NOMEM;
    }
    j->info = png_create_info_struct(j->png);
    if (j->info == NULL) {
        return OCC_ERR_NOMEM;
    }
    if (setjmp(j->pe.jb) != 0) {
        char why[200];
        (void)snprintf(why, sizeof why, "%s%s", feof(j->f) ? "truncated file: " : "",
                       j->pe.why);
        set_msg(msg, msg_len, path, ftell(j->f), why);
        return OCC_ERR_FORMAT;
    }
    png_init_io(j->png, j->f);
    png_set_sig_bytes(j->png, 8);
    png_read_info(j->png, j->info);
    const uint32_t w = png_get_image_width(j->png, j->info);
    const uint32_t h = png_get_image_height(j->png, j->info);
    if (png_get_bit_depth(j->png, j->info) != 16 ||
        png_get_color_type(j->png, j->info) != PNG_COLOR_TYPE_GRAY ||
        png_get_interlace_type(j->png, j->info) != PNG_INTERLACE_NONE) {
        set_msg(msg, msg_len, path, ftell(j->f), "not a 16-bit grayscale non-interlaced PNG");
        return OCC_ERR_FORMAT;
    }
    if (w == 0u || h == 0u || w > 16384u || h > 16384u) {
        set_msg(msg, msg_len, path, ftell(j->f), "image size out of range");
        return OCC_ERR_FORMAT;
    }
    png_set_swap(j->png); /* PNG is big-endian; the host is little-endian */
    j->pix = malloc((size_t)w * h * sizeof *j->pix);
    j->rows = malloc(h * sizeof *j->rows);
    if (j->pix == NULL || j->rows == NULL) {
        return OCC_ERR_NOMEM;
    }
    for (uint32_t v = 0; v < h; v++) {
        j->rows[v] = (png_bytep)(void *)(j->pix + (size_t)v * w);
    }
    png_read_image(j->png, j->rows);
    png_read_end(j->png, NULL);
    *w_out = w;
    *h_out = h;
    return OCC_OK;
}

occ_err_t occ_depth_read_png(const char *path, const occ_depth_camera_t *cam, const float t[3],
                             const float q[4], unsigned stride, occ_scan_frame_t *frame,
                             char *msg, size_t msg_len)
{
    if (path == NULL || cam == NULL || t == NULL || q == NULL || frame == NULL) {
        return OCC_ERR_ARG;
    }
    if (stride == 0u) {
        stride = 1u;
    }
    memset(frame, 0, sizeof *frame);
    png_job_t j;
    if (job_open(&j, path, msg, msg_len) != OCC_OK) {
        return OCC_ERR_IO;
    }
    uint32_t w = 0, h = 0;
    occ_err_t e = decode(&j, path, &w, &h, msg, msg_len);
    if (e == OCC_OK) {
        j.pts = malloc((size_t)w * h * sizeof *j.pts);
        if (j.pts == NULL) {
            e = OCC_ERR_NOMEM;
        }
    }
    size_t n = 0;
    if (e == OCC_OK) {
        const double q0 = (double)q[0], q1 = (double)q[1], q2 = (double)q[2], q3 = (double)q[3];
        const double qn = sqrt(q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3);
        const double qw = q0 / qn, qx = q1 / qn, qy = q2 / qn, qz = q3 / qn;
        const double r[3][3] = {
            {1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qw * qz), 2 * (qx * qz + qw * qy)},
            {2 * (qx * qy + qw * qz), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qw * qx)},
            {2 * (qx * qz - qw * qy), 2 * (qy * qz + qw * qx), 1 - 2 * (qx * qx + qy * qy)},
        };
        for (uint32_t v = 0; v < h; v += stride) {
            for (uint32_t u = 0; u < w; u += stride) {
                const uint16_t raw = j.pix[(size_t)v * w + u];
                if (raw == 0u) {
                    continue;
                }
                const double d = (double)raw / (double)cam->depth_scale;
                const double c[3] = {((double)u - (double)cam->cx) * d / (double)cam->fx,
                                     ((double)v - (double)cam->cy) * d / (double)cam->fy, d};
                occ_vec3_t p;
                p.x = (float)(r[0][0] * c[0] + r[0][1] * c[1] + r[0][2] * c[2] + (double)t[0]);
                p.y = (float)(r[1][0] * c[0] + r[1][1] * c[1] + r[1][2] * c[2] + (double)t[1]);
                p.z = (float)(r[2][0] * c[0] + r[2][1] * c[1] + r[2][2] * c[2] + (double)t[2]);
                j.pts[n++] = p;
            }
        }
    }
    if (j.png != NULL) {
        png_destroy_read_struct(&j.png, j.info != NULL ? &j.info : NULL, NULL);
    }
    (void)fclose(j.f);
    free(j.pix);
    free(j.rows);
    if (e != OCC_OK) {
        free(j.pts);
        return e;
    }
    frame->points = j.pts;
    frame->n_points = n;
    frame->origin.x = t[0];
    frame->origin.y = t[1];
    frame->origin.z = t[2];
    memcpy(frame->pose_t, t, sizeof frame->pose_t);
    memcpy(frame->pose_q, q, sizeof frame->pose_q);
    const char *const base = strrchr(path, '/');
    (void)snprintf(frame->name, sizeof frame->name, "%s", base != NULL ? base + 1 : path);
    return OCC_OK;
}

occ_err_t occ_depth_read_png_image(const char *path, uint16_t **pixels, uint32_t *width,
                                   uint32_t *height, char *msg, size_t msg_len)
{
    if (path == NULL || pixels == NULL || width == NULL || height == NULL) {
        return OCC_ERR_ARG;
    }
    *pixels = NULL;
    png_job_t j;
    if (job_open(&j, path, msg, msg_len) != OCC_OK) {
        return OCC_ERR_IO;
    }
    const occ_err_t e = decode(&j, path, width, height, msg, msg_len);
    if (j.png != NULL) {
        png_destroy_read_struct(&j.png, j.info != NULL ? &j.info : NULL, NULL);
    }
    (void)fclose(j.f);
    free(j.rows);
    if (e != OCC_OK) {
        free(j.pix);
        return e;
    }
    *pixels = j.pix;
    return OCC_OK;
}

occ_err_t occ_depth_read_tum_dir(const char *dir, unsigned stride, size_t max_frames,
                                 occ_scan_frame_t **frames, size_t *n_frames, char *msg,
                                 size_t msg_len)
{
    if (dir == NULL || frames == NULL || n_frames == NULL) {
        return OCC_ERR_ARG;
    }
    *frames = NULL;
    *n_frames = 0;
    char path[4096];
    (void)snprintf(path, sizeof path, "%s/my_association.txt", dir);
    FILE *const f = fopen(path, "r");
    if (f == NULL) {
        set_msg(msg, msg_len, path, -1, strerror(errno));
        return OCC_ERR_IO;
    }
    const occ_depth_camera_t cam = occ_depth_camera_tum_fr2();
    occ_scan_frame_t *out = NULL;
    size_t n = 0, cap = 0;
    occ_err_t e = OCC_OK;
    char line[1024];
    unsigned long lineno = 0;
    while (e == OCC_OK && (max_frames == 0u || n < max_frames) && fgets(line, sizeof line, f)) {
        lineno++;
        if (line[0] == '#' || line[0] == '\n' || line[0] == '\r') {
            continue;
        }
        char rgb[512], depth[512], tail;
        float t[3], qv[4];
        if (strchr(line, '\n') == NULL && !feof(f)) {
            e = OCC_ERR_FORMAT;
        } else if (sscanf(line, "%511s %511s %f %f %f %f %f %f %f %c", rgb, depth, &t[0], &t[1],
                          &t[2], &qv[0], &qv[1], &qv[2], &qv[3], &tail) != 9) {
            e = OCC_ERR_FORMAT;
        }
        if (e != OCC_OK) {
            char what[64];
            (void)snprintf(what, sizeof what, "line %lu: expected 'rgb depth tx ty tz qx qy qz qw'",
                           lineno);
            set_msg(msg, msg_len, path, -1, what);
            break;
        }
        char png_path[4096];
        (void)snprintf(png_path, sizeof png_path, "%s/%s", dir, depth);
        FILE *const probe = fopen(png_path, "rb");
        if (probe == NULL) {
            continue; /* frame not in this copy of the data set */
        }
        (void)fclose(probe);
        if (n == cap) {
            const size_t nc = cap == 0u ? 16u : cap * 2u;
            occ_scan_frame_t *const g = realloc(out, nc * sizeof *g);
            if (g == NULL) {
                e = OCC_ERR_NOMEM;
                break;
            }
            out = g;
            cap = nc;
        }
        const float q[4] = {qv[3], qv[0], qv[1], qv[2]}; /* file order x y z w */
        e = occ_depth_read_png(png_path, &cam, t, q, stride, &out[n], msg, msg_len);
        if (e == OCC_OK) {
            n++;
        }
    }
    (void)fclose(f);
    if (e == OCC_OK && n == 0u) {
        set_msg(msg, msg_len, path, -1, "no depth frame of the association file was found");
        e = OCC_ERR_IO;
    }
    if (e != OCC_OK) {
        occ_scan_frames_free(out, n);
        return e;
    }
    *frames = out;
    *n_frames = n;
    return OCC_OK;
}
