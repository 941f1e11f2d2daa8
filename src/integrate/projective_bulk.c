/* SPDX-License-Identifier: BSD-3-Clause */
/* projective_bulk.c - the per-voxel rule over every voxel of a small node (level 1 or 2: 8 or
 * 64 voxels) at once, where the walk stops testing nodes. The lanes are in raster order (x
 * fastest) so that the camera-frame coordinates are sums of per-axis rows and the loops
 * vectorise; the answer is a bit mask in Morton order. The arithmetic is the header's rule,
 * lane for lane (q_b = r[0][b] w_0 + r[1][b] w_1 + r[2][b] w_2, left to right). */
#include <float.h>

#include "projective_internal.h"

/* The rule's test for every lane: camera-frame centre (qa, qb, qc) -> in front of the camera,
 * inside the image, within max range; the pixel's column and row (0 where not). */
static void project_lanes(const occ_proj_t *const x, const float *restrict qa,
                          const float *restrict qb, const float *restrict qc,
                          int32_t *restrict col, int32_t *restrict row, int32_t *restrict in)
{
    const occ_proj_camera_t *const k = x->cam;
    const float fx = k->fx, fy = k->fy, cx = k->cx, cy = k->cy;
    const float wf = x->wf, hf = x->hf, max2 = x->max2;
    for (unsigned m = 0; m < OCC_PROJ_BULK; m++) {
        const float u = fx * (qa[m] / qc[m]) + cx + 0.5f;
        const float v = fy * (qb[m] / qc[m]) + cy + 0.5f;
        const float r2 = qa[m] * qa[m] + qb[m] * qb[m] + qc[m] * qc[m];
        const int32_t ok = (qc[m] > 0.0f) & (u >= 0.0f) & (u < wf) & (v >= 0.0f) & (v < hf) &
                           (r2 <= max2);
        col[m] = (int32_t)(ok ? u : 0.0f); /* u, v in [0, 65535] where ok: truncation is floor */
        row[m] = (int32_t)(ok ? v : 0.0f);
        in[m] = ok;
    }
}

/* Free where inside and in front of the pixel's surface by the margin (no reading: -inf). */
static void front_lanes(const occ_proj_t *const x, const float *restrict qc,
                        const int32_t *restrict col, const int32_t *restrict row,
                        int32_t *restrict in)
{
    const float keep = x->keep, m0 = x->m0;
    const float *const d0 = x->d0;
    const size_t w = x->im->width;
    float d[OCC_PROJ_BULK];
    for (unsigned m = 0; m < OCC_PROJ_BULK; m++) {
        d[m] = d0[(size_t)row[m] * w + (size_t)col[m]];
    }
    for (unsigned m = 0; m < OCC_PROJ_BULK; m++) {
        in[m] &= (int32_t)(qc[m] < keep * d[m] - m0);
    }
}

/* Per axis and camera-frame component b, r[axis][b] (centre - t) of the node's voxels at key
 * offsets 0..s-1 from k (the rule's products; summed per lane below). */
static void axis_products(const occ_proj_t *const x, const uint32_t k[3], const unsigned s,
                          float p[3][3][4])
{
    const occ_proj_camera_t *const cam = x->cam;
    const float t[3] = {cam->t.x, cam->t.y, cam->t.z};
    for (unsigned a = 0; a < 3u; a++) {
        for (unsigned o = 0; o < s; o++) {
            const float w = occi_raygeo_center(&x->g, k[a] + o) - t[a];
            for (unsigned b = 0; b < 3u; b++) {
                p[a][b][o] = cam->r[a][b] * w;
            }
        }
    }
}

/* Camera-frame centres q[b][m] = (p[0][b][x] + p[1][b][y]) + p[2][b][z] of the voxels in
 * Morton lanes m (x = bits 0 and 3, y = 1 and 4, z = 2 and 5 of m). Four lanes at a time share
 * z and the high bits: x0 and y0 vary as (0,0) (1,0) (0,1) (1,1). */
static void centres(const float p[3][3][4], float *restrict qa, float *restrict qb,
                    float *restrict qc)
{
    float *const q[3] = {qa, qb, qc};
    for (unsigned b = 0; b < 3u; b++) {
        float xy[2][2][4]; /* [y1][x1][lane]: the first sum, shared by the four z */
        for (unsigned y1 = 0; y1 < 2u; y1++) {
            for (unsigned x1 = 0; x1 < 2u; x1++) {
                for (unsigned l = 0; l < 4u; l++) {
                    xy[y1][x1][l] = p[0][b][2u * x1 + (l & 1u)] + p[1][b][2u * y1 + (l >> 1)];
                }
            }
        }
        float *out = q[b];
        for (unsigned z1 = 0; z1 < 2u; z1++) {
            for (unsigned y1 = 0; y1 < 2u; y1++) {
                for (unsigned x1 = 0; x1 < 2u; x1++) {
                    for (unsigned z0 = 0; z0 < 2u; z0++, out += 4) {
                        const float z = p[2][b][2u * z1 + z0];
                        for (unsigned l = 0; l < 4u; l++) {
                            out[l] = xy[y1][x1][l] + z;
                        }
                    }
                }
            }
        }
    }
}

uint64_t occi_proj_bulk(const occ_proj_t *const x, const uint32_t k[3], const unsigned level)
{
    OCC_ASSERT(level == 1u || level == 2u);
    float p[3][3][4];
    axis_products(x, k, 1u << level, p);
    if (level == 1u) { /* lanes 0..7 as for a level-2 node's first child (offsets 0, 1) */
        for (unsigned a = 0; a < 3u; a++) {
            for (unsigned b = 0; b < 3u; b++) {
                p[a][b][2] = p[a][b][0];
                p[a][b][3] = p[a][b][1];
            }
        }
    }
    float qa[OCC_PROJ_BULK], qb[OCC_PROJ_BULK], qc[OCC_PROJ_BULK];
    int32_t col[OCC_PROJ_BULK], row[OCC_PROJ_BULK], in[OCC_PROJ_BULK];
    centres((const float(*)[3][4])p, qa, qb, qc);
    project_lanes(x, qa, qb, qc, col, row, in);
    front_lanes(x, qc, col, row, in);
    uint64_t mask = 0u;
    const unsigned n = 1u << (3u * level);
    for (unsigned m = 0; m < n; m++) {
        mask |= (uint64_t)(uint32_t)in[m] << m;
    }
    return mask;
}
