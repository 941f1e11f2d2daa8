/* SPDX-License-Identifier: BSD-3-Clause */
/* pose.c - pose algebra: quaternions, compose/invert/apply, Euler angles, NED <-> ENU. */
#include <math.h>

#include "occmap/occ_pose.h"

#define PI_F 3.14159265358979323846f
/* NED <- ENU and FRD <- FLU are both half turns: about (1, 1, 0)/sqrt(2) and about x. */
#define HALF_SQRT2_F 0.70710678118654752440f

static const occ_quat_t Q_ENU_FROM_NED = {0.0f, HALF_SQRT2_F, HALF_SQRT2_F, 0.0f};
static const occ_quat_t Q_FRD_FROM_FLU = {0.0f, 1.0f, 0.0f, 0.0f};

static bool finite3(const occ_vec3_t v)
{
    return isfinite(v.x) && isfinite(v.y) && isfinite(v.z);
}

static bool finite4(const occ_quat_t q)
{
    return isfinite(q.w) && isfinite(q.x) && isfinite(q.y) && isfinite(q.z);
}

static float quat_norm(const occ_quat_t q)
{
    return sqrtf(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
}

static occ_quat_t quat_mul(const occ_quat_t a, const occ_quat_t b)
{
    occ_quat_t r;
    r.w = a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z;
    r.x = a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y;
    r.y = a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x;
    r.z = a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w;
    return r;
}

static occ_quat_t quat_conj(const occ_quat_t q)
{
    const occ_quat_t r = {q.w, -q.x, -q.y, -q.z};
    return r;
}

/* Unit again after float products (no-op for a zero or NaN quaternion: checks refuse those). */
static occ_quat_t quat_renorm(const occ_quat_t q)
{
    occ_quat_t r = q;
    (void)occ_quat_normalize(q, &r);
    return r;
}

/* R(q) v = v + 2w (u x v) + 2 u x (u x v), u = (x, y, z). */
static occ_vec3_t quat_rotate(const occ_quat_t q, const occ_vec3_t v)
{
    const float tx = 2.0f * (q.y * v.z - q.z * v.y);
    const float ty = 2.0f * (q.z * v.x - q.x * v.z);
    const float tz = 2.0f * (q.x * v.y - q.y * v.x);
    occ_vec3_t r;
    r.x = v.x + q.w * tx + (q.y * tz - q.z * ty);
    r.y = v.y + q.w * ty + (q.z * tx - q.x * tz);
    r.z = v.z + q.w * tz + (q.x * ty - q.y * tx);
    return r;
}

occ_quat_t occ_quat_identity(void)
{
    const occ_quat_t q = {1.0f, 0.0f, 0.0f, 0.0f};
    return q;
}

occ_pose_t occ_pose_identity(void)
{
    occ_pose_t p;
    p.p.x = p.p.y = p.p.z = 0.0f;
    p.q = occ_quat_identity();
    return p;
}

occ_err_t occ_quat_normalize(const occ_quat_t q, occ_quat_t *out)
{
    if (out == NULL || !finite4(q)) {
        return OCC_ERR_ARG;
    }
    const float n = quat_norm(q);
    if (!(n >= 1e-6f) || !isfinite(n)) {
        return OCC_ERR_ARG;
    }
    const float inv = 1.0f / n;
    out->w = q.w * inv;
    out->x = q.x * inv;
    out->y = q.y * inv;
    out->z = q.z * inv;
    return OCC_OK;
}

occ_err_t occ_quat_from_axis_angle(const occ_vec3_t axis, const float angle_rad, occ_quat_t *out)
{
    const float n = sqrtf(axis.x * axis.x + axis.y * axis.y + axis.z * axis.z);
    if (out == NULL || !finite3(axis) || !isfinite(angle_rad) || !(n >= 1e-12f) || !isfinite(n)) {
        return OCC_ERR_ARG;
    }
    const float s = sinf(0.5f * angle_rad) / n;
    const occ_quat_t q = {cosf(0.5f * angle_rad), axis.x * s, axis.y * s, axis.z * s};
    *out = quat_renorm(q);
    return OCC_OK;
}

occ_quat_t occ_quat_from_euler(const float roll_rad, const float pitch_rad, const float yaw_rad)
{
    const float cr = cosf(0.5f * roll_rad), sr = sinf(0.5f * roll_rad);
    const float cp = cosf(0.5f * pitch_rad), sp = sinf(0.5f * pitch_rad);
    const float cy = cosf(0.5f * yaw_rad), sy = sinf(0.5f * yaw_rad);
    occ_quat_t q; /* Rz(yaw) Ry(pitch) Rx(roll) */
    q.w = cy * cp * cr + sy * sp * sr;
    q.x = cy * cp * sr - sy * sp * cr;
    q.y = cy * sp * cr + sy * cp * sr;
    q.z = sy * cp * cr - cy * sp * sr;
    return q;
}

/* cos(pitch) below which the pose counts as pitched straight up or down: roll and yaw then
 * turn about (nearly) the same axis and only their difference (sum) is defined; roll is 0. */
#define GIMBAL_COSP 1e-3f

void occ_quat_to_euler(const occ_quat_t q, float *roll_rad, float *pitch_rad, float *yaw_rad)
{
    /* Body x in the parent frame is (cp cy, cp sy, -sp): pitch from atan2, not asin, keeps
     * it exact near +-90 deg where sin is flat. */
    const float r00 = 1.0f - 2.0f * (q.y * q.y + q.z * q.z);
    const float r10 = 2.0f * (q.w * q.z + q.x * q.y);
    const float sinp = 2.0f * (q.w * q.y - q.z * q.x);
    const float cosp = sqrtf(r00 * r00 + r10 * r10);
    const bool gimbal = cosp < GIMBAL_COSP;
    float yaw = gimbal ? 2.0f * atan2f(q.z, q.w) : atan2f(r10, r00);
    if (yaw > PI_F) { /* 2 atan2 spans (-2 pi, 2 pi]; atan2 gives -pi for a -0 numerator */
        yaw -= 2.0f * PI_F;
    } else if (yaw <= -PI_F) {
        yaw += 2.0f * PI_F;
    }
    if (roll_rad != NULL) {
        *roll_rad = gimbal ? 0.0f
                           : atan2f(2.0f * (q.w * q.x + q.y * q.z), 1.0f - 2.0f * (q.x * q.x + q.y * q.y));
    }
    if (pitch_rad != NULL) {
        *pitch_rad = atan2f(sinp, cosp);
    }
    if (yaw_rad != NULL) {
        *yaw_rad = yaw;
    }
}

occ_err_t occ_pose_check(const occ_pose_t *const pose)
{
    if (pose == NULL || !finite3(pose->p) || !finite4(pose->q)) {
        return OCC_ERR_ARG;
    }
    const float n = quat_norm(pose->q);
    return fabsf(n - 1.0f) <= OCC_POSE_QUAT_NORM_TOL ? OCC_OK : OCC_ERR_ARG;
}

occ_pose_t occ_pose_compose(const occ_pose_t *const a_from_b, const occ_pose_t *const b_from_c)
{
    occ_pose_t r;
    r.p = occ_pose_apply(a_from_b, b_from_c->p);
    r.q = quat_renorm(quat_mul(a_from_b->q, b_from_c->q));
    return r;
}

occ_pose_t occ_pose_invert(const occ_pose_t *const a_from_b)
{
    occ_pose_t r;
    r.q = quat_conj(a_from_b->q);
    r.p = quat_rotate(r.q, a_from_b->p);
    r.p.x = -r.p.x;
    r.p.y = -r.p.y;
    r.p.z = -r.p.z;
    return r;
}

occ_vec3_t occ_pose_apply(const occ_pose_t *const a_from_b, const occ_vec3_t v_b)
{
    occ_vec3_t r = quat_rotate(a_from_b->q, v_b);
    r.x += a_from_b->p.x;
    r.y += a_from_b->p.y;
    r.z += a_from_b->p.z;
    return r;
}

occ_vec3_t occ_pose_rotate(const occ_pose_t *const a_from_b, const occ_vec3_t d_b)
{
    return quat_rotate(a_from_b->q, d_b);
}

float occ_pose_yaw(const occ_pose_t *const pose)
{
    float yaw = 0.0f;
    occ_quat_to_euler(pose->q, NULL, NULL, &yaw);
    return yaw;
}

occ_err_t occ_pose_from_ned(const occ_vec3_t ned_m, const occ_quat_t ned_from_frd,
                            occ_pose_t *const map_from_body)
{
    occ_quat_t q;
    if (map_from_body == NULL || !finite3(ned_m) || occ_quat_normalize(ned_from_frd, &q) != OCC_OK) {
        return OCC_ERR_ARG;
    }
    map_from_body->p.x = ned_m.y;
    map_from_body->p.y = ned_m.x;
    map_from_body->p.z = -ned_m.z;
    map_from_body->q = quat_renorm(quat_mul(quat_mul(Q_ENU_FROM_NED, q), Q_FRD_FROM_FLU));
    return OCC_OK;
}

occ_err_t occ_pose_to_ned(const occ_pose_t *const map_from_body, occ_vec3_t *const ned_m,
                          occ_quat_t *const ned_from_frd)
{
    if (ned_m == NULL || ned_from_frd == NULL || occ_pose_check(map_from_body) != OCC_OK) {
        return OCC_ERR_ARG;
    }
    ned_m->x = map_from_body->p.y;
    ned_m->y = map_from_body->p.x;
    ned_m->z = -map_from_body->p.z;
    /* Both half turns are their own inverse up to sign: conj(Q) = -Q, same rotation. */
    const occ_quat_t q = quat_mul(quat_mul(quat_conj(Q_ENU_FROM_NED), map_from_body->q),
                                  quat_conj(Q_FRD_FROM_FLU));
    *ned_from_frd = quat_renorm(q);
    return OCC_OK;
}

/* Slerp as a turn from a: rel = conj(a) b on the shortest arc is a turn by 2 th about u; the
 * result is a (cos s th, sin s th u). atan2 keeps th exact for nearly equal rotations, and the
 * same formula extrapolates (s > 1) along the same axis at the same rate. */
occ_pose_t occ_pose_interpolate(const occ_pose_t *const a, const occ_pose_t *const b,
                                const float s)
{
    occ_pose_t r;
    r.p.x = a->p.x + s * (b->p.x - a->p.x);
    r.p.y = a->p.y + s * (b->p.y - a->p.y);
    r.p.z = a->p.z + s * (b->p.z - a->p.z);
    occ_quat_t rel = quat_mul(quat_conj(a->q), b->q);
    if (rel.w < 0.0f) { /* q and -q are the same rotation: take the short way */
        rel.w = -rel.w, rel.x = -rel.x, rel.y = -rel.y, rel.z = -rel.z;
    }
    const float vn = sqrtf(rel.x * rel.x + rel.y * rel.y + rel.z * rel.z);
    occ_quat_t turn = occ_quat_identity();
    if (vn > 0.0f) {
        const float th = atan2f(vn, rel.w) * s;
        const float k = sinf(th) / vn;
        turn.w = cosf(th);
        turn.x = k * rel.x;
        turn.y = k * rel.y;
        turn.z = k * rel.z;
    }
    r.q = quat_renorm(quat_mul(a->q, turn));
    return r;
}
