#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""range_frames.py - uavcan.equipment.range_sensor.Measurement transfers built by pydronecan
(dronecan 1.0.27), the peer for tests/test_dronecan_range.c.

usage: range_frames.py N_RANDOM > build/can/range_frames.txt
One case per line: the fields as pydronecan decodes its own frames back (float16 values as
exact decimal, inf / nan as such), then '|' and the frames as ID:HEX. Fixed cases first (every
reading type, field-of-view and range edges), then N_RANDOM random ones (seed printed in a
comment line, OCC_SEED overrides).
"""
import os
import random
import sys

import dronecan
from dronecan import transport

M = dronecan.uavcan.equipment.range_sensor.Measurement


def build(c):
    m = M(sensor_id=c["sensor"], field_of_view=c["fov"], sensor_type=c["stype"],
          reading_type=c["rtype"], range=c["range"])
    m.timestamp.usec = c["usec"]
    m.beam_orientation_in_body_frame.fixed_axis_roll_pitch_yaw = list(c["rpy"])
    m.beam_orientation_in_body_frame.orientation_defined = c["defined"]
    t = transport.Transfer(payload=m, source_node_id=c["node"], transfer_id=c["tid"],
                           transfer_priority=c["prio"])
    return t.to_frames()


def decoded(frames):
    t = transport.Transfer()
    t.from_frames(frames)  # pydronecan checks tail bytes, toggles and the CRC
    return t.source_node_id, t.transfer_id, t.payload


def line(c):
    frames = build(c)
    src, tid, m = decoded(frames)
    o = m.beam_orientation_in_body_frame
    fields = [src, tid, m.timestamp.usec, m.sensor_id, *list(o.fixed_axis_roll_pitch_yaw),
              int(bool(o.orientation_defined)), repr(float(m.field_of_view)), m.sensor_type,
              m.reading_type, repr(float(m.range))]
    text = " ".join(str(f) for f in fields)
    return text + " | " + " ".join("%08X:%s" % (f.message_id, bytes(f.bytes).hex()) for f in frames)


def case(node=10, tid=0, prio=20, usec=123456789, sensor=3, rpy=(0, -8, 0), defined=True,
         fov=0.0, stype=1, rtype=1, rng=2.5):
    return dict(node=node, tid=tid, prio=prio, usec=usec, sensor=sensor, rpy=rpy,
                defined=defined, fov=fov, stype=stype, rtype=rtype, range=rng)


def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 100
    seed = int(os.environ.get("OCC_SEED", "1050"))
    rng = random.Random(seed)
    print("# seed %d" % seed)
    fixed = [case(), case(rtype=0), case(rtype=2, rng=0.05), case(rtype=3, rng=0.0),
             case(fov=0.5, rng=1.25), case(fov=float("nan")), case(fov=-0.2),
             case(rng=float("inf")), case(rng=1e9), case(rng=float("nan")),
             case(rpy=(15, -16, 7), usec=(1 << 56) - 1, node=127, tid=31, prio=31, sensor=255),
             case(sensor=9), case(rtype=7)]
    for c in fixed:
        print(line(c))
    for _ in range(n):
        c = case(node=rng.randint(1, 127), tid=rng.randint(0, 31), prio=rng.randint(0, 31),
                 usec=rng.getrandbits(56), sensor=rng.choice([3, 4, 9]),
                 rpy=tuple(rng.randint(-16, 15) for _ in range(3)), defined=rng.random() < 0.5,
                 fov=rng.choice([0.0, rng.uniform(0.0, 1.2)]), stype=rng.randint(0, 3),
                 rtype=rng.randint(0, 3), rng=rng.uniform(0.0, 60.0))
        print(line(c))


if __name__ == "__main__":
    main()
