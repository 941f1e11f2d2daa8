#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""mcast_peer.py - occmap can-feed on pydronecan's `mcast:` bus, with pydronecan as the peer.

usage: mcast_peer.py OCCMAP MAP      (run inside a network namespace that has only loopback:
                                      tests/can/mcast_netns.sh sets it up)
Phase 1, --pose: the vehicle at the origin, heading 30 degrees (NED); the map has a wall 3 m
north. pydronecan must receive Proximity readings (GOOD, sensor 2, from node 100) that all lie on
the wall, NodeStatus with health OK, and a GetNodeInfo answer.
Phase 2, --mavlink-udp: pymavlink plays the autopilot for ~1 s (LOCAL_POSITION_NED + ATTITUDE,
heading 90 degrees) until the wall has been reported, then goes silent: the readings first show the wall at body yaw -90, then
the node reports NO_DATA.
"""
import json
import math
import os
import signal
import subprocess
import sys
import time

import dronecan

PROX = dronecan.ardupilot.equipment.proximity_sensor.Proximity


def wall_point_ok(yaw_ned_deg, body_yaw_deg, dist):
    a = math.radians(yaw_ned_deg + body_yaw_deg)
    north, east = dist * math.cos(a), dist * math.sin(a)
    return 2.8 <= north <= 3.15 and abs(east) <= 2.3


def run_phase(node, cmd, mav_sender=None, request_info=True, done=None):
    got = {"prox": [], "status": [], "info": None}

    def on_prox(e):
        m = e.message
        got["prox"].append((time.monotonic(), e.transfer.source_node_id, m.sensor_id,
                            m.reading_type, m.yaw, m.distance))

    def on_status(e):
        if e.transfer.source_node_id == 100:
            got["status"].append((e.message.health, e.message.mode, e.message.uptime_sec,
                                  time.monotonic()))

    h1 = node.add_handler(PROX, on_prox)
    h2 = node.add_handler(dronecan.uavcan.protocol.NodeStatus, on_status)
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    t0 = time.monotonic()
    asked = False
    while proc.poll() is None and time.monotonic() - t0 < 20:
        node.spin(0)
        if mav_sender:
            mav_sender(time.monotonic() - t0, got)
        if request_info and not asked and got["prox"]:  # the node is up: ask it
            asked = True

            def on_info(e):
                got["info"] = e.response if e is not None else "timeout"
            node.request(dronecan.uavcan.protocol.GetNodeInfo.Request(), 100, on_info,
                         timeout=2)
        if done is not None and done(got):
            proc.send_signal(signal.SIGINT)  # can-feed stops cleanly and prints its stats
            done = None
        time.sleep(0.005)
    t_end = time.monotonic() + 0.5
    while time.monotonic() < t_end:  # the last frames and the answer may still be queued
        node.spin(0)
        time.sleep(0.005)
    out, err = proc.communicate(timeout=5)
    h1.remove()
    h2.remove()
    stats = json.loads(out.decode().strip().splitlines()[-1]) if proc.returncode == 0 else None
    return proc.returncode, stats, err.decode(), got


def main():
    occmap, map_path = sys.argv[1], sys.argv[2]
    node = dronecan.make_node("mcast:0", node_id=10)
    time.sleep(0.3)  # the driver's I/O process joins the group
    errors = []

    # ---- phase 1: fixed pose -----------------------------------------------------------------
    cmd = [occmap, "can-feed", "--map", map_path, "--mcast", "0", "--node-id", "100",
           "--sensor-id", "2", "--pose", "0,0,0,30", "--rate-hz", "10", "--duration-s", "2.5"]
    rc, stats, err, got = run_phase(node, cmd)
    print("phase 1: can-feed exit %d, stats %s" % (rc, stats))
    if rc != 0:
        errors.append("can-feed failed: %s" % err)
    prox = [p for p in got["prox"] if p[1] == 100]
    good = [p for p in prox if p[3] == 2]
    yaws = sorted(set(round(p[4], 1) for p in good))
    print("phase 1: %d Proximity (GOOD %d), body yaws %s" % (len(prox), len(good), yaws))
    print("phase 1: NodeStatus (health, mode, uptime) %s" % [s[:3] for s in got["status"]])
    if len(good) < 12 or any(p[2] != 2 for p in good):
        errors.append("too few GOOD readings or wrong sensor id")
    bad = [p for p in good if not wall_point_ok(30.0, p[4], p[5])]
    if bad:
        errors.append("%d readings not on the wall, e.g. %r" % (len(bad), bad[:3]))
    north = [p[5] for p in good if abs(p[4] + 30.0) < 0.01]
    if not north or any(abs(d - 3.0) > 0.06 for d in north):
        errors.append("reading straight at the wall (body yaw -30) should be 3.0 m: %r" % north[:3])
    if not got["status"] or any(s[:2] != (0, 0) for s in got["status"]):
        errors.append("NodeStatus missing or not OK/OPERATIONAL")
    info = got["info"]
    if info is None or info == "timeout" or info.name.decode() != "org.occmap.obstacles":
        errors.append("GetNodeInfo not answered: %r" % (info,))
    else:
        print("phase 1: GetNodeInfo name %s, sw %d.%d, uptime %d s" % (
            info.name.decode(), info.software_version.major, info.software_version.minor,
            info.status.uptime_sec))
    if stats and (stats["node_info_answered"] != 1 or stats["proximity_sent"] != len(good) and
                  stats["proximity_sent"] < len(good)):
        errors.append("can-feed stats disagree with what was received")

    # ---- phase 2: poses from MAVLink, then silence -----------------------------------------------
    try:
        from pymavlink import mavutil
    except ImportError:
        mavutil = None
    if mavutil is not None:
        port = 14700 + os.getpid() % 200
        mav = mavutil.mavlink_connection("udpout:127.0.0.1:%d" % port, source_system=1,
                                         source_component=1)
        last = [0.0]

        def sender(t, got):
            # Poses until the node has shown the wall a few times, then silence.
            n_good = sum(1 for p in got["prox"] if p[3] == 2)
            if n_good < 30 and t < 5.0 and t - last[0] >= 0.05:
                last[0] = t
                ms = int(t * 1000)
                # An autopilot's HEARTBEAT names the system whose poses the feed takes.
                mav.mav.heartbeat_send(2, 3, 0, 0, 4)
                mav.mav.local_position_ned_send(ms, 0.0, 0.0, 0.0, 0, 0, 0)
                mav.mav.attitude_send(ms, 0.0, 0.0, math.radians(90.0), 0, 0, 0)
        cmd = [occmap, "can-feed", "--map", map_path, "--mcast", "0", "--node-id", "100",
               "--sensor-id", "2", "--mavlink-udp", "127.0.0.1:%d" % port, "--duration-s", "6"]
        def enough(got):
            kinds = [p[3] for p in got["prox"]]
            return 2 in kinds and kinds[-3:] == [0, 0, 0]
        rc, stats, err, got = run_phase(node, cmd, sender, request_info=False, done=enough)
        prox = [p for p in got["prox"] if p[1] == 100]
        good = [p for p in prox if p[3] == 2]
        nodata = [p for p in prox if p[3] == 0]
        print("phase 2: can-feed exit %d; GOOD %d, NO_DATA %d" % (rc, len(good), len(nodata)))
        if rc != 0:
            errors.append("can-feed --mavlink-udp failed: %s" % err)
        if not good or any(not wall_point_ok(90.0, p[4], p[5]) for p in good):
            errors.append("MAVLink pose not applied (wall should be at body yaw -90)")
        if not nodata or (good and nodata[-1][0] < good[-1][0]):
            errors.append("no NO_DATA after the MAVLink stream stopped")
        if nodata:
            # NodeStatus sent well after the data went stale must say WARNING (1).
            late = [st for st in got["status"] if st[3] > nodata[0][0] + 0.05]
            if any(st[0] != 1 for st in late):
                errors.append("NodeStatus should say WARNING once stale: %r" % late)
    else:
        print("SKIP: mcast phase 2 (live MAVLink poses): pymavlink missing")

    for e in errors:
        print("mcast: FAIL " + e)
    print("mcast: %s" % ("PASS" if not errors else "FAIL"))
    node.close()
    return 1 if errors else (0 if mavutil is not None else 77)  # 77: skipped (counted)


if __name__ == "__main__":
    sys.exit(main())
