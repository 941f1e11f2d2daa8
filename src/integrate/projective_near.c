/* SPDX-License-Identifier: BSD-3-Clause */
/* projective_near.c - the near field: within a few voxels of the camera a voxel is large against
 * the frustum's cross-section, so most voxels there have their centre outside the image though
 * the camera's rays cross them (OctoMap frees them). Exact rays (computeRayKeys) from the camera
 * along a sparse grid of pixels, each to OCC_PROJ_NEAR_VOXELS voxels of depth, the front of its
 * surface or max range along its ray, whichever is nearest, free the voxels they cross
 * (occ_integrate.h). */
#include <math.h>
#include <string.h>

#include "projective_internal.h"

/* Pixels on the grid: every `step`-th of a row or column and the last one. */
static uint32_t next_on_grid(const uint32_t i, const uint32_t step, const uint32_t n)
{
    return i + 1u == n ? n : (i + step < n ? i + step : n - 1u);
}

uint32_t occi_proj_near_step(const occ_proj_camera_t *const k)
{
    const float f = k->fx < k->fy ? k->fx : k->fy;
    const float s = f / 32.0f; /* a ray every ~1.8 deg */
    return s >= 1.0f ? (s < 65535.0f ? (uint32_t)s : 65535u) : 1u;
}

size_t occi_proj_near_rays(const uint32_t w, const uint32_t h, const uint32_t step)
{
    const size_t nw = (size_t)(w - 1u) / step + 1u + ((w - 1u) % step != 0u ? 1u : 0u);
    const size_t nh = (size_t)(h - 1u) / step + 1u + ((h - 1u) % step != 0u ? 1u : 0u);
    return nw * nh;
}

/* The near ray of pixel (i, j) with depth d (a reading): its end point (the header's
 * arithmetic), false when it has no length. Its depth is also held to max range along the
 * pixel's ray: far off the optical axis (a very wide field of view, or a principal point off
 * the image) 4 voxels of depth are a long ray, and a reading beyond max range frees no further
 * than max range. */
static bool ray_end(const occ_proj_t *const x, const uint32_t i, const uint32_t j, const float d,
                    float e[3])
{
    const occ_proj_camera_t *const k = x->cam;
    const float a = ((float)i - k->cx) / k->fx, b = ((float)j - k->cy) / k->fy;
    const float reach = k->max_range_m / sqrtf(a * a + (b * b + 1.0f));
    const float front = occ_proj_front(x, d);
    float z = front < x->near_z ? front : x->near_z;
    z = reach < z ? reach : z;
    if (!(z > 0.0f)) {
        return false;
    }
    const float t[3] = {k->t.x, k->t.y, k->t.z};
    for (unsigned ax = 0; ax < 3u; ax++) {
        e[ax] = (k->r[ax][0] * a + k->r[ax][1] * b + k->r[ax][2]) * z + t[ax];
    }
    return true;
}

bool occi_proj_near(occ_proj_t *const x)
{
    const uint32_t w = x->im->width, h = x->im->height, step = occi_proj_near_step(x->cam);
    const float o[3] = {x->cam->t.x, x->cam->t.y, x->cam->t.z};
    const uint32_t ko[3] = {(uint32_t)x->kcam[0], (uint32_t)x->kcam[1], (uint32_t)x->kcam[2]};
    occ_code_t *const out = x->out + x->nh;
    const size_t cap = x->cap - x->nh;
    size_t n = 0;
    for (uint32_t j = 0; j < h; j = next_on_grid(j, step, h)) {
        for (uint32_t i = 0; i < w; i = next_on_grid(i, step, w)) {
            const float d = x->d0[(size_t)j * w + i];
            float e[3];
            uint32_t ke[3];
            if (!(d > 0.0f) || !ray_end(x, i, j, d, e) || !occi_raygeo_key(&x->g, e, ke)) {
                continue; /* no reading, no length, or its end off the map */
            }
            const size_t room = cap / 2u > n ? cap / 2u - n : 0u; /* codes and the sort's temporary */
            const size_t got = occi_dda_codes(&x->g, o, e, ko, ke, out + n, room);
            if (got > room) {
                return false;
            }
            n += got;
        }
    }
    occ_code_t *const sorted = occi_keyset_sort(out, out + n, n, x->hist);
    if (sorted != out) {
        memcpy(out, sorted, n * sizeof *sorted);
    }
    x->hwm = x->hwm > x->nh + 2u * n ? x->hwm : x->nh + 2u * n;
    x->near = out;
    x->nr = occi_keyset_unique(out, n);
    return true;
}
