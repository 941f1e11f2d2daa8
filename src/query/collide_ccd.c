/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * collide_ccd.c - convex shapes against the map with libccd (host only, see sources.mk).
 */
#include <ccd/ccd.h>
#include "occmap/host/occ_collide_ccd.h"
#include "query_internal.h"

typedef struct {
    occ_vec3_t c;
    float h;
} cube_t;

static void shape_support(const void *obj, const ccd_vec3_t *dir, ccd_vec3_t *vec)
{
    const occ_convex_t *const s = (const occ_convex_t *)obj;
    occ_vec3_t d;
    occ_vec3_t p;
    d.x = (float)dir->v[0];
    d.y = (float)dir->v[1];
    d.z = (float)dir->v[2];
    s->support(s->shape, &d, &p);
    ccdVec3Set(vec, (ccd_real_t)p.x, (ccd_real_t)p.y, (ccd_real_t)p.z);
}

static void shape_center(const void *obj, ccd_vec3_t *center)
{
    const occ_convex_t *const s = (const occ_convex_t *)obj;
    ccdVec3Set(center, (ccd_real_t)s->center.x, (ccd_real_t)s->center.y, (ccd_real_t)s->center.z);
}

static void cube_support(const void *obj, const ccd_vec3_t *dir, ccd_vec3_t *vec)
{
    const cube_t *const b = (const cube_t *)obj;
    const ccd_real_t h = (ccd_real_t)b->h;
    ccdVec3Set(vec, (ccd_real_t)b->c.x + (dir->v[0] >= 0 ? h : -h),
               (ccd_real_t)b->c.y + (dir->v[1] >= 0 ? h : -h),
               (ccd_real_t)b->c.z + (dir->v[2] >= 0 ? h : -h));
}

static void cube_center(const void *obj, ccd_vec3_t *center)
{
    const cube_t *const b = (const cube_t *)obj;
    ccdVec3Set(center, (ccd_real_t)b->c.x, (ccd_real_t)b->c.y, (ccd_real_t)b->c.z);
}

occ_err_t occ_collide_convex(const occ_map_t *map, const occ_convex_t *shape,
                             occ_unknown_policy_t policy, occ_ccd_algo_t algo,
                             occ_collision_t *out)
{
    occi_q_collision_unsafe(out); /* until the walk proves otherwise */
    if (map == NULL || shape == NULL || out == NULL || shape->support == NULL ||
        !occ_finite3(shape->center) || (policy != OCC_UNKNOWN_UNSAFE && policy != OCC_UNKNOWN_SAFE) ||
        (algo != OCC_CCD_GJK && algo != OCC_CCD_MPR)) {
        return OCC_ERR_ARG;
    }
    occ_volume_t box;
    occ_err_t e = occ_volume_aabb(&box, shape->bmin, shape->bmax);
    if (e != OCC_OK) {
        return e;
    }
    const float half = occ_map_node_size(map, map->cfg.depth_levels) * 0.5f;
    if (policy == OCC_UNKNOWN_UNSAFE &&
        (box.bmin.x < -half || box.bmin.y < -half || box.bmin.z < -half ||
         box.bmax.x >= half || box.bmax.y >= half || box.bmax.z >= half)) {
        /* The shape leaves the map unless it lies in the map cube: check its support extremes. */
        static const float dirs[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
        for (unsigned i = 0; i < 6u; i++) {
            occ_vec3_t d;
            occ_vec3_t p;
            d.x = dirs[i][0];
            d.y = dirs[i][1];
            d.z = dirs[i][2];
            shape->support(shape->shape, &d, &p);
            if (p.x < -half || p.y < -half || p.z < -half || p.x >= half || p.y >= half ||
                p.z >= half) {
                out->outside = true;
                return OCC_OK;
            }
        }
    }
    occ_pred_t pred;
    pred.states = (uint8_t)occ_q_blocking_states(policy);
    pred.min_level = 0;
    pred.options = 0;
    occ_query_iter_t it;
    e = occ_query_begin(&it, map, &box, pred);
    if (e != OCC_OK) {
        return e;
    }
    ccd_t ccd;
    CCD_INIT(&ccd);
    ccd.support1 = shape_support;
    ccd.support2 = cube_support;
    ccd.center1 = shape_center;
    ccd.center2 = cube_center;
    ccd.max_iterations = 200;
    occ_query_node_t n;
    while (occ_query_next(&it, &n)) {
        cube_t cube;
        cube.c = n.center;
        cube.h = 0.5f * n.size_m;
        const int hit = algo == OCC_CCD_GJK ? ccdGJKIntersect(shape, &cube, &ccd)
                                            : ccdMPRIntersect(shape, &cube, &ccd);
        if (hit) {
            out->node = n;
            return OCC_OK;
        }
    }
    if (occ_query_status(&it) != OCC_OK) {
        return OCC_ERR_STATE; /* the support function wrote the map: the walk did not finish */
    }
    out->safe = true; /* every blocking node in the box was tested against the shape */
    return OCC_OK;
}
