/* SPDX-License-Identifier: BSD-3-Clause */
/* run_3d.c - nearest occupied space above and below the band (run_3d.h). */
#include "run_3d.h"

#include <math.h>

static float clampf(float v, float lo, float hi)
{
    return v < lo ? lo : (v > hi ? hi : v);
}

/* The node's part between up-coordinates [ulo, uhi] (s: +1 ENU, -1 NED): its point nearest p.
 * false when that part is empty. */
static bool clipped_nearest(const occ_query_node_t *n, occ_vec3_t p, float s, float ulo,
                            float uhi, occ_vec3_t *q, float *d)
{
    const float h = 0.5f * n->size_m;
    const float nu_lo = s * n->center.z - h;
    const float nu_hi = s * n->center.z + h;
    const float lo = nu_lo > ulo ? nu_lo : ulo;
    const float hi = nu_hi < uhi ? nu_hi : uhi;
    if (!(lo <= hi)) {
        return false;
    }
    q->x = clampf(p.x, n->center.x - h, n->center.x + h);
    q->y = clampf(p.y, n->center.y - h, n->center.y + h);
    q->z = s * clampf(s * p.z, lo, hi);
    const float dx = q->x - p.x;
    const float dy = q->y - p.y;
    const float dz = q->z - p.z;
    *d = sqrtf(dx * dx + dy * dy + dz * dz);
    return true;
}

static void take(run_3d_side_t *side, occ_vec3_t q, float d)
{
    if (!side->found || d < side->dist_m) {
        side->found = true;
        side->map_m = q;
        side->dist_m = d;
    }
}

/* Body FRD offset of a map point from the vehicle. */
static occ_vec3_t to_frd(const occ_pose_t *pose, occ_vec3_t q, bool map_ned)
{
    const occ_pose_t inv = occ_pose_invert(pose);
    const occ_vec3_t d = {q.x - pose->p.x, q.y - pose->p.y, q.z - pose->p.z};
    occ_vec3_t b = occ_pose_rotate(&inv, d);
    if (!map_ned) { /* FLU -> FRD */
        b.y = -b.y;
        b.z = -b.z;
    }
    return b;
}

static void fail_closed(const occ_pose_t *pose, const occ_sectors_config_t *cfg, run_3d_t *out)
{
    const float d = (float)cfg->min_distance_cm / 100.0f;
    const float s = cfg->map_ned ? -1.0f : 1.0f;
    out->above.found = out->below.found = true;
    out->above.dist_m = out->below.dist_m = d;
    out->above.map_m = out->below.map_m = pose->p;
    out->above.map_m.z += s * d;
    out->below.map_m.z -= s * d;
    out->above.frd_m = (occ_vec3_t){0.0f, 0.0f, -d}; /* straight up / down in the body */
    out->below.frd_m = (occ_vec3_t){0.0f, 0.0f, d};
}

static occ_err_t search(const occ_map_t *map, const occ_pose_t *pose,
                        const occ_sectors_config_t *cfg, occ_nearest_entry_t *buf, size_t cap,
                        run_3d_t *out)
{
    const float s = cfg->map_ned ? -1.0f : 1.0f;
    const float u0 = s * pose->p.z;
    const float r = (float)cfg->max_distance_cm / 100.0f;
    const occ_pred_t pred = {OCC_PRED_OCCUPIED, 0u, 0u};
    occ_nearest_t it;
    occ_err_t e = occ_nearest_begin(&it, map, pose->p, r, pred, buf, cap);
    for (bool found = e == OCC_OK; found;) {
        occ_query_node_t n;
        float dn = 0.0f;
        e = occ_nearest_next(&it, &n, &dn, &found);
        if (e != OCC_OK || !found) {
            break;
        }
        if (out->above.found && out->below.found && dn >= out->above.dist_m &&
            dn >= out->below.dist_m) {
            return OCC_OK; /* nothing later can be nearer on either side */
        }
        occ_vec3_t q;
        float d;
        if (clipped_nearest(&n, pose->p, s, u0 + cfg->band_above_m, INFINITY, &q, &d) && d <= r) {
            take(&out->above, q, d);
        }
        if (clipped_nearest(&n, pose->p, s, -INFINITY, u0 - cfg->band_below_m, &q, &d) && d <= r) {
            take(&out->below, q, d);
        }
    }
    return e;
}

void run_3d_nearest(const occ_map_t *map, const occ_pose_t *map_from_body,
                    const occ_sectors_config_t *cfg, occ_nearest_entry_t *buf, size_t cap,
                    run_3d_t *out)
{
    const run_3d_side_t none = {false, {0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 0.0f}, 0.0f};
    out->above = out->below = none;
    out->err = occ_pose_check(map_from_body);
    if (out->err == OCC_OK) {
        out->err = search(map, map_from_body, cfg, buf, cap, out);
    }
    if (out->err != OCC_OK) {
        out->above = out->below = none;
        fail_closed(map_from_body, cfg, out);
        return;
    }
    out->above.frd_m = to_frd(map_from_body, out->above.map_m, cfg->map_ned);
    out->below.frd_m = to_frd(map_from_body, out->below.map_m, cfg->map_ned);
}
