/* SPDX-License-Identifier: BSD-3-Clause */
/* depth.c - depth images: validate, back-project the valid pixels into the scratch, and hand
 * them to occ_map_insert_cloud() with the rest of the scratch. */
#include <math.h>
#include <string.h>

#include "occmap/occ_depth.h"

static bool finite_pos(const float v)
{
    return isfinite(v) && v > 0.0f;
}

static size_t pixel_bytes(const occ_depth_format_t f)
{
    return f == OCC_DEPTH_U16 ? 2u : 4u;
}

static bool image_ok(const occ_depth_image_t *im)
{
    if (im->data == NULL || (im->format != OCC_DEPTH_U16 && im->format != OCC_DEPTH_F32)) {
        return false;
    }
    if (im->width == 0u || im->height == 0u || im->width > OCC_DEPTH_MAX_SIDE ||
        im->height > OCC_DEPTH_MAX_SIDE) {
        return false;
    }
    if (im->row_stride_bytes < (size_t)im->width * pixel_bytes(im->format)) {
        return false;
    }
    return im->format != OCC_DEPTH_U16 || finite_pos(im->depth_scale_m);
}

static bool params_ok(const occ_depth_params_t *d)
{
    const occ_pinhole_t *const k = &d->intrinsics;
    if (!finite_pos(k->fx) || !finite_pos(k->fy) || !isfinite(k->cx) || !isfinite(k->cy)) {
        return false;
    }
    if (!isfinite(d->min_range_m) || d->min_range_m < 0.0f || !isfinite(d->max_range_m) ||
        !(d->max_range_m > d->min_range_m)) {
        return false;
    }
    return d->pixel_step >= 1u;
}

size_t occ_depth_scratch_bytes(const occ_map_t *map, const uint32_t width, const uint32_t height,
                               const uint32_t pixel_step, const float max_range_m,
                               const occ_insert_params_t *insert)
{
    if (map == NULL || insert == NULL || width == 0u || height == 0u || pixel_step == 0u ||
        width > OCC_DEPTH_MAX_SIDE || height > OCC_DEPTH_MAX_SIDE || !finite_pos(max_range_m)) {
        return 0u;
    }
    const size_t n = OCC_DEPTH_PIXELS(width, height, pixel_step);
    if (insert->method == OCC_INSERT_PROJECTIVE) {
        const size_t w = (width + pixel_step - 1u) / pixel_step, h = n / w;
        if (n > (SIZE_MAX - OCC_PROJ_FIXED_BYTES - OCC_PROJ_COLUMN_BYTES(w) -
                 8u * (w + h + 20u + 16384u) - 48u) / 24u) {
            return SIZE_MAX; /* a 32-bit size_t: no scratch that big */
        }
        return OCC_PROJ_SCRATCH_BYTES(w, h, OCC_PROJ_OUT_DEFAULT(w, h));
    }
    const size_t cloud = occ_insert_scratch_bytes(map, n, max_range_m, insert);
    if (n > (SIZE_MAX - 3u) / 12u) {
        return SIZE_MAX; /* a 32-bit size_t: no scratch that big */
    }
    const size_t points = 3u + 12u * n;
    return cloud > SIZE_MAX - points ? SIZE_MAX : cloud + points;
}

/* Depth in metres of pixel (u, v), or a value the caller classifies (NaN = no reading). */
static float pixel_depth(const occ_depth_image_t *im, const uint32_t u, const uint32_t v)
{
    const unsigned char *const p =
        (const unsigned char *)im->data + (size_t)v * im->row_stride_bytes +
        (size_t)u * pixel_bytes(im->format);
    if (im->format == OCC_DEPTH_U16) {
        uint16_t raw;
        memcpy(&raw, p, sizeof raw);
        return raw == 0u ? NAN : (float)raw * im->depth_scale_m;
    }
    float d;
    memcpy(&d, p, sizeof d);
    return d;
}

/* Where the points go in the scratch: 4-byte aligned start, room for `cap` of them. */
typedef struct {
    occ_vec3_t *pts;
    size_t cap;
    size_t skip; /* alignment bytes before pts */
} point_buf_t;

static point_buf_t point_buf(void *scratch, const size_t bytes)
{
    point_buf_t b = {NULL, 0u, 0u};
    if (scratch == NULL) {
        return b;
    }
    const uintptr_t a = (uintptr_t)scratch;
    const size_t skip = (size_t)((4u - (a & 3u)) & 3u);
    if (bytes >= skip + sizeof(occ_vec3_t)) {
        b.skip = skip;
        b.pts = (occ_vec3_t *)(void *)((unsigned char *)scratch + skip);
        b.cap = (bytes - skip) / sizeof(occ_vec3_t);
    }
    return b;
}

/* Back-project every pixel on the step grid with a usable reading into buf; counters in out.
 * false when buf is too small (out->points then counts the points that did not fit too). */
static bool back_project(const occ_depth_image_t *im, const occ_depth_params_t *dp,
                         const occ_pose_t *pose, const point_buf_t *buf, occ_depth_result_t *out)
{
    const occ_pinhole_t *const k = &dp->intrinsics;
    const float min2 = dp->min_range_m * dp->min_range_m;
    const float max2 = dp->max_range_m * dp->max_range_m;
    const float far = 1024.0f * dp->max_range_m;
    for (uint32_t v = 0; v < im->height; v += dp->pixel_step) {
        for (uint32_t u = 0; u < im->width; u += dp->pixel_step) {
            out->pixels_sampled++;
            float d = pixel_depth(im, u, v);
            if (!(d > 0.0f)) { /* 0, NaN, negative, -Inf */
                out->pixels_no_reading++;
                continue;
            }
            if (d > far) {
                d = 2.0f * dp->max_range_m; /* +Inf (REP 117 "no return") or absurdly far */
            }
            const occ_vec3_t c = {((float)u - k->cx) * d / k->fx, ((float)v - k->cy) * d / k->fy,
                                  d};
            const float r2 = c.x * c.x + c.y * c.y + c.z * c.z;
            if (!isfinite(r2)) { /* the ray itself overflows float: nothing to integrate */
                out->pixels_no_reading++;
                continue;
            }
            if (r2 < min2) {
                out->pixels_too_close++;
                continue;
            }
            out->pixels_beyond_max += r2 > max2 ? 1u : 0u;
            if (out->points < buf->cap) {
                buf->pts[out->points] = occ_pose_apply(pose, c);
            }
            out->points++;
        }
    }
    return out->points <= buf->cap;
}

/* The points of the step grid in the scratch (from its first 4-aligned byte: *pts), *n of them
 * in its first *used bytes; the counters into out (if non-NULL). OCC_ERR_SCRATCH when they do
 * not fit. Out of line: its counters and loop state are not on the stack under the integration
 * (make cross). */
#if defined(__GNUC__)
__attribute__((noinline))
#endif
static occ_err_t project_points(const occ_depth_image_t *im, const occ_depth_params_t *dp,
                                const occ_pose_t *pose, void *scratch, const size_t scratch_bytes,
                                occ_vec3_t **pts, size_t *n, size_t *used, occ_depth_result_t *out)
{
    occ_depth_result_t r;
    memset(&r, 0, sizeof r);
    const point_buf_t buf = point_buf(scratch, scratch_bytes);
    const bool fit = back_project(im, dp, pose, &buf, &r);
    if (fit) {
        r.scratch_points = buf.skip + r.points * sizeof(occ_vec3_t);
    }
    if (out != NULL) {
        *out = r;
    }
    *pts = buf.pts;
    *n = r.points;
    *used = r.scratch_points;
    return fit ? OCC_OK : OCC_ERR_SCRATCH;
}

/* OCC_INSERT_PROJECTIVE: the image as the projective integrator's view of the step grid (pixel
 * (i, j) is the image's (i step, j step); intrinsics divided by the step) and the pose as a
 * rotation matrix; the counters into out (if non-NULL). Kept out of line: inlined, its camera
 * and result stayed on the stack under the ray-cast methods' whole integration too (make
 * cross). */
#if defined(__GNUC__)
__attribute__((noinline))
#endif
static occ_err_t insert_projective(occ_map_t *map, const occ_depth_image_t *im,
                                   const occ_depth_params_t *dp, const occ_pose_t *pose,
                                   const occ_insert_params_t *insert, void *scratch,
                                   const size_t scratch_bytes, occ_depth_result_t *r)
{
    const uint32_t st = dp->pixel_step;
    const float sf = (float)st;
    const occ_proj_image_t pim = {im->data,
                                  im->format == OCC_DEPTH_U16 ? OCC_PROJ_U16 : OCC_PROJ_F32,
                                  (im->width + st - 1u) / st,
                                  (im->height + st - 1u) / st,
                                  im->height > st ? im->row_stride_bytes * st : im->row_stride_bytes,
                                  im->width > st ? pixel_bytes(im->format) * st : pixel_bytes(im->format),
                                  im->depth_scale_m};
    occ_proj_camera_t cam;
    memset(&cam, 0, sizeof cam);
    cam.fx = dp->intrinsics.fx / sf;
    cam.fy = dp->intrinsics.fy / sf;
    cam.cx = dp->intrinsics.cx / sf;
    cam.cy = dp->intrinsics.cy / sf;
    const occ_vec3_t axes[3] = {{1.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}, {0.0f, 0.0f, 1.0f}};
    for (unsigned b = 0; b < 3u; b++) {
        const occ_vec3_t col = occ_pose_rotate(pose, axes[b]);
        cam.r[0][b] = col.x;
        cam.r[1][b] = col.y;
        cam.r[2][b] = col.z;
    }
    cam.t = pose->p;
    cam.min_range_m = dp->min_range_m;
    cam.max_range_m = dp->max_range_m;
    cam.noise_rel = insert->proj_noise_rel;
    occ_proj_result_t pr;
    const occ_err_t e = occ_map_insert_projective(map, &pim, &cam, scratch, scratch_bytes, &pr);
    if (r != NULL) {
        r->pixels_sampled = pr.pixels;
        r->pixels_no_reading = pr.pixels_no_reading;
        r->pixels_too_close = pr.pixels_too_close;
        r->pixels_beyond_max = pr.pixels_beyond_max;
        r->points = pr.pixels - pr.pixels_no_reading - pr.pixels_too_close;
        r->insert = pr.insert;
    }
    return e;
}

/* Nothing but the insert parameters stays in this frame: it sits on top of the integration,
 * the deepest call chain of the library (make cross, the 1.5 KB class). */
occ_err_t occ_map_insert_depth(occ_map_t *map, const occ_depth_image_t *image,
                               const occ_depth_params_t *depth,
                               const occ_pose_t *map_from_camera,
                               const occ_insert_params_t *insert, void *scratch,
                               const size_t scratch_bytes, occ_depth_result_t *out)
{
    if (out != NULL) {
        memset(out, 0, sizeof *out);
    }
    if (map == NULL || image == NULL || depth == NULL || map_from_camera == NULL ||
        insert == NULL || !image_ok(image) || !params_ok(depth) ||
        occ_pose_check(map_from_camera) != OCC_OK) {
        return OCC_ERR_ARG;
    }
    if (insert->method == OCC_INSERT_PROJECTIVE) {
        return insert_projective(map, image, depth, map_from_camera, insert, scratch, scratch_bytes,
                                 out);
    }
    occ_vec3_t *pts = NULL;
    size_t n = 0, used = 0;
    const occ_err_t e = project_points(image, depth, map_from_camera, scratch, scratch_bytes, &pts,
                                       &n, &used, out);
    if (e != OCC_OK) {
        return e;
    }
    occ_insert_params_t p = *insert;
    p.max_range_m = depth->max_range_m;
    unsigned char *const rest = scratch != NULL ? (unsigned char *)scratch + used : NULL;
    /* occ_map_insert_cloud without its frame: the same call */
    return occ_map_insert_rays(map, &map_from_camera->p, pts, NULL, n, &p, rest,
                               scratch_bytes - used, out != NULL ? &out->insert : NULL);
}
