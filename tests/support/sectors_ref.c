/* SPDX-License-Identifier: BSD-3-Clause */
/* sectors_ref.c - the sectors tests' fixture and brute-force reference (see sectors_ref.h). */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "sectors_ref.h"
#include "leak_check.h"

#define ARENA_BYTES (8u << 20)
static uint8_t arena[ARENA_BYTES];
occ_map_t sref_map;
occ_sectors_t sref_sect;
unsigned sref_seed;

occ_pose_t sref_at_yaw(float x, float y, float z, float yaw)
{
    occ_pose_t p;
    p.p.x = x;
    p.p.y = y;
    p.p.z = z;
    p.q = occ_quat_from_euler(0.0f, 0.0f, yaw);
    return p;
}

void sref_set_yaw(occ_pose_t *p, float yaw)
{
    p->q = occ_quat_from_euler(0.0f, 0.0f, yaw);
}

double sref_yaw_of(const occ_pose_t *p)
{
    const double w = p->q.w, x = p->q.x, y = p->q.y, z = p->q.z;
    return atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z));
}

int sref_setup(void **state)
{
    (void)state;
    occ_map_config_t cfg = occ_map_config_default();
    cfg.resolution_m = 0.1f;
    assert_int_equal(occ_map_init(&sref_map, &cfg, arena, sizeof arena), OCC_OK);
    return 0;
}

int sref_teardown(void **state)
{
    (void)state;
    return leak_check(&sref_map);
}

void sref_reinit(float res, unsigned depth)
{
    occ_map_config_t cfg = occ_map_config_default();
    cfg.resolution_m = res;
    cfg.depth_levels = (uint8_t)depth;
    assert_int_equal(occ_map_init(&sref_map, &cfg, arena, sizeof arena), OCC_OK);
}

/* ---- the reference ------------------------------------------------------------------------- */

typedef struct { double x, y; } pt_t;

/* Keep the part of polygon `in` (n points) where cross(d, p) * sign >= 0. */
static int clip(const pt_t *in, int n, double dx, double dy, double sign, pt_t *out)
{
    int m = 0;
    for (int i = 0; i < n; i++) {
        const pt_t a = in[i];
        const pt_t b = in[(i + 1) % n];
        const double fa = sign * (dx * a.y - dy * a.x);
        const double fb = sign * (dx * b.y - dy * b.x);
        if (fa >= 0.0) {
            out[m++] = a;
        }
        if ((fa >= 0.0) != (fb >= 0.0)) {
            const double t = fa / (fa - fb);
            out[m].x = a.x + t * (b.x - a.x);
            out[m].y = a.y + t * (b.y - a.y);
            m++;
        }
    }
    return m;
}

static double seg_dist(pt_t a, pt_t b)
{
    const double vx = b.x - a.x, vy = b.y - a.y;
    const double l2 = vx * vx + vy * vy;
    double t = l2 > 0.0 ? -(a.x * vx + a.y * vy) / l2 : 0.0;
    t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
    const double px = a.x + t * vx, py = a.y + t * vy;
    return sqrt(px * px + py * py);
}

/* Distance from the origin to square [x0,x1]x[y0,y1] clipped to the wedge between map angles
 * lo and lo + inc (inc <= 90 deg); < 0 when the intersection is empty. */
static double wedge_dist(double x0, double y0, double x1, double y1, double lo, double inc)
{
    pt_t p0[4] = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
    pt_t p1[12], p2[16];
    int n = clip(p0, 4, cos(lo), sin(lo), 1.0, p1);
    if (n == 0) {
        return -1.0;
    }
    n = clip(p1, n, cos(lo + inc), sin(lo + inc), -1.0, p2);
    if (n == 0) {
        return -1.0;
    }
    if (x0 <= 0.0 && x1 >= 0.0 && y0 <= 0.0 && y1 >= 0.0) {
        return 0.0;
    }
    double best = 1e300;
    for (int i = 0; i < n; i++) {
        const double d = seg_dist(p2[i], p2[(i + 1) % n]);
        best = d < best ? d : best;
    }
    return best;
}

/* Column state at voxel column (kx, ky) (int keys, maybe outside the volume): bit0 occupied,
 * bit1 unknown, over the voxels whose z extent overlaps [za, zb). */
static unsigned column_state(int64_t kx, int64_t ky, double za, double zb)
{
    const double res = sref_map.cfg.resolution_m;
    const int64_t half = (int64_t)1 << (sref_map.cfg.depth_levels - 1);
    const int64_t kmax = ((int64_t)1 << sref_map.cfg.depth_levels) - 1;
    unsigned st = 0;
    for (int64_t kz = (int64_t)floor(za / res) + half - 1; kz <= (int64_t)ceil(zb / res) + half;
         kz++) {
        const double z0 = (double)(kz - half) * res;
        if (!(z0 < zb && z0 + res > za)) {
            continue;
        }
        if (kx < 0 || ky < 0 || kz < 0 || kx > kmax || ky > kmax || kz > kmax) {
            st |= 2u;
            continue;
        }
        occ_key_t k = {{(uint32_t)kx, (uint32_t)ky, (uint32_t)kz}};
        occ_node_info_t info;
        assert_int_equal(occ_map_read_key(&sref_map, k, 0, &info), OCC_OK);
        if (!info.observed || info.state == OCC_STATE_UNKNOWN) {
            st |= 2u;
        } else if (info.state == OCC_STATE_OCCUPIED) {
            st |= 1u;
        }
    }
    return st;
}

static uint16_t ref_cm(double d, const occ_sectors_config_t *cfg)
{
    const double cm = floor(d * 100.0);
    if (cm <= cfg->min_distance_cm) {
        return cfg->min_distance_cm;
    }
    if (cm >= cfg->max_distance_cm) {
        return cfg->max_distance_cm;
    }
    return (uint16_t)cm;
}

typedef struct {
    double d_occ[OCC_SECTORS_MAX], d_unk[OCC_SECTORS_MAX];
    uint16_t cm[OCC_SECTORS_MAX];
} ref_t;

/* The ground rule of occ_sectors.h, in double: the first occupied voxel down the vehicle's column
 * (from its own voxel while the voxel reaches above za) lifts za to its top + clearance. */
static double ref_band_lo(const occ_pose_t *p, const occ_sectors_config_t *cfg, double za,
                          double zb)
{
    if (!cfg->ignore_ground) {
        return za;
    }
    const double res = sref_map.cfg.resolution_m;
    const int64_t half = (int64_t)1 << (sref_map.cfg.depth_levels - 1);
    const int64_t kx = (int64_t)floor((double)p->p.x / res) + half;
    const int64_t ky = (int64_t)floor((double)p->p.y / res) + half;
    for (int64_t kz = (int64_t)floor((double)p->p.z / res) + half; kz >= 0; kz--) {
        const double top = (double)(kz - half + 1) * res;
        if (!(top > za)) {
            break;
        }
        occ_key_t k = {{(uint32_t)kx, (uint32_t)ky, (uint32_t)kz}};
        occ_node_info_t info;
        assert_int_equal(occ_map_read_key(&sref_map, k, 0, &info), OCC_OK);
        if (info.observed && info.state == OCC_STATE_OCCUPIED) {
            const double lifted = top + (double)cfg->ground_clearance_m;
            return lifted > za && lifted < zb ? lifted : za;
        }
    }
    return za;
}

static void reference(const occ_pose_t *p, const occ_sectors_config_t *cfg, ref_t *r)
{
    const double res = sref_map.cfg.resolution_m;
    const int64_t half = (int64_t)1 << (sref_map.cfg.depth_levels - 1);
    const double R = cfg->max_distance_cm * 0.01;
    const double px = p->p.x, py = p->p.y, pz = p->p.z, yaw = sref_yaw_of(p);
    const double zb = pz + (double)cfg->band_above_m;
    const double za = ref_band_lo(p, cfg, pz - (double)cfg->band_below_m, zb);
    const double inc = (double)cfg->increment_deg * M_PI / 180.0;
    const double off = (double)cfg->angle_offset_deg * M_PI / 180.0;
    for (unsigned s = 0; s < cfg->n_sectors; s++) {
        r->d_occ[s] = r->d_unk[s] = 1e300;
    }
    const int64_t kx0 = (int64_t)floor((px - R) / res) + half - 1;
    const int64_t kx1 = (int64_t)floor((px + R) / res) + half + 1;
    const int64_t ky0 = (int64_t)floor((py - R) / res) + half - 1;
    const int64_t ky1 = (int64_t)floor((py + R) / res) + half + 1;
    for (int64_t kx = kx0; kx <= kx1; kx++) {
        for (int64_t ky = ky0; ky <= ky1; ky++) {
            const unsigned st = column_state(kx, ky, za, zb);
            if (st == 0u) {
                continue;
            }
            const double x0 = (double)(kx - half) * res - px;
            const double y0 = (double)(ky - half) * res - py;
            for (unsigned s = 0; s < cfg->n_sectors; s++) {
                /* Body [c - inc/2, c + inc/2) clockwise -> map angles from yaw - c - inc/2. */
                const double lo = yaw - (off + s * inc) - inc / 2.0;
                const double d = wedge_dist(x0, y0, x0 + res, y0 + res, lo, inc);
                if (d < 0.0) {
                    continue;
                }
                if ((st & 1u) && d < r->d_occ[s]) {
                    r->d_occ[s] = d;
                }
                if ((st & 2u) && d < r->d_unk[s]) {
                    r->d_unk[s] = d;
                }
            }
        }
    }
    for (unsigned s = 0; s < cfg->n_sectors; s++) {
        if (r->d_occ[s] <= r->d_unk[s] && r->d_occ[s] < R) {
            r->cm[s] = ref_cm(r->d_occ[s], cfg);
        } else if (r->d_unk[s] < R) {
            r->cm[s] = cfg->unknown_as_distance ? ref_cm(r->d_unk[s], cfg) : UINT16_MAX;
        } else {
            r->cm[s] = (uint16_t)(cfg->max_distance_cm + 1u); /* "no obstacle" */
        }
    }
}

unsigned sref_compare(const occ_pose_t *p, const occ_sectors_config_t *cfg, const char *what)
{
    static ref_t r;
    reference(p, cfg, &r);
    assert_int_equal(occ_sectors_compute(&sref_map, p, cfg, &sref_sect), OCC_OK);
    assert_int_equal(sref_sect.n, cfg->n_sectors);
    const double R = cfg->max_distance_cm * 0.01;
    unsigned bad = 0;
    for (unsigned s = 0; s < cfg->n_sectors; s++) {
        const int a = sref_sect.distance_cm[s], b = r.cm[s];
        assert_true(a != 0);
        bool ok = abs(a - b) <= 1;
        if (!ok && (a == UINT16_MAX || b == UINT16_MAX)) {
            const double dd = fabs(r.d_occ[s] - r.d_unk[s]);
            ok = dd < 0.01 || fabs(r.d_unk[s] - R) < 0.01 || fabs(r.d_occ[s] - R) < 0.01;
        }
        if (!ok) {
            bad++;
            fprintf(stderr,
                    "%s seed %u: pose (%.3f %.3f %.3f yaw %.4f) n %u inc %.2f off %.2f: sector %u "
                    "got %d want %d (ref occ %.4f unk %.4f; got occ %.4f unk %.4f)\n",
                    what, sref_seed, (double)p->p.x, (double)p->p.y, (double)p->p.z, sref_yaw_of(p),
                    cfg->n_sectors, (double)cfg->increment_deg, (double)cfg->angle_offset_deg, s,
                    a, b, r.d_occ[s], r.d_unk[s], (double)sref_sect.d_occ_m[s],
                    (double)sref_sect.d_unk_m[s]);
        }
    }
    return bad;
}

void sref_key_at(double x, double y, double z, occ_key_t *k)
{
    occ_vec3_t v = {(float)x, (float)y, (float)z};
    assert_int_equal(occ_map_key(&sref_map, v, k), OCC_OK);
}
