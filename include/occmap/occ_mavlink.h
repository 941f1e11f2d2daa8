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
 *    angle_offset = body angle of sector 0, real min/max distances; obstacle = distance clamped
 *    to [min, max], observed free = max_distance, unknown = UINT16_MAX, never 0, elements past
 *    the configured sectors = UINT16_MAX.
 *  - autopilot ARDUPILOT (PRX1_TYPE = 2): `increment` also carries the rounded width (ArduPilot
 *    uses increment_f when non-zero, so this only helps older firmware). PX4 (CP_DIST > 0):
 *    `increment` = 0; PX4 reads all 72 elements, so the feed refuses configs with
 *    n_sectors * increment_deg < 360 (occ_mav_feed_init returns OCC_ERR_ARG).
 *  - Stale pose (no position or no attitude within pose_timeout_us): nothing is sent; both
 *    autopilots fall back to "no data" 0.5 s after the last message.
 */
#ifndef OCC_MAVLINK_H_INCLUDED
#define OCC_MAVLINK_H_INCLUDED

#include "occmap/occ_feed.h"

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
#define OCC_MAV_COMP_ID_OBSTACLE_AVOIDANCE 196u
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

typedef struct {
    occ_mav_counters_t counters;
    uint16_t pos;           /* bytes of the current frame held in buf */
    uint16_t need;          /* total frame length once known, else 0 */
    uint8_t buf[OCC_MAV_FRAME_MAX];
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

/* Encode as one MAVLink 2 frame into out (cap >= OCC_MAV_FRAME_MAX always suffices); returns
 * the length or 0 (cap too small). O(payload). */
size_t occ_mav_encode_obstacle_distance(occ_mav_sender_t *tx, const occ_mav_obstacle_distance_t *m,
                                        uint8_t *out, size_t cap);
size_t occ_mav_encode_heartbeat(occ_mav_sender_t *tx, const occ_mav_heartbeat_t *m, uint8_t *out,
                                size_t cap);

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

/* Yaw (rad, NED heading) of a w,x,y,z quaternion; roll and pitch (may be NULL). */
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
    occ_sectors_config_t sectors;    /* default occ_sectors_config_default() */
} occ_mav_feed_config_t;

typedef struct {
    uint32_t positions_rx;           /* LOCAL_POSITION_NED and ODOMETRY taken */
    uint32_t attitudes_rx;           /* ATTITUDE, ATTITUDE_QUATERNION and ODOMETRY taken */
    uint32_t ignored_rx;             /* good frames of other messages, ours echoed, odd frames */
    uint32_t obstacle_tx, heartbeat_tx;
    uint32_t stale_skips;            /* OBSTACLE_DISTANCE periods skipped: pose stale/missing */
    uint32_t sector_errors;          /* occ_sectors_compute() failures (vehicle off the map) */
} occ_mav_feed_counters_t;

typedef struct {
    occ_mav_feed_config_t cfg;
    occ_mav_parser_t parser;
    occ_mav_sender_t tx;
    occ_mav_feed_counters_t counters;
    bool have_pos, have_att, started;
    uint64_t pos_us, att_us;         /* receive times */
    float north, east, down, yaw_ned, roll, pitch;
    uint64_t next_obstacle_us, next_heartbeat_us;
    occ_sectors_t sectors;           /* last result + scratch */
} occ_mav_feed_t;

occ_mav_feed_config_t occ_mav_feed_config_default(void);

/* Initialize (the feed owns nothing else). OCC_ERR_ARG: NULL, bad sector config, period 0,
 * timeout 0, PX4 with fewer than 360 degrees of sectors. O(1). */
occ_err_t occ_mav_feed_init(occ_mav_feed_t *f, const occ_mav_feed_config_t *cfg);

/* Bytes received from the autopilot at `now_us`: parsed; poses update the pose state. Frames
 * from our own sysid/compid are ignored (a shared bus echoes). O(n). */
void occ_mav_feed_rx(occ_mav_feed_t *f, const uint8_t *data, size_t n, uint64_t now_us);

/* Produce the next due frame into out (cap >= OCC_MAV_FRAME_MAX): a HEARTBEAT when one is due,
 * else an OBSTACLE_DISTANCE when one is due and the pose is fresh. Returns its length, or 0
 * when nothing is due. Call until it returns 0. Deadlines advance by whole periods (no burst
 * after a pause). Reads `map` (not kept); pass NULL while the map is stale (being rebuilt, or
 * not updated for too long): like a stale pose, the OBSTACLE_DISTANCE period is then skipped.
 * One occ_sectors_compute() per OBSTACLE_DISTANCE (see occ_feed.h for its cost). */
size_t occ_mav_feed_poll(occ_mav_feed_t *f, const occ_map_t *map, uint64_t now_us, uint8_t *out,
                         size_t cap);

/* The current pose in the map frame, true if fresh at now_us. */
bool occ_mav_feed_pose(const occ_mav_feed_t *f, uint64_t now_us, occ_pose_t *pose);

/* The next time poll() may have something to send (for a sleeping loop). */
uint64_t occ_mav_feed_next_due(const occ_mav_feed_t *f);

#ifdef __cplusplus
}
#endif
#endif
