/* SPDX-License-Identifier: BSD-3-Clause */
/* projective_bulk.c - the per-voxel rule over every voxel of a small node (level 1 or 2: 8 or
 * 64 voxels) at once, where the walk stops testing nodes. Lanes are the voxels in Morton
 * order; the loops are branch-free over whole arrays so that a host compiler vectorises them,
 * and the arithmetic is the header's rule lane for lane (q_b = r[0][b] w_0 + r[1][b] w_1 +
 * r[2][b] w_2, left to right). The answer is a bit mask in Morton order. */
#include <string.h>

#include "projective_internal.h"

/* Per axis a and camera-frame component b, r[a][b] (centre - t) of the voxels at key offsets
 * 0..3 from k (the rule's products, summed per lane by centres()). A level-1 node (offsets 0,
 * 1) repeats them at 2, 3: its 8 voxels are then the first 8 lanes. */
static void axis_products(const occ_proj_t *const x, const uint32_t k[3], const unsigned level,
                          float p[3][3][4])
{
    const occ_proj_camera_t *const cam = x->cam;
    const float t[3] = {cam->t.x, cam->t.y, cam->t.z};
    const uint32_t hi = level == 2u ? 2u : 0u; /* offsets 2, 3 (level 1: 0, 1 again) */
    for (unsigned a = 0; a < 3u; a++) {
        /* occi_raygeo_center's values, inline: a call per offset spilled every register */
        const occ_real_t res = x->g.res;
        const int32_t tmv = x->g.tmv;
        const float w[4] = {(float)occ_geom_center_of(res, tmv, k[a], 0u) - t[a],
                            (float)occ_geom_center_of(res, tmv, k[a] + 1u, 0u) - t[a],
                            (float)occ_geom_center_of(res, tmv, k[a] + hi, 0u) - t[a],
                            (float)occ_geom_center_of(res, tmv, k[a] + hi + 1u, 0u) - t[a]};
        for (unsigned b = 0; b < 3u; b++) {
            for (unsigned o = 0; o < 4u; o++) {
                p[a][b][o] = cam->r[a][b] * w[o];
            }
        }
    }
}

/* Four lanes: a row of x + y sums plus a z term. */
static void add4(float *const out, const float *const row, const float z)
{
    for (unsigned l = 0; l < 4u; l++) {
        out[l] = row[l] + z;
    }
}

/* Camera-frame centres q[b][m] = (p[0][b][x] + p[1][b][y]) + p[2][b][z] of the voxels in
 * Morton lanes m (x = bits 0 and 3 of m, y = 1 and 4, z = 2 and 5). Four consecutive lanes
 * share z and the high bits while (x0, y0) runs (0,0) (1,0) (0,1) (1,1): per high x and y bit
 * a row of four x + y sums, shared by the four z. The 16 groups of four written out (group
 * g = z0 | x1 << 1 | y1 << 2 | z1 << 3 at lane 4 g): gcc leaves loops of two trips rolled,
 * and their counting cost more than the adds. */
static void centres(const float p[3][3][4], float q[3][OCC_PROJ_BULK])
{
    for (unsigned b = 0; b < 3u; b++) {
        float xr[2][4], yr[2][4], xy[2][2][4]; /* [x1][lane], [y1][lane], [y1][x1][lane] */
        for (unsigned h = 0; h < 2u; h++) {
            xr[h][0] = xr[h][2] = p[0][b][2u * h];
            xr[h][1] = xr[h][3] = p[0][b][2u * h + 1u];
            yr[h][0] = yr[h][1] = p[1][b][2u * h];
            yr[h][2] = yr[h][3] = p[1][b][2u * h + 1u];
        }
        for (unsigned y1 = 0; y1 < 2u; y1++) {
            for (unsigned x1 = 0; x1 < 2u; x1++) {
                for (unsigned l = 0; l < 4u; l++) {
                    xy[y1][x1][l] = xr[x1][l] + yr[y1][l];
                }
            }
        }
        const float *const z = p[2][b]; /* z[z0 | z1 << 1] */
        float *const out = q[b];
        add4(out + 0, xy[0][0], z[0]);
        add4(out + 4, xy[0][0], z[1]);
        add4(out + 8, xy[0][1], z[0]);
        add4(out + 12, xy[0][1], z[1]);
        add4(out + 16, xy[1][0], z[0]);
        add4(out + 20, xy[1][0], z[1]);
        add4(out + 24, xy[1][1], z[0]);
        add4(out + 28, xy[1][1], z[1]);
        add4(out + 32, xy[0][0], z[2]);
        add4(out + 36, xy[0][0], z[3]);
        add4(out + 40, xy[0][1], z[2]);
        add4(out + 44, xy[0][1], z[3]);
        add4(out + 48, xy[1][0], z[2]);
        add4(out + 52, xy[1][0], z[3]);
        add4(out + 56, xy[1][1], z[2]);
        add4(out + 60, xy[1][1], z[3]);
    }
}

/* Every lane's camera-frame centre -> in front of the camera, inside the image, within max
 * range (`in`, 0 / 1) and its pixel's index (0 where not). */
OCC_PROJ_LANES static void project_lanes(const occ_proj_t *const x, const float *restrict qa,
                                         const float *restrict qb, const float *restrict qc,
                                         uint32_t *restrict pix, int32_t *restrict in)
{
    const occ_proj_camera_t *const k = x->cam;
    const float fx = k->fx, fy = k->fy, cx = k->cx, cy = k->cy;
    const float wf = x->wf, hf = x->hf, max2 = x->max2;
    const uint32_t w = x->im->width;
    for (unsigned m = 0; m < OCC_PROJ_BULK; m++) {
        const float iz = 1.0f / qc[m]; /* one division, not two: the lanes' limit */
        const float u = fx * (qa[m] * iz) + cx + 0.5f;
        const float v = fy * (qb[m] * iz) + cy + 0.5f;
        const float r2 = qa[m] * qa[m] + qb[m] * qb[m] + qc[m] * qc[m];
        const int32_t ok = (qc[m] > 0.0f) & (u >= 0.0f) & (u < wf) & (v >= 0.0f) & (v < hf) &
                           (r2 <= max2);
        /* u, v in [0, 65535] where ok: truncation is floor; the index fits 32 bits */
        const uint32_t col = (uint32_t)(int32_t)(ok ? u : 0.0f);
        const uint32_t row = (uint32_t)(int32_t)(ok ? v : 0.0f);
        pix[m] = row * w + col;
        in[m] = ok;
    }
}

/* Free where inside and in front of the pixel's surface by the margin (no reading: -inf),
 * as one byte (0 / 1) per lane (one loop: a second pass over 32-bit answers cost a loop exit
 * per call). d: the lanes' depths (workspace). */
OCC_PROJ_LANES static void front_lanes(const occ_proj_t *const x, const float *restrict qc,
                                       const uint32_t *restrict pix, const int32_t *restrict in,
                                       float *restrict d, uint8_t *restrict free8)
{
    const float keep = x->keep;
    const float *const d0 = x->d0;
    for (unsigned m = 0; m < OCC_PROJ_BULK; m++) {
        d[m] = d0[pix[m]];
    }
    for (unsigned m = 0; m < OCC_PROJ_BULK; m++) {
        free8[m] = (uint8_t)(in[m] & (int32_t)(qc[m] < keep * d[m]));
    }
}

/* Eight 0 / 1 bytes to the bits of one byte (bit i: byte i). */
static unsigned pack8(const uint8_t *const b)
{
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
    uint64_t v;
    memcpy(&v, b, 8u);
    return (unsigned)((v * 0x0102040810204080ull) >> 56); /* each byte to its bit, no carries */
#else
    unsigned r = 0;
    for (unsigned i = 0; i < 8u; i++) {
        r |= (unsigned)b[i] << i;
    }
    return r;
#endif
}

#if OCC_PROJ_X86
#include <immintrin.h>

/* centres(), project_lanes and front_lanes in one, 16 lanes at a time with AVX-512 where the
 * CPU has it: the same IEEE operations in the same order (C99 mode contracts no intrinsic into
 * an FMA). A lane's centre is (x + y) + z of its axis products, picked by permutes (lane m's
 * offsets: x bits 0 and 3 of m, y 1 and 4, z 2 and 5); the compares are masks (ordered: NaN
 * is false, as in C); the depths come by the hardware's gather (GCC builds one from 16 scalar
 * loads) of only the lanes inside; the answer goes straight into the mask. The i386 test
 * build, without it, runs the C loops through the same tests. Pixel indices are int32 here:
 * the caller checks that the image has at most 2^31 pixels. */
__attribute__((target("avx512f"))) static __m512 centre16(const float p[3][3][4], const unsigned b,
                                                          const __m512i ix, const __m512i iy,
                                                          const __m512i iz)
{
    const __m512 px = _mm512_castps128_ps512(_mm_loadu_ps(p[0][b]));
    const __m512 py = _mm512_castps128_ps512(_mm_loadu_ps(p[1][b]));
    const __m512 pz = _mm512_castps128_ps512(_mm_loadu_ps(p[2][b]));
    const __m512 xy = _mm512_add_ps(_mm512_permutexvar_ps(ix, px), _mm512_permutexvar_ps(iy, py));
    return _mm512_add_ps(xy, _mm512_permutexvar_ps(iz, pz));
}

/* Lane m's offset (0..3) on the axis whose bits are bit0 and bit0 + 3 of m. */
__attribute__((target("avx512f"))) static __m512i offset16(const __m512i m, const unsigned bit0)
{
    const __m512i one = _mm512_set1_epi32(1);
    const __m512i lo = _mm512_and_si512(_mm512_srli_epi32(m, bit0), one);
    const __m512i two = _mm512_add_epi32(one, one);
    const __m512i hi = _mm512_and_si512(_mm512_srli_epi32(m, bit0 + 2u), two);
    return _mm512_or_si512(lo, hi);
}

__attribute__((target("avx512f"))) static uint64_t rule_avx512(const occ_proj_t *const x,
                                                               const float p[3][3][4],
                                                               const unsigned lanes)
{
    const occ_proj_camera_t *const k = x->cam;
    const __m512 fx = _mm512_set1_ps(k->fx), fy = _mm512_set1_ps(k->fy);
    const __m512 cx = _mm512_set1_ps(k->cx), cy = _mm512_set1_ps(k->cy);
    const __m512 one = _mm512_set1_ps(1.0f), half = _mm512_set1_ps(0.5f);
    const __m512 zero = _mm512_setzero_ps(), keep = _mm512_set1_ps(x->keep);
    const __m512 wf = _mm512_set1_ps(x->wf), hf = _mm512_set1_ps(x->hf);
    const __m512 max2 = _mm512_set1_ps(x->max2);
    const __m512i w = _mm512_set1_epi32((int32_t)x->im->width);
    __m512i m = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    uint64_t mask = 0u;
    for (unsigned g = 0; g < lanes; g += 16u) {
        const __m512i ox = offset16(m, 0u), oy = offset16(m, 1u), oz = offset16(m, 2u);
        const __m512 qa = centre16(p, 0u, ox, oy, oz), qb = centre16(p, 1u, ox, oy, oz);
        const __m512 qc = centre16(p, 2u, ox, oy, oz);
        const __m512 iz = _mm512_div_ps(one, qc);
        const __m512 u = /* fx (qa iz) + cx + 0.5, left to right */
            _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(fx, _mm512_mul_ps(qa, iz)), cx), half);
        const __m512 v =
            _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(fy, _mm512_mul_ps(qb, iz)), cy), half);
        const __m512 r2 = _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(qa, qa), _mm512_mul_ps(qb, qb)),
                                        _mm512_mul_ps(qc, qc));
        __mmask16 ok = _mm512_cmp_ps_mask(qc, zero, _CMP_GT_OQ);
        ok = _mm512_mask_cmp_ps_mask(ok, u, zero, _CMP_GE_OQ);
        ok = _mm512_mask_cmp_ps_mask(ok, u, wf, _CMP_LT_OQ);
        ok = _mm512_mask_cmp_ps_mask(ok, v, zero, _CMP_GE_OQ);
        ok = _mm512_mask_cmp_ps_mask(ok, v, hf, _CMP_LT_OQ);
        ok = _mm512_mask_cmp_ps_mask(ok, r2, max2, _CMP_LE_OQ);
        const __m512i pix = _mm512_add_epi32(_mm512_mullo_epi32(_mm512_cvttps_epi32(v), w),
                                             _mm512_cvttps_epi32(u));
        const __m512 d = _mm512_mask_i32gather_ps(zero, ok, pix, x->d0, 4);
        const __mmask16 fr = _mm512_mask_cmp_ps_mask(ok, qc, _mm512_mul_ps(keep, d), _CMP_LT_OQ);
        mask |= (uint64_t)fr << g;
        m = _mm512_add_epi32(m, _mm512_set1_epi32(16));
    }
    return mask;
}

static bool rule_x86(const occ_proj_t *const x)
{
    return (uint64_t)x->im->width * x->im->height <= (uint64_t)INT32_MAX &&
           __builtin_cpu_supports("avx512f");
}
#endif

uint64_t occi_proj_bulk(const occ_proj_t *const x, const uint32_t k[3], const unsigned level)
{
    OCC_ASSERT(level == 1u || level == 2u);
    float p[3][3][4];
    axis_products(x, k, level, p);
    const unsigned groups = level == 2u ? 8u : 1u;
#if OCC_PROJ_X86
    if (rule_x86(x)) { /* level 1: the first 16 lanes, of which the first 8 are its voxels */
        const uint64_t all = rule_avx512(x, (const float(*)[3][4])p, 8u * groups);
        return groups == 8u ? all : all & 0xFFu;
    }
#endif
    occ_proj_bulk_t *const b = x->bulk; /* the lanes' arrays: in the scratch, off the stack */
    centres((const float(*)[3][4])p, b->q);
    project_lanes(x, b->q[0], b->q[1], b->q[2], b->pix, b->in);
    front_lanes(x, b->q[2], b->pix, b->in, b->d, b->free8);
    uint64_t mask = 0u;
    for (unsigned c = 0; c < groups; c++) {
        mask |= (uint64_t)pack8(b->free8 + 8u * c) << (8u * c);
    }
    return mask;
}
