#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""run_can_peer.py OCCMAP WALL_MAP OUTDIR - `occmap run --can` (issue 21) on pydronecan's mcast:
bus, with a pymavlink autopilot stand-in on UDP loopback (tests/run_peer.py's Peer) holding the
vehicle at the origin of the wall map (tests/can/make_wall_map.c: free disc of 5 m, a wall 3 m
north), level, heading 30 deg. Run inside a network namespace with only loopback
(tests/run_can.sh). Options come from a --config file (the mount of range sensor 3: forward,
0.2..10 m; the duration; the rate), and one option on the command line overrides it.
pydronecan node 10 sends uavcan.equipment.range_sensor.Measurement: sensor 3 reads 1.50 m
(VALID), sensor 9 (no mount) 0.5 m. Checks (PASS/FAIL run-can):
 - before the first reading the configured sensor is stale (--sensor-timeout-ms applies to
   each configured input): Proximity from node 100 says NO_DATA, never GOOD;
   after it, Proximity from node 100 (GOOD) of the sector centred on body yaw 0 reports
   1.35..1.50 m (1.5 - 0.1 sqrt 2: the nearest point of the hit voxel)
   (the hit voxel 1.5 m ahead, nearer than the wall), the wall sectors stay (2.9..3.5 m);
 - telemetry: readings integrated > 0, sensor 9 counted as unknown_sensor, never integrated;
 - the config's rate (5 Hz) is overridden by --rate 10 on the command line (stats config line);
 - a config line without '=' is refused with exit 2 and FILE:LINE."""
import json
import math
import os
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import dronecan  # noqa: E402
from run_peer import Peer, free_port  # noqa: E402

PROX = dronecan.ardupilot.equipment.proximity_sensor.Proximity
MEAS = dronecan.uavcan.equipment.range_sensor.Measurement


def main():
    occmap, wall, out = sys.argv[1], sys.argv[2], sys.argv[3]
    os.makedirs(out, exist_ok=True)
    bad = []
    cfg = os.path.join(out, "can_run.conf")
    with open(cfg, "w") as f:
        f.write("# occmap run: sensors and options\ncan = mcast:0\n"
                "can-range-mount = 3, 0,0,0, 0,0,0, 0.2,10   # sensor 3 looks forward\n"
                "map = %s\nduration = 3\nrate = 5\n" % wall)
    badcfg = os.path.join(out, "can_bad.conf")
    with open(badcfg, "w") as f:
        f.write("duration = 3\nthis line has no equals sign\n")
    r = subprocess.run([occmap, "run", "--udp", "127.0.0.1:1", "--config", badcfg],
                       capture_output=True, text=True)
    if r.returncode != 2 or "can_bad.conf:2" not in r.stderr:
        bad.append("bad config: exit %d, %r" % (r.returncode, r.stderr[-200:]))
    node = dronecan.make_node("mcast:0", node_id=10)
    time.sleep(0.3)
    prox = []
    node.add_handler(PROX, lambda e: prox.append((time.monotonic(), e.transfer.source_node_id,
                                                  e.message.reading_type, e.message.yaw,
                                                  e.message.distance)))
    port = free_port()
    peer = Peer(port, [(1, (0, 0, 0), (0, 0, 0), (0.0, 0.0, math.radians(30)))], hold_last=True)
    st = os.path.join(out, "can_stats.json")
    p = subprocess.Popen([occmap, "run", "--udp", "127.0.0.1:%d" % port, "--config", cfg,
                          "--rate", "10", "--stats", st],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    t0 = time.monotonic()
    t_read, nxt = t0 + 1.2, 0.0  # readings start after 1.2 s: sensor 3 is stale until then
    while p.poll() is None and time.monotonic() - t0 < 20:
        peer.step()
        node.spin(0)
        now = time.monotonic()
        if now >= t_read and now >= nxt:
            nxt = now + 0.05
            for sid, rng in ((3, 1.5), (9, 0.5)):
                node.broadcast(MEAS(sensor_id=sid, sensor_type=2, reading_type=1, range=rng,
                                    field_of_view=0.0))
    _, err = p.communicate(timeout=5)
    peer.conn.close()
    node.close()
    if p.returncode != 0:
        bad.append("exit %s: %s" % (p.returncode, err[-300:]))
    ours = [x for x in prox if x[1] == 100 and x[2] == 2]
    fwd = [x for x in ours if abs(x[3]) < 1.0]  # the sector centred on body yaw 0
    good_before = [x for x in ours if x[0] < t_read]
    nodata_before = [x for x in prox if x[1] == 100 and x[2] == 0 and x[0] < t_read]
    after = [x[4] for x in fwd if x[0] > t_read + 0.5]
    if good_before or not nodata_before:
        bad.append("before the first reading (sensor 3 silent: stale) %d GOOD, %d NO_DATA "
                   "(want none, some)" % (len(good_before), len(nodata_before)))
    if not after or not all(1.35 <= d <= 1.5 for d in after):
        bad.append("forward after the reading %s (want 1.35..1.50 m)" % after[:5])
    wall_after = [x for x in ours if x[0] > t_read + 0.5 and abs(x[3] + 30) <= 20]
    if not wall_after or not all(2.9 <= x[4] <= 3.5 for x in wall_after):
        bad.append("wall sectors after %s" % [(x[3], x[4]) for x in wall_after[:5]])
    lines = [json.loads(x) for x in open(st)] if os.path.exists(st) else [{}]
    rate = lines[0].get("config", {}).get("rate_hz", lines[0].get("config", {}).get("rate"))
    can = lines[-1].get("final", {}).get("can", {})
    rng = lines[-1].get("final", {}).get("ranges", {})
    # every reading of the mounted sensor integrated, or (the last few, still waiting for a pose
    # after their time when the run ended) counted as dropped: none lost
    done = rng.get("integrated", 0) + rng.get("dropped", {}).get("no_pose", 0)
    if not (can.get("readings", 0) > 0 and can.get("unknown_sensor", 0) > 0 and
            rng.get("integrated", 0) > 0 and done == can.get("readings")):
        bad.append("telemetry can %s ranges %s" % (can, rng))
    mounts = lines[0].get("config", {}).get("can_mounts")
    if not mounts or mounts[0][0] != 3 or abs(mounts[0][8] - 0.2) > 1e-6 or abs(mounts[0][9] - 10) > 1e-6:
        bad.append("mounts in the config line %s (want sensor 3, 0.2..10 m)" % mounts)
    if rate is None or abs(float(rate) - 10.0) > 1e-6:
        bad.append("rate in the config line %s (want the command line's 10)" % rate)
    if bad:
        print("FAIL run-can: " + "; ".join(bad))
        return 1
    print("PASS run-can: %d NO_DATA while sensor 3 was silent, then forward sector %.2f m after "
          "%d DroneCAN readings (sensor 3, 1.50 m), wall sectors kept; %d unknown-sensor readings "
          "refused; %d Proximity GOOD" % (len(nodata_before), after[-1], can["readings"],
                                          can["unknown_sensor"], len(ours)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
