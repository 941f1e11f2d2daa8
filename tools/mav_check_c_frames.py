#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""mav_check_c_frames.py FRAMES.bin VALUES.txt - pymavlink decodes the frames our C encoder wrote
(tests/mavlink/mav_dump.c) and every field must equal the value the C side meant to send."""
import os
import struct
import sys

os.environ["MAVLINK20"] = "1"
from pymavlink.dialects.v20 import ardupilotmega as mav2  # noqa: E402


def f32(x):
    return struct.unpack("<f", struct.pack("<f", float(x)))[0]


def main():
    data = open(sys.argv[1], "rb").read()
    want = [l.split() for l in open(sys.argv[2]) if l.strip()]
    mav = mav2.MAVLink(None)
    mav.robust_parsing = True
    msgs = mav.parse_buffer(data) or []
    errors = []
    if len(msgs) != len(want):
        errors.append("decoded %d messages, expected %d" % (len(msgs), len(want)))
    for i, (m, w) in enumerate(zip(msgs, want)):
        if m.get_type() == "BAD_DATA":
            errors.append("frame %d: BAD_DATA %s" % (i, m.reason))
            continue
        hdr = m.get_header()
        got = [m.get_msgId(), hdr.srcSystem, hdr.srcComponent, hdr.seq]
        if got != [int(x) for x in w[:4]]:
            errors.append("frame %d: header %s want %s" % (i, got, w[:4]))
        if m.get_msgId() == 330:
            vals = [m.time_usec, m.sensor_type, m.increment, m.min_distance, m.max_distance]
            if vals != [int(x) for x in w[4:9]]:
                errors.append("frame %d: %s want %s" % (i, vals, w[4:9]))
            if f32(m.increment_f) != f32(w[9]) or f32(m.angle_offset) != f32(w[10]):
                errors.append("frame %d: floats %r %r want %s %s" % (i, m.increment_f, m.angle_offset, w[9], w[10]))
            if m.frame != int(w[11]) or list(m.distances) != [int(x) for x in w[12:84]]:
                errors.append("frame %d: frame/distances differ" % i)
        else:
            vals = [m.custom_mode, m.type, m.autopilot, m.base_mode, m.system_status, m.mavlink_version]
            if vals != [int(x) for x in w[4:10]]:
                errors.append("frame %d: heartbeat %s want %s" % (i, vals, w[4:10]))
    trimmed = sum(1 for m in msgs if m.get_msgId() == 330 and len(m.get_msgbuf()) < 179)
    for e in errors[:20]:
        print("FAIL", e)
    print("mav_check_c_frames: %d frames decoded by pymavlink, %d OBSTACLE_DISTANCE trimmed, %d errors"
          % (len(msgs), trimmed, len(errors)))
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
