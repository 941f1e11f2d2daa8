/* SPDX-License-Identifier: BSD-3-Clause */
/* run_can.h - `occmap run --can`: the DroneCAN front end of the loop (link thread).
 * In: uavcan.equipment.range_sensor.Measurement from any node, placed by the --can-range-mount
 * table (by sensor_id) and queued like the MAVLink range messages (run_ranges.h: stamped with
 * the autopilot's time at arrival, integrated by the mapping thread with the pose then).
 * Out: ardupilot.equipment.proximity_sensor.Proximity per sector with an obstacle (NO_DATA while
 * the pose or the sensors are stale), NodeStatus at 1 Hz, GetNodeInfo answered
 * (occ_dronecan.h). Bus: SocketCAN IFACE (occ_socketcan.h) or mcast:BUS (pydronecan's / SITL's
 * CAN over UDP multicast, occ_can_mcast.h). */
#ifndef OCC_TOOLS_RUN_CAN_H_INCLUDED
#define OCC_TOOLS_RUN_CAN_H_INCLUDED

#include "run.h"
#include "occmap/occ_dronecan.h"
#include "occmap/host/occ_can_mcast.h"
#include "occmap/host/occ_socketcan.h"

typedef struct run_can_s {
    bool use_mcast;
    occ_socketcan_t sc;
    occ_can_mcast_t mc;
    occ_can_iface_t iface;
    occ_dronecan_node_t node;
    occ_dronecan_range_rx_t rx;
    uint64_t readings, invalid;     /* Measurements placed / without a valid beam */
    uint32_t poll_errors;           /* occ_dronecan_poll_map errors (vehicle off the map ...) */
} run_can_t;

/* Open o->can and start the node. 0, or 1 after a message. */
int run_can_open(run_can_t *c, const run_opts_t *o);
void run_can_close(run_can_t *c);

struct run_link_s;
/* Link thread, every loop turn: every frame waiting on the bus; then the node's publications
 * when due, from a view of the map at the feed's pose. `fresh`: the sensors are fresh. */
void run_can_poll(struct run_link_s *l, run_can_t *c, uint64_t now, bool fresh);

/* Telemetry members ("can": {...}). */
void run_can_print(FILE *f, const run_can_t *c);

#endif
