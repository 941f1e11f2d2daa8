/* SPDX-License-Identifier: BSD-3-Clause */
/* projective_pixels.c - one pass over the image, a row at a time: each pixel's depth (level 0
 * of the pyramid), its counters, and its end point's voxel. A voxel repeated from the left or
 * the upper neighbour is dropped at once, the rest are bits of their level-2 node's entry in
 * a small cache, whose entries go to the output as records (a node's code, its voxels' bits;
 * sorted and merged afterwards: a pioneer frame's 31,000 new-voxel pixels are ~1,300 records
 * where they were 17,700 codes to sort). The row loops are branch-free so that a host compiler
 * vectorises them; the arithmetic is the header's, lane for lane. */
#include <float.h>
#include <math.h>
#include <string.h>

#include "projective_internal.h"
#include "../core/morton_internal.h"

/* A key offset no pixel gets (offsets are clamped to +-OCC_PROJ_KEY_LIM). */
#define NO_VOXEL INT32_MIN

/* Bytes of one array of n 4-byte cells, rounded up to 16 (each array starts 16-byte aligned). */
static size_t cells16(const size_t n)
{
    return (4u * n + 15u) & ~(size_t)15u;
}

size_t occi_proj_pixels_bytes(const uint32_t w)
{
    /* asq, u[3], dr, ds, nw: w cells padded to 4; kc[3], kp[3]: column -1 and w padded to 4 */
    return 7u * cells16(w) + 6u * cells16((size_t)w + 4u);
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
    x->px.ds = (float *)(void *)mem;
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

/* The lane loops over n pixels (a multiple of 4): branch-free, restrict-qualified, so that a
 * host compiler vectorises them; two loops, because one would hold more values than SSE2 has
 * registers (the header's arithmetic, lane for lane). First the depths: level 0, the class
 * counts, and in ds the depth of a hit (0 where the pixel marks nothing). */
OCC_PROJ_LANES static void depth_lanes(const uint32_t n, const row_consts_t *const c,
                                       const float *restrict dr, const float *restrict asq,
                                       float *restrict d0row, float *restrict ds,
                                       row_counts_t *const cnt)
{
    uint32_t finite = 0, valid_n = 0, in_n = 0;
    const float bsq1 = c->bsq1, min2 = c->min2, max2 = c->max2, max2h = c->max2h;
    for (uint32_t i = 0; i < n; i++) {
        const float d = dr[i];
        const float r2 = (d * d) * (asq[i] + bsq1);
        const int32_t fin = (d > 0.0f) & (r2 <= FLT_MAX);
        const int32_t valid = fin & (r2 >= min2);
        const int32_t in = valid & (r2 <= max2);
        const int32_t hit = valid & (r2 <= max2h);
        d0row[i] = valid ? d : -INFINITY;
        ds[i] = hit ? d : 0.0f;
        finite += (uint32_t)fin;
        valid_n += (uint32_t)valid;
        in_n += (uint32_t)in;
    }
    cnt->finite = finite;
    cnt->valid = valid_n;
    cnt->in = in_n;
}

/* Then the end voxels: per hit its key offsets from the camera's voxel (k0 NO_VOXEL where the
 * pixel marks nothing: no hit, or off the map). A hit farther than OCC_PROJ_HIT_VOXELS voxels is
 * outside every map: with that bound the offsets always convert to int32. */
OCC_PROJ_LANES static void key_lanes(const uint32_t n, const row_consts_t *const c,
                                     const float *restrict ds, const float *restrict u0,
                                     const float *restrict u1, const float *restrict u2,
                                     int32_t *restrict k0, int32_t *restrict k1,
                                     int32_t *restrict k2, row_counts_t *const cnt)
{
    uint32_t marked = 0;
    const float v0 = c->v[0], v1 = c->v[1], v2 = c->v[2], f0 = c->f[0], f1 = c->f[1], f2 = c->f[2];
    const int32_t t0 = c->t[0], t1 = c->t[1], t2 = c->t[2], hi = -c->side;
    for (uint32_t i = 0; i < n; i++) {
        const float e0 = ds[i] * (u0[i] + v0) + f0, e1 = ds[i] * (u1[i] + v1) + f1,
                    e2 = ds[i] * (u2[i] + v2) + f2;
        int32_t q0 = (int32_t)e0, q1 = (int32_t)e1, q2 = (int32_t)e2;
        q0 -= (int32_t)(e0 < (float)q0); /* truncation to floor */
        q1 -= (int32_t)(e1 < (float)q1);
        q2 -= (int32_t)(e2 < (float)q2);
        /* on the map: every key in [0, side), side a power of two: no bit at or above it
         * (a negative key has them all) */
        const int32_t off = ((q0 + t0) | (q1 + t1) | (q2 + t2)) & hi;
        const int32_t mark = (ds[i] > 0.0f) & (off == 0);
        marked += (uint32_t)mark;
        k0[i] = mark ? q0 : NO_VOXEL;
        k1[i] = q1;
        k2[i] = q2;
    }
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
    row_counts_t s = {0u, 0u, 0u, 0u}; /* the lane loops set every field; gcc -fanalyzer cannot
                                        * see through their clones' load-time pick */
    const occ_proj_pixels_t *const p = &x->px;
    depth_lanes(n, &c, p->dr, p->asq, d0row, p->ds, &s);
    key_lanes(n, &c, p->ds, p->u[0], p->u[1], p->u[2], p->kc[0], p->kc[1], p->kc[2], &s);
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

/* The voxel code of column i's end point (its key is on the map: 21 bits per axis at most).
 * Inlined into the row's loop (GCC called it: 0.979 and 0.981 of the frame's time inlined,
 * bench/ab_split with both halves built alike, 21 and 31 rounds). */
static OCC_ALWAYS_INLINE occ_code_t code_at(const occ_proj_t *const x, const uint32_t i)
{
    const uint32_t k[3] = {(uint32_t)(x->kcam[0] + x->px.kc[0][i]),
                           (uint32_t)(x->kcam[1] + x->px.kc[1][i]),
                           (uint32_t)(x->kcam[2] + x->px.kc[2][i])};
    const occ_code_t c = occi_morton_spread21(k[0]) | (occi_morton_spread21(k[1]) << 1) |
                         (occi_morton_spread21(k[2]) << 2);
    const occ_key_t key = {{k[0], k[1], k[2]}}; /* the check's only (tests) */
    OCC_ASSERT(c == occ_morton_encode(key));
    (void)key;
    return c;
}

/* Set of a level-2 node's code in the brick cache (its two ways: slots 2 s and 2 s + 1). */
static size_t cache_set(const occ_code_t brick)
{
    const occ_code_t c = brick >> 6;
    return (size_t)((c ^ (c >> 8) ^ (c >> 17) ^ (c >> 31)) & (OCC_PROJ_CACHE_N / 2u - 1u));
}

/* One record (a level-2 node's code, its end points' bits) to the output; false when the
 * output cannot hold it and the sort's temporary. */
static bool put_record(occ_proj_t *const x, const occ_code_t brick, const uint64_t bits)
{
    if (4u * (x->nh + 1u) > x->cap) {
        return false;
    }
    x->out[2u * x->nh] = brick;
    x->out[2u * x->nh + 1u] = bits;
    x->nh++;
    return true;
}

/* The end point with voxel code c into the brick cache: its level-2 node's bits there (two
 * ways per set; a new node enters the first, whose entry moves to the second, whose entry goes
 * to the output as a record: the sort merges a node's records). */
static bool add_hit(occ_proj_t *const x, const occ_code_t c)
{
    const occ_code_t brick = c & ~(occ_code_t)63u;
    const uint64_t bit = (uint64_t)1 << (c & 63u);
    occ_code_t *const code = x->cache_code + 2u * cache_set(brick);
    uint64_t *const bits = x->cache_bits + (code - x->cache_code);
    if (code[0] == brick) {
        bits[0] |= bit;
        return true;
    }
    if (code[1] == brick) {
        bits[1] |= bit;
        return true;
    }
    if (bits[1] != 0u && !put_record(x, code[1], bits[1])) {
        return false;
    }
    code[1] = code[0];
    bits[1] = bits[0];
    code[0] = brick;
    bits[0] = bit;
    return true;
}

/* The flagged columns' indices to the front of nw, in order; their count. In place and
 * without branches, as the flags fall at random: index n <= i is read before it is written. */
static uint32_t compact_scalar(int32_t *const nw, const uint32_t from, uint32_t n,
                               const uint32_t n4)
{
    for (uint32_t i = from; i < n4; i++) {
        const int32_t f = nw[i];
        nw[n] = (int32_t)i;
        n += (uint32_t)f;
    }
    return n;
}

#if OCC_PROJ_X86
#include <immintrin.h>

/* The same with AVX-512's compress, 16 flags at a time, where the CPU has it (the scalar loop
 * was a third of the pixel pass's own time: the frame in 0.964x and 0.968x the time,
 * bench/ab_split, 41 and 31 rounds, same maps). Each store writes 16 cells from n <= i: cells
 * already read. The i386 test build, without it, runs the scalar loop through the same tests. */
__attribute__((target("avx512f"))) static uint32_t compact_avx512(int32_t *const nw,
                                                                  const uint32_t n4)
{
    const __m512i step = _mm512_set1_epi32(16);
    __m512i idx = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    uint32_t n = 0, i = 0;
    for (; i + 16u <= n4; i += 16u) {
        const __m512i f = _mm512_loadu_si512((const void *)(nw + i));
        const __mmask16 k = _mm512_test_epi32_mask(f, f);
        _mm512_storeu_si512((void *)(nw + n), _mm512_maskz_compress_epi32(k, idx));
        n += (uint32_t)__builtin_popcount((unsigned)k);
        idx = _mm512_add_epi32(idx, step);
    }
    return compact_scalar(nw, i, n, n4);
}

static uint32_t compact_flags(int32_t *const nw, const uint32_t n4)
{
    return __builtin_cpu_supports("avx512f") ? compact_avx512(nw, n4)
                                             : compact_scalar(nw, 0u, 0u, n4);
}
#else
static uint32_t compact_flags(int32_t *const nw, const uint32_t n4)
{
    return compact_scalar(nw, 0u, 0u, n4);
}
#endif

/* The flagged pixels' end points into the brick cache; false when the output is full. */
static bool emit_row(occ_proj_t *const x)
{
    int32_t *const nw = x->px.nw;
    const uint32_t m = compact_flags(nw, (x->im->width + 3u) & ~3u);
    for (uint32_t j = 0; j < m; j++) {
        if (!add_hit(x, code_at(x, (uint32_t)nw[j]))) {
            return false;
        }
    }
    return true;
}

/* The cache's entries to the output as records, after the last row. */
static bool flush_cache(occ_proj_t *const x)
{
    for (size_t i = 0; i < OCC_PROJ_CACHE_N; i++) {
        if (x->cache_bits[i] != 0u && !put_record(x, x->cache_code[i], x->cache_bits[i])) {
            return false;
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
    for (size_t i = 0; i < OCC_PROJ_CACHE_N; i++) {
        x->cache_code[i] = ~(occ_code_t)0; /* never a level-2 node's code (low bits clear) */
        x->cache_bits[i] = 0u;
    }
    for (unsigned a = 0; a < 3u; a++) {
        for (uint32_t i = 0; i <= w; i++) {
            x->px.kp[a][i] = NO_VOXEL;
            x->px.kc[a][i] = NO_VOXEL;
        }
        x->px.kp[a]++; /* views from column 0: column -1 stays NO_VOXEL for every row */
        x->px.kc[a]++;
    }
    columns(x);
    x->raw_lanes = raw_rows(x->im);
    x->nh = 0u;
    bool fit = true;
    for (uint32_t j = 0; j < h; j++) {
        load_row(x, j);
        classify_row(x, j, x->d0 + (size_t)j * w);
        flag_new(x);
        fit = fit && emit_row(x);
        next_row(x);
    }
    fit = fit && flush_cache(x);
    x->hwm = 4u * x->nh; /* the records and the sort's temporary (so far, when not all fit) */
    return fit;
}
