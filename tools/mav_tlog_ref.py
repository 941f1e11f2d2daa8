#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""mav_tlog_ref.py TLOG OUT - what pymavlink reads in a telemetry log, for test_mavlink.c.

Writes one line per message id ("count MSGID OK BAD_CRC"), one line per DISTANCE_SENSOR frame
("ds time_boot_ms min max current type id orientation covariance hfov vfov q0 q1 q2 q3
signal_quality", floats with 9 significant digits so they round-trip through float32), and a
"total" line. When the log is missing the file holds "SKIP reason" and the C test skips.
"""
import collections
import os
import sys

os.environ.setdefault("MAVLINK20", "1")
from pymavlink import mavutil  # noqa: E402


def frame_msgid(buf):
    buf = bytes(buf)
    if len(buf) >= 10 and buf[0] == 0xFD:
        return buf[7] | (buf[8] << 8) | (buf[9] << 16)
    if len(buf) >= 6 and buf[0] == 0xFE:
        return buf[5]
    return None


def main():
    tlog, out = sys.argv[1], sys.argv[2]
    if not os.path.exists(tlog):
        with open(out, "w") as f:
            f.write("SKIP %s not found\n" % tlog)
        print("mav_tlog_ref: %s not found, the tlog test will skip" % tlog)
        return 0
    conn = mavutil.mavlink_connection(tlog, dialect="ardupilotmega", robust_parsing=True)
    ok = collections.Counter()
    bad = collections.Counter()
    other_bad = 0
    unknown = collections.Counter()
    ds = []
    while True:
        m = conn.recv_msg()
        if m is None:
            break
        t = m.get_type()
        if t == "BAD_DATA":
            mid = frame_msgid(m.data)
            if mid is not None and "CRC" in str(m.reason):
                bad[mid] += 1
            else:
                other_bad += 1
            continue
        if t.startswith("UNKNOWN_"):
            unknown[int(t[8:])] += 1
            continue
        ok[m.get_msgId()] += 1
        if t == "DISTANCE_SENSOR":
            q = list(m.quaternion)
            ds.append([m.time_boot_ms, m.min_distance, m.max_distance, m.current_distance,
                       m.type, m.id, m.orientation, m.covariance, m.horizontal_fov,
                       m.vertical_fov] + q + [m.signal_quality])
    with open(out + ".tmp", "w") as f:
        for mid in sorted(set(ok) | set(bad)):
            f.write("count %d %d %d\n" % (mid, ok[mid], bad[mid]))
        for mid in sorted(unknown):
            f.write("unknown %d %d\n" % (mid, unknown[mid]))
        for r in ds:
            f.write("ds " + " ".join(("%.9g" % v) if isinstance(v, float) else str(v) for v in r) + "\n")
        f.write("total %d %d %d %d\n" % (sum(ok.values()), sum(bad.values()),
                                          sum(unknown.values()), other_bad))
    os.replace(out + ".tmp", out)
    print("mav_tlog_ref: %d good frames, %d bad CRC, %d unknown, %d other bad, %d DISTANCE_SENSOR"
          % (sum(ok.values()), sum(bad.values()), sum(unknown.values()), other_bad, len(ds)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
