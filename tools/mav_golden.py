#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""mav_golden.py FRAMES.bin VALUES.txt - pose and sensor frames encoded by pymavlink, for the C
decoder test (test_mavlink.c). Each frame's expected values go on one line of VALUES.txt:
"MSGID VERSION SYSID COMPID SEQ SIGNED field...", floats with 9 significant digits."""
import os
import random
import struct
import sys

os.environ["MAVLINK20"] = "1"
from pymavlink.dialects.v20 import ardupilotmega as mav2  # noqa: E402
from pymavlink.dialects.v10 import ardupilotmega as mav1  # noqa: E402


class Sink:
    def __init__(self):
        self.buf = bytearray()

    def write(self, b):
        self.buf += b


def f32(x):
    return struct.unpack("<f", struct.pack("<f", x))[0]


def fmt(v):
    return ("%.9g" % v) if isinstance(v, float) else str(v)


def main():
    out_bin, out_txt = sys.argv[1], sys.argv[2]
    rnd = random.Random(7)
    sink = Sink()
    lines = []
    m2 = mav2.MAVLink(sink, srcSystem=1, srcComponent=1)
    m1 = mav1.MAVLink(sink, srcSystem=3, srcComponent=1)
    signer = mav2.MAVLink(sink, srcSystem=9, srcComponent=42)
    signer.signing.secret_key = bytes(range(32))
    signer.signing.sign_outgoing = True
    signer.signing.timestamp = 123456789

    def rf(a=-100.0, b=100.0):
        return f32(rnd.uniform(a, b))

    def emit(link, msg, version, signed, values):
        start = len(sink.buf)
        seq = link.seq
        link.send(msg)
        assert len(sink.buf) > start
        lines.append(" ".join([str(msg.get_msgId()), str(version), str(link.srcSystem),
                               str(link.srcComponent), str(seq), "1" if signed else "0"]
                              + [fmt(v) for v in values]))

    for i in range(40):
        kind = i % 8
        if kind == 0:
            v = [rnd.randrange(1 << 32)] + [rf() for _ in range(6)]
            emit(m2, m2.local_position_ned_encode(*v), 2, False, v)
        elif kind == 1:
            v = [rnd.randrange(1 << 32)] + [rf(-3.14, 3.14) for _ in range(6)]
            emit(m2, m2.attitude_encode(*v), 2, False, v)
        elif kind == 2:
            v = [rnd.randrange(1 << 32)] + [rf(-1, 1) for _ in range(4)] + [rf(-1, 1) for _ in range(3)]
            emit(m2, m2.attitude_quaternion_encode(*v), 2, False, v)
        elif kind == 3:
            t = rnd.randrange(1 << 63)
            pos = [rf() for _ in range(3)]
            q = [rf(-1, 1) for _ in range(4)]
            vel = [rf() for _ in range(3)]
            frame_id = rnd.choice([1, 20])
            msg = m2.odometry_encode(t, frame_id, 12, pos[0], pos[1], pos[2], q, vel[0], vel[1],
                                     vel[2], 0, 0, 0, [float("nan")] + [0.0] * 20,
                                     [float("nan")] + [0.0] * 20, 0, 0, 0)
            emit(m2, msg, 2, False, [t, frame_id, 12] + pos + q + vel)
        elif kind == 4:
            v = [rnd.randrange(1 << 32)] + [rf() for _ in range(6)]
            emit(m1, m1.local_position_ned_encode(*v), 1, False, v)
        elif kind == 5:
            v = [rnd.randrange(1 << 32), rnd.randrange(65536), rnd.randrange(65536),
                 rnd.randrange(65536), rnd.randrange(256), rnd.randrange(256), rnd.randrange(256),
                 rnd.randrange(256), rf(0, 3), rf(0, 3), [rf(-1, 1) for _ in range(4)],
                 rnd.randrange(101)]
            msg = m2.distance_sensor_encode(*v)
            emit(m2, msg, 2, False, v[:10] + v[10] + [v[11]])
        elif kind == 6:
            v = [rnd.randrange(1 << 32)] + [rf(-3.14, 3.14) for _ in range(6)]
            emit(signer, signer.attitude_encode(*v), 2, True, v)
        else:
            v = [rnd.randrange(1 << 32), rnd.randrange(256), rnd.randrange(256),
                 rnd.randrange(256), rnd.randrange(256), 3]
            msg = m2.heartbeat_encode(v[1], v[2], v[3], v[0], v[4], v[5])
            emit(m2, msg, 2, False, v)
    with open(out_bin, "wb") as f:
        f.write(sink.buf)
    with open(out_txt, "w") as f:
        f.write("\n".join(lines) + "\n")
    print("mav_golden: %d frames, %d bytes" % (len(lines), len(sink.buf)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
