/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * occ_mavlink.h - MAVLink front end: a frame parser, encoders for OBSTACLE_DISTANCE (330) and
 * HEARTBEAT (0), decoders for the pose messages an autopilot streams, and a feed state machine
 * that turns poses into OBSTACLE_DISTANCE at a fixed rate. Pure C99: no OS, no heap, time is
 * passed in as microseconds of a monotonic clock; bytes go in and out through caller buffers
 * (port/posix or port/baremetal move them).
 *
 * Message definitions (ids, CRC_EXTRA, lengths, field layout) come from the C headers that
 * pymavlink's mavgen generates at build time from ardupilotmega.xml (which includes
 * common.xml); this header does not need them. Little-endian targets only (x86, Cortex-M).
 *
 * What we send, and why (read from ArduPilot and PX4):
 *  - MAVLink 2, compid 196 (MAV_COMP_ID_OBSTACLE_AVOIDANCE), a 1 Hz HEARTBEAT as
 *    MAV_TYPE_ONBOARD_CONTROLLER / MAV_AUTOPILOT_INVALID / MAV_STATE_ACTIVE.
 *  - OBSTACLE_DISTANCE with frame 12 (MAV_FRAME_BODY_FRD), increment_f = sector width,
 *    angle_offset = body angle of sector 0's centre (default -20 deg, below), real min/max
 *    distances; obstacle = distance clamped to [min, max], observed free = max_distance + 1
 *    (MAVLink's "no obstacle"), unknown = UINT16_MAX (or its distance with
 *    sectors.unknown_as_distance), never 0, elements past the configured sectors = UINT16_MAX.
 *  - What the autopilots do with each value (read from their sources, checked in ArduCopter
 *    SITL 4.7-dev): ArduPilot resets its 8 faces of 45 deg (centred on 0, 45, ..., 315) on each
 *    message, walks the elements in order, drops 0, UINT16_MAX, < min and > max, keeps the
 *    nearest valid element per face and writes a face each time the element's face changes.
 *    So obstacle = that face's distance; max + 1 (free) = dropped, the face reads "no
 *    obstacle"; UINT16_MAX (unknown) = dropped too: a face of only unknown elements reads "no
 *    obstacle" and its arming check (> 0.6 m in every face) passes. With
 *    unknown_as_distance, unknown space is an obstacle at its distance (min_distance when the
 *    vehicle is in unknown space): ArduPilot then stops short of unexplored space and refuses
 *    to arm when it is within 0.6 m. PX4 (collision prevention): UINT16_MAX = no data (with
 *    CP_GO_NO_DATA = 0 it will not move that way), values >= max_distance = free, others
 *    obstacles.
 *  - angle_offset: with 0, ArduPilot's forward face (337.5..22.5 deg) is visited twice (elements
 *    0-4, then 68-71) and the second visit overwrites the first. The default
 *    OCC_MAV_ANGLE_OFFSET_DEFAULT_DEG = -20 (element centres -20, -15, ..., 335) makes every
 *    face one contiguous run of 9 elements; for another width w use -22.5 + w / 2.
 *  - The autopilot's streams: ArduPilot sends no LOCAL_POSITION_NED / ATTITUDE on a companion
 *    link until asked. The feed asks with COMMAND_LONG MAV_CMD_SET_MESSAGE_INTERVAL (511;
 *    param1 = message id, param2 = pose_interval_us) for each of LOCAL_POSITION_NED and
 *    ATTITUDE that is not fresh (ODOMETRY or ATTITUDE_QUATERNION count too), every
 *    request_period_us until it arrives, and again when it stops (the setting is lost when the
 *    autopilot reboots). A COMMAND_ACK for 511 with a result other than ACCEPTED is counted in
 *    request_refusals (the CLI logs it).
 *  - Poses only from the autopilot: LOCAL_POSITION_NED, ATTITUDE, ATTITUDE_QUATERNION and
 *    ODOMETRY are taken only from (autopilot_sysid, autopilot_compid). autopilot_sysid 0 (the
 *    default) learns the sysid from the first autopilot HEARTBEAT (autopilot field not
 *    MAV_AUTOPILOT_INVALID, type not MAV_TYPE_GCS); until then poses are ignored.
 *  - autopilot ARDUPILOT (PRX1_TYPE = 2): `increment` also carries the rounded width (ArduPilot
 *    uses increment_f when non-zero, so this only helps older firmware). PX4 (CP_DIST > 0):
 *    `increment` = 0; PX4 reads all 72 elements, so the feed refuses configs with
 *    n_sectors * increment_deg < 360 (occ_mav_feed_init returns OCC_ERR_ARG).
 *  - Stale pose (no position or no attitude within pose_timeout_us): nothing is sent; both
 *    autopilots fall back to "no data" 0.5 s after the last message.
 */
#ifndef OCC_MAVLINK_H_INCLUDED
#define OCC_MAVLINK_H_INCLUDED

#include "occmap/occ_sectors.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Largest frame: MAVLink 2 header 10 + payload 255 + CRC 2 + signature 13. */
#define OCC_MAV_FRAME_MAX 280u

#define OCC_MAV_MSG_HEARTBEAT 0u
#define OCC_MAV_MSG_ATTITUDE 30u
#define OCC_MAV_MSG_LOCAL_POSITION_NED 32u
#define OCC_MAV_MSG_ATTITUDE_QUATERNION 31u
#define OCC_MAV_MSG_DISTANCE_SENSOR 132u
#define OCC_MAV_MSG_OBSTACLE_DISTANCE 330u
#define OCC_MAV_MSG_ODOMETRY 331u
#define OCC_MAV_MSG_COMMAND_LONG 76u
#define OCC_MAV_MSG_COMMAND_ACK 77u
#define OCC_MAV_CMD_SET_MESSAGE_INTERVAL 511u
#define OCC_MAV_RESULT_ACCEPTED 0u
#define OCC_MAV_COMP_ID_AUTOPILOT1 1u
#define OCC_MAV_COMP_ID_OBSTACLE_AVOIDANCE 196u
#define OCC_MAV_TYPE_GCS 6u
#define OCC_MAV_AUTOPILOT_INVALID 8u
#define OCC_MAV_ANGLE_OFFSET_DEFAULT_DEG (-20.0f)
#define OCC_MAV_FRAME_BODY_FRD 12u

/* ---- Parser ----------------------------------------------------------------------------------- */
typedef enum {
    OCC_MAV_NONE = 0,      /* byte consumed, no frame finished yet */
    OCC_MAV_OK = 1,        /* a frame of a known message with a good CRC and length */
    OCC_MAV_BAD_CRC = 2,   /* CRC (with the message's CRC_EXTRA) does not match */
    OCC_MAV_BAD_LEN = 3,   /* MAVLink 2 payload longer than the message; MAVLink 1 payload
                            * length different from the message's */
    OCC_MAV_UNKNOWN = 4,   /* message id not in the dialect (CRC cannot be checked) */
    OCC_MAV_BAD_FLAGS = 5, /* MAVLink 2 incompat_flags other than "signed" */
    OCC_MAV_JUNK = 6       /* a byte outside any frame (not a start marker) */
} occ_mav_result_t;

/* A frame the parser finished (for every result but NONE and JUNK). Pointers point into the
 * parser's buffer and stay valid until the next occ_mav_parser_push(). */
typedef struct {
    uint32_t msgid;
    uint8_t version;        /* 1 or 2 */
    uint8_t seq, sysid, compid;
    uint8_t incompat_flags, compat_flags;
    uint8_t len;            /* payload bytes on the wire (MAVLink 2 trims trailing zeros) */
    bool is_signed;         /* a 13-byte signature followed (not verified: no key) */
    const uint8_t *payload;
    const uint8_t *frame;   /* the whole frame, frame_len bytes */
    uint16_t frame_len;
} occ_mav_frame_t;

typedef struct {
    uint64_t bytes;         /* bytes pushed */
    uint32_t frames_ok, bad_crc, bad_len, unknown_id, bad_flags;
    uint32_t junk_bytes;    /* bytes outside frames */
} occ_mav_counters_t;

/* A caller may read `counters` (never write them); `priv` is the parser's own state. */
typedef struct {
    occ_mav_counters_t counters;
    struct {                /* internal: do not touch, layout may change */
        uint16_t pos;       /* bytes of the current frame held in buf */
        uint16_t need;      /* total frame length once known, else 0 */
        uint8_t buf[OCC_MAV_FRAME_MAX];
    } priv;
} occ_mav_parser_t;

/* Reset the parser and its counters. O(1). */
void occ_mav_parser_init(occ_mav_parser_t *p);

/* Feed one byte. Frames are delimited as pymavlink does (a start marker 0xFD/0xFE, the length
 * byte, the signature flag), so after a bad frame the parser resumes after that frame's last
 * byte, like pymavlink and the MAVLink C library. Every result other than NONE bumps one
 * counter. `frame` (may be NULL) is filled for OK, BAD_CRC, BAD_LEN, UNKNOWN and BAD_FLAGS.
 * O(1) per byte; O(log n) per frame for the CRC_EXTRA lookup. Never reads past its buffer,
 * whatever the input. */
occ_mav_result_t occ_mav_parser_push(occ_mav_parser_t *p, uint8_t byte, occ_mav_frame_t *frame);

/* CRC_EXTRA and payload length limits of a message id of the dialect; false if unknown. */
bool occ_mav_msg_info(uint32_t msgid, uint8_t *crc_extra, uint8_t *min_len, uint8_t *max_len);

/* ---- Encoding ----------------------------------------------------------------------------------- */
typedef struct {
    uint8_t sysid, compid;
    uint8_t seq;            /* next sequence number, +1 per frame */
} occ_mav_sender_t;

/* Frame `payload` (len bytes, the message's full wire layout) as MAVLink 2 (trailing zero bytes
 * trimmed, at least one kept), unsigned, with this sender's ids and next sequence number.
 * Returns the frame length written to `out`, or 0 if the id is unknown, len exceeds the
 * message's length, or `cap` is too small (then nothing is written and seq is unchanged). */
size_t occ_mav_finalize(occ_mav_sender_t *tx, uint32_t msgid, const uint8_t *payload, size_t len,
                        uint8_t *out, size_t cap);

typedef struct {
    uint64_t time_usec;
    uint8_t sensor_type;    /* MAV_DISTANCE_SENSOR: 0 laser, 4 unknown */
    uint16_t distances[72]; /* cm */
    uint8_t increment;      /* deg */
    uint16_t min_distance, max_distance; /* cm */
    float increment_f;      /* deg, overrides increment when > 0 */
    float angle_offset;     /* deg, body angle of element 0, clockwise */
    uint8_t frame;          /* MAV_FRAME: 12 = BODY_FRD */
} occ_mav_obstacle_distance_t;

typedef struct {
    uint32_t custom_mode;
    uint8_t type, autopilot, base_mode, system_status, mavlink_version;
} occ_mav_heartbeat_t;

typedef struct {
    uint8_t target_system, target_component;
    uint16_t command;       /* MAV_CMD */
    uint8_t confirmation;   /* 0 first transmission, +1 per retransmission */
    float param[7];         /* param1..param7 */
} occ_mav_command_long_t;

typedef struct {
    uint16_t command;       /* MAV_CMD acknowledged */
    uint8_t result;         /* MAV_RESULT: 0 ACCEPTED, 1 TEMPORARILY_REJECTED, 2 DENIED,
                             * 3 UNSUPPORTED, 4 FAILED, ... */
    uint8_t progress;
    int32_t result_param2;
    uint8_t target_system, target_component;
} occ_mav_command_ack_t;

/* Encode as one MAVLink 2 frame into out (cap >= OCC_MAV_FRAME_MAX always suffices); returns
 * the length or 0 (cap too small). O(payload). */
size_t occ_mav_encode_obstacle_distance(occ_mav_sender_t *tx, const occ_mav_obstacle_distance_t *m,
                                        uint8_t *out, size_t cap);
size_t occ_mav_encode_heartbeat(occ_mav_sender_t *tx, const occ_mav_heartbeat_t *m, uint8_t *out,
                                size_t cap);
size_t occ_mav_encode_command_long(occ_mav_sender_t *tx, const occ_mav_command_long_t *m,
                                   uint8_t *out, size_t cap);
size_t occ_mav_encode_command_ack(occ_mav_sender_t *tx, const occ_mav_command_ack_t *m,
                                  uint8_t *out, size_t cap);

/* ---- Decoding (frames the parser returned as OCC_MAV_OK) ---------------------------------------
 * Each returns OCC_ERR_ARG for NULLs or a frame of another message id. Truncated MAVLink 2
 * payloads are zero-filled, as the protocol requires. O(payload). */
typedef struct {
    uint32_t time_boot_ms;
    float x, y, z, vx, vy, vz;       /* m, m/s, local NED */
} occ_mav_local_position_ned_t;
typedef struct {
    uint32_t time_boot_ms;
    float roll, pitch, yaw;          /* rad; yaw from north, clockwise */
    float rollspeed, pitchspeed, yawspeed;
} occ_mav_attitude_t;
typedef struct {
    uint32_t time_boot_ms;
    float q[4];                      /* w, x, y, z: body FRD to local NED */
    float rollspeed, pitchspeed, yawspeed;
} occ_mav_attitude_quaternion_t;
typedef struct {
    uint64_t time_usec;
    uint8_t frame_id, child_frame_id;
    float x, y, z;                   /* m, in frame_id */
    float q[4];                      /* w, x, y, z */
    float vx, vy, vz;
} occ_mav_odometry_t;
typedef struct {
    uint32_t time_boot_ms;
    uint16_t min_distance, max_distance, current_distance;
    uint8_t type, id, orientation, covariance;
    float horizontal_fov, vertical_fov;
    float quaternion[4];
    uint8_t signal_quality;
} occ_mav_distance_sensor_t;

occ_err_t occ_mav_decode_local_position_ned(const occ_mav_frame_t *f, occ_mav_local_position_ned_t *out);
occ_err_t occ_mav_decode_attitude(const occ_mav_frame_t *f, occ_mav_attitude_t *out);
occ_err_t occ_mav_decode_attitude_quaternion(const occ_mav_frame_t *f, occ_mav_attitude_quaternion_t *out);
occ_err_t occ_mav_decode_odometry(const occ_mav_frame_t *f, occ_mav_odometry_t *out);
occ_err_t occ_mav_decode_distance_sensor(const occ_mav_frame_t *f, occ_mav_distance_sensor_t *out);
occ_err_t occ_mav_decode_heartbeat(const occ_mav_frame_t *f, occ_mav_heartbeat_t *out);
occ_err_t occ_mav_decode_obstacle_distance(const occ_mav_frame_t *f, occ_mav_obstacle_distance_t *out);
occ_err_t occ_mav_decode_command_long(const occ_mav_frame_t *f, occ_mav_command_long_t *out);
occ_err_t occ_mav_decode_command_ack(const occ_mav_frame_t *f, occ_mav_command_ack_t *out);

/* Yaw (rad, NED heading) of a w,x,y,z quaternion; roll and pitch (may be NULL): the ZYX Euler
 * angles of occ_quat_to_euler() (occ_pose.h), for a quaternion in a MAVLink float[4]. */
float occ_mav_quat_yaw(const float q[4], float *roll, float *pitch);

/* ---- The feed (src/feed/mavlink_feed.c) --------------------------------------------------------- */
typedef enum { OCC_AUTOPILOT_ARDUPILOT = 0, OCC_AUTOPILOT_PX4 = 1 } occ_autopilot_t;
typedef enum { OCC_MAP_FRAME_ENU = 0, OCC_MAP_FRAME_NED = 1 } occ_map_frame_t;

typedef struct {
    uint8_t sysid, compid;           /* ours; defaults 1 and 196 */
    uint32_t period_us;              /* OBSTACLE_DISTANCE period, default 100000 (10 Hz) */
    uint32_t heartbeat_period_us;    /* default 1000000 */
    uint32_t pose_timeout_us;        /* default 300000: older position/attitude = stale */
    occ_autopilot_t autopilot;       /* default ARDUPILOT */
    occ_map_frame_t map_frame;       /* default ENU */
    uint8_t sensor_type;             /* default 0 (MAV_DISTANCE_SENSOR_LASER) */
    uint8_t autopilot_sysid;         /* poses only from this system; 0 (default): learn it from
                                      * the first autopilot HEARTBEAT */
    uint8_t autopilot_compid;        /* poses only from this component; default 1 */
    uint32_t pose_interval_us;       /* interval asked with SET_MESSAGE_INTERVAL, default 50000
                                      * (20 Hz); 0: never ask (streams set on the autopilot) */
    uint32_t request_period_us;      /* resend period while a stream is missing, default 1 s */
    occ_sectors_config_t sectors;    /* default occ_sectors_config_default() with
                                      * angle_offset_deg = OCC_MAV_ANGLE_OFFSET_DEFAULT_DEG */
} occ_mav_feed_config_t;

typedef struct {
    uint32_t positions_rx;           /* LOCAL_POSITION_NED and ODOMETRY taken */
    uint32_t attitudes_rx;           /* ATTITUDE, ATTITUDE_QUATERNION and ODOMETRY taken */
    uint32_t ignored_rx;             /* good frames of other messages, ours echoed, odd frames */
    uint32_t foreign_rx;             /* pose messages from another system or component (ignored;
                                      * also counted in ignored_rx) */
    uint32_t requests_tx;            /* SET_MESSAGE_INTERVAL commands sent */
    uint32_t request_acks;           /* COMMAND_ACK for them with MAV_RESULT_ACCEPTED */
    uint32_t request_refusals;       /* COMMAND_ACK for them with another result */
    uint8_t last_refusal_result;     /* MAV_RESULT of the last refusal */
    uint32_t obstacle_tx, heartbeat_tx;
    uint32_t stale_skips;            /* OBSTACLE_DISTANCE periods skipped: pose stale/missing */
    uint32_t sector_errors;          /* occ_sectors_compute() failures (vehicle off the map) */
} occ_mav_feed_counters_t;

/* The feed: caller-allocated, set up by occ_mav_feed_init(), changed only through the API.
 * A caller may read the fields above `priv` (never write them); `priv` is the feed's own
 * state: do not touch, its layout may change. */
typedef struct {
    occ_mav_feed_config_t cfg;       /* the configuration occ_mav_feed_init() accepted */
    occ_mav_parser_t parser;         /* parser.counters: every byte and frame received */
    occ_mav_feed_counters_t counters;
    bool have_autopilot;             /* ap_sysid known (given or learned) */
    uint8_t ap_sysid, ap_compid;     /* the autopilot poses are taken from */
    struct {
        occ_mav_sender_t tx;
        bool have_pos, have_att, started;
        uint8_t request_mask;        /* streams still to ask for in this round: 1 pos, 2 att */
        uint64_t pos_us, att_us;     /* receive times */
        uint64_t next_request_us;
        occ_vec3_t ned_m;            /* last position, local NED metres */
        occ_quat_t ned_from_frd;     /* last attitude, body FRD -> local NED (unit) */
        uint64_t next_obstacle_us, next_heartbeat_us;
        occ_sectors_t sectors;       /* last result + scratch */
        uint8_t system_status;       /* HEARTBEAT's MAV_STATE (occ_mav_feed_set_status) */
    } priv;                          /* internal: do not touch, layout may change */
} occ_mav_feed_t;

occ_mav_feed_config_t occ_mav_feed_config_default(void);

/* Initialize (the feed owns nothing else). OCC_ERR_ARG: NULL, bad sector config, period 0,
 * timeout 0, request period 0 while pose_interval_us > 0, PX4 with fewer than 360 degrees of
 * sectors. O(1). */
occ_err_t occ_mav_feed_init(occ_mav_feed_t *f, const occ_mav_feed_config_t *cfg);

/* Bytes received from the autopilot at `now_us`: parsed; poses from the autopilot (see "Poses
 * only from the autopilot") update the pose state, its HEARTBEAT names it, COMMAND_ACKs for
 * SET_MESSAGE_INTERVAL are counted. Frames from our own sysid/compid are ignored (a shared bus
 * echoes). O(n). */
void occ_mav_feed_rx(occ_mav_feed_t *f, const uint8_t *data, size_t n, uint64_t now_us);

/* Produce the next due frame into out (cap >= OCC_MAV_FRAME_MAX): a HEARTBEAT when one is due,
 * else a SET_MESSAGE_INTERVAL for a missing pose stream when a request round is due (the
 * autopilot known, pose_interval_us > 0), else an OBSTACLE_DISTANCE when one is due and the
 * pose is fresh. Returns its length, or 0
 * when nothing is due. Call until it returns 0. Deadlines advance by whole periods (no burst
 * after a pause). Reads `map` (not kept); pass NULL while the map is stale (being rebuilt, or
 * not updated for too long): like a stale pose, the OBSTACLE_DISTANCE period is then skipped.
 * One occ_sectors_compute() per OBSTACLE_DISTANCE (see occ_sectors.h for its cost). */
size_t occ_mav_feed_poll(occ_mav_feed_t *f, const occ_map_t *map, uint64_t now_us, uint8_t *out,
                         size_t cap);

/* The current pose in the map frame, true if fresh at now_us: map(ENU) <- body(FLU) by
 * occ_pose_from_ned() for an ENU map, the autopilot's own NED position and NED <- FRD attitude
 * for map_frame NED (what occ_sectors_compute() reads with cfg.map_ned). *pose is written
 * whenever a position and an attitude have been received (may be NULL). */
bool occ_mav_feed_pose(const occ_mav_feed_t *f, uint64_t now_us, occ_pose_t *pose);

/* The next time poll() may have something to send (for a sleeping loop). */
uint64_t occ_mav_feed_next_due(const occ_mav_feed_t *f);

/* ---- Budgets (issue 24) -------------------------------------------------------------------
 * Worst call-chain stack, Cortex-M4F / Cortex-M0+ (GCC 12 -Os, newlib nano; make cross checks
 * every line below against -fcallgraph-info), and the work per call. Callbacks (CAN tx, I/O
 * sinks) add their own stack. Instruction counts on a real map: README, Firmware.
 *   occ_mav_feed_poll: stack <= 960 / 1,024 B; work: one message: occ_sectors_compute
 *       (occ_sectors.h) when OBSTACLE_DISTANCE is due
 *   occ_mav_feed_rx: stack <= 768 / 832 B; work: one frame, O(payload)
 *   occ_mav_parser_push: stack <= 320 / 384 B; work: O(1) per byte, O(log n) per frame
 *   occ_mav_feed_pose: stack <= 320 / 448 B; work: O(1)
 *   occ_mav_*: stack <= 320 / 384 B; work: O(1) or O(payload bytes); no map access
 */

#ifdef __cplusplus
}
#endif
#endif
