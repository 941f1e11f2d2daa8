/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * projective_internal.h - what projective.c (entry, apply), projective_pyramid.c (depths and
 * their min/max pyramid) and projective_walk.c (the virtual octree walk) share. src/integrate
 * only; the rule they implement is in occ_integrate.h.
 */
#ifndef OCC_PROJECTIVE_INTERNAL_H_INCLUDED
#define OCC_PROJECTIVE_INTERNAL_H_INCLUDED

#include "integrate_internal.h"

/* A vectorisable loop kept out of line: inlined into its caller, GCC 12 drops the loop's
 * restrict qualifiers and leaves it scalar. On x86-64 glibc hosts GCC also builds an AVX-512
 * and an AVX2 clone of it, one picked once at load time by the CPU (an ifunc; libgcc's
 * __cpu_model): 16 or 8 lanes instead of SSE2's four. The same IEEE operations lane for lane
 * (C99 mode contracts nothing into an FMA), so the same map (bench/ab_split compares digests;
 * test_projective_rel runs the oracle test on the release build). The AVX2 clone measured 0.94x
 * the time of SSE2 alone on the TUM frames. The AVX-512 clone measured 0.993x of AVX2 alone when
 * the pixel pass was most of the lanes; with the 64-voxel rule's lanes it is 0.959x (q1 0.950,
 * q3 0.974; 31 rounds) and 0.959x (21 rounds) on a Sapphire Rapids Xeon, same maps; an
 * x86-64-v4 clone (AVX-512 BW, DQ, VL too) instead measured 1.007x of it. */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && defined(__GLIBC__)
/* Where GCC cannot vectorise a loop (a compaction; gathers, which it builds from scalar
 * loads), projective_pixels.c and projective_bulk.c also carry AVX-512 intrinsics, taken when
 * __builtin_cpu_supports says so; the C loops stay beside them (other CPUs, the i386 tests). */
#define OCC_PROJ_X86 1
#define OCC_PROJ_LANES \
    OCC_NOINLINE __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define OCC_PROJ_X86 0
#define OCC_PROJ_LANES OCC_NOINLINE
#endif

/* Pyramid levels: level 0 is the image, each next one halves both sides (ceil) down to 1x1;
 * 65535 pixels per side need 17. */
#define OCC_PROJ_MAX_LEVELS 18u
/* The footprint query's windows: from pyramid level OCC_PROJ_WIN_LEVEL on, per cell the min
 * and max over the N x N cells from it (N = 2^OCC_PROJ_WIN_SHIFT), so that two windows per
 * axis bound a footprint of up to 2 N cells: tighter than 3 x 3 cells of a coarser level, and
 * fewer reads. On the 10 TUM frames at 0.05 m: 10 % fewer nodes tested, 3.4 % fewer
 * instructions per frame (callgrind: 309.2 M -> 298.6 M for the 10); in time, bench/ab_split
 * with both halves built alike gave 0.98 to 1.02 of the time without windows, inside its own
 * spread (the same library on both sides: 1.01 and 1.04). N = 4 and N = 16 test more nodes
 * (N = 16: more footprints fall below level 2); windows from level 1 cost 1.07 to 1.12 (their
 * build costs more than they save). */
#define OCC_PROJ_WIN_LEVEL 2u
#define OCC_PROJ_WIN_SHIFT 3u /* projective_pyramid.c's column steps are written out for 3 */
#define OCC_PROJ_WIN_CELLS (1u << OCC_PROJ_WIN_SHIFT)
/* Entries of the end points' brick cache (a level-2 node's code and its end points' bits, 16
 * bytes each), two ways per set: on the pioneer frames 1,255 records per frame for 1,121
 * nodes; direct mapped, two nodes of a row that share a slot evict each other on every row:
 * 4,089 records. */
#define OCC_PROJ_CACHE_N 512u
/* An end point farther than this from the camera (in voxels: 2^22) is outside every map (keys
 * have at most 21 bits, and one axis differs by more than 2^22 / sqrt(3) > 2^21); below it the
 * key offsets from the camera's voxel convert to int32 without overflow. */
#define OCC_PROJ_HIT_VOXELS 4194304.0f

/* The pixel pass's per-column tables and row buffers (projective_pixels.c), in the scratch. */
typedef struct {
    float *asq;        /* a_i^2, a_i = (i - cx) / fx */
    float *u[3];       /* r[a][0] a_i rf: the direction's column part per map axis, in voxels */
    float *dr;         /* the row's depths (0: no reading) */
    float *ds;         /* the row's hit depths (0: the pixel marks nothing) */
    int32_t *kc[3];    /* this row's end-point key offsets from the camera's voxel (index -1 ok) */
    int32_t *kp[3];    /* the previous row's */
    int32_t *nw;       /* this row's "new voxel" flags (0 / 1), padded to a multiple of 4;
                        * then the flagged columns */
} occ_proj_pixels_t;

/* One level of the walk's explicit stack: a node being opened and its next child slot. */
typedef struct {
    uint32_t k[3];
    occ_code_t code;
    float cap;
    uint8_t level, next;
    uint8_t kids; /* a level-3 node: its MIXED level-2 children, by slot */
} occ_proj_frame_t;

/* The inputs of the walk's tests of a level-3 node's 8 children at once (projective_walk.c):
 * the children's faces, and copies of the camera's and the walk's constants for level 2, so
 * that the lane loop reads everything through one restrict pointer. */
typedef struct {
    float lo[3][8]; /* the children's lower faces, by child slot */
    float t[3], r[3][3], pn[4][3], pc[4][3], dz[3];
    float s, tabs, max2, max_range, peps0, cap;
} occ_proj_kids_t;

/* Lanes of the bulk rule: the voxels of a level-2 node. */
#define OCC_PROJ_BULK 64u
/* The bulk rule's lane arrays (projective_bulk.c), in the scratch: 1.8 KB were too much for a
 * firmware task's stack (make cross). */
typedef struct {
    float q[3][OCC_PROJ_BULK];  /* camera-frame centres */
    float d[OCC_PROJ_BULK];     /* their pixels' depths */
    uint32_t pix[OCC_PROJ_BULK];
    int32_t in[OCC_PROJ_BULK];
    uint8_t free8[OCC_PROJ_BULK];
    occ_proj_kids_t kids;       /* the walk's tests of 8 children at once: inputs */
} occ_proj_bulk_t;

/* Per node level, the walk's constants (see occ_proj_t). */
typedef struct {
    float side[OCC_MAX_DEPTH + 1u]; /* node edge length (m) */
    float edge[OCC_MAX_DEPTH + 1u][3][3];
    float plane_pos[OCC_MAX_DEPTH + 1u][4][3];
} occ_proj_levels_t;

typedef struct {
    occ_map_t *map;
    occ_raygeo_t g;
    const occ_proj_image_t *im;
    const occ_proj_camera_t *cam;
    float max2, min2;       /* squared ranges */
    float max2_hit;         /* max2, at most (OCC_PROJ_HIT_VOXELS res)^2: end points beyond are outside */
    float far;              /* F32 depths beyond this are "no return" (2 max range) */
    float keep;             /* 1 - noise_rel */
    float dmax;             /* largest depth with a reading (-inf: none) */
    float rf;               /* 1 / resolution (float) */
    int32_t kcam[3];        /* the camera's voxel key */
    float kfrac[3];         /* the camera's position within its voxel, in voxels [0, 1) */
    int32_t kside;          /* 2^depth: keys are below it */
    occ_proj_pixels_t px;
    bool raw_lanes;         /* rows are plain uint16 arrays (U16, contiguous, aligned) */
    float *d0;              /* level 0: depth per pixel, -INFINITY = no reading */
    float *mn[OCC_PROJ_MAX_LEVELS], *mx[OCC_PROJ_MAX_LEVELS]; /* levels >= 1 */
    /* levels >= OCC_PROJ_WIN_LEVEL: min / max over N x N cells from each cell */
    float *wmn[OCC_PROJ_MAX_LEVELS], *wmx[OCC_PROJ_MAX_LEVELS];
    uint32_t lw[OCC_PROJ_MAX_LEVELS], lh[OCC_PROJ_MAX_LEVELS];
    unsigned levels;
    float pn[4][3], pr[4][3]; /* the walk's side planes and their products with the map axes */
    /* Per node level, the walk's constants (the same products test_node used to form per node):
     * the edge vectors s r[a] (camera frame) and the side planes' positive parts s pr[p][a]. */
    occ_proj_levels_t *lv;  /* in the caller's scratch (1.9 KB: off the stack for firmware) */
    occ_proj_bulk_t *bulk;  /* in the caller's scratch too */
    float tabs;             /* |t.x| + |t.y| + |t.z| */
    float wf, hf;           /* image width and height as floats (exact) */
    float peps0;            /* 1e-5 (fx + fy + |cx| + |cy| + w + h) */
    occ_code_t *cache_code; /* the brick cache: OCC_PROJ_CACHE_N level-2 nodes' codes */
    uint64_t *cache_bits;   /* and their end points' bits (0: empty) */
    uint32_t *hist;         /* the radix sort's histograms */
    /* The output: the end points as records of two slots (a level-2 node's code, the bits of
     * its voxels holding one), sorted and one per node (nh slots; nhv end points), the near
     * field's voxels (nr), then the walk's stream (ns slots, tree_internal.h's occi_frame_t:
     * bricks and whole nodes in code order), the brick being gathered in bcode / bmiss / bhit
     * / bwhole until the walk moves past it. nv: free voxels decided one by one; nn: whole free
     * nodes (the call's counters). The pixel pass counts records in nh. */
    occ_code_t *out;
    size_t cap, nh, nhv, nv, nn, ns, hwm;
    occ_code_t bcode;
    uint64_t bmiss, bhit, bwhole;
    bool bopen;
    size_t hit_cur;         /* the walk's cursor over the hit records (a slot: even) */
    uint64_t hit_rest;      /* the bits of the record at hit_cur not yet taken */
    /* The near field's free voxels (projective_near.c): sorted codes after the hits, merged
     * into the walk's output in code order by its cursor. */
    const occ_code_t *near;
    size_t nr, near_cur;
    float near_z;           /* the near rays' depth: OCC_PROJ_NEAR_VOXELS voxels */
    bool overflow;
    occ_proj_result_t *r;   /* = &res */
    occ_proj_result_t res;  /* the call's counters, copied out at the end */
    occ_proj_frame_t walk[OCC_MAX_DEPTH + 1u]; /* the walk's stack (the context is in scratch) */
} occ_proj_t;

/* The surface threshold of a depth: a voxel centre nearer than this is in front (monotone in d,
 * so the pyramid's min and max bound it). */
static inline float occ_proj_front(const occ_proj_t *x, const float d)
{
    return x->keep * d;
}

/* Bytes the pyramid levels >= 1 take (min and max) and their layout for a w x h image. */
size_t occi_proj_pyramid_bytes(uint32_t w, uint32_t h);
/* Bytes of the pixel pass's tables and row buffers for an image `w` pixels wide. */
size_t occi_proj_pixels_bytes(uint32_t w);
/* Lay them out from `mem` (16-byte aligned, occi_proj_pixels_bytes(w) bytes). */
void occi_proj_pixels_carve(occ_proj_t *x, unsigned char *mem);
/* The pixel pass: level 0 (x->d0), the counters, and the end points as nh records in
 * out[0..2 nh) (unsorted, a node's in several at times); false when the output cannot hold
 * them and the sort's temporary. */
bool occi_proj_pixels(occ_proj_t *x);
/* Level 0's single-pixel gaps closed for the free test (projective_fill.c), in place, with
 * occi_proj_fill_bytes(w) bytes of rows at `mem` (4-byte aligned). */
size_t occi_proj_fill_bytes(uint32_t w);
void occi_proj_fill(occ_proj_t *x, float *mem);
/* Level 0's gaps filled, then the pyramid over it: levels >= 1 laid out from `mem` (4-byte
 * aligned, occi_proj_pyramid_bytes bytes); x->dmax. */
void occi_proj_build(occ_proj_t *x, float *mem);
/* Min and max depth over pixels [i0, i1] x [j0, j1] (inside the image, i0 <= i1, j0 <= j1),
 * over-approximated (so mn may be lower, mx higher): from 2 x 2 windows of one level >=
 * OCC_PROJ_WIN_LEVEL that cover the footprint's at most 16 x 16 cells there, else (small
 * footprints) from at most 3 x 3 cells of one level. Pixels within twice the footprint's
 * longer side of it (tests/test_proj_range.c). */
void occi_proj_range(const occ_proj_t *x, uint32_t i0, uint32_t i1, uint32_t j0, uint32_t j1,
                     float *mn, float *mx);

/* Sort the end points' records by node and merge a node's into one: nh becomes their slots,
 * nhv the end points. */
void occi_proj_hits_sort(occ_proj_t *x);

/* The near field (projective_near.c): rays from the camera along every step-th pixel
 * (occi_proj_near_step: min(fx, fy) / 32, at least 1) and the last row and column, to this
 * many voxels of depth or the front of their surface if nearer. */
#define OCC_PROJ_NEAR_VOXELS 4u
uint32_t occi_proj_near_step(const occ_proj_camera_t *k);
/* Rays of a w x h image's grid. */
size_t occi_proj_near_rays(uint32_t w, uint32_t h, uint32_t step);
/* The near rays' voxels, sorted and unique, at out + nh (x->near, x->nr); false when the
 * output cannot hold them and the sort's temporary. Needs level 0 (x->d0). */
bool occi_proj_near(occ_proj_t *x);

/* The per-voxel rule for every voxel of the node at `level` (1 or 2) whose first voxel has key
 * k: bit m of the result is set when the voxel in Morton slot m (below the node) is free. */
uint64_t occi_proj_bulk(const occ_proj_t *x, const uint32_t k[3], unsigned level);

/* The walk: the stream after the hits and near voxels (x->ns slots), the counters nv and nn;
 * or sets x->overflow. */
void occi_proj_walk(occ_proj_t *x);

#endif
