#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""mav_tlog_sonar_ref.py TLOG OUT - where each DISTANCE_SENSOR reading of a telemetry log says the
surface is, worked out with pymavlink alone, for test_tlog_ranges.c (the C reader, translator
and pose history must put the beams there).

Per reading (frames from sysid 1 other than our compid 196), on the log's stamps (the only clock
the sonar, compid 194, and the autopilot, compid 1, share):
  attitude = ATTITUDE roll/pitch/yaw of the autopilot linearly interpolated between the two
             samples around the stamp (none before the first ATTITUDE that follows a position)
  position = the latest GLOBAL_POSITION_INT before that attitude sample (ArduSub without a fix:
             lat = lon = 0, so north = east = 0, down = -relative_alt)
  axis     = R(yaw, pitch, roll) applied to the mount's boresight in FRD (PITCH_270: (0, 0, 1)),
             NED -> ENU (e, n, -d)
Writes "r STAMP_US DIST_M CONE_HALF_RAD OX OY OZ AX AY AZ" (ENU, 9 digits) per reading with a
pose, "nopose STAMP_US" otherwise; "SKIP reason" when the log is missing."""
import bisect
import math
import os
import sys

os.environ.setdefault("MAVLINK20", "1")
from pymavlink import mavutil  # noqa: E402


def rot_zyx(roll, pitch, yaw, v):
    cr, sr, cp, sp, cy, sy = (math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch),
                              math.cos(yaw), math.sin(yaw))
    x, y, z = v
    y, z = cr * y - sr * z, sr * y + cr * z          # Rx(roll)
    x, z = cp * x + sp * z, -sp * x + cp * z         # Ry(pitch)
    x, y = cy * x - sy * y, sy * x + cy * y          # Rz(yaw)
    return (x, y, z)


BORESIGHT_FRD = {25: (0.0, 0.0, 1.0), 24: (0.0, 0.0, -1.0), 0: (1.0, 0.0, 0.0)}


def main():
    tlog, out = sys.argv[1], sys.argv[2]
    if not os.path.exists(tlog):
        with open(out, "w") as f:
            f.write("SKIP %s not found\n" % tlog)
        print("mav_tlog_sonar_ref: %s not found, the test will skip" % tlog)
        return 0
    conn = mavutil.mavlink_connection(tlog, dialect="ardupilotmega")
    att, readings = [], []
    down = None
    while True:
        m = conn.recv_match(type=["ATTITUDE", "GLOBAL_POSITION_INT", "DISTANCE_SENSOR"])
        if m is None:
            break
        t = int(round(m._timestamp * 1e6))
        src = (m.get_srcSystem(), m.get_srcComponent())
        if m.get_type() == "GLOBAL_POSITION_INT" and src == (1, 1):
            assert m.lat == 0 and m.lon == 0, "this reference assumes no horizontal fix"
            down = -m.relative_alt / 1000.0
        elif m.get_type() == "ATTITUDE" and src == (1, 1) and down is not None:
            if not att or t > att[-1][0]:
                att.append((t, m.roll, m.pitch, m.yaw, down))
        elif m.get_type() == "DISTANCE_SENSOR" and src[0] == 1 and src[1] != 196:
            readings.append((t, m))
    times = [a[0] for a in att]
    lines = []
    for t, m in readings:
        i = bisect.bisect_right(times, t)
        if i == 0 or i == len(times):
            lines.append("nopose %d" % t)
            continue
        a, b = att[i - 1], att[i]
        s = (t - a[0]) / float(b[0] - a[0])
        r, p, y, d = (a[k] + s * (b[k] - a[k]) for k in (1, 2, 3, 4))
        ax = rot_zyx(r, p, y, BORESIGHT_FRD[m.orientation])
        fovs = [f for f in (m.horizontal_fov, m.vertical_fov) if f > 0]
        cone = min(fovs) / 2 if fovs else 0.0
        lines.append("r %d %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g" % (
            t, m.current_distance / 100.0, cone, 0.0, 0.0, -d, ax[1], ax[0], -ax[2]))
    with open(out + ".tmp", "w") as f:
        f.write("\n".join(lines) + "\n")
    os.replace(out + ".tmp", out)
    print("mav_tlog_sonar_ref: %d readings, %d with a pose" % (
        len(lines), sum(1 for x in lines if x.startswith("r "))))
    return 0


if __name__ == "__main__":
    sys.exit(main())
