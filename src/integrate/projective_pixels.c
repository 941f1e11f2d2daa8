/* SPDX-License-Identifier: BSD-3-Clause */
/* projective_pixels.c - one pass over the image, a row at a time: each pixel's depth (level 0
 * of the pyramid), its counters, and its end point's voxel. A voxel repeated from the left or
 * the upper neighbour is dropped at once, the rest go through a small repeat filter to the
 * output as hit codes (sorted and collapsed afterwards). The row loops are branch-free so that
 * a host compiler vectorises them; the arithmetic is the header's, lane for lane. */
#include <float.h>
#include <math.h>
#include <string.h>

#include "projective_internal.h"

/* A key offset no pixel gets (offsets are clamped to +-OCC_PROJ_KEY_LIM). */
#define NO_VOXEL INT32_MIN

/* Bytes of one array of n 4-byte cells, rounded up to 16 (each array starts 16-byte aligned). */
static size_t cells16(const size_t n)
{
    return (4u * n + 15u) & ~(size_t)15u;
}

size_t occi_proj_pixels_bytes(const uint32_t w)
{
    /* asq, u[3], dr, nw: w cells padded to 4; kc[3], kp[3]: column -1 and w padded to 4 */
    return 6u * cells16(w) + 6u * cells16((size_t)w + 4u);
}

void occi_proj_pixels_carve(occ_proj_t *const x, unsigned char *mem)
{
    const uint32_t w = x->im->width;
    x->px.asq = (float *)(void *)mem;
    mem += cells16(w);
    for (unsigned a = 0; a < 3u; a++) {
        x->px.u[a] = (float *)(void *)mem;
        mem += cells16(w);
    }
    x->px.dr = (float *)(void *)mem;
    mem += cells16(w);
    for (unsigned a = 0; a < 3u; a++) {
        x->px.kc[a] = (int32_t *)(void *)mem;
        mem += cells16((size_t)w + 4u);
        x->px.kp[a] = (int32_t *)(void *)mem;
        mem += cells16((size_t)w + 4u);
    }
    x->px.nw = (int32_t *)(void *)mem;
}

/* Per-column tables of the frame (a_i = (i - cx) / fx): a_i^2 and the map-frame direction's
 * parts per axis in voxels, r[a][0] a_i rf. */
static void columns(occ_proj_t *x)
{
    const occ_proj_camera_t *const k = x->cam;
    const float rf = x->rf;
    const uint32_t w = x->im->width, n = (w + 3u) & ~3u;
    for (uint32_t i = 0; i < w; i++) {
        const float a = ((float)i - k->cx) / k->fx;
        x->px.asq[i] = a * a;
        for (unsigned ax = 0; ax < 3u; ax++) {
            x->px.u[ax][i] = (k->r[ax][0] * a) * rf;
        }
    }
    for (uint32_t i = w; i < n; i++) { /* the pad lanes: depth 0, no reading */
        x->px.asq[i] = 0.0f;
        x->px.u[0][i] = x->px.u[1][i] = x->px.u[2][i] = 0.0f;
        x->px.dr[i] = 0.0f;
    }
}

/* Are the rows plain uint16 arrays? (U16, contiguous, 2-byte aligned.) */
static bool raw_rows(const occ_proj_image_t *const im)
{
    return im->format == OCC_PROJ_U16 && im->pixel_stride_bytes == 2u &&
           ((uintptr_t)im->data & 1u) == 0u && (im->row_stride_bytes & 1u) == 0u;
}

/* The common image's depths to floats: a loop that vectorises. */
OCC_PROJ_LANES static void row_u16(const uint32_t w, const uint16_t *restrict raw, const float scale,
                    float *restrict dr)
{
    const uint32_t w4 = w & ~3u; /* a multiple of 4: no scalar epilogue to weigh */
    for (uint32_t i = 0; i < w4; i++) {
        dr[i] = (float)raw[i] * scale; /* raw 0: 0, no reading */
    }
    for (uint32_t i = w4; i < w; i++) {
        dr[i] = (float)raw[i] * scale;
    }
}

/* Row j's depths for the lane loop as floats into px.dr (0 = no reading). Pad lanes stay 0. */
static void load_row(const occ_proj_t *x, const uint32_t j)
{
    const occ_proj_image_t *const im = x->im;
    const unsigned char *const row = (const unsigned char *)im->data + (size_t)j * im->row_stride_bytes;
    const uint32_t w = im->width;
    float *const dr = x->px.dr;
    if (x->raw_lanes) {
        row_u16(w, (const uint16_t *)(const void *)row, im->depth_scale_m, dr);
        return;
    }
    if (im->format == OCC_PROJ_U16) {
        const float scale = im->depth_scale_m;
        for (uint32_t i = 0; i < w; i++) {
            uint16_t raw;
            memcpy(&raw, row + (size_t)i * im->pixel_stride_bytes, 2u);
            dr[i] = (float)raw * scale; /* raw 0: 0, no reading */
        }
        return;
    }
    const float far = x->far, beyond = 2.0f * x->cam->max_range_m;
    for (uint32_t i = 0; i < w; i++) {
        float d;
        memcpy(&d, row + (size_t)i * im->pixel_stride_bytes, 4u);
        dr[i] = d > far ? beyond : d; /* +Inf or absurdly far: no return within range */
    }
}

/* A row's inputs for the lane loop: per map axis the row's part of the direction (voxels) and
 * the camera's position in its voxel, the camera's key, the ranges, and the U16 scale. */
typedef struct {
    float bsq1, v[3], f[3], min2, max2, max2h, scale;
    int32_t t[3], side;
} row_consts_t;

/* Sums of one row: pixels with a finite depth, valid ones (not blind), those within max range,
 * and those marking a voxel (the counters follow by differences). */
typedef struct {
    uint32_t finite, valid, in, marked;
} row_counts_t;

/* One pixel of the lane loops (the header's arithmetic): its level-0 depth, its end voxel's
 * key offsets from the camera's voxel (k0 NO_VOXEL where it marks nothing) and its class. A hit
 * farther than OCC_PROJ_HIT_VOXELS voxels is outside every map: with that bound the offsets
 * always convert to int32. (The map test is always made: without it GCC 12 sinks the key
 * arithmetic under the hit test and no longer vectorises the loop.) */
typedef struct {
    float d0;
    int32_t k0, k1, k2;
    int32_t finite, valid, in, mark;
} px_t;

static inline px_t classify_px(const float d, const float asq, const float u0, const float u1,
                               const float u2, const row_consts_t c)
{
    px_t o;
    const float r2 = (d * d) * (asq + c.bsq1);
    o.finite = (d > 0.0f) & (r2 <= FLT_MAX);
    o.valid = o.finite & (r2 >= c.min2);
    o.in = o.valid & (r2 <= c.max2);
    const int32_t hit = o.valid & (r2 <= c.max2h);
    o.d0 = o.valid ? d : -INFINITY;
    const float ds = hit ? d : 0.0f; /* no hit: the camera's own voxel, dropped below */
    const float e0 = ds * (u0 + c.v[0]) + c.f[0], e1 = ds * (u1 + c.v[1]) + c.f[1],
                e2 = ds * (u2 + c.v[2]) + c.f[2];
    int32_t q0 = (int32_t)e0, q1 = (int32_t)e1, q2 = (int32_t)e2;
    q0 -= (int32_t)(e0 < (float)q0); /* truncation to floor */
    q1 -= (int32_t)(e1 < (float)q1);
    q2 -= (int32_t)(e2 < (float)q2);
    const int32_t s = c.side;
    o.mark = hit & (q0 + c.t[0] >= 0) & (q0 + c.t[0] < s) & (q1 + c.t[1] >= 0) &
             (q1 + c.t[1] < s) & (q2 + c.t[2] >= 0) & (q2 + c.t[2] < s);
    o.k0 = o.mark ? q0 : NO_VOXEL;
    o.k1 = q1;
    o.k2 = q2;
    return o;
}

/* The lane loop over n pixels (a multiple of 4): branch-free, restrict-qualified, so that a
 * host compiler vectorises it. */
OCC_PROJ_LANES static void classify_lanes(const uint32_t n, const row_consts_t *const c, const float *restrict dr,
                        const float *restrict asq, const float *restrict u0,
                        const float *restrict u1, const float *restrict u2,
                        float *restrict d0row, int32_t *restrict k0, int32_t *restrict k1,
                        int32_t *restrict k2, row_counts_t *const cnt)
{
    uint32_t finite = 0, valid = 0, in = 0, marked = 0;
    const row_consts_t cc = *c; /* a copy the stores cannot alias */
    for (uint32_t i = 0; i < n; i++) {
        const px_t o = classify_px(dr[i], asq[i], u0[i], u1[i], u2[i], cc);
        d0row[i] = o.d0;
        k0[i] = o.k0;
        k1[i] = o.k1;
        k2[i] = o.k2;
        finite += (uint32_t)o.finite;
        valid += (uint32_t)o.valid;
        in += (uint32_t)o.in;
        marked += (uint32_t)o.mark;
    }
    cnt->finite = finite;
    cnt->valid = valid;
    cnt->in = in;
    cnt->marked = marked;
}

/* Row j: level 0, counters, and per end point its key offsets from the camera's voxel
 * (NO_VOXEL in k0 where the pixel marks no hit), over the row padded to a multiple of 4 (the
 * pad lanes read depth 0: no reading, taken off the counters). */
static void classify_row(occ_proj_t *const x, const uint32_t j, float *const d0row)
{
    const occ_proj_camera_t *const k = x->cam;
    const float b = ((float)j - k->cy) / k->fy;
    row_consts_t c;
    memset(&c, 0, sizeof c); /* gcc -fanalyzer cannot follow the loop below */
    c.bsq1 = b * b + 1.0f;
    for (unsigned a = 0; a < 3u; a++) {
        c.v[a] = (k->r[a][1] * b + k->r[a][2]) * x->rf;
        c.f[a] = x->kfrac[a];
        c.t[a] = x->kcam[a];
    }
    c.min2 = x->min2;
    c.max2 = x->max2;
    c.max2h = x->max2_hit;
    c.scale = x->im->depth_scale_m;
    c.side = x->kside;
    const uint32_t w = x->im->width, n = (w + 3u) & ~3u;
    row_counts_t s;
    const occ_proj_pixels_t *const p = &x->px;
    classify_lanes(n, &c, p->dr, p->asq, p->u[0], p->u[1], p->u[2], d0row, p->kc[0], p->kc[1],
                   p->kc[2], &s);
    occ_proj_result_t *const r = x->r;
    r->pixels_no_reading += w - s.finite; /* the pad lanes are not finite */
    r->pixels_too_close += s.finite - s.valid;
    r->pixels_beyond_max += s.valid - s.in;
    r->insert.points_skipped += s.in - s.marked;
}

/* New-voxel flags over n lanes: a marked pixel whose voxel is not its left or upper
 * neighbour's (c: this row's offsets, from column -1; p: the previous row's). */
OCC_PROJ_LANES static void flag_lanes(const uint32_t n, const int32_t *restrict c0, const int32_t *restrict c1,
                       const int32_t *restrict c2, const int32_t *restrict p0,
                       const int32_t *restrict p1, const int32_t *restrict p2,
                       int32_t *restrict nw)
{
    for (uint32_t i = 1; i <= (n & ~3u); i++) { /* n is a multiple of 4: say so */
        const int32_t left = (c0[i] == c0[i - 1u]) & (c1[i] == c1[i - 1u]) & (c2[i] == c2[i - 1u]);
        const int32_t up = (c0[i] == p0[i]) & (c1[i] == p1[i]) & (c2[i] == p2[i]);
        nw[i - 1u] = (c0[i] != NO_VOXEL) & (left == 0) & (up == 0);
    }
}

static void flag_new(occ_proj_t *const x)
{
    const uint32_t n = (x->im->width + 3u) & ~3u; /* pad lanes hold NO_VOXEL */
    flag_lanes(n, x->px.kc[0] - 1, x->px.kc[1] - 1, x->px.kc[2] - 1, x->px.kp[0] - 1,
               x->px.kp[1] - 1, x->px.kp[2] - 1, x->px.nw);
}

/* Slot of a code in the repeat filter. */
static size_t filter_slot(const occ_code_t c)
{
    return (size_t)((c ^ (c >> 17) ^ (c >> 31)) & (OCC_PROJ_FILTER_N - 1u));
}

/* Morton code bits of axis 0 (axis a: shifted by a). */
#define MORTON_AXIS0 0x1249249249249249ull

/* The code of key k (hit bit set): from the last emitted voxel's when each axis moved by at
 * most one (a masked add or subtract on that axis' bits), else the full encode. */
static occ_code_t code_of(occ_proj_t *const x, const uint32_t k[3])
{
    occ_code_t c = x->px.last_code;
    unsigned a = 0;
    for (; a < 3u && c != 0u; a++) {
        const occ_code_t m = (occ_code_t)MORTON_AXIS0 << a, one = (occ_code_t)1 << a;
        if (k[a] == x->px.last_key[a] + 1u) {
            c = (((c | ~m) + one) & m) | (c & ~m);
        } else if (k[a] + 1u == x->px.last_key[a]) {
            c = (((c & m) - one) & m) | (c & ~m);
        } else if (k[a] != x->px.last_key[a]) {
            break;
        }
    }
    if (a < 3u || c == 0u) {
        const occ_key_t key = {{k[0], k[1], k[2]}};
        c = occ_morton_encode(key) | OCC_CODE_HIT_BIT;
    }
    x->px.last_code = c;
    memcpy(x->px.last_key, k, sizeof x->px.last_key);
    return c;
}

/* One end point's code to the output (unless the repeat filter has it); false when the output
 * cannot hold it and the sort's temporary. */
static bool emit(occ_proj_t *const x, const uint32_t i, size_t *const n)
{
    const uint32_t k[3] = {(uint32_t)(x->kcam[0] + x->px.kc[0][i]),
                           (uint32_t)(x->kcam[1] + x->px.kc[1][i]),
                           (uint32_t)(x->kcam[2] + x->px.kc[2][i])};
    const occ_code_t code = code_of(x, k);
    const occ_key_t key = {{k[0], k[1], k[2]}}; /* the check's only (tests) */
    OCC_ASSERT(code == (occ_morton_encode(key) | OCC_CODE_HIT_BIT));
    (void)key;
    const size_t s = filter_slot(code);
    if (x->filter[s] == code) {
        return true;
    }
    x->filter[s] = code;
    if (2u * (*n + 1u) > x->cap) {
        return false;
    }
    x->out[(*n)++] = code;
    return true;
}

/* The flagged pixels' codes to the output; false when it is full. */
static bool emit_row(occ_proj_t *const x, size_t *const n)
{
    const int32_t *const nw = x->px.nw;
    const uint32_t w4 = (x->im->width + 3u) & ~3u;
    for (uint32_t i0 = 0; i0 < w4; i0 += 4u) {
        uint64_t lo, hi;
        memcpy(&lo, nw + i0, 8u); /* four flags at a time: most are 0 */
        memcpy(&hi, nw + i0 + 2u, 8u);
        if ((lo | hi) == 0u) {
            continue;
        }
        for (uint32_t i = i0; i < i0 + 4u; i++) {
            if (nw[i] != 0 && !emit(x, i, n)) {
                return false;
            }
        }
    }
    return true;
}

/* The previous row's offsets become the upper neighbours (swap the buffers). */
static void next_row(occ_proj_t *const x)
{
    for (unsigned a = 0; a < 3u; a++) {
        int32_t *const t = x->px.kp[a];
        x->px.kp[a] = x->px.kc[a];
        x->px.kc[a] = t;
    }
}

bool occi_proj_pixels(occ_proj_t *const x)
{
    const uint32_t w = x->im->width, h = x->im->height;
    for (size_t i = 0; i < OCC_PROJ_FILTER_N; i++) {
        x->filter[i] = 0u; /* a hit code always has bit 63: 0 is never one */
    }
    for (unsigned a = 0; a < 3u; a++) {
        for (uint32_t i = 0; i <= w; i++) {
            x->px.kp[a][i] = NO_VOXEL;
            x->px.kc[a][i] = NO_VOXEL;
        }
        x->px.kp[a]++; /* views from column 0: column -1 stays NO_VOXEL for every row */
        x->px.kc[a]++;
    }
    x->px.last_code = 0u; /* none yet (a hit code always has bit 63) */
    columns(x);
    x->raw_lanes = raw_rows(x->im);
    bool fit = true;
    size_t n = 0;
    for (uint32_t j = 0; j < h; j++) {
        load_row(x, j);
        classify_row(x, j, x->d0 + (size_t)j * w);
        flag_new(x);
        fit = fit && emit_row(x, &n);
        next_row(x);
    }
    x->nh = n;
    return fit;
}
