/* SPDX-License-Identifier: BSD-3-Clause */
/* occ_mavlink_ranges.h - MAVLink range messages other components send (rangefinders, sonar,
 * proximity sensors) as range beams for occ_map_insert_ranges() (occ_ranges.h).
 *
 * Messages (ids and layouts from the generated dialect, see occ_mavlink.h):
 *  - DISTANCE_SENSOR (132): one beam. Distances are cm on the wire; the beam's interval is the
 *    wire's inclusive [min_distance, max_distance]: min_m = min / 100, max_m = (max + 0.5) / 100,
 *    so a reading of exactly max_distance is a hit and any reading above it is "no return"
 *    (free up to max_m, no hit, occ_ranges.h). signal_quality 0 (unknown) and 2..100 are used,
 *    1 (invalid) gives the beam valid = false (skipped and counted by the insert), > 100 is a
 *    malformed message. Field of view: horizontal_fov / vertical_fov (rad, 0 = unknown); the
 *    cone half-angle is half the smaller known one (a cone claims free space across its whole
 *    width, so the narrower axis is the one that holds: fail closed), 0 when neither is known.
 *    The sensor frame has the beam along +x; the mount body_from_sensor comes from `orientation`
 *    (MAV_SENSOR_ORIENTATION, see occ_mav_sensor_mount()).
 *  - OBSTACLE_DISTANCE (330): up to 72 thin beams, element j at bearing
 *    angle_offset + j * increment (deg, clockwise; increment_f wins when non-zero, a negative
 *    increment_f runs counter-clockwise), horizontal. frame MAV_FRAME_BODY_FRD (12): bearings from
 *    the vehicle's forward axis in its x-y plane (the beams tilt with the vehicle); frames
 *    MAV_FRAME_GLOBAL (0, the message's default) and MAV_FRAME_LOCAL_NED (1): bearings from
 *    north in the level plane (what PX4 accepts too); other frames are refused. Elements:
 *    UINT16_MAX = no information, no beam (counted in unknown_elements); max_distance + 1 (any
 *    value above max) = nothing within max, free up to max; other values are readings with
 *    [min, max] as for DISTANCE_SENSOR (0 = "touching": below a non-zero min, so skipped by the
 *    insert). Each element is one thin beam through its bearing (no cone: a 2D scanner's element
 *    is the nearest return in its sector, not free space across the sector's height).
 *  - OBSTACLE_DISTANCE_3D (11037, ardupilotmega.xml, work in progress): one beam to the point
 *    (x, y, z) m with min/max_distance m. frame MAV_FRAME_BODY_FRD only (ArduPilot reads only
 *    that one); other frames are refused. A point at the origin is malformed.
 * Never our own component's messages: frames from (own_sysid, own_compid) are refused (a shared
 * bus echoes what we send) and counted.
 * Frames: the body is FLU, the map ENU (occ_pose.h); MAVLink's body frame is FRD and its world
 * NED. A beam set's sensor pose is occ_mav_beams_sensor_pose(map_from_body): for body beams
 * map_from_body o mount, for north beams the vehicle's position with the map's axes.
 * Time: time_us is the message's own stamp on the SENDER's clock (time_boot_ms * 1000, or
 * time_usec); a companion-computer sensor's clock is not the autopilot's (see README, --tlog).
 * Everything here is pure C99, no heap, O(1) per message (O(72) for OBSTACLE_DISTANCE).
 */
#ifndef OCC_MAVLINK_RANGES_H_INCLUDED
#define OCC_MAVLINK_RANGES_H_INCLUDED

#include "occmap/occ_mavlink.h"
#include "occmap/occ_pose.h"
#include "occmap/occ_ranges.h"

#ifdef __cplusplus
extern "C" {
#endif

#define OCC_MAV_MSG_OBSTACLE_DISTANCE_3D 11037u
#define OCC_MAV_FRAME_GLOBAL 0u
#define OCC_MAV_FRAME_LOCAL_NED 1u
#define OCC_MAV_SENSOR_ROTATION_NONE 0u
#define OCC_MAV_SENSOR_ROTATION_PITCH_90 24u   /* up */
#define OCC_MAV_SENSOR_ROTATION_PITCH_270 25u  /* down */
#define OCC_MAV_SENSOR_ROTATION_CUSTOM 100u    /* the message's quaternion field */
#define OCC_MAV_OBSTACLE_ELEMENTS 72u

/* The mount (body FLU <- sensor, beam along sensor +x, no translation) of a sensor facing
 * MAV_SENSOR_ORIENTATION `orientation`: 0..40 are MAVLink's fixed rotations (roll, pitch, yaw in
 * degrees applied as R = Rz(yaw) Ry(pitch) Rx(roll) in FRD, as ArduPilot does; 38 is ArduPilot's
 * roll 90, pitch 68.8, yaw 293.3), 100 (CUSTOM) the w, x, y, z quaternion `custom_q` (body FRD
 * <- sensor, normalised; may be NULL for the others). Examples: NONE -> beam forward (+x),
 * YAW_90 -> right (-y FLU), PITCH_90 -> up (+z), PITCH_270 -> down (-z).
 * OCC_ERR_UNSUPPORTED for other values, OCC_ERR_FORMAT for CUSTOM with a zero or non-finite
 * quaternion, OCC_ERR_ARG for NULL out. O(1). */
occ_err_t occ_mav_sensor_mount(uint8_t orientation, const float custom_q[4],
                               occ_pose_t *body_from_sensor);

typedef enum {
    OCC_MAV_BEAMS_BODY = 0,   /* beam dirs in the sensor frame, mounted on the body by `mount` */
    OCC_MAV_BEAMS_NORTH = 1   /* beam dirs in the map's ENU axes at the vehicle's position */
} occ_mav_beam_frame_t;

/* What one message says, as beams. */
typedef struct {
    uint32_t msgid;
    uint8_t sysid, compid;        /* the sender */
    uint8_t sensor_id;            /* DISTANCE_SENSOR id, else 0 */
    uint64_t time_us;             /* the message's stamp, sender's clock (see above) */
    occ_mav_beam_frame_t frame;
    occ_pose_t mount;             /* body_from_sensor (BODY); identity for NORTH */
    size_t n;                     /* beams filled, 0..72 (0: every element unknown) */
    uint32_t unknown_elements;    /* OBSTACLE_DISTANCE elements of UINT16_MAX (no beam) */
    occ_range_beam_t beam[OCC_MAV_OBSTACLE_ELEMENTS];
} occ_mav_beams_t;

typedef struct {
    uint32_t translated;          /* messages turned into beams */
    uint32_t own_refused;         /* range messages from our own sysid/compid */
    uint32_t malformed;           /* OCC_ERR_FORMAT: min >= max, NaN fields, bad increment ... */
    uint32_t unsupported;         /* OCC_ERR_UNSUPPORTED: orientation or frame we do not map */
    uint32_t other_msgs;          /* frames of other messages (not range messages) */
    uint32_t invalid_readings;    /* DISTANCE_SENSOR with signal_quality 1 (beam valid = false) */
    uint32_t unknown_elements;    /* OBSTACLE_DISTANCE UINT16_MAX elements, summed */
} occ_mav_ranges_counters_t;

typedef struct {
    uint8_t own_sysid, own_compid;
    occ_mav_ranges_counters_t counters;
} occ_mav_ranges_t;

/* Start a translator for a component that is (own_sysid, own_compid). O(1). OCC_ERR_ARG: NULL. */
occ_err_t occ_mav_ranges_init(occ_mav_ranges_t *rx, uint8_t own_sysid, uint8_t own_compid);

/* Translate a frame the parser returned as OCC_MAV_OK. OCC_OK: *out holds the beams (see the top
 * of this header). Errors (each counted, *out unspecified, nothing to insert):
 * OCC_ERR_ARG NULL, or a range message from our own component (own_refused);
 * OCC_ERR_UNSUPPORTED another message (other_msgs), or an orientation / frame not mapped
 * (unsupported); OCC_ERR_FORMAT a malformed range message (malformed). O(72). */
occ_err_t occ_mav_ranges_decode(occ_mav_ranges_t *rx, const occ_mav_frame_t *f,
                                occ_mav_beams_t *out);

/* The pose of the beams' frame in the map, from the vehicle's map_from_body (ENU <- FLU, e.g.
 * occ_pose_from_ned() of the autopilot's pose at the message's time): BODY beams
 * map_from_body o mount, NORTH beams (map_from_body.p, identity). OCC_ERR_ARG for NULL or a bad
 * pose (occ_pose_check). O(1). */
occ_err_t occ_mav_beams_sensor_pose(const occ_mav_beams_t *beams, const occ_pose_t *map_from_body,
                                    occ_pose_t *map_from_sensor);

/* ---- Budgets (issue 24) -------------------------------------------------------------------
 * Worst call-chain stack, Cortex-M4F / Cortex-M0+ (GCC 12 -Os, newlib nano; make cross checks
 * every line below against -fcallgraph-info), and the work per call. Callbacks (CAN tx, I/O
 * sinks) add their own stack. Instruction counts on a real map: README, Firmware.
 *   occ_mav_ranges_decode: stack <= 960 / 1,024 B; work: one message: <= 72 beams
 *   occ_mav_sensor_mount: stack <= 640 / 768 B; work: O(1)
 *   occ_mav_beams_sensor_pose, occ_mav_ranges_init: stack <= 320 / 384 B; work: O(1)
 */

#ifdef __cplusplus
}
#endif
#endif
