#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""mav_tlog_synth.py OUT.tlog - a small telemetry log of pymavlink-packed frames (8-byte
big-endian stamps; read back by pymavlink's tlog reader before it is kept) for test_tlog_ranges.c: an autopilot (1/1) at LOCAL_POSITION_NED
(2.05, 1.05, -3.05) heading east, level, ATTITUDE every 100 ms for 2 s; a DISTANCE_SENSOR before the
first pose (no pose: refused); from a proximity sensor (1/158) at t = 1.0 s an OBSTACLE_DISTANCE
in the body frame: forward (east) 4 m, right (south) max_distance + 1 (nothing within 10 m);
our own OBSTACLE_DISTANCE (1/196) at 1.05 s: forward 1 m (must be refused); at 1.5 s a
downward DISTANCE_SENSOR of 2.5 m. Stamps start at T0 = 1.7e15 us."""
import os
import sys

os.environ["MAVLINK20"] = "1"
from pymavlink import mavutil  # noqa: E402
from pymavlink.dialects.v20 import ardupilotmega as mav2  # noqa: E402

T0 = 1700000000000000
UNKNOWN = 65535


def main():
    out = sys.argv[1]
    f = open(out + ".tmp", "wb")
    links = {}

    def send(t_us, sysid, compid, make):
        if (sysid, compid) not in links:
            links[(sysid, compid)] = mav2.MAVLink(None, srcSystem=sysid, srcComponent=compid)
        link = links[(sysid, compid)]
        msg = make(link)
        buf = msg.pack(link)
        link.seq = (link.seq + 1) % 256
        f.write(int(t_us).to_bytes(8, "big") + buf)

    send(T0, 1, 158, lambda m: m.distance_sensor_encode(5, 20, 1000, 300, 0, 1, 25, 255))
    for k in range(21):
        t = T0 + 1000 + k * 100000
        send(t, 1, 1, lambda m: m.local_position_ned_encode(k * 100, 2.05, 1.05, -3.05, 0, 0, 0))
        send(t + 10, 1, 1, lambda m: m.attitude_encode(k * 100, 0.0, 0.0, 1.5707963, 0, 0, 0))
    d = [UNKNOWN] * 72
    d[0], d[18] = 400, 1001
    send(T0 + 1000000, 1, 158, lambda m: m.obstacle_distance_encode(0, 0, d, 0, 20, 1000, 5.0,
                                                                    0.0, 12))
    own = [UNKNOWN] * 72
    own[0] = 100
    send(T0 + 1050000, 1, 196, lambda m: m.obstacle_distance_encode(0, 0, own, 0, 20, 1000, 5.0,
                                                                    0.0, 12))
    send(T0 + 1500000, 1, 158, lambda m: m.distance_sensor_encode(1500, 20, 1000, 250, 0, 1, 25,
                                                                  255))
    f.close()
    conn = mavutil.mavlink_connection(out + ".tmp")
    types = []
    while True:
        m = conn.recv_match()
        if m is None:
            break
        types.append((int(round(m._timestamp * 1e6)), m.get_type()))
    assert len(types) == 46 and types[0] == (T0, "DISTANCE_SENSOR"), types[:3]
    assert types[-1] == (T0 + 1500000, "DISTANCE_SENSOR"), types[-1]
    os.replace(out + ".tmp", out)
    print("mav_tlog_synth: %s, %d frames pymavlink reads back" % (out, len(types)))


if __name__ == "__main__":
    main()
