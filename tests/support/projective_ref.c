/* SPDX-License-Identifier: BSD-3-Clause */
/* projective_ref.c - the brute-force oracle of the projective rule (see projective_ref.h). */
#include "projective_ref.h"

#include "geom/geom_internal.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The frame's per-pixel arithmetic (occ_integrate.h): a = (i - cx) / fx, b = (j - cy) / fy,
 * |c|^2 = (d d) (a a + (b b + 1)). */
typedef struct {
    float a, b, r2;
} ref_ray_t;

static ref_ray_t ref_ray(const occ_proj_camera_t *k, uint32_t i, uint32_t j, float d)
{
    ref_ray_t r;
    r.a = ((float)i - k->cx) / k->fx;
    r.b = ((float)j - k->cy) / k->fy;
    r.r2 = (d * d) * (r.a * r.a + (r.b * r.b + 1.0f));
    return r;
}

/* Pixel depth per the header: NaN for no reading / too close / non-finite range. */
static float ref_depth(const occ_proj_image_t *im, const occ_proj_camera_t *k, uint32_t i,
                       uint32_t j, ref_ray_t *ray)
{
    const unsigned char *p = (const unsigned char *)im->data + (size_t)j * im->row_stride_bytes +
                             (size_t)i * im->pixel_stride_bytes;
    float d;
    if (im->format == OCC_PROJ_U16) {
        uint16_t raw;
        memcpy(&raw, p, 2);
        d = raw == 0u ? NAN : (float)raw * im->depth_scale_m;
    } else {
        memcpy(&d, p, 4);
        if (d > 1024.0f * k->max_range_m) {
            d = 2.0f * k->max_range_m;
        }
    }
    if (!(d > 0.0f)) {
        return NAN;
    }
    *ray = ref_ray(k, i, j, d);
    if (!(ray->r2 <= FLT_MAX) || ray->r2 < k->min_range_m * k->min_range_m) {
        return NAN;
    }
    return d;
}

/* The depth the free test uses (occ_integrate.h): the pixel's reading, else the smallest
 * reading among its four neighbours (left, right, up, down), else NaN. */
static float ref_free_depth(const occ_proj_image_t *im, const occ_proj_camera_t *k, uint32_t i,
                            uint32_t j)
{
    ref_ray_t ray;
    const float d = ref_depth(im, k, i, j, &ray);
    if (!isnan(d)) {
        return d;
    }
    float best = NAN;
    const int di[4] = {-1, 1, 0, 0}, dj[4] = {0, 0, -1, 1};
    for (unsigned n = 0; n < 4u; n++) {
        const int64_t ni = (int64_t)i + di[n], nj = (int64_t)j + dj[n];
        if (ni < 0 || nj < 0 || ni >= (int64_t)im->width || nj >= (int64_t)im->height) {
            continue;
        }
        const float e = ref_depth(im, k, (uint32_t)ni, (uint32_t)nj, &ray);
        if (!isnan(e) && (isnan(best) || e < best)) {
            best = e;
        }
    }
    return best;
}

static int by_code(const void *a, const void *b)
{
    const occ_code_t x = *(const occ_code_t *)a & ~OCC_CODE_HIT_BIT;
    const occ_code_t y = *(const occ_code_t *)b & ~OCC_CODE_HIT_BIT;
    return x < y ? -1 : (x > y ? 1 : 0);
}

size_t projref_end_points(const occ_proj_image_t *im, const occ_proj_camera_t *k,
                          occ_vec3_t **pts)
{
    *pts = malloc(((size_t)im->width * im->height + 1u) * sizeof **pts);
    size_t n = 0;
    const float max2 = k->max_range_m * k->max_range_m;
    for (uint32_t j = 0; j < im->height; j++) {
        for (uint32_t i = 0; i < im->width; i++) {
            ref_ray_t ray;
            const float d = ref_depth(im, k, i, j, &ray);
            if (isnan(d) || ray.r2 > max2) {
                continue;
            }
            float p[3];
            for (unsigned a = 0; a < 3u; a++) {
                p[a] = d * (k->r[a][0] * ray.a + k->r[a][1] * ray.b + k->r[a][2]);
            }
            (*pts)[n].x = p[0] + k->t.x;
            (*pts)[n].y = p[1] + k->t.y;
            (*pts)[n].z = p[2] + k->t.z;
            n++;
        }
    }
    return n;
}

size_t projref_end_keys(const occ_map_t *map, const occ_proj_image_t *im,
                        const occ_proj_camera_t *k, occ_key_t **keys)
{
    *keys = malloc(((size_t)im->width * im->height + 1u) * sizeof **keys);
    const double rfd = occ_geom_inv(map); /* the map's 1 / resolution */
    const float rf = (float)rfd, max2 = k->max_range_m * k->max_range_m;
    const float hit_m = 4194304.0f * map->cfg.resolution_m; /* 2^22 voxels */
    const float max2h = max2 < hit_m * hit_m ? max2 : hit_m * hit_m;
    const float t[3] = {k->t.x, k->t.y, k->t.z};
    const int64_t side = (int64_t)1 << map->cfg.depth_levels;
    occ_key_t kt;
    if (occ_map_key(map, k->t, &kt) != OCC_OK) {
        return 0;
    }
    float frac[3];
    for (unsigned a = 0; a < 3u; a++) {
        const double s = (double)t[a] * rfd;
        frac[a] = (float)(s - floor(s));
    }
    size_t n = 0;
    for (uint32_t j = 0; j < im->height; j++) {
        for (uint32_t i = 0; i < im->width; i++) {
            ref_ray_t ray;
            const float d = ref_depth(im, k, i, j, &ray);
            if (isnan(d) || !(ray.r2 <= max2h)) {
                continue;
            }
            occ_key_t key;
            bool inside = true;
            for (unsigned a = 0; a < 3u; a++) {
                const float u = (k->r[a][0] * ray.a) * rf;
                const float v = (k->r[a][1] * ray.b + k->r[a][2]) * rf;
                const float e = d * (u + v) + frac[a];
                const int64_t kk = (int64_t)kt.k[a] + (int64_t)floorf(e);
                inside = inside && kk >= 0 && kk < side;
                key.k[a] = inside ? (uint32_t)kk : 0u;
            }
            if (inside) {
                (*keys)[n++] = key;
            }
        }
    }
    return n;
}

/* The rule for one voxel centre: free? */
static bool ref_free(const occ_proj_image_t *im, const occ_proj_camera_t *k, occ_vec3_t centre)
{
    const float w[3] = {centre.x - k->t.x, centre.y - k->t.y, centre.z - k->t.z};
    float q[3];
    for (unsigned a = 0; a < 3u; a++) {
        q[a] = k->r[0][a] * w[0] + k->r[1][a] * w[1] + k->r[2][a] * w[2];
    }
    if (!(q[2] > 0.0f)) {
        return false;
    }
    const float iz = 1.0f / q[2];
    const float u = floorf(k->fx * (q[0] * iz) + k->cx + 0.5f);
    const float v = floorf(k->fy * (q[1] * iz) + k->cy + 0.5f);
    if (!(u >= 0.0f && u < (float)im->width && v >= 0.0f && v < (float)im->height)) {
        return false;
    }
    const float d = ref_free_depth(im, k, (uint32_t)u, (uint32_t)v);
    if (isnan(d) || !(q[2] < (1.0f - k->noise_rel) * d)) {
        return false;
    }
    return q[0] * q[0] + q[1] * q[1] + q[2] * q[2] <= k->max_range_m * k->max_range_m;
}

/* The near field (occ_integrate.h): rays from the camera along the pixel grid (every step-th
 * pixel and the last of a row and a column, step = min(fx, fy) / 32 truncated, at least 1) with
 * a reading, to depth min(front of its surface, 4 voxels, max range along the pixel's ray); the
 * voxels occ_ray_keys() gives for each (the camera's first, the end's excluded; however long
 * the ray) are free. Appended to c[n..). */
static size_t ref_near(const occ_map_t *map, const occ_proj_image_t *im,
                       const occ_proj_camera_t *k, occ_code_t **c, size_t n, size_t *cap)
{
    const float f = k->fx < k->fy ? k->fx : k->fy;
    const uint32_t step = f / 32.0f >= 1.0f ? (uint32_t)(f / 32.0f) : 1u;
    const float near = 4.0f * map->cfg.resolution_m;
    const float keep = 1.0f - k->noise_rel;
    const float t[3] = {k->t.x, k->t.y, k->t.z};
    for (uint32_t j = 0; j < im->height; j = j + 1u == im->height ? j + 1u : (j + step < im->height ? j + step : im->height - 1u)) {
        for (uint32_t i = 0; i < im->width; i = i + 1u == im->width ? i + 1u : (i + step < im->width ? i + step : im->width - 1u)) {
            const float d = ref_free_depth(im, k, i, j);
            const float a = ((float)i - k->cx) / k->fx, b = ((float)j - k->cy) / k->fy;
            const float reach = k->max_range_m / sqrtf(a * a + (b * b + 1.0f));
            const float front = keep * d;
            float z = front < near ? front : near;
            z = reach < z ? reach : z;
            if (isnan(d) || !(z > 0.0f)) {
                continue;
            }
            float e[3];
            for (unsigned ax = 0; ax < 3u; ax++) {
                e[ax] = (k->r[ax][0] * a + k->r[ax][1] * b + k->r[ax][2]) * z + t[ax];
            }
            size_t nk = 0;
            const occ_vec3_t ev = {e[0], e[1], e[2]};
            const size_t room = occ_ray_max_keys(map, k->t, ev); /* 0: the end off the map */
            occ_key_t *const keys = malloc((room + 1u) * sizeof *keys);
            if (keys == NULL || room == 0u ||
                occ_ray_keys(map, k->t, ev, keys, room, &nk) != OCC_OK) {
                free(keys);
                continue;
            }
            for (size_t q = 0; q < nk; q++) {
                if (n == *cap) {
                    *cap *= 2u;
                    *c = realloc(*c, *cap * sizeof **c);
                }
                (*c)[n++] = occ_morton_encode(keys[q]);
            }
            free(keys);
        }
    }
    return n;
}

size_t projref_codes(const occ_map_t *map, const occ_proj_image_t *im,
                     const occ_proj_camera_t *cam, occ_code_t **codes, size_t *n_hits)
{
    occ_key_t *pts = NULL;
    const size_t np = projref_end_keys(map, im, cam, &pts);
    uint32_t lo[3], hi[3];
    const float t[3] = {cam->t.x, cam->t.y, cam->t.z};
    size_t box = 1;
    for (unsigned a = 0; a < 3u; a++) {
        (void)occ_map_key_range(map, t[a] - cam->max_range_m, t[a] + cam->max_range_m, &lo[a],
                                &hi[a]);
        box *= (size_t)(hi[a] - lo[a] + 1u);
    }
    size_t cap = np + 1024u, n = 0;
    occ_code_t *c = malloc(cap * sizeof *c);
    for (size_t i = 0; i < np; i++) {
        c[n++] = occ_morton_encode(pts[i]) | OCC_CODE_HIT_BIT;
    }
    free(pts);
    occ_key_t key;
    for (key.k[2] = lo[2]; key.k[2] <= hi[2]; key.k[2]++) {
        for (key.k[1] = lo[1]; key.k[1] <= hi[1]; key.k[1]++) {
            for (key.k[0] = lo[0]; key.k[0] <= hi[0]; key.k[0]++) {
                if (!ref_free(im, cam, occ_map_key_center(map, key, 0u))) {
                    continue;
                }
                if (n == cap) {
                    cap *= 2u;
                    c = realloc(c, cap * sizeof *c);
                }
                c[n++] = occ_morton_encode(key);
            }
        }
    }
    (void)box;
    n = ref_near(map, im, cam, &c, n, &cap);
    const size_t u = projref_sort_unique(c, n);
    size_t hits = 0;
    for (size_t i = 0; i < u; i++) {
        hits += (c[i] & OCC_CODE_HIT_BIT) != 0u ? 1u : 0u;
    }
    *n_hits = hits;
    *codes = c;
    return u;
}

void projref_rotation_of(const occ_pose_t *const pose, float r[3][3])
{
    const occ_vec3_t axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (unsigned b = 0; b < 3u; b++) {
        const occ_vec3_t col = occ_pose_rotate(pose, axes[b]);
        r[0][b] = col.x;
        r[1][b] = col.y;
        r[2][b] = col.z;
    }
}

size_t projref_sort_unique(occ_code_t *const c, const size_t n)
{
    qsort(c, n, sizeof *c, by_code);
    size_t u = 0;
    for (size_t i = 0; i < n; i++) {
        if (u > 0u && by_code(&c[u - 1u], &c[i]) == 0) {
            c[u - 1u] |= c[i] & OCC_CODE_HIT_BIT;
        } else {
            c[u++] = c[i];
        }
    }
    return u;
}
