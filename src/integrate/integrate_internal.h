/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * integrate_internal.h - what raycast.c, keyset.c, vset.c, integrate.c and superray.c share
 * (src/integrate only): OctoMap's key arithmetic, the exact DDA writing Morton codes or marking
 * a voxel set, the key-set sort.
 */
#ifndef OCC_INTEGRATE_INTERNAL_H_INCLUDED
#define OCC_INTEGRATE_INTERNAL_H_INCLUDED

#include "occmap/occmap.h"
#include "../geom/geom_internal.h"
#include "../core/tree_internal.h"

typedef occ_real_t occ_rr_t;

/* The map's geometry (geom_internal.h) copied to locals for the hot loops:
 * key = floor(x * (1/res)) + 2^(D-1) with the map's decimal resolution. */
typedef struct {
    occ_rr_t res;      /* the decimal resolution */
    occ_rr_t rf;       /* 1 / res */
    occ_rr_t tmv_r;    /* 2^(D-1) as a real */
    int32_t tmv;       /* 2^(D-1) */
    uint8_t depth;     /* D */
} occ_raygeo_t;

void occi_raygeo_init(occ_raygeo_t *g, const occ_map_t *map);
/* Key of a point (all three axes valid). */
bool occi_raygeo_key(const occ_raygeo_t *g, const float p[3], uint32_t k[3]);
/* Centre coordinate of key k, as OctoMap's float(keyToCoord(k)). */
float occi_raygeo_center(const occ_raygeo_t *g, uint32_t k);
/* OctoMap's |p - o| (float squares, double sqrt when OCC_RAY_DOUBLE). */
occ_rr_t occi_raygeo_dist(const float o[3], const float p[3]);
/* OctoMap's origin + normalized(p - o) * (float)range. */
void occi_raygeo_clip(const float o[3], const float p[3], float range, float out[3]);

/* Upper bound of the codes occi_dda_codes() writes for keys ko -> ke. */
size_t occi_dda_bound(const uint32_t ko[3], const uint32_t ke[3]);

/* computeRayKeys(o, e) as Morton codes: the origin's code first, the end's excluded, nothing
 * when ko == ke. Writes at most `cap` codes; returns the count (which may exceed cap). ko/ke
 * must be the keys of o/e. */
size_t occi_dda_codes(const occ_raygeo_t *g, const float o[3], const float e[3],
                      const uint32_t ko[3], const uint32_t ke[3], occ_code_t *out, size_t cap);

/* Dilated (Morton) +-1 along axis `dim`: the axis' bits x = c & m step as an integer whose
 * carries (x - m = x + 1 through the other bits) and borrows (x - 1) the mask then drops; one
 * constant, so that a walk keeps its three in registers. */
static inline occ_code_t occ_code_step(occ_code_t c, unsigned dim, int step)
{
    const occ_code_t m = (occ_code_t)0x1249249249249249ull << dim;
    const occ_code_t x = c & m;
    return c + (((step > 0 ? x - m : x - 1u) & m) - x); /* c - x + x': only m's bits change */
}

/* ---- key sets (keyset.c) ----------------------------------------------------------------- */
#define OCC_KS_RADIX (1u << OCC_INSERT_RADIX_BITS)
#define OCC_KS_PASSES OCC_INSERT_RADIX_PASSES
/* Histogram words the sort needs (uint32_t). */
#define OCC_KS_HIST_WORDS ((size_t)OCC_KS_PASSES * OCC_KS_RADIX)

/* Stable LSD radix sort of a[0..n) by bits 0..62 (bit 63, the hit flag, is carried along),
 * using tmp[n] and hist[OCC_KS_HIST_WORDS]; n < 2^32. Returns a or tmp: where the result is. */
occ_code_t *occi_keyset_sort(occ_code_t *a, occ_code_t *tmp, size_t n, uint32_t *hist);
/* The same sort of keys k[0..n) (bits 0..62) carrying v[]; tk/tv are the temporaries. Returns
 * the key array holding the result; its values are in v if it is k, else in tv. */
uint64_t *occi_keyset_sort_pairs(uint64_t *k, uint32_t *v, uint64_t *tk, uint32_t *tv, size_t n,
                                 uint32_t *hist);
/* The same sort of n records r[2 i] (key, bits 0..62), r[2 i + 1] (carried along), using
 * tmp[2 n]. Returns r or tmp: where the result is. */
occ_code_t *occi_keyset_sort_records(occ_code_t *r, occ_code_t *tmp, size_t n, uint32_t *hist);
/* Collapse runs of equal codes (bits 0..62) of a sorted array to one entry whose hit bit is the
 * OR of the run's. Returns the new length. */
size_t occi_keyset_unique(occ_code_t *a, size_t n);

/* ---- dense set over a bounding box (keyset.c): FAST_DISCRETE's coarse nodes ------------------
 * One 64-bit word per 4x4x4 brick aligned to absolute keys, so a brick's voxels are the
 * 64 consecutive Morton codes (brick code << 6) + bit. Bricks are stored in chunks of 8x8x8
 * (4 KiB, Morton order inside). A visit is a test-and-set; first visits of a brick are listed. */
typedef struct {
    uint64_t *words;     /* chunks * 512 words, zeroed */
    uint64_t *touched;   /* word indices of bricks in first-touch order (cap: all bricks) */
    size_t n_touched;
    size_t n_set;        /* voxels in the set */
    uint32_t b0[3];      /* first brick (key >> 2) per axis, a multiple of 8 */
    uint32_t nb[3];      /* bricks per axis, multiples of 8 */
    size_t stride_y, stride_z; /* chunks per y step and per z step */
    bool overflow;       /* a visit fell outside the box: the caller falls back to sorting */
} occ_bitset_t;

/* Spread 3 bits to every third bit. */
static inline uint32_t occ_spread3b(uint32_t v)
{
    return (v & 1u) | ((v & 2u) << 2) | ((v & 4u) << 4);
}

/* Word index of brick (bx, by, bz) relative to b0 (each < nb). */
static inline size_t occ_bitset_index(const occ_bitset_t *bs, uint32_t bx, uint32_t by,
                                      uint32_t bz)
{
    const size_t chunk = (size_t)(bx >> 3) +
                         (size_t)(bs->nb[0] >> 3) *
                             ((size_t)(by >> 3) + (size_t)(bs->nb[1] >> 3) * (size_t)(bz >> 3));
    return (chunk << 9) | occ_spread3b(bx & 7u) | (occ_spread3b(by & 7u) << 1) |
           (occ_spread3b(bz & 7u) << 2);
}

/* Bit of voxel key (low 2 bits per axis) inside its brick word: Morton order. */
static inline unsigned occ_brick_bit(uint32_t kx, uint32_t ky, uint32_t kz)
{
    return (kx & 1u) | ((ky & 1u) << 1) | ((kz & 1u) << 2) | ((kx & 2u) << 2) | ((ky & 2u) << 3) |
           ((kz & 2u) << 4);
}

/* Morton interleave of the low 5 bits of a key for one axis (shift by the axis). */
extern const uint16_t occi_spread5[32];

/* Add voxel (kx, ky, kz); false when it is outside the box. */
static inline bool occ_bitset_add(occ_bitset_t *bs, uint32_t kx, uint32_t ky, uint32_t kz)
{
    const uint32_t cx = (kx >> 5) - (bs->b0[0] >> 3), cy = (ky >> 5) - (bs->b0[1] >> 3),
                   cz = (kz >> 5) - (bs->b0[2] >> 3);
    if (cx >= (bs->nb[0] >> 3) || cy >= (bs->nb[1] >> 3) || cz >= (bs->nb[2] >> 3)) {
        return false;
    }
    const uint32_t local = (uint32_t)occi_spread5[kx & 31u] | ((uint32_t)occi_spread5[ky & 31u] << 1) |
                           ((uint32_t)occi_spread5[kz & 31u] << 2);
    const size_t idx = (((size_t)cx + bs->stride_y * cy + bs->stride_z * cz) << 9) | (local >> 6);
    const uint64_t bit = (uint64_t)1 << (local & 63u);
    const uint64_t w = bs->words[idx];
    if ((w & bit) == 0u) {
        if (w == 0u) {
            bs->touched[bs->n_touched++] = idx;
        }
        bs->words[idx] = w | bit;
        bs->n_set++;
    }
    return true;
}

/* ---- the scan's voxel set (vset.c): sparse, grows with the chunks a scan touches -------------
 * The same bricks (one word per 4x4x4 voxels, bit = Morton order inside) in chunks of 32^3
 * voxels (512 words, 4 KiB, bricks in Morton order) aligned to absolute keys, so voxel code =
 * (chunk code << 15) | (word << 6) | bit. Chunks are taken on first touch from the top of the
 * set's memory downward and found through an open-addressing hash directory of the chunk
 * coordinates. A visit is one OR; memory is 4 KiB per chunk touched, not per visit. */
#define OCC_VSET_WORDS 512u
/* Bytes per chunk of room: its words, its entry in the list and the list's sort temporary,
 * and up to 4 directory entries (uint64_t key, uint32_t slot). */
#define OCC_VSET_CHUNK_BYTES (OCC_VSET_WORDS * 8u + 16u + 48u)
typedef struct {
    uint64_t *top;       /* chunk s: the 512 words below top - s * 512 */
    uint64_t *keys;      /* directory: packed chunk coordinates + 1, 0 = empty (2^tbits) */
    uint32_t *slots;     /* directory: the chunk's s */
    uint64_t *list;      /* packed chunk coordinates + 1 by s; chunk codes, sorted, after
                          * occi_vset_sort() */
    uint64_t *ltmp;      /* the list's sort temporary; then the chunks' places */
    size_t cap, n;       /* chunks: room and taken */
    uint32_t cmax;       /* chunk coordinates are below this (the map's edge / 32) */
    unsigned tbits;      /* log2 of the directory's entries */
    bool overflow;       /* full, or a visit left the map: the caller falls back to sorting */
} occ_vset_t;

/* Lay a set with room for at most max_chunks chunks out in [mem, mem + bytes) (mem 8-aligned):
 * the directory at the top, the chunks below it. False when not one chunk fits. */
bool occi_vset_init(occ_vset_t *vs, uint8_t *mem, size_t bytes, size_t max_chunks,
                    unsigned depth);
/* The words of chunk (cx, cy, cz) (key >> 5 per axis), taken and zeroed on first touch; NULL
 * when the set is full or the chunk is outside the map. */
uint64_t *occi_vset_chunk(occ_vset_t *vs, uint32_t cx, uint32_t cy, uint32_t cz);
/* Lowest byte of the set's memory in use (chunks taken): what is below it is free. */
uint8_t *occi_vset_low(const occ_vset_t *vs);
/* Bytes of the set's memory written so far (chunks, directory, list). */
size_t occi_vset_bytes(const occ_vset_t *vs);
/* Voxels in the set (a popcount over the chunks taken). */
size_t occi_vset_count(const occ_vset_t *vs);
/* Sort the chunk list by code and note each chunk's place (in the list's sort temporary):
 * call once after the scan, before reading. */
void occi_vset_sort(occ_vset_t *vs, uint32_t *hist);
/* After occi_vset_sort(): the set and `hits` (sorted, unique, hit bit set) as the core reads
 * them (occi_dense_next / _read / _need, occi_tree_apply_dense). O(1). */
void occi_vset_dense(const occ_vset_t *vs, const occ_code_t *hits, size_t n_hits,
                     occi_dense_t *d);

/* computeRayKeys(o, e) into the set; returns the visits. Sets vs->overflow and stops when the
 * set is full or a voxel is outside the map. */
size_t occi_dda_mark(const occ_raygeo_t *g, const float o[3], const float e[3],
                     const uint32_t ko[3], const uint32_t ke[3], occ_vset_t *vs);

/* One ray's walk into the set (raycast.c), for the walks that step it elsewhere. */
typedef struct {
    occ_dda_t dd;   /* tMax, tDelta, steps (the walk keeps them in registers) */
    occ_rr_t len;
    occ_code_t c, ce;
    uint32_t cc[3]; /* chunk coordinates (key >> 5) */
    uint32_t n[3];  /* steps on each axis until the next chunk */
} occi_mwalk_t;
/* Visits of a walk from ko that ended with w's countdowns and chunk coordinates. */
size_t occi_mwalk_visits(const occi_mwalk_t *w, const uint32_t ko[3]);

/* ---- the same walk over 8 rays at once (raycast_lanes.c: x86-64 GCC with AVX-512) ---------- */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && defined(__GLIBC__) && \
    OCC_RAY_DOUBLE
#define OCC_MARK_LANES 1
#else
#define OCC_MARK_LANES 0
#endif
#if OCC_MARK_LANES
/* Rays a batch holds (occ_ictx_t's queue), and chunks the lanes' cache holds (a power of 2). */
#define OCC_MARK_BATCH 128u
#define OCC_MARK_CACHE 256u
typedef struct {
    float e[3];
    uint32_t ke[3];
} occi_ray_end_t;
/* Chunk code + 1 (0: empty) -> the chunk's words, direct-mapped. */
typedef struct {
    uint64_t key[OCC_MARK_CACHE], ptr[OCC_MARK_CACHE];
} occi_mwalk_cache_t;
/* Set up o -> e and mark the origin's voxel; *cw: its chunk's words. False when there is
 * nothing to walk (ko == ke; or the origin's chunk cannot be had: vs->overflow set). */
bool occi_mwalk_start(occi_mwalk_t *w, uint64_t **cw, const occ_raygeo_t *g, const float o[3],
                      const float e[3], const uint32_t ko[3], const uint32_t ke[3],
                      occ_vset_t *vs);
/* The words of the chunk the walk just entered (w->cc), or NULL: the walk ends (an overflow
 * unless c is the end voxel's code and the chunk is off the map). */
uint64_t *occi_mwalk_enter(const occi_mwalk_t *w, occ_vset_t *vs, occ_code_t c);
/* Does this CPU run occi_mwalk_batch, on a map of this depth (below 21: a step off the map
 * shows in the code)? */
bool occi_mwalk_lanes_ok(unsigned depth);
/* occi_dda_mark(g, o, e_i, ko, ke_i, vs) for the n <= OCC_MARK_BATCH rays of ends: the same
 * set, chunks, overflow and total of visits. cache: zeros when vs is new, then kept with it. */
size_t occi_mwalk_batch(const occ_raygeo_t *g, const float o[3], const uint32_t ko[3],
                        const occi_ray_end_t *ends, size_t n, occ_vset_t *vs,
                        occi_mwalk_cache_t *cache);
#endif

/* Sorted, collapsed codes of the set merged with `hits` (sorted, unique, hit bit set): a voxel
 * in both is a hit. Writes to out (cap codes); returns the count, or SIZE_MAX when cap is too
 * small. tmp must hold n_touched codes. The touched list is reordered. */
size_t occi_bitset_extract(occ_bitset_t *bs, const occ_code_t *hits, size_t n_hits,
                           occ_code_t *out, size_t cap, occ_code_t *tmp, uint32_t *hist);

/* ---- one insert call (integrate.c); superray.c and fastdiscrete.c add rays through it ----- */
typedef struct {
    occ_map_t *map;
    occ_raygeo_t g;
    float o[3];            /* sensor origin */
    uint32_t ko[3];        /* its key */
    float max_range;       /* > 0: limited */
    occ_rr_t max_range_r;
    occ_code_t *filt;      /* 2^OCC_INSERT_FILTER_BITS recently emitted codes */
    uint32_t *hist;        /* radix histograms */
    occ_code_t *a, *b;     /* emitted codes (may repeat) and the sort's temporary, cap each */
    size_t cap, n;
    size_t b_cap;          /* set path: codes that fit at b (free until the set is read) */
    occ_vset_t *bs;        /* non-NULL: free voxels go to this set, hits to a[] */
    occ_bitset_t *cbs;     /* FAST_DISCRETE, d > 0: coarse nodes (keys >> cd) to clear */
    uint8_t cd, cn;        /* FAST_DISCRETE: coarse level d and n */
    uint32_t box_lo[3], box_hi[3]; /* keys of the scan's box (padded) */
    size_t a_hwm, b_hwm;   /* codes ever written at a[] and at b[] (scratch_used) */
    size_t n_ends;         /* DISCRETE: end voxels written (scratch_used) */
    const bool *hit;       /* per point, false: no hit (occ_map_insert_rays); NULL: all hit */
    occ_code_t win_lo, win_hi; /* sorted path: only codes in [win_lo, win_hi) are kept */
    bool chunked;          /* reserve may shrink win_hi instead of failing (bounded scratch) */
    occ_insert_result_t *r;
#if OCC_MARK_LANES
    bool lanes;            /* the set path's rays wait in q for occi_mwalk_batch */
    size_t nq;
    occi_ray_end_t q[OCC_MARK_BATCH];
    occi_mwalk_cache_t cache; /* its chunks of bs */
#endif
} occ_ictx_t;

/* Does point i mark its end voxel (false: its ray only clears)? */
static inline bool occ_ictx_hit(const occ_ictx_t *x, size_t i)
{
    return x->hit == NULL || x->hit[i];
}

/* Note that codes a[0..na) and b[0..nb) have been written. */
static inline void occ_ictx_note(occ_ictx_t *x, size_t na, size_t nb)
{
    x->a_hwm = na > x->a_hwm ? na : x->a_hwm;
    x->b_hwm = nb > x->b_hwm ? nb : x->b_hwm;
}

/* From here to occi_ictx_lanes_end, rays into the set (occi_ictx_set_ray) wait in a queue and
 * are walked 8 at a time where the CPU can (OCC_MARK_LANES): the set's bits, its chunks and the
 * visits do not depend on the rays' order. The end walks what waits. */
void occi_ictx_lanes_begin(occ_ictx_t *x);
void occi_ictx_lanes_end(occ_ictx_t *x);
/* computeRayKeys(o, e) into the set x->bs (keys ko, ke valid), counted in x->r. */
void occi_ictx_set_ray(occ_ictx_t *x, const float e[3], const uint32_t ke[3]);

/* Make room for `need` more codes in a (sorting and collapsing what is there if needed). */
bool occi_ictx_reserve(occ_ictx_t *x, size_t need);
/* Emit one voxel code (free, or hit with OCC_CODE_HIT_BIT); room must have been reserved. */
static inline void occ_ictx_emit(occ_ictx_t *x, occ_code_t c)
{
    x->a[x->n++] = c;
}

#ifdef OCC_TESTING
/* Test builds only: how the last occ_map_insert_rays() call ran - traversals of the whole scan
 * (run_method / a window's pass), those into the voxel set, batches applied with
 * occ_map_observe_codes(), and sets applied by bricks (occi_tree_apply_dense). */
typedef struct {
    unsigned traces;
    unsigned set_traces;
    unsigned pieces;
    unsigned bricks;
} occi_insert_probe_t;
extern occi_insert_probe_t occi_insert_probe;
/* Test builds only: true sends the voxel set the way of the codes (one batch or pieces), so
 * that tests reach those paths where bricks would do. */
extern bool occi_insert_bricks_off;
/* Test builds only: true keeps every ray on the scalar walk (occi_dda_mark), so that tests can
 * hold the 8-lane walk against it. */
extern bool occi_insert_lanes_off;
#endif

/* FAST_DISCRETE's ray (fastdiscrete.c): coarse marching, then fine DDA near the end. */
void occi_fast_ray(occ_ictx_t *x, const float e[3], const uint32_t ke[3]);

/* One point as OctoMap's computeUpdate() treats it: max range, keys, ray, and the hit unless
 * `hit` is false (then the ray to p clears and p's voxel is not marked, as for a clipped ray).
 * Returns 0 (integrated), 1 (bad point, skipped) or -1 (no scratch). */
int occi_ictx_point(occ_ictx_t *x, const float p[3], bool hit);
/* occi_ictx_point() on points[0..n) (only the no-hit ones if no_hit_only), each counted as
 * integrated or skipped. Returns 0, or -1 when scratch ran out. */
int occi_ictx_points(occ_ictx_t *x, const occ_vec3_t *points, size_t n, bool no_hit_only);

/* SUPER_RAYS (superray.c): integrate the valid points whose end voxel codes are ends[0..n)
 * (sorted, bit 63 clear) - equal result to occi_ictx_point() on each. `work` has work_cap codes.
 * Returns false when scratch ran out. */
bool occi_superray_run(occ_ictx_t *x, const occ_vec3_t *points, size_t n_points,
                       uint16_t k_min);
/* Bytes occi_superray_run() needs at x->b for n points (less: it casts each ray alone). */
size_t occi_superray_need(size_t n);

#endif
