#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""mav_ranges_golden.py FRAMES.bin LABELS.txt - range messages encoded by pymavlink (the real
peer) for test_mavlink_ranges.c: DISTANCE_SENSOR in every orientation case, OBSTACLE_DISTANCE in
body and north frames, OBSTACLE_DISTANCE_3D, malformed ones and our own echoes. One label per
frame, in order, goes to LABELS.txt ("LABEL MSGID SYSID COMPID"); the C test holds the expected
beams, worked out by hand, under the same labels."""
import math
import os
import sys

os.environ["MAVLINK20"] = "1"
from pymavlink.dialects.v20 import ardupilotmega as mav2  # noqa: E402
from pymavlink.dialects.v10 import ardupilotmega as mav1  # noqa: E402

UNKNOWN = 65535


class Sink:
    def __init__(self):
        self.buf = bytearray()

    def write(self, b):
        self.buf += b


def main():
    out_bin, out_txt = sys.argv[1], sys.argv[2]
    sink = Sink()
    labels = []
    sensor = mav2.MAVLink(sink, srcSystem=1, srcComponent=158)   # a peripheral
    sensor_v1 = mav1.MAVLink(sink, srcSystem=1, srcComponent=158)
    own = mav2.MAVLink(sink, srcSystem=1, srcComponent=196)      # ourselves, echoed

    def emit(label, link, msg):
        link.send(msg)
        labels.append("%s %d %d %d" % (label, msg.get_msgId(), link.srcSystem, link.srcComponent))

    def ds(label, orient, cur=250, mn=20, mx=1000, hfov=0.0, vfov=0.0, q=(0, 0, 0, 0), sq=0,
           link=sensor):
        emit(label, link, link.distance_sensor_encode(123456, mn, mx, cur, 0, 3, orient, 255,
                                                      hfov, vfov, list(q), sq))

    for yaw in range(8):   # NONE and the yaw steps of 45 degrees
        ds("ds_yaw%d" % (45 * yaw), yaw)
    ds("ds_roll180", 8)
    ds("ds_pitch180", 12)
    ds("ds_pitch90", 24)
    ds("ds_pitch270", 25)
    ds("ds_pitch315", 39)
    h = math.sqrt(0.5)
    ds("ds_custom_yaw90", 100, q=(h, 0, 0, h))
    a = math.radians(-15.0)   # pitch -30 (nose down), not normalised on purpose
    ds("ds_custom_pitch_m30", 100, q=(2 * math.cos(a), 0, 2 * math.sin(a), 0))
    ds("ds_custom_zero", 100)
    ds("ds_orient41", 41)
    ds("ds_sq1", 25, sq=1)
    ds("ds_sq100", 25, sq=100)
    ds("ds_sq101", 25, sq=101)
    ds("ds_fov", 25, hfov=0.52, vfov=0.3)
    ds("ds_fov_v", 25, hfov=0.0, vfov=0.4)
    ds("ds_fov_nan", 25, hfov=float("nan"))
    ds("ds_min_eq_max", 0, mn=500, mx=500)
    ds("ds_at_max", 0, cur=1000)
    ds("ds_past_max", 0, cur=1001)
    ds("ds_own", 0, link=own)
    emit("ds_v1", sensor_v1, sensor_v1.distance_sensor_encode(99, 30, 4000, 1234, 1, 2, 25, 255))

    def od(label, dist, inc=0, inc_f=0.0, off=0.0, frame=12, link=sensor):
        emit(label, link, link.obstacle_distance_encode(777, 0, dist, inc, 20, 2000, inc_f, off,
                                                        frame))

    d = [UNKNOWN] * 72
    d[0], d[4], d[22], d[58] = 300, 150, 500, 2001
    od("od_body", d, inc_f=5.0, off=-20.0, frame=12)
    d = [UNKNOWN] * 72
    d[0], d[9], d[27] = 400, 900, 1999
    od("od_global", d, inc=10, frame=0)
    d = [UNKNOWN] * 72
    d[1] = 700
    od("od_local_ned_ccw", d, inc=10, inc_f=-5.0, frame=1)
    od("od_frame8", d, inc_f=5.0, frame=8)
    od("od_inc0", d, inc=0, inc_f=0.0)
    od("od_all_unknown", [UNKNOWN] * 72, inc_f=5.0)
    od("od_own", d, inc_f=5.0, link=own)

    def o3(label, x, y, z, frame=12, mn=0.5, mx=30.0):
        emit(label, sensor, sensor.obstacle_distance_3d_encode(4242, 0, frame, 7, x, y, z, mn, mx))

    o3("o3_body", 3.0, 4.0, 0.0)
    o3("o3_down", 0.0, 0.0, 2.0)
    o3("o3_local_ned", 3.0, 4.0, 0.0, frame=1)
    o3("o3_origin", 0.0, 0.0, 0.0)
    o3("o3_max_le_min", 1.0, 0.0, 0.0, mn=2.0, mx=2.0)
    emit("heartbeat", sensor, sensor.heartbeat_encode(18, 8, 0, 0, 4))
    with open(out_bin, "wb") as f:
        f.write(bytes(sink.buf))
    with open(out_txt, "w") as f:
        f.write("\n".join(labels) + "\n")
    print("mav_ranges_golden: %d frames, %d bytes" % (len(labels), len(sink.buf)))


if __name__ == "__main__":
    main()
