#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""decode_candump.py - pydronecan decodes what candump captured on the guest's vcan0.

usage: decode_candump.py CANDUMP_LOG [--can-feed-node N]   (candump -L: "(time) vcan0 ID#DATA")
Checks what socketcan_guest.c makes the node send: 9 GOOD Proximity readings (yaw 45 / 180 / -45
at 3.5 / 10 / 0.8 m, three rounds), one NO_DATA, one NOT_CONNECTED, two NodeStatus (OK, then
ERROR), a GetNodeInfo request from node 10 and the node's response named org.occmap.obstacles.
With --can-feed-node N: `occmap can-feed --pose 0,0,0,30` ran as node N on the wall map of
make_wall_map.c (a wall 3 m north): its GOOD readings (sensor 3) must all lie on that wall.
"""
import math
import sys

import dronecan
from dronecan import transport


def frames(path):
    for line in open(path, encoding="ascii", errors="replace"):
        parts = line.split()
        if len(parts) < 3 or "#" not in parts[2] or "##" in parts[2]:
            continue
        ident, data = parts[2].split("#", 1)
        if len(ident) != 8 or data.startswith("R"):
            continue  # 11-bit and remote frames are the port checks, not DroneCAN
        yield transport.Frame(int(ident, 16), bytes.fromhex(data))


def transfers(path):
    pending = {}
    for f in frames(path):
        if not f.bytes:
            continue
        key = (f.message_id, f.bytes[-1] & 0x1F)
        if f.start_of_transfer:
            pending[key] = []
        if key not in pending:
            continue
        pending[key].append(f)
        if f.end_of_transfer:
            fs = pending.pop(key)
            t = transport.Transfer()
            try:
                t.from_frames(fs)
            except Exception as ex:  # the port checks send DroneCAN-looking junk too
                print("decode: skipped %d frame(s) id %08X: %s" % (len(fs), f.message_id, ex))
                continue
            yield t


def check_can_feed(path, node_id):
    good = [t.payload for t in transfers(path)
            if t.source_node_id == node_id and
            dronecan.get_dronecan_data_type(t.payload).full_name ==
            "ardupilot.equipment.proximity_sensor.Proximity" and t.payload.reading_type == 2]
    errors = []
    for p in good:
        a = math.radians(30.0 + p.yaw)
        north, east = p.distance * math.cos(a), p.distance * math.sin(a)
        if not (2.8 <= north <= 3.15 and abs(east) <= 2.3) or p.sensor_id != 3:
            errors.append("can-feed reading off the wall: yaw %.1f, %.2f m" % (p.yaw, p.distance))
    print("decode: can-feed node %d: %d GOOD readings, body yaws %s" % (
        node_id, len(good), sorted(set(round(p.yaw) for p in good))))
    if len(good) < 15:
        errors.append("can-feed sent too few readings (%d)" % len(good))
    return errors[:5]


def main():
    prox, status, req, resp = [], [], [], []
    for t in transfers(sys.argv[1]):
        name = dronecan.get_dronecan_data_type(t.payload).full_name
        if name == "ardupilot.equipment.proximity_sensor.Proximity" and t.source_node_id == 100:
            prox.append(t.payload)
        elif name == "uavcan.protocol.NodeStatus" and t.source_node_id == 100:
            status.append(t.payload)
        elif name == "uavcan.protocol.GetNodeInfo" and t.request_not_response:
            req.append(t)
        elif name == "uavcan.protocol.GetNodeInfo":
            resp.append(t)
    good = sorted((round(p.yaw, 2), round(p.distance, 2)) for p in prox if p.reading_type == 2)
    kinds = [p.reading_type for p in prox]
    print("decode: Proximity %d (GOOD %d, NO_DATA %d, NOT_CONNECTED %d), NodeStatus %d, "
          "GetNodeInfo requests %d, responses %d" % (len(prox), kinds.count(2), kinds.count(0),
                                                      kinds.count(1), len(status), len(req),
                                                      len(resp)))
    errors = []
    want_good = sorted([(45.0, 3.5), (180.0, 10.0), (-45.0, 0.8)] * 3)
    if [(y, round(d, 1)) for y, d in good] != [(y, d) for y, d in want_good]:
        errors.append("GOOD readings %r, want %r" % (good, want_good))
    if kinds.count(0) != 1 or kinds.count(1) != 1 or any(p.sensor_id != 1 for p in prox):
        errors.append("NO_DATA / NOT_CONNECTED / sensor_id wrong")
    if [(s.health, s.mode) for s in status] != [(0, 0), (2, 1)]:
        errors.append("NodeStatus health/mode %r" % [(s.health, s.mode) for s in status])
    if len(req) != 1 or req[0].source_node_id != 10 or req[0].dest_node_id != 100:
        errors.append("GetNodeInfo request not seen")
    if len(resp) != 1 or resp[0].dest_node_id != 10 or resp[0].transfer_id != 5 or \
            resp[0].payload.name.decode() != "org.occmap.obstacles" or \
            resp[0].payload.hardware_version.unique_id[0] != 0x0C:
        errors.append("GetNodeInfo response wrong: %r" % resp)
    if "--can-feed-node" in sys.argv:
        errors += check_can_feed(sys.argv[1], int(sys.argv[sys.argv.index("--can-feed-node") + 1]))
    for e in errors:
        print("decode: FAIL " + e)
    if not errors:
        print("decode: pydronecan decoded every transfer as expected")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
