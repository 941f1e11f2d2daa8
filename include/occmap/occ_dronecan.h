/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * occ_dronecan.h - the CAN front end: a minimal DroneCAN (UAVCAN v0) node that tells an autopilot
 * where the obstacles are. This header is the manual.
 *
 * Layers (all portable C99, no heap, no OS; time is always passed in, microseconds):
 *  - occ_can_frame_t + occ_can_iface_t: one CAN frame and the transmit hook a port provides
 *    (port/baremetal/can_hooks.c; on a host port/posix/socketcan.c and can_mcast.c, declared in
 *    occmap/host/occ_socketcan.h and occmap/host/occ_can_mcast.h).
 *  - Transfer layer (can_transfer.c): 29-bit ids, tail bytes, multi-frame split with the
 *    transfer CRC seeded by the data type signature, bit-stream packing, IEEE half floats.
 *  - Messages (dronecan.c): ardupilot.equipment.proximity_sensor.Proximity (21910),
 *    uavcan.protocol.NodeStatus (341), the uavcan.protocol.GetNodeInfo (service 1) response.
 *  - The node (dronecan.c): static node id, per-type transfer ids, Proximity at 10 Hz (one
 *    transfer per sector with an obstacle; one NO_DATA reading when the data is stale; one
 *    NOT_CONNECTED reading when there is no map), NodeStatus at 1 Hz, GetNodeInfo answered.
 *  - occ_dronecan_poll_map() (dronecan_map.c): the same fed straight from a map and a pose through
 *    the sector module (occ_sectors.h).
 *  - Range sensors in (range_rx.c): uavcan.equipment.range_sensor.Measurement (1050) received
 *    (multi-frame reassembly, CRC) and turned into a range beam (occ_ranges.h) with the mount
 *    configured for its sensor_id.
 *
 * Only classic CAN (8-byte) frames are emitted by the node; the frame type carries FD frames for
 * the ports. Bit-exact with pydronecan 1.0.27 (tests/can_golden.py checks it byte for byte).
 * Not thread-safe: one node per thread, or serialize the calls.
 */
#ifndef OCC_DRONECAN_H_INCLUDED
#define OCC_DRONECAN_H_INCLUDED

#include <stddef.h>
#include <stdint.h>
#include <stdbool.h>

#include "occmap/occ_core.h"
#include "occmap/occ_pose.h"
#include "occmap/occ_ranges.h"
#include "occmap/occ_sectors.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- Frames and the port hook ----------------------------------------------------------------- */
#define OCC_CAN_FLAG_EXT 0x01u /* 29-bit identifier (every DroneCAN frame) */
#define OCC_CAN_FLAG_FD 0x02u  /* CAN FD frame (len up to 64) */
#define OCC_CAN_FLAG_BRS 0x04u /* FD bit rate switch */
#define OCC_CAN_FLAG_RTR 0x08u /* remote request (classic only) */
#define OCC_CAN_FLAG_ERR 0x10u /* error report from the port (rx only): see occ_can_err_* below */
#define OCC_CAN_MAX_DATA 64u
#define OCC_CAN_EXT_ID_MASK 0x1FFFFFFFu

typedef struct {
    uint32_t id;      /* identifier without flag bits: 29 bits with EXT, else 11 bits */
    uint8_t len;      /* data bytes: 0..8 classic, 0..64 FD (a valid FD length) */
    uint8_t flags;    /* OCC_CAN_FLAG_* */
    uint8_t data[OCC_CAN_MAX_DATA];
} occ_can_frame_t;

/* With OCC_CAN_FLAG_ERR the port reports a bus condition; `id` holds OCC_CAN_ERR_* bits. */
#define OCC_CAN_ERR_BUS_OFF 0x01u   /* controller went bus-off */
#define OCC_CAN_ERR_PASSIVE 0x02u   /* error passive (warning limits passed) */
#define OCC_CAN_ERR_TX_TIMEOUT 0x04u
#define OCC_CAN_ERR_LOST_ARB 0x08u
#define OCC_CAN_ERR_PROTOCOL 0x10u  /* bit/stuff/form/ack errors */
#define OCC_CAN_ERR_OTHER 0x80u

/* Transmit one frame without blocking. Return OCC_OK when queued, OCC_ERR_NOMEM when the transmit
 * queue is full (the frame is dropped), OCC_ERR_IO for a driver error. `frame` is only borrowed
 * for the call. */
typedef occ_err_t (*occ_can_tx_fn)(void *user, const occ_can_frame_t *frame);
/* Free transmit slots now (optional: NULL means unknown; the node then sends frame by frame and
 * stops a transfer at the first full queue). */
typedef uint32_t (*occ_can_tx_space_fn)(void *user);

typedef struct {
    occ_can_tx_fn tx;
    occ_can_tx_space_fn tx_space; /* may be NULL */
    void *user;                   /* passed back to the hooks */
} occ_can_iface_t;

/* ---- DroneCAN transfer layer (can_transfer.c) ------------------------------------------------- */
#define OCC_DRONECAN_PRIO_HIGHEST 0u
#define OCC_DRONECAN_PRIO_MEDIUM 16u
#define OCC_DRONECAN_PRIO_LOWEST 31u

#define OCC_DRONECAN_TAIL_START 0x80u
#define OCC_DRONECAN_TAIL_END 0x40u
#define OCC_DRONECAN_TAIL_TOGGLE 0x20u
#define OCC_DRONECAN_TAIL_TID 0x1Fu

/* Largest transfer payload the node builds (GetNodeInfo response with an 80-byte name). */
#define OCC_DRONECAN_MAX_PAYLOAD 128u

/* Message frame id: priority (0..31) << 24 | data type id << 8 | source node (1..127). */
uint32_t occ_dronecan_msg_id(uint8_t priority, uint16_t data_type_id, uint8_t src_node);
/* Service frame id: priority << 24 | service id << 16 | request << 15 | dst << 8 | 0x80 | src. */
uint32_t occ_dronecan_svc_id(uint8_t priority, uint8_t service_id, bool request, uint8_t dst_node,
                             uint8_t src_node);

/* CRC-16-CCITT-FALSE (poly 0x1021, no reflection, no final xor) of `n` bytes continuing `crc`
 * (start with 0xFFFF). O(n). */
uint16_t occ_dronecan_crc16(uint16_t crc, const uint8_t *data, size_t n);
/* The transfer CRC's seed: 0xFFFF continued over the 8 signature bytes, little endian. */
uint16_t occ_dronecan_crc_seed(uint64_t signature);

/* Write the low `bit_len` (1..64) bits of `value` at bit `bit_off` of `buf` the way DSDL v0 does
 * (little-endian bytes, MSB-first bit stream; a partial last byte keeps its low bits). Bits
 * outside the field are left as they are; the caller zeroes the buffer first. */
void occ_dronecan_put_bits(uint8_t *buf, size_t bit_off, unsigned bit_len, uint64_t value);
/* Read back what occ_dronecan_put_bits() wrote. */
uint64_t occ_dronecan_get_bits(const uint8_t *buf, size_t bit_off, unsigned bit_len);

/* IEEE 754 half from float, as DSDL saturated float16 and pydronecan do it: +-Inf and values
 * beyond +-65504 saturate to +-65504 (0x7BFF), NaN gives 0x7FFF (with the sign), the mantissa
 * rounds half away from zero, subnormals are kept. O(1), float math only. */
uint16_t occ_float16_from_float(float f);
/* Half to float, exact (Inf and NaN survive). */
float occ_float16_to_float(uint16_t h);

/* Frames a transfer of `payload_len` bytes takes on classic CAN: 1 up to 7 bytes, else
 * ceil((payload_len + 2) / 7). */
size_t occ_dronecan_frame_count(size_t payload_len);

/* Split one transfer into classic CAN frames and hand them to `iface`, in order.
 * `can_id` from occ_dronecan_msg_id()/occ_dronecan_svc_id(); `signature` seeds the CRC of
 * multi-frame transfers; `tid` 0..31. If iface->tx_space says there is room for fewer frames than
 * needed, nothing is sent and OCC_ERR_NOMEM is returned. If the hook reports a full queue midway,
 * the rest is dropped and OCC_ERR_NOMEM is returned. `frames_sent` (may be NULL) gets the frames
 * the hook accepted. OCC_ERR_ARG for NULL, an empty hook, tid > 31 or payload_len >
 * OCC_DRONECAN_MAX_PAYLOAD; OCC_ERR_IO when the hook reported a driver error. O(payload_len). */
occ_err_t occ_dronecan_send_transfer(const occ_can_iface_t *iface, uint32_t can_id,
                                     uint64_t signature, uint8_t tid, const uint8_t *payload,
                                     size_t payload_len, size_t *frames_sent);

/* ---- Messages (dronecan.c) -------------------------------------------------------------------- */
#define OCC_DRONECAN_PROXIMITY_ID 21910u
#define OCC_DRONECAN_PROXIMITY_SIG 0x99DD3985FB3222CEull
#define OCC_DRONECAN_NODESTATUS_ID 341u
#define OCC_DRONECAN_NODESTATUS_SIG 0x0F0868D0C1A7C6F1ull
#define OCC_DRONECAN_GETNODEINFO_ID 1u
#define OCC_DRONECAN_GETNODEINFO_SIG 0xEE468A8121C46A9Eull

typedef enum {
    OCC_PROX_NO_DATA = 0,       /* distance unknown (stale map or pose) */
    OCC_PROX_NOT_CONNECTED = 1, /* no map */
    OCC_PROX_GOOD = 2
} occ_prox_reading_t;

typedef struct {
    uint8_t sensor_id;
    occ_prox_reading_t reading_type;
    uint8_t flags;      /* 5 bits, reserved: 0 */
    float yaw_deg;      /* body frame, 0 = forward, clockwise positive */
    float pitch_deg;    /* body frame, up positive */
    float distance_m;
} occ_dronecan_proximity_t;

/* Payload of a Proximity message: always 8 bytes written to `out`. Returns 8. */
size_t occ_dronecan_encode_proximity(const occ_dronecan_proximity_t *msg, uint8_t out[8]);

#define OCC_NODE_HEALTH_OK 0u
#define OCC_NODE_HEALTH_WARNING 1u
#define OCC_NODE_HEALTH_ERROR 2u
#define OCC_NODE_HEALTH_CRITICAL 3u
#define OCC_NODE_MODE_OPERATIONAL 0u
#define OCC_NODE_MODE_INITIALIZATION 1u
#define OCC_NODE_MODE_MAINTENANCE 2u

typedef struct {
    uint32_t uptime_sec;
    uint8_t health;     /* 2 bits: OCC_NODE_HEALTH_* */
    uint8_t mode;       /* 3 bits: OCC_NODE_MODE_* */
    uint8_t sub_mode;   /* 3 bits */
    uint16_t vendor_status;
} occ_dronecan_node_status_t;

/* Payload of a NodeStatus message: always 7 bytes written. Returns 7. */
size_t occ_dronecan_encode_node_status(const occ_dronecan_node_status_t *msg, uint8_t out[7]);

typedef struct {
    occ_dronecan_node_status_t status;
    uint8_t sw_major, sw_minor;
    uint8_t sw_optional_flags;   /* 1: vcs_commit valid, 2: image_crc valid */
    uint32_t vcs_commit;
    uint64_t image_crc;
    uint8_t hw_major, hw_minor;
    uint8_t unique_id[16];
    const char *name;            /* NUL-terminated, at most 80 bytes are sent; NULL = empty */
} occ_dronecan_node_info_t;

/* Payload of a GetNodeInfo response (status, software and hardware version with an empty
 * certificate, name as the tail array). Writes at most OCC_DRONECAN_MAX_PAYLOAD bytes (cap must
 * be >= that) and returns the length, or 0 on a NULL argument or a small buffer. */
size_t occ_dronecan_encode_node_info(const occ_dronecan_node_info_t *info, uint8_t *out,
                                     size_t cap);

/* ---- The node (dronecan.c) -------------------------------------------------------------------- */
typedef struct {
    uint8_t node_id;               /* static node id 1..127 */
    uint8_t sensor_id;             /* Proximity sensor_id (ArduPilot PRXn_ADDR) */
    uint8_t priority;              /* Proximity and NodeStatus priority, 0..31 */
    uint32_t proximity_period_us;  /* > 0; default 100000 (10 Hz) */
    uint32_t status_period_us;     /* > 0, <= 1000000; default 1000000 (1 Hz) */
    uint32_t stale_after_us;       /* data older than this is stale; default 500000 */
    float pitch_deg;               /* pitch reported with every reading, default 0 */
    const char *name;              /* GetNodeInfo name; default "org.occmap.obstacles" */
    uint8_t sw_major, sw_minor, hw_major, hw_minor;
    uint32_t vcs_commit;           /* sent with optional flag 1 when non-zero */
    uint8_t unique_id[16];
} occ_dronecan_config_t;

typedef struct {
    uint32_t tx_frames;       /* frames the hook accepted */
    uint32_t tx_transfers;    /* transfers sent completely */
    uint32_t tx_full;         /* transfers (partly) dropped because the queue was full */
    uint32_t tx_errors;       /* transfers stopped by a driver error */
    uint32_t rx_frames;       /* frames ingested */
    uint32_t rx_ignored;      /* frames not for us / not understood */
    uint32_t rx_bus_errors;   /* error reports from the port */
    uint32_t bus_off;         /* bus-off reports */
    uint32_t node_info_answered;
    uint32_t proximity_sent;  /* Proximity transfers sent completely */
} occ_dronecan_stats_t;

/* The node: caller-allocated, set up by occ_dronecan_init(), changed only through the API.
 * A caller may read the fields above `priv` (never write them); `priv` is the node's own
 * state: do not touch, its layout may change. */
typedef struct {
    occ_dronecan_config_t cfg;  /* the configuration occ_dronecan_init() accepted */
    occ_dronecan_stats_t stats;
    uint64_t next_proximity_us, next_status_us; /* when the next publications are due (valid
                                                 * after the first poll) */
    uint8_t health, mode;       /* OCC_NODE_HEALTH_*, OCC_NODE_MODE_* from the last poll */
    uint16_t last_obstacles;    /* sectors with an obstacle in the last publication (NodeStatus
                                 * vendor_specific_status_code) */
    struct {
        occ_can_iface_t iface;
        uint8_t tid_proximity, tid_status;
        bool started;
        uint64_t start_us;
        occ_sectors_t sectors;  /* scratch for occ_dronecan_poll_map() */
    } priv;                     /* internal: do not touch, layout may change */
} occ_dronecan_node_t;

/* Node id 0 (must be set), sensor 0, priority 24, 10 Hz, 1 Hz, 500 ms, version 0.1. */
occ_dronecan_config_t occ_dronecan_config_default(void);

/* Initialize `node` (caller-owned, no deinit). OCC_ERR_ARG for NULL, node id outside 1..127,
 * priority > 31, zero periods, a status period over 1 s, iface->tx NULL. O(1). */
occ_err_t occ_dronecan_init(occ_dronecan_node_t *node, const occ_dronecan_config_t *cfg,
                            const occ_can_iface_t *iface);

/* What the node knows at one instant. */
typedef struct {
    bool have_map;                       /* false: NOT_CONNECTED, health ERROR */
    bool fresh;                          /* false: NO_DATA, health WARNING */
    const occ_sectors_t *sectors;        /* needed when have_map && fresh */
    const occ_sectors_config_t *sectors_cfg; /* angles and max distance of `sectors` */
} occ_dronecan_view_t;

/* Publish what is due at `now_us` (monotonic microseconds; the first call starts the clock and
 * publishes both at once): NodeStatus every status period, Proximity every proximity period -
 * GOOD, one transfer per sector whose distance is below sectors_cfg->max_distance_cm (yaw = sector
 * centre in (-180, 180], distance in metres), nothing else when no sector has an obstacle; one
 * NO_DATA or NOT_CONNECTED reading otherwise. A call between due times does nothing.
 * Returns OCC_OK, OCC_ERR_NOMEM when a transfer was dropped on a full queue (counted, the rest is
 * still tried), OCC_ERR_IO on a driver error, OCC_ERR_ARG for NULL or a fresh view without
 * sectors. Never blocks. O(sectors). */
occ_err_t occ_dronecan_poll(occ_dronecan_node_t *node, uint64_t now_us,
                            const occ_dronecan_view_t *view);

/* Publish every sector with an obstacle right now (what poll does when due): returns the number of
 * transfers sent completely through *sent (may be NULL). Errors as occ_dronecan_poll. */
occ_err_t occ_dronecan_publish_sectors(occ_dronecan_node_t *node, const occ_sectors_t *sectors,
                                       const occ_sectors_config_t *cfg, size_t *sent);
/* Publish one Proximity reading (any type) now. */
occ_err_t occ_dronecan_publish_proximity(occ_dronecan_node_t *node,
                                         const occ_dronecan_proximity_t *msg);
/* Publish one NodeStatus now with uptime from now_us. */
occ_err_t occ_dronecan_publish_status(occ_dronecan_node_t *node, uint64_t now_us);

/* Hand one received frame to the node. Answers a GetNodeInfo request addressed to this node
 * (single-frame request, empty payload) with the response, same priority and transfer id; counts
 * bus-off / error reports; ignores everything else (counted in rx_ignored). Returns OCC_OK, or
 * the send error of the response. O(1) plus the response. */
occ_err_t occ_dronecan_ingest(occ_dronecan_node_t *node, const occ_can_frame_t *frame,
                              uint64_t now_us);

/* Poll straight from a map (dronecan_map.c): `map` NULL = no map; `pose` is the vehicle's
 * map_from_body as occ_sectors_compute() reads it (ENU <- FLU, or NED <- FRD with
 * sectors_cfg->map_ned; NULL = no pose); the data is fresh when both
 * stamps are within cfg.stale_after_us of now_us (a stamp ahead of now_us counts as fresh).
 * When a Proximity publication is due and the data is fresh, sectors are computed with
 * occ_sectors_compute() into the node's scratch (only then; it is ~5 KB, so
 * keep the node static on a small stack). If that fails (e.g. OCC_ERR_RANGE: the vehicle is
 * outside the map), the node still publishes - a NO_DATA reading and NodeStatus - and the
 * sector error is returned. Otherwise errors as occ_dronecan_poll. */
occ_err_t occ_dronecan_poll_map(occ_dronecan_node_t *node, uint64_t now_us, const occ_map_t *map,
                                uint64_t map_stamp_us, const occ_pose_t *pose,
                                uint64_t pose_stamp_us, const occ_sectors_config_t *sectors_cfg);

/* ---- Range sensors in (range_rx.c) ---------------------------------------------------------- */
#define OCC_DRONECAN_RANGE_ID 1050u
#define OCC_DRONECAN_RANGE_SIG 0x68FFFE70FC771952ull
#define OCC_DRONECAN_RANGE_BYTES 15u  /* the message's payload: 120 bits */
/* Transfers reassembled at once (one per source node), and how long one may take. */
#define OCC_DRONECAN_RANGE_RX_SLOTS 4u
#define OCC_DRONECAN_RANGE_RX_TIMEOUT_US 2000000u

/* reading_type of the message. */
#define OCC_DRONECAN_RANGE_UNDEFINED 0u
#define OCC_DRONECAN_RANGE_VALID 1u
#define OCC_DRONECAN_RANGE_TOO_CLOSE 2u
#define OCC_DRONECAN_RANGE_TOO_FAR 3u

/* The message's fields, decoded. */
typedef struct {
    uint64_t timestamp_us;      /* uavcan.Timestamp, 56 bits (0: unknown), the sender's clock */
    uint8_t sensor_id;
    int8_t orientation_rpy[3];  /* CoarseOrientation fixed-axis roll, pitch, yaw in units of
                                 * pi/15 rad (12 deg), -16..15; decoded, not used (the mount
                                 * table is what places the beam, as ArduPilot's RNGFNDn_ORIENT) */
    bool orientation_defined;
    float field_of_view_rad;    /* full angle (float16) */
    uint8_t sensor_type;        /* 0 undefined, 1 sonar, 2 lidar, 3 radar */
    uint8_t reading_type;       /* OCC_DRONECAN_RANGE_* */
    float range_m;              /* float16 */
} occ_dronecan_range_t;

/* Decode a Measurement payload (exactly OCC_DRONECAN_RANGE_BYTES; more or less is
 * OCC_ERR_FORMAT, NULL OCC_ERR_ARG; *out untouched on error). O(1). */
occ_err_t occ_dronecan_decode_range(const uint8_t *payload, size_t len, occ_dronecan_range_t *out);

/* Where a sensor sits: the caller's table, one entry per sensor_id. The message carries
 * neither the mount nor the valid interval, so both are configured (ArduPilot RNGFNDn_ORIENT,
 * _POS, _MIN_CM, _MAX_CM). */
typedef struct {
    uint8_t sensor_id;
    occ_pose_t body_from_sensor; /* body (FLU, occ_pose.h) <- sensor; the beam is the sensor's +x */
    float min_m, max_m;          /* the sensor's valid interval, 0 <= min < max */
} occ_dronecan_range_mount_t;

/* The beam a message gives, in the sensor frame (dir +x), and its mount from the table:
 *  - VALID: distance = range (the beam rules of occ_ranges.h then apply: < min skipped,
 *    >= max no return, NaN / Inf skipped);
 *  - TOO_FAR: no return, distance = max_m (cleared up to max, no hit);
 *  - TOO_CLOSE, UNDEFINED (and the unused codes 4..7): valid = false (skipped, counted).
 * A field of view fov > 0 makes a cone of half-angle fov / 2; a fov that is NaN, negative or
 * wider than 2 * OCC_RANGES_CONE_MAX_RAD makes the beam invalid (fail closed: no guessed cone).
 * OCC_ERR_ARG for NULL, OCC_ERR_UNSUPPORTED when no mount has the message's sensor_id (*beam
 * and *mount untouched). O(n_mounts). */
occ_err_t occ_dronecan_range_beam(const occ_dronecan_range_t *msg,
                                  const occ_dronecan_range_mount_t *mounts, size_t n_mounts,
                                  occ_range_beam_t *beam,
                                  const occ_dronecan_range_mount_t **mount);

/* A received reading: who sent it, the message, its beam and its mount. */
typedef struct {
    uint8_t src_node;
    occ_dronecan_range_t msg;
    occ_range_beam_t beam;
    const occ_dronecan_range_mount_t *mount;  /* into the receiver's table */
} occ_dronecan_range_reading_t;

/* One transfer being reassembled (private to range_rx.c). */
typedef struct {
    bool busy_;
    uint8_t src_, tid_, toggle_, len_;
    uint64_t start_us_;
    uint8_t buf_[OCC_DRONECAN_RANGE_BYTES + 2u]; /* CRC + payload */
} occ_dronecan_range_slot_t;

/* Receiver of Measurement transfers. Size public for static allocation; callers read only the
 * counters. */
typedef struct {
    /* read-only for callers: counters since init */
    uint32_t frames;          /* Measurement frames seen */
    uint32_t readings;        /* transfers completed, decoded and mapped to a mount */
    uint32_t crc_errors;      /* multi-frame transfers whose CRC did not match (dropped) */
    uint32_t sequence_errors; /* frames out of sequence: toggle, transfer id, no start, timeout,
                               * too long (the transfer is dropped) */
    uint32_t unknown_sensor;  /* readings from a sensor_id without a mount (dropped) */
    uint32_t bad_payload;     /* completed transfers of the wrong length (dropped) */
    /* private: layout may change, do not touch */
    occ_dronecan_range_slot_t slot_[OCC_DRONECAN_RANGE_RX_SLOTS];
    const occ_dronecan_range_mount_t *mounts_;
    size_t n_mounts_;
} occ_dronecan_range_rx_t;

/* Start a receiver over the caller's mount table (kept by reference: it must outlive rx and
 * not change). OCC_ERR_ARG for NULL (mounts may be NULL with n_mounts 0), a bad pose
 * (occ_pose_check), a bad interval or a sensor_id listed twice. O(n_mounts^2). */
occ_err_t occ_dronecan_range_rx_init(occ_dronecan_range_rx_t *rx,
                                     const occ_dronecan_range_mount_t *mounts, size_t n_mounts);

/* Hand one received frame (any frame of the bus: others are ignored) to the receiver. When it
 * completes a Measurement transfer (single frame, or multi-frame with matching toggles, transfer
 * id and CRC, within OCC_DRONECAN_RANGE_RX_TIMEOUT_US of its first frame) whose sensor has a
 * mount, *got = true and *out holds the reading; otherwise *got = false (the reason counted).
 * Up to OCC_DRONECAN_RANGE_RX_SLOTS sources interleave; a start frame from one more source
 * takes the oldest slot. OCC_ERR_ARG for NULL. O(frame length). The integration is the
 * caller's: map_from_sensor = compose(map_from_body at msg.timestamp_us or the arrival time,
 * out->mount->body_from_sensor), then occ_map_insert_ranges() with &out->beam. */
occ_err_t occ_dronecan_range_rx_frame(occ_dronecan_range_rx_t *rx, const occ_can_frame_t *frame,
                                      uint64_t now_us, occ_dronecan_range_reading_t *out,
                                      bool *got);

/* ---- Budgets (issue 24) -------------------------------------------------------------------
 * Worst call-chain stack, Cortex-M4F / Cortex-M0+ (GCC 12 -Os, newlib nano; make cross checks
 * every line below against -fcallgraph-info), and the work per call. Callbacks (CAN tx, I/O
 * sinks) add their own stack. Instruction counts on a real map: README, Firmware.
 *   occ_dronecan_poll_map: stack <= 896 / 960 B; work: occ_sectors_compute (occ_sectors.h), then
 *       what occ_dronecan_poll sends
 *   occ_dronecan_poll, occ_dronecan_publish_sectors: stack <= 512 / 512 B; work: O(sectors): a
 *       Proximity transfer per sector with an obstacle, NodeStatus when due
 *   occ_dronecan_send_transfer, occ_dronecan_publish_*: stack <= 512 / 512 B; work:
 *       frame_count(payload_len) frames, O(payload_len)
 *   occ_dronecan_ingest, occ_dronecan_range_rx_frame: stack <= 512 / 512 B; work: one frame, O(1) /
 *       O(frame length) (ingest: + one response transfer)
 *   occ_dronecan_range_beam, occ_dronecan_range_rx_init: stack <= 512 / 512 B; work: O(n_mounts)
 *       (rx_init: O(n_mounts^2))
 *   occ_dronecan_*: stack <= 512 / 512 B; work: O(1) or O(payload bytes); no map access
 *   occ_float16_*: stack <= 64 / 128 B; work: O(1) or O(payload bytes); no map access
 */

#ifdef __cplusplus
}
#endif
#endif
