/* SPDX-License-Identifier: BSD-3-Clause */
/* projective.c - occ_map_insert_projective(): check the call, lay out the scratch, build the
 * pyramid, walk, then the all-or-nothing pool check and the writes (the walk's stream of
 * bricks and whole free nodes through the core's frame pass: one walk of the tree). */
#include <math.h>
#include <string.h>

#include "projective_internal.h"
#include "../core/tree_internal.h"

/* The header's fixed term names the brick cache's 8 KiB. */
typedef char proj_cache_matches_header[OCC_PROJ_CACHE_N * 16u == 8192u ? 1 : -1];

static bool finite_pos(const float v)
{
    return isfinite(v) && v > 0.0f;
}

static bool image_ok(const occ_proj_image_t *im)
{
    if (im->data == NULL || (im->format != OCC_PROJ_U16 && im->format != OCC_PROJ_F32) ||
        im->width == 0u || im->height == 0u || im->width > 65535u || im->height > 65535u) {
        return false;
    }
    const size_t px = im->format == OCC_PROJ_U16 ? 2u : 4u;
    if (im->pixel_stride_bytes < px || im->row_stride_bytes / im->pixel_stride_bytes < im->width) {
        return false;
    }
    return im->format != OCC_PROJ_U16 || finite_pos(im->depth_scale_m);
}

/* r orthonormal within 1e-3 per entry of r r^T. */
static bool rotation_ok(const float r[3][3])
{
    for (unsigned a = 0; a < 3u; a++) {
        for (unsigned b = 0; b < 3u; b++) {
            const float dot = r[a][0] * r[b][0] + r[a][1] * r[b][1] + r[a][2] * r[b][2];
            if (!(fabsf(dot - (a == b ? 1.0f : 0.0f)) <= 1e-3f)) {
                return false;
            }
        }
    }
    return true;
}

static bool camera_ok(const occ_proj_camera_t *k)
{
    if (!finite_pos(k->fx) || !finite_pos(k->fy) || !isfinite(k->cx) || !isfinite(k->cy) ||
        !isfinite(k->min_range_m) || k->min_range_m < 0.0f || !isfinite(k->max_range_m) ||
        !(k->max_range_m > k->min_range_m) || !(k->noise_rel >= 0.0f && k->noise_rel <= 0.5f)) {
        return false;
    }
    const occ_vec3_t t = k->t;
    return isfinite(t.x) && isfinite(t.y) && isfinite(t.z) && rotation_ok(k->r);
}

/* The bulk rule's lane arrays too (OCC_PROJ_BULK_BYTES), 8-byte aligned after the tables. */
typedef char occ_proj_bulk_fit[sizeof(occ_proj_bulk_t) <= OCC_PROJ_BULK_BYTES && OCC_PROJ_LEVELS_BYTES % 8u == 0u ? 1 : -1];

/* The per-level tables live in the scratch's fixed part (OCC_PROJ_FIXED_BYTES counts
 * OCC_PROJ_LEVELS_BYTES for them): a C99 static assertion that they fit. */
typedef char occ_proj_levels_fit[sizeof(occ_proj_levels_t) <= OCC_PROJ_LEVELS_BYTES ? 1 : -1];
/* And the call's context (occ_proj_t) in OCC_PROJ_CTX_BYTES, a multiple of 8. */
typedef char occ_proj_ctx_fit[sizeof(occ_proj_t) <= OCC_PROJ_CTX_BYTES && OCC_PROJ_CTX_BYTES % 8u == 0u ? 1 : -1];

/* Carve the scratch: the brick cache and the sort's histograms (8-byte aligned), the depths and
 * the pyramid (floats), the pixel pass's tables (16-byte aligned), then the output (8-byte
 * codes). false when it cannot hold all that and one output slot. */
static bool carve(occ_proj_t *x, void *scratch, const size_t bytes, float **mem)
{
    if (scratch == NULL) {
        return false;
    }
    const uintptr_t a = (uintptr_t)scratch;
    const size_t skip = (size_t)((16u - (a & 15u)) & 15u);
    const size_t fixed = OCC_PROJ_CACHE_N * 16u + OCC_KS_HIST_WORDS * 4u + OCC_PROJ_LEVELS_BYTES +
                         OCC_PROJ_BULK_BYTES;
    const size_t px = (size_t)x->im->width * x->im->height;
    /* level 0 plus 4 floats: the row loop writes up to 3 past a row (the next row's, later
     * rewritten; past the last row: this pad) */
    const size_t floats = 4u * px + 16u + occi_proj_pyramid_bytes(x->im->width, x->im->height);
    const size_t tables = skip + ((fixed + floats + 15u) & ~(size_t)15u);
    const size_t head = tables + occi_proj_pixels_bytes(x->im->width);
    if (bytes < head + 8u) {
        return false;
    }
    unsigned char *const base = (unsigned char *)scratch + skip;
    x->cache_code = (occ_code_t *)(void *)base;
    x->cache_bits = (uint64_t *)(void *)(base + OCC_PROJ_CACHE_N * 8u);
    x->hist = (uint32_t *)(void *)(base + OCC_PROJ_CACHE_N * 16u);
    x->lv = (occ_proj_levels_t *)(void *)(base + OCC_PROJ_CACHE_N * 16u + OCC_KS_HIST_WORDS * 4u);
    x->bulk = (occ_proj_bulk_t *)(void *)((unsigned char *)x->lv + OCC_PROJ_LEVELS_BYTES);
    x->d0 = (float *)(void *)(base + fixed);
    *mem = x->d0 + px + 4u;
    occi_proj_pixels_carve(x, (unsigned char *)scratch + tables);
    x->out = (occ_code_t *)(void *)((unsigned char *)scratch + head);
    x->cap = (bytes - head) / 8u;
    x->r->insert.scratch_used = head;
    return true;
}

/* The writes: the walk's stream of bricks (free voxels and hits) and whole free nodes in one
 * pass over the tree (its pool check first: a bound as if no node on the paths existed), one
 * version of a shared map. */
static occ_err_t apply(occ_proj_t *x)
{
    occ_map_t *const m = x->map;
    occi_frame_t f;
    f.s = x->out + x->nh + x->nr;
    f.n = x->ns;
    f.node_delta = occi_delta_from_logodds(m->cfg.miss);
    const bool shared = m->priv.shared != NULL && occ_map_write_begin(m) == OCC_OK;
    occi_frame_out_t fo;
    const occ_err_t e = occi_tree_apply_frame(m, &f, &fo);
    if (shared) {
        (void)occ_map_write_end(m);
    }
    occ_insert_result_t *const r = &x->r->insert;
    r->voxels_free = x->nv;
    r->voxels_updated = r->voxels_free + x->nhv;
    r->voxels_changed = fo.changed;
    r->coarse_updated = e == OCC_OK ? x->nn : 0u;
    return e;
}

/* Counters of the voxel output. */
static void count_output(occ_proj_t *x)
{
    occ_insert_result_t *const r = &x->r->insert;
    r->voxels_occupied = x->nhv;
    r->voxel_visits = x->r->nodes_tested;
    r->rays_clipped = x->r->pixels_beyond_max;
    r->points_integrated = x->r->pixels - x->r->pixels_no_reading - x->r->pixels_too_close -
                           x->r->pixels_beyond_max - r->points_skipped;
}

/* The call's context sits at the front of the scratch (OCC_PROJ_CTX_BYTES of its fixed part),
 * off the stack that firmware budgets. NULL when the scratch cannot hold it. */
static occ_proj_t *context_in(void *scratch, const size_t bytes, size_t *used)
{
    if (scratch == NULL) {
        return NULL;
    }
    const size_t skip = (size_t)((8u - ((uintptr_t)scratch & 7u)) & 7u);
    if (bytes < skip + OCC_PROJ_CTX_BYTES) {
        return NULL;
    }
    *used = skip + OCC_PROJ_CTX_BYTES;
    occ_proj_t *const x = (occ_proj_t *)(void *)((unsigned char *)scratch + skip);
    memset(x, 0, sizeof *x);
    return x;
}

/* The camera's voxel, its position in it (voxels) and the key side, for the end points. */
static void camera_voxel(occ_proj_t *x, const float t[3], const uint32_t kt[3])
{
    x->rf = (float)x->g.rf;
    x->kside = (int32_t)((uint32_t)1 << x->g.depth);
    for (unsigned a = 0; a < 3u; a++) {
        x->kcam[a] = (int32_t)kt[a];
        const occ_rr_t s = (occ_rr_t)t[a] * x->g.rf - ((occ_rr_t)kt[a] - x->g.tmv_r);
        x->kfrac[a] = (float)s;
    }
}

/* Pyramid, end points, walk, then the writes, in the scratch after the context. */
static occ_err_t run(occ_proj_t *x, void *rest, const size_t rest_bytes)
{
    float *mem = NULL;
    if (!carve(x, rest, rest_bytes, &mem)) {
        return OCC_ERR_SCRATCH;
    }
    const bool hits_fit = occi_proj_pixels(x);
    occi_proj_build(x, mem);
    bool fit = hits_fit;
    if (fit) {
        occi_proj_hits_sort(x);
        fit = occi_proj_near(x);
    }
    if (fit) {
        occi_proj_walk(x);
    }
    const size_t slots = x->nh + x->nr + x->ns;
    x->r->insert.scratch_used += 8u * (slots > x->hwm ? slots : x->hwm);
    if (!fit || x->overflow) {
        return OCC_ERR_SCRATCH;
    }
    count_output(x);
    return apply(x);
}

/* The camera's voxel, or false off the map (occ_map_insert_projective refuses it then, before
 * it needs any scratch). Out of line: its ray geometry is not needed again until the context
 * holds its own copy. */
OCC_NOINLINE static bool camera_in_map(const occ_map_t *map, const occ_proj_camera_t *camera,
                                       occ_raygeo_t *g, uint32_t kt[3])
{
    occi_raygeo_init(g, map);
    const float t[3] = {camera->t.x, camera->t.y, camera->t.z};
    return occi_raygeo_key(g, t, kt);
}

/* The counters and the context live in the scratch (x->res): off the stack of the tree update,
 * the deepest chain of every integration (make cross). */
occ_err_t occ_map_insert_projective(occ_map_t *map, const occ_proj_image_t *image,
                                    const occ_proj_camera_t *camera, void *scratch,
                                    const size_t scratch_bytes, occ_proj_result_t *out)
{
    if (out != NULL) {
        memset(out, 0, sizeof *out);
    }
    if (map == NULL || image == NULL || camera == NULL || !image_ok(image) || !camera_ok(camera)) {
        return OCC_ERR_ARG;
    }
    occ_raygeo_t g;
    uint32_t kt[3];
    if (!camera_in_map(map, camera, &g, kt)) {
        return OCC_ERR_RANGE;
    }
    const size_t pixels = (size_t)image->width * image->height;
    if (out != NULL) {
        out->pixels = pixels;
    }
    size_t used = 0;
    occ_proj_t *const x = context_in(scratch, scratch_bytes, &used);
    if (x == NULL) {
        return OCC_ERR_SCRATCH;
    }
    x->map = map;
    x->im = image;
    x->cam = camera;
    x->r = &x->res;
    x->res.pixels = pixels;
    x->g = g;
    x->max2 = camera->max_range_m * camera->max_range_m;
    const float hit_m = OCC_PROJ_HIT_VOXELS * map->cfg.resolution_m;
    x->max2_hit = x->max2 < hit_m * hit_m ? x->max2 : hit_m * hit_m;
    x->min2 = camera->min_range_m * camera->min_range_m;
    x->far = 1024.0f * camera->max_range_m;
    x->keep = 1.0f - camera->noise_rel;
    x->near_z = (float)OCC_PROJ_NEAR_VOXELS * map->cfg.resolution_m;
    const float t[3] = {camera->t.x, camera->t.y, camera->t.z};
    camera_voxel(x, t, kt);
    const occ_err_t e = run(x, (unsigned char *)scratch + used, scratch_bytes - used);
    x->res.insert.scratch_used += used;
    if (out != NULL) {
        *out = x->res;
    }
    return e;
}
