/* SPDX-License-Identifier: BSD-3-Clause */
/* occ_pose.h - the one pose type of occmap: frames, sensor mounts, a timed pose history.
 *
 * Frames (right-handed, metres, radians):
 *  - map: ENU, x east, y north, z up (the map the tree holds; the sectors' NED option aside).
 *  - body: FLU, x forward, y left, z up (ROS REP-103). An autopilot's body frame is FRD in a
 *    NED world: occ_pose_from_ned() converts both at once.
 *  - sensor: whatever the sensor's call states (depth cameras: optical, x right, y down,
 *    z forward; range beams: the beam directions' frame).
 * A pose `a_from_b` maps coordinates in frame b to frame a: v_a = R(q) v_b + p. It is at the
 * same time "frame b's origin and orientation seen in a". The vehicle's pose is map_from_body,
 * a sensor mount is body_from_sensor, and the sensor's pose at a time is their composition
 * map_from_sensor = compose(map_from_body, body_from_sensor).
 * Quaternions are Hamilton, w first, unit length (every function here returns unit ones).
 * All functions are pure, O(1) (history lookups O(log n)), no heap, no global state.
 */
#ifndef OCC_OCC_POSE_H_INCLUDED
#define OCC_OCC_POSE_H_INCLUDED

#include "occmap/occ_core.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct { float w, x, y, z; } occ_quat_t;   /* unit quaternion, Hamilton, w first */

typedef struct {
    occ_vec3_t p;   /* metres: frame b's origin in frame a */
    occ_quat_t q;   /* rotation b -> a: v_a = R(q) v_b + p */
} occ_pose_t;

/* Largest | |q| - 1 | occ_pose_check() accepts (a pose made from float sums stays well inside). */
#define OCC_POSE_QUAT_NORM_TOL 1e-3f

/* ---- construction and checks --------------------------------------------------------------- */
occ_quat_t occ_quat_identity(void);
occ_pose_t occ_pose_identity(void);

/* Rotation about an axis by angle_rad (right hand). axis need not be unit: it is normalised.
 * A zero or non-finite axis, a non-finite angle or a NULL out gives OCC_ERR_ARG and *out
 * untouched (angle 0 is the identity). */
occ_err_t occ_quat_from_axis_angle(occ_vec3_t axis, float angle_rad, occ_quat_t *out);

/* Euler angles as autopilots send them (MAVLink ATTITUDE): the rotation is yaw about z, then
 * pitch about the new y, then roll about the new x (R = Rz(yaw) Ry(pitch) Rx(roll)). Always a
 * unit quaternion for finite input; NaN in, NaN out (occ_pose_check() refuses it). */
occ_quat_t occ_quat_from_euler(float roll_rad, float pitch_rad, float yaw_rad);
/* The inverse: roll and yaw in (-pi, pi], pitch in [-pi/2, pi/2]. Any output may be NULL.
 * Pitched straight up or down (cos pitch < 1e-3, within ~0.06 deg of +-90) roll and yaw turn
 * about the same axis: roll is then 0 and yaw carries yaw - roll (pitch +90) or yaw + roll
 * (pitch -90), so from_euler(to_euler(q)) is still q's rotation (within ~1e-3 rad). */
void occ_quat_to_euler(occ_quat_t q, float *roll_rad, float *pitch_rad, float *yaw_rad);

/* q / |q|. OCC_ERR_ARG (*out untouched) when q has NaN/Inf or |q| < 1e-6. */
occ_err_t occ_quat_normalize(occ_quat_t q, occ_quat_t *out);

/* OCC_OK when p and q are finite and | |q| - 1 | <= OCC_POSE_QUAT_NORM_TOL, OCC_ERR_ARG otherwise
 * (also for NULL). Every call that takes a pose from outside checks it with this. */
occ_err_t occ_pose_check(const occ_pose_t *pose);

/* ---- algebra ------------------------------------------------------------------------------ */
/* a_from_c = a_from_b o b_from_c (p = a.p + R_a c.p, q = a.q c.q, renormalised). */
occ_pose_t occ_pose_compose(const occ_pose_t *a_from_b, const occ_pose_t *b_from_c);
/* b_from_a for a_from_b. */
occ_pose_t occ_pose_invert(const occ_pose_t *a_from_b);
/* v_a = R(q) v_b + p: a point of frame b in frame a. */
occ_vec3_t occ_pose_apply(const occ_pose_t *a_from_b, occ_vec3_t v_b);
/* R(q) d_b: a direction (no translation). */
occ_vec3_t occ_pose_rotate(const occ_pose_t *a_from_b, occ_vec3_t d_b);

/* Heading of the pose's x axis about frame a's z axis, (-pi, pi]: in the ENU map 0 = east,
 * counter-clockwise positive; for a NED pose (occ_pose_to_ned) 0 = north, clockwise. Roll and
 * pitch do not change it (it is the yaw of the ZYX Euler angles; pitched straight up or down,
 * where the x axis has no heading, it is the yaw occ_quat_to_euler() gives). */
float occ_pose_yaw(const occ_pose_t *pose);

/* ---- autopilot (NED / FRD) ---------------------------------------------------------------- */
/* An autopilot pose - position NED (LOCAL_POSITION_NED x, y, z) and attitude NED <- FRD
 * (ATTITUDE_QUATERNION q1..q4, or occ_quat_from_euler(ATTITUDE roll, pitch, yaw)) - as the
 * map pose map(ENU) <- body(FLU). OCC_ERR_ARG for NULL, NaN/Inf or a zero quaternion (q is
 * normalised otherwise). Example: NED heading 0 (north), level -> ENU yaw pi/2. */
occ_err_t occ_pose_from_ned(occ_vec3_t ned_m, occ_quat_t ned_from_frd, occ_pose_t *map_from_body);
/* The inverse of occ_pose_from_ned(). */
occ_err_t occ_pose_to_ned(const occ_pose_t *map_from_body, occ_vec3_t *ned_m,
                          occ_quat_t *ned_from_frd);

/* ---- timed pose history -------------------------------------------------------------------- */
/* Poses arrive at other times than the sensor samples: the history keeps the last `cap` poses
 * (a caller-owned ring, no heap) and answers the pose at a sample's time. */
typedef struct {
    uint64_t t_us;     /* microseconds on the caller's clock (one clock for poses and samples) */
    occ_pose_t pose;   /* map_from_body */
} occ_pose_sample_t;

typedef struct {
    uint64_t max_gap_us;          /* two samples further apart than this do not interpolate */
    uint64_t max_extrapolate_us;  /* at(t) may go this far past the newest sample (0: never) */
} occ_pose_history_cfg_t;

/* Why occ_pose_history_at() refused (OCC_POSE_OK when it did not). */
typedef enum {
    OCC_POSE_OK = 0,
    OCC_POSE_EMPTY,     /* no sample yet */
    OCC_POSE_TOO_OLD,   /* t before the oldest sample the ring still holds */
    OCC_POSE_TOO_NEW,   /* t after the newest sample by more than max_extrapolate_us */
    OCC_POSE_GAP        /* the bracketing samples are more than max_gap_us apart */
} occ_pose_refusal_t;

/* Instance. Size public for static allocation; a caller reads only the counters. */
typedef struct {
    /* read-only for callers: counters since init */
    uint32_t pushed;              /* samples accepted */
    uint32_t rejected_order;      /* pushes refused: not newer than the newest sample */
    uint32_t rejected_bad;        /* pushes refused: bad pose (occ_pose_check) */
    uint32_t refused[5];          /* at() refusals, indexed by occ_pose_refusal_t */
    /* private: layout may change, do not touch */
    occ_pose_sample_t *ring_;
    size_t cap_, head_, count_;   /* head_ = index of the oldest sample */
    occ_pose_history_cfg_t cfg_;
} occ_pose_history_t;

/* Start an empty history over `storage[cap]` (caller-owned, must outlive h; cap >= 2).
 * OCC_ERR_ARG for NULL, cap < 2 or max_gap_us == 0. O(1). */
occ_err_t occ_pose_history_init(occ_pose_history_t *h, occ_pose_sample_t *storage, size_t cap,
                                const occ_pose_history_cfg_t *cfg);

/* Append a pose taken at t_us; the oldest sample is dropped when the ring is full.
 * OCC_ERR_TIME when t_us is not after the newest sample (out of order or duplicate; counted in
 * rejected_order), OCC_ERR_ARG for NULL or a bad pose (counted in rejected_bad). On error the
 * history is unchanged. O(1). */
occ_err_t occ_pose_history_push(occ_pose_history_t *h, uint64_t t_us, const occ_pose_t *pose);

/* The pose at t_us: between two bracketing samples, position linear and rotation slerp
 * (shortest arc); exactly a sample's pose at its time; after the newest sample (up to
 * max_extrapolate_us) the last two samples' motion continued when they are at most max_gap_us
 * apart, else the newest pose held. OCC_ERR_TIME when refused (see occ_pose_refusal_t; counted
 * in refused[]; *out untouched), OCC_ERR_ARG for NULL h/out. `why` may be NULL. O(log cap). */
occ_err_t occ_pose_history_at(occ_pose_history_t *h, uint64_t t_us, occ_pose_t *out,
                              occ_pose_refusal_t *why);

/* Samples held now (0..cap), and the oldest / newest time (OCC_ERR_STATE when empty). */
size_t occ_pose_history_count(const occ_pose_history_t *h);
occ_err_t occ_pose_history_span(const occ_pose_history_t *h, uint64_t *oldest_us,
                                uint64_t *newest_us);

/* Interpolation of two poses at fraction s (0 = a, 1 = b; outside [0, 1] extrapolates):
 * position a.p + s (b.p - a.p), rotation slerp along the shortest arc (q and -q are the same
 * rotation); outside [0, 1] the turn from a to b continues about the same axis at the same
 * rate. a and b unit (occ_pose_check); the result is unit. O(1). */
occ_pose_t occ_pose_interpolate(const occ_pose_t *a, const occ_pose_t *b, float s);

/* ---- Budgets (issue 24) -------------------------------------------------------------------
 * Worst call-chain stack, Cortex-M4F / Cortex-M0+ (GCC 12 -Os, newlib nano; make cross checks
 * every line below against -fcallgraph-info), and the work per call. Callbacks (CAN tx, I/O
 * sinks) add their own stack. Instruction counts on a real map: README, Firmware.
 *   occ_pose_history_at: stack <= 768 / 896 B; work: O(log cap)
 *   occ_pose_history_push, occ_pose_history_init: stack <= 320 / 384 B; work: O(1) (init does
 *       not touch the storage)
 *   occ_pose_history_count, occ_pose_history_span: stack <= 320 / 384 B; work: O(1)
 *   occ_pose_interpolate: stack <= 640 / 768 B; work: O(1), no map access
 *   occ_quat_from_axis_angle, occ_quat_from_euler: stack <= 576 / 704 B; work: O(1), no map access
 *   occ_pose_identity, occ_pose_check, occ_pose_compose: stack <= 320 / 384 B; work: O(1), no
 *       map access
 *   occ_pose_invert, occ_pose_apply, occ_pose_rotate: stack <= 320 / 384 B; work: O(1), no map
 *       access
 *   occ_pose_yaw, occ_pose_from_ned, occ_pose_to_ned: stack <= 320 / 384 B; work: O(1), no map
 *       access
 *   occ_quat_identity, occ_quat_to_euler, occ_quat_normalize: stack <= 128 / 192 B; work: O(1), no
 *       map access
 */

#ifdef __cplusplus
}
#endif
#endif
