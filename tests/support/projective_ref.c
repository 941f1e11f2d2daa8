/* SPDX-License-Identifier: BSD-3-Clause */
/* projective_ref.c - the brute-force oracle of the projective rule (see projective_ref.h). */
#include "projective_ref.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Pixel depth per the header: NaN for no reading / too close / non-finite range. */
static float ref_depth(const occ_proj_image_t *im, const occ_proj_camera_t *k, uint32_t i,
                       uint32_t j, float c[3])
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
    c[0] = ((float)i - k->cx) * d / k->fx;
    c[1] = ((float)j - k->cy) * d / k->fy;
    c[2] = d;
    const float r2 = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
    if (!isfinite(r2) || r2 < k->min_range_m * k->min_range_m) {
        return NAN;
    }
    return d;
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
            float c[3];
            if (isnan(ref_depth(im, k, i, j, c)) ||
                c[0] * c[0] + c[1] * c[1] + c[2] * c[2] > max2) {
                continue;
            }
            (*pts)[n].x = k->r[0][0] * c[0] + k->r[0][1] * c[1] + k->r[0][2] * c[2] + k->t.x;
            (*pts)[n].y = k->r[1][0] * c[0] + k->r[1][1] * c[1] + k->r[1][2] * c[2] + k->t.y;
            (*pts)[n].z = k->r[2][0] * c[0] + k->r[2][1] * c[1] + k->r[2][2] * c[2] + k->t.z;
            n++;
        }
    }
    return n;
}

/* The rule for one voxel centre: free? */
static bool ref_free(const occ_map_t *map, const occ_proj_image_t *im,
                     const occ_proj_camera_t *k, occ_vec3_t centre)
{
    const float w[3] = {centre.x - k->t.x, centre.y - k->t.y, centre.z - k->t.z};
    float q[3];
    for (unsigned a = 0; a < 3u; a++) {
        q[a] = k->r[0][a] * w[0] + k->r[1][a] * w[1] + k->r[2][a] * w[2];
    }
    if (!(q[2] > 0.0f)) {
        return false;
    }
    const float u = floorf(k->fx * (q[0] / q[2]) + k->cx + 0.5f);
    const float v = floorf(k->fy * (q[1] / q[2]) + k->cy + 0.5f);
    if (!(u >= 0.0f && u < (float)im->width && v >= 0.0f && v < (float)im->height)) {
        return false;
    }
    float c[3];
    const float d = ref_depth(im, k, (uint32_t)u, (uint32_t)v, c);
    const float m0 = 0.8660254f * map->cfg.resolution_m;
    if (isnan(d) || !(q[2] < (1.0f - k->noise_rel) * d - m0)) {
        return false;
    }
    return q[0] * q[0] + q[1] * q[1] + q[2] * q[2] <= k->max_range_m * k->max_range_m;
}

size_t projref_codes(const occ_map_t *map, const occ_proj_image_t *im,
                     const occ_proj_camera_t *cam, occ_code_t **codes, size_t *n_hits)
{
    occ_vec3_t *pts = NULL;
    const size_t np = projref_end_points(im, cam, &pts);
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
        occ_key_t key;
        if (occ_map_key(map, pts[i], &key) == OCC_OK) {
            c[n++] = occ_morton_encode(key) | OCC_CODE_HIT_BIT;
        }
    }
    free(pts);
    occ_key_t key;
    for (key.k[2] = lo[2]; key.k[2] <= hi[2]; key.k[2]++) {
        for (key.k[1] = lo[1]; key.k[1] <= hi[1]; key.k[1]++) {
            for (key.k[0] = lo[0]; key.k[0] <= hi[0]; key.k[0]++) {
                if (!ref_free(map, im, cam, occ_map_key_center(map, key, 0u))) {
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
    qsort(c, n, sizeof *c, by_code);
    size_t u = 0, hits = 0;
    for (size_t i = 0; i < n; i++) {
        if (u > 0u && by_code(&c[u - 1u], &c[i]) == 0) {
            c[u - 1u] |= c[i] & OCC_CODE_HIT_BIT;
        } else {
            c[u++] = c[i];
        }
    }
    for (size_t i = 0; i < u; i++) {
        hits += (c[i] & OCC_CODE_HIT_BIT) != 0u ? 1u : 0u;
    }
    *n_hits = hits;
    *codes = c;
    return u;
}
