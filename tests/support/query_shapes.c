/* SPDX-License-Identifier: BSD-3-Clause */
/* query_shapes.c - random volumes in two implementations (see query_shapes.h). */
#include "query_shapes.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

uint64_t qs_rand(uint64_t *st)
{
    uint64_t x = *st;
    x ^= x >> 12;
    x ^= x << 25;
    x ^= x >> 27;
    *st = x;
    return x * 2685821657736338717ull;
}

double qs_uniform(uint64_t *st, double lo, double hi)
{
    return lo + (hi - lo) * ((double)(qs_rand(st) >> 11) / 9007199254740992.0);
}

uint64_t qs_seed(const char *test)
{
    const char *env = getenv("OCC_SEED");
    uint64_t seed = env != NULL ? strtoull(env, NULL, 10) : (uint64_t)time(NULL);
    printf("%s: seed %llu (set OCC_SEED to repeat)\n", test, (unsigned long long)seed);
    return seed == 0u ? 1u : seed;
}

static double snap(uint64_t *st, const occ_map_t *map, double x)
{
    if (qs_rand(st) % 4u != 0u) {
        return x;
    }
    const double side = (double)map->cfg.resolution_m * (double)(1u << (qs_rand(st) % 4u));
    return floor(x / side) * side; /* a node border (exact for power-of-two resolutions) */
}

static occ_vec3_t fv(const double p[3])
{
    occ_vec3_t v;
    v.x = (float)p[0];
    v.y = (float)p[1];
    v.z = (float)p[2];
    return v;
}

/* Round to float so both implementations see the same numbers. */
static void rf(double p[3])
{
    for (int i = 0; i < 3; i++) {
        p[i] = (double)(float)p[i];
    }
}

bool qs_random_shape(uint64_t *st, const occ_map_t *map, int kind, double reach, double max_size,
                     qs_shape_t *out)
{
    double c[3], d[3];
    for (int i = 0; i < 3; i++) {
        c[i] = snap(st, map, qs_uniform(st, -reach, reach));
        d[i] = qs_uniform(st, -max_size, max_size);
    }
    rf(c);
    occ_err_t e = OCC_ERR_ARG;
    const double r = (double)(float)qs_uniform(st, 0.02, max_size / 2);
    switch (kind) {
    case OCC_VOL_AABB: {
        double mn[3], mx[3];
        for (int i = 0; i < 3; i++) {
            const double a = c[i], b = (double)(float)(c[i] + fabs(d[i]));
            mn[i] = a;
            mx[i] = b;
        }
        out->name = "aabb";
        out->oracle = oracle_q_aabb(mn, mx);
        e = occ_volume_aabb(&out->vol, fv(mn), fv(mx));
        snprintf(out->desc, sizeof out->desc, "aabb %.4f,%.4f,%.4f %.4f,%.4f,%.4f", mn[0], mn[1],
                 mn[2], mx[0], mx[1], mx[2]);
        break;
    }
    case OCC_VOL_SPHERE:
        out->name = "sphere";
        out->oracle = oracle_q_sphere(c, r);
        e = occ_volume_sphere(&out->vol, fv(c), (float)r);
        snprintf(out->desc, sizeof out->desc, "sphere %.4f,%.4f,%.4f r %.4f", c[0], c[1], c[2], r);
        break;
    case OCC_VOL_OBB: {
        double half[3];
        for (int i = 0; i < 3; i++) {
            half[i] = (double)(float)fabs(d[i] / 2);
        }
        const double yaw = qs_uniform(st, -3.2, 3.2), pitch = qs_uniform(st, -1.5, 1.5),
                     roll = qs_uniform(st, -3.2, 3.2);
        out->name = "obb";
        out->oracle = oracle_q_obb(c, half, yaw, pitch, roll);
        float ax[9];
        oracle_q_axes(out->oracle, ax);
        /* The oracle keeps its double rotation; the core gets the float axes. */
        occ_vec3_t axes[3];
        for (int i = 0; i < 3; i++) {
            axes[i].x = ax[3 * i];
            axes[i].y = ax[3 * i + 1];
            axes[i].z = ax[3 * i + 2];
        }
        const float hf[3] = {(float)half[0], (float)half[1], (float)half[2]};
        e = occ_volume_obb(&out->vol, fv(c), hf, axes);
        snprintf(out->desc, sizeof out->desc, "obb c %.4f,%.4f,%.4f half %.3f,%.3f,%.3f ypr %.3f,%.3f,%.3f",
                 c[0], c[1], c[2], half[0], half[1], half[2], yaw, pitch, roll);
        break;
    }
    case OCC_VOL_CAPSULE:
    case OCC_VOL_SEGMENT: {
        double b[3];
        for (int i = 0; i < 3; i++) {
            b[i] = c[i] + d[i];
        }
        rf(b);
        if (kind == OCC_VOL_CAPSULE) {
            out->name = "capsule";
            out->oracle = oracle_q_capsule(c, b, r);
            e = occ_volume_capsule(&out->vol, fv(c), fv(b), (float)r);
        } else {
            out->name = "segment";
            out->oracle = oracle_q_segment(c, b);
            e = occ_volume_segment(&out->vol, fv(c), fv(b));
        }
        snprintf(out->desc, sizeof out->desc, "%s %.4f,%.4f,%.4f -> %.4f,%.4f,%.4f r %.4f", out->name,
                 c[0], c[1], c[2], b[0], b[1], b[2], kind == OCC_VOL_CAPSULE ? r : 0.0);
        break;
    }
    case OCC_VOL_FRUSTUM:
    default: {
        const double yaw = qs_uniform(st, -3.2, 3.2), pitch = qs_uniform(st, -1.5, 1.5),
                     roll = qs_uniform(st, -3.2, 3.2);
        const double hfov = (double)(float)qs_uniform(st, 0.2, 2.5);
        const double vfov = (double)(float)qs_uniform(st, 0.2, 2.0);
        const double nearm = (double)(float)(qs_rand(st) % 3u == 0u ? 0.0 : qs_uniform(st, 0.0, max_size / 4));
        const double farm = (double)(float)(nearm + qs_uniform(st, 0.1, max_size));
        out->name = "frustum";
        out->oracle = oracle_q_frustum(c, yaw, pitch, roll, hfov, vfov, nearm, farm);
        float ax[9];
        oracle_q_axes(out->oracle, ax);
        occ_vec3_t axes[3];
        for (int i = 0; i < 3; i++) {
            axes[i].x = ax[3 * i];
            axes[i].y = ax[3 * i + 1];
            axes[i].z = ax[3 * i + 2];
        }
        e = occ_volume_frustum(&out->vol, fv(c), axes, (float)hfov, (float)vfov, (float)nearm,
                               (float)farm);
        snprintf(out->desc, sizeof out->desc,
                 "frustum o %.4f,%.4f,%.4f ypr %.3f,%.3f,%.3f fov %.3f,%.3f range %.3f..%.3f", c[0],
                 c[1], c[2], yaw, pitch, roll, hfov, vfov, nearm, farm);
        break;
    }
    }
    return e == OCC_OK;
}

void qs_free(qs_shape_t *s)
{
    oracle_q_free(s->oracle);
    s->oracle = NULL;
}
