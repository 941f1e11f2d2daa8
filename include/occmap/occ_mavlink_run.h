/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * occ_mavlink_run.h - the MAVLink parts of the onboard loop (`occmap run`, issue 21) that the
 * static feed (occ_mavlink.h) does not need: TIMESYNC (111) and its clock-offset filter,
 * STATUSTEXT (253), and a pose receiver that takes poses only from one autopilot and stamps
 * them with the autopilot's own time (for a pose history, occ_pose.h). Pure C99: no OS, no
 * heap; times are passed in as microseconds of the caller's monotonic clock ("local").
 *
 * Clocks: "remote" is the autopilot's time since boot (time_boot_ms x 1000, ODOMETRY time_usec,
 * TIMESYNC tc1 / 1000). The offset filter estimates offset = remote - local.
 */
#ifndef OCC_MAVLINK_RUN_H_INCLUDED
#define OCC_MAVLINK_RUN_H_INCLUDED

#include "occmap/occ_mavlink.h"
#include "occmap/occ_pose.h"

#ifdef __cplusplus
extern "C" {
#endif

#define OCC_MAV_MSG_TIMESYNC 111u
#define OCC_MAV_MSG_STATUSTEXT 253u
/* MAV_SEVERITY (RFC 5424) */
#define OCC_MAV_SEVERITY_CRITICAL 2u
#define OCC_MAV_SEVERITY_WARNING 4u
#define OCC_MAV_SEVERITY_INFO 6u
/* MAV_STATE for HEARTBEAT.system_status */
#define OCC_MAV_STATE_BOOT 1u
#define OCC_MAV_STATE_STANDBY 3u
#define OCC_MAV_STATE_ACTIVE 4u
#define OCC_MAV_STATE_CRITICAL 5u

/* ---- TIMESYNC ----------------------------------------------------------------------------- */
typedef struct {
    int64_t tc1; /* ns: 0 in a request; the responder's time in a reply */
    int64_t ts1; /* ns: the requester's time (echoed in the reply) */
} occ_mav_timesync_t;

/* One MAVLink 2 frame into out (cap >= OCC_MAV_FRAME_MAX suffices); length or 0 (NULL, cap). */
size_t occ_mav_encode_timesync(occ_mav_sender_t *tx, const occ_mav_timesync_t *m, uint8_t *out,
                               size_t cap);
/* OCC_ERR_ARG for NULLs or another message id. O(1). */
occ_err_t occ_mav_decode_timesync(const occ_mav_frame_t *f, occ_mav_timesync_t *out);

/* ---- STATUSTEXT --------------------------------------------------------------------------- */
/* Severity and up to 50 bytes of `text` (longer text is cut at 50; shorter is NUL-padded, as the
 * message wants), id 0 (single chunk). Length or 0 (NULL, cap too small). O(50). */
size_t occ_mav_encode_statustext(occ_mav_sender_t *tx, uint8_t severity, const char *text,
                                 uint8_t *out, size_t cap);

/* ---- OBSTACLE_DISTANCE_3D (11037): one obstacle point ------------------------------------------
 * x, y, z: metres from the vehicle in `frame` (OCC_MAV_FRAME_BODY_FRD: x forward, y right,
 * z down); min/max_distance: the sensor's range in metres. obstacle_id lets the receiver replace
 * an earlier point of the same id (ArduPilot keeps the latest per id until its timeout). */
typedef struct {
    uint32_t time_boot_ms;
    uint8_t sensor_type;     /* MAV_DISTANCE_SENSOR: 0 laser, 4 unknown */
    uint8_t frame;           /* MAV_FRAME: 12 = BODY_FRD */
    uint16_t obstacle_id;
    float x, y, z;           /* m */
    float min_distance, max_distance; /* m */
} occ_mav_obstacle_3d_t;

/* One MAVLink 2 frame into out (cap >= OCC_MAV_FRAME_MAX suffices); length or 0 (NULL, cap too
 * small, or a coordinate that is not finite: nothing is encoded). O(payload). */
size_t occ_mav_encode_obstacle_3d(occ_mav_sender_t *tx, const occ_mav_obstacle_3d_t *m,
                                  uint8_t *out, size_t cap);

/* ---- the clock offset (TIMESYNC) ------------------------------------------------------------
 * A request carries ts1 = local time (ns); the autopilot answers tc1 = its time, ts1 echoed.
 * For a reply received at local time r: rtt = r - ts1, and assuming the two legs take equally
 * long, offset = tc1 - (ts1 + r) / 2 (all in us). Of the last OCC_TIMESYNC_WINDOW accepted
 * replies the one with the smallest rtt is used (the least queued one bounds the error best:
 * |error| <= rtt / 2). A reply is refused when its ts1 is not one of ours (in the future, or
 * older than max_rtt_us, or tc1 <= 0: a request from the peer, not a reply). */
#define OCC_TIMESYNC_WINDOW 8u

typedef struct {
    bool valid;           /* an offset is known */
    int64_t offset_us;    /* remote - local, of the sample in use */
    uint32_t rtt_us;      /* that sample's round trip */
    uint32_t accepted;    /* replies taken */
    uint32_t refused;     /* replies refused (see above) */
    struct {              /* internal: do not touch, layout may change */
        uint32_t max_rtt_us;
        uint32_t n, next;
        int64_t off[OCC_TIMESYNC_WINDOW];
        uint32_t rtt[OCC_TIMESYNC_WINDOW];
    } priv;
} occ_timesync_t;

/* Start with no offset; replies with a round trip above max_rtt_us (> 0) are refused.
 * OCC_ERR_ARG for NULL or 0. O(1). */
occ_err_t occ_timesync_init(occ_timesync_t *ts, uint32_t max_rtt_us);

/* The request to send at local time now_us: tc1 = 0, ts1 = now_us * 1000. */
occ_mav_timesync_t occ_timesync_request(uint64_t now_us);

/* Take a reply received at local time now_us. OCC_OK (taken: offset_us / rtt_us updated),
 * OCC_ERR_TIME (refused, counted), OCC_ERR_ARG (NULL). O(OCC_TIMESYNC_WINDOW). */
occ_err_t occ_timesync_take(occ_timesync_t *ts, const occ_mav_timesync_t *reply, uint64_t now_us);

/* ---- poses from the autopilot, on its clock ----------------------------------------------------
 * Takes LOCAL_POSITION_NED, ATTITUDE, ATTITUDE_QUATERNION and ODOMETRY (frames 1, 16, 18, 20)
 * only from (sysid, compid); everything else is ignored (counted). A position and an attitude
 * make one pose when their stamps are at most pair_tol_us apart and the one received first is
 * newer than the last pose handed out (so P(t1) A(t1) P(t2) A(t2) gives poses at t1 and t2, never
 * P(t2) with A(t1)); the pose is stamped with the later of the two, in remote microseconds,
 * and converted by
 * occ_pose_from_ned() to map ENU <- body FLU. ODOMETRY is a whole pose. A pose is handed out only
 * when its stamp is newer than the last one handed out (so a history push never fails for
 * order). NaN / Inf / zero quaternions are refused (counted in bad). */
typedef struct {
    uint8_t sysid, compid;      /* the autopilot; defaults 1, 1 */
    uint32_t pair_tol_us;       /* default 25000 */
} occ_mav_pose_rx_config_t;

typedef struct {
    uint32_t positions, attitudes; /* messages taken */
    uint32_t poses;                /* poses handed out */
    uint32_t foreign;              /* pose messages from another system or component */
    uint32_t bad;                  /* pose messages that did not decode or were not finite */
    uint32_t unpaired;             /* positions / attitudes replaced by a newer one without
                                    * ever having made a pose (no partner within pair_tol_us);
                                    * one that pairs with a later partner is not counted */
} occ_mav_pose_rx_counters_t;

typedef struct {
    occ_mav_pose_rx_config_t cfg;
    occ_mav_pose_rx_counters_t counters;
    struct {                       /* internal: do not touch, layout may change */
        bool have_pos, have_att, have_out;
        bool pos_paired, att_paired; /* the stored part is in a pose handed out */
        uint64_t pos_us, att_us, out_us;
        occ_vec3_t ned;
        occ_quat_t q;
    } priv;
} occ_mav_pose_rx_t;

occ_mav_pose_rx_config_t occ_mav_pose_rx_config_default(void);
/* OCC_ERR_ARG for NULL. O(1). */
occ_err_t occ_mav_pose_rx_init(occ_mav_pose_rx_t *rx, const occ_mav_pose_rx_config_t *cfg);

/* Take one parsed frame (OCC_MAV_OK). Returns true and fills *out (remote us, map_from_body)
 * when the frame completed a new pose; false otherwise (not a pose message, foreign, bad,
 * unpaired, or not newer). O(1). */
bool occ_mav_pose_rx_take(occ_mav_pose_rx_t *rx, const occ_mav_frame_t *f, occ_pose_sample_t *out);

/* A pose message id (LOCAL_POSITION_NED, ATTITUDE, ATTITUDE_QUATERNION, ODOMETRY). */
bool occ_mav_is_pose_msg(uint32_t msgid);

/* The feed's HEARTBEAT system_status (MAV_STATE; default ACTIVE): the loop sets BOOT, ACTIVE or
 * CRITICAL as its inputs are. A change makes a HEARTBEAT due at once (the next
 * occ_mav_feed_poll sends it), then the 1 Hz period resumes from there. Defined in
 * mavlink_feed.c. No effect for NULL or for the status it already has. */
void occ_mav_feed_set_status(occ_mav_feed_t *f, uint8_t system_status);

/* ---- Budgets (issue 24) -------------------------------------------------------------------
 * Worst call-chain stack, Cortex-M4F / Cortex-M0+ (GCC 12 -Os, newlib nano; make cross checks
 * every line below against -fcallgraph-info), and the work per call.
 *   occ_mav_pose_rx_take: stack <= 704 / 832 B (cosf's argument reduction in
 *       occ_quat_from_euler); work: O(1)
 *   occ_mav_encode_statustext: stack <= 320 / 384 B; work: O(text length), at most 50 bytes
 *   occ_timesync_take: stack <= 128 / 192 B; work: O(window), 8 replies
 *   occ_mav_encode_timesync, occ_mav_decode_timesync: stack <= 320 / 384 B; work: O(1)
 *   occ_mav_encode_obstacle_3d: stack <= 320 / 384 B; work: O(1): one OBSTACLE_DISTANCE_3D frame
 *       (a 28-byte payload)
 *   occ_timesync_init, occ_timesync_request: stack <= 128 / 192 B; work: O(1)
 *   occ_mav_pose_rx_config_default, occ_mav_pose_rx_init: stack <= 320 / 384 B; work: O(1)
 *   occ_mav_is_pose_msg, occ_mav_feed_set_status: stack <= 320 / 384 B; work: O(1)
 */

#ifdef __cplusplus
}
#endif
#endif
