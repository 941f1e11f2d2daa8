#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""golden.py - occmap's DroneCAN encoder against pydronecan, byte for byte.

usage: golden.py DUMP_BINARY [N_RANDOM]
Builds test cases (fixed edge cases + N_RANDOM random ones; seed printed, OCC_SEED overrides),
has pydronecan (dronecan 1.0.27) encode each into CAN frames, has occmap encode the same values
(DUMP_BINARY reads the cases on stdin), compares every frame id and byte, then has pydronecan
decode occmap's frames and checks the decoded fields. Exit 0 only if every case matches.
"""
import math
import os
import random
import struct
import subprocess
import sys

import dronecan
from dronecan import transport


def f32(x):
    """Round to float32 (what the C side sees) and return (value, bits)."""
    b = struct.unpack("<I", struct.pack("<f", x))[0]
    return struct.unpack("<f", struct.pack("<I", b))[0], b


def f32_from_bits(b):
    return struct.unpack("<f", struct.pack("<I", b))[0]


def frames_text(frames):
    return " ".join("%08X:%s" % (f.message_id, bytes(f.bytes).hex()) for f in frames)


def parse_frames(text):
    out = []
    for tok in text.split():
        ident, data = tok.split(":")
        out.append(transport.Frame(int(ident, 16), bytes.fromhex(data)))
    return out


FLOAT_EDGES = [0.0, -0.0, 1.0, -1.0, 45.0, 3.5, 0.1, 180.0, -180.0, 359.99, 65504.0, 65519.0,
               65520.0, 1e9, -1e9, float("inf"), float("-inf"), float("nan"), 6.103515625e-05,
               5.9604644775390625e-08, 2.98e-08, 1e-10, 1.00048828125, 1.000244140625, 0.2,
               20.0, 1.2, 3.14159]


def rand_float(rng):
    k = rng.random()
    if k < 0.1:
        return rng.choice(FLOAT_EDGES)
    if k < 0.3:
        return f32_from_bits(rng.getrandbits(32))   # any bit pattern, incl. NaN payloads
    if k < 0.6:
        return rng.uniform(-180.0, 180.0)
    if k < 0.9:
        return rng.uniform(0.0, 60.0)
    return rng.uniform(-1e-4, 1e-4)


def prox_case(rng, fixed=None):
    c = dict(prio=rng.randrange(32), node=rng.randrange(1, 128), tid=rng.randrange(32),
             sensor=rng.randrange(256), type=rng.randrange(8), flags=rng.randrange(32),
             yaw=rand_float(rng), pitch=rand_float(rng), dist=rand_float(rng))
    if fixed:
        c.update(fixed)
    for k in ("yaw", "pitch", "dist"):
        c[k], c[k + "_bits"] = f32(c[k])
    return c


def status_case(rng, fixed=None):
    c = dict(prio=rng.randrange(32), node=rng.randrange(1, 128), tid=rng.randrange(32),
             up=rng.getrandbits(32), health=rng.randrange(4), mode=rng.randrange(8),
             sub=rng.randrange(8), vendor=rng.getrandbits(16))
    if fixed:
        c.update(fixed)
    return c


def info_case(rng, fixed=None):
    n = rng.choice([0, 1, 5, 20, 79, 80, rng.randrange(81)])
    name = bytes(rng.randrange(0x20, 0x7F) for _ in range(n))
    c = dict(prio=rng.randrange(32), dst=rng.randrange(1, 128), node=rng.randrange(1, 128),
             tid=rng.randrange(32), up=rng.getrandbits(32), health=rng.randrange(4),
             mode=rng.randrange(8), sub=rng.randrange(8), vendor=rng.getrandbits(16),
             swmaj=rng.randrange(256), swmin=rng.randrange(256), swfl=rng.randrange(4),
             vcs=rng.getrandbits(32), crc=rng.getrandbits(64), hwmaj=rng.randrange(256),
             hwmin=rng.randrange(256), uid=bytes(rng.getrandbits(8) for _ in range(16)),
             name=name)
    if fixed:
        c.update(fixed)
    return c


def py_frames(kind, c):
    P = dronecan.uavcan.protocol
    if kind == "P":
        msg = dronecan.ardupilot.equipment.proximity_sensor.Proximity(
            sensor_id=c["sensor"], reading_type=c["type"], flags=c["flags"], yaw=c["yaw"],
            pitch=c["pitch"], distance=c["dist"])
        t = transport.Transfer(payload=msg, source_node_id=c["node"], transfer_id=c["tid"],
                               transfer_priority=c["prio"])
    elif kind == "S":
        msg = P.NodeStatus(uptime_sec=c["up"], health=c["health"], mode=c["mode"],
                           sub_mode=c["sub"], vendor_specific_status_code=c["vendor"])
        t = transport.Transfer(payload=msg, source_node_id=c["node"], transfer_id=c["tid"],
                               transfer_priority=c["prio"])
    else:
        msg = P.GetNodeInfo.Response()
        msg.status = P.NodeStatus(uptime_sec=c["up"], health=c["health"], mode=c["mode"],
                                  sub_mode=c["sub"], vendor_specific_status_code=c["vendor"])
        msg.software_version = P.SoftwareVersion(major=c["swmaj"], minor=c["swmin"],
                                                 optional_field_flags=c["swfl"],
                                                 vcs_commit=c["vcs"], image_crc=c["crc"])
        hw = P.HardwareVersion(major=c["hwmaj"], minor=c["hwmin"])
        hw.unique_id = list(c["uid"])
        msg.hardware_version = hw
        msg.name = list(c["name"])
        t = transport.Transfer(payload=msg, source_node_id=c["node"], dest_node_id=c["dst"],
                               transfer_id=c["tid"], transfer_priority=c["prio"],
                               service_not_message=True, request_not_response=False)
    return t.to_frames()


def c_line(kind, c):
    if kind == "P":
        return "P %x %x %x %x %x %x %x %x %x" % (c["prio"], c["node"], c["tid"], c["sensor"],
                                                 c["type"], c["flags"], c["yaw_bits"],
                                                 c["pitch_bits"], c["dist_bits"])
    if kind == "S":
        return "S %x %x %x %x %x %x %x %x" % (c["prio"], c["node"], c["tid"], c["up"],
                                              c["health"], c["mode"], c["sub"], c["vendor"])
    return "I %x %x %x %x %x %x %x %x %x %x %x %x %x %x %x %x %s %s" % (
        c["prio"], c["dst"], c["node"], c["tid"], c["up"], c["health"], c["mode"], c["sub"],
        c["vendor"], c["swmaj"], c["swmin"], c["swfl"], c["vcs"], c["crc"], c["hwmaj"],
        c["hwmin"], c["uid"].hex(), c["name"].hex() or "-")


def same_f16(a, b):
    """pydronecan's decoded value vs. what we expect after the saturated half conversion."""
    if math.isnan(a) or math.isnan(b):
        return math.isnan(a) and math.isnan(b)
    return a == b


def check_decoded(kind, c, frames):
    t = transport.Transfer()
    t.from_frames(frames)       # raises on a bad tail byte, toggle or CRC
    m = t.payload
    if t.transfer_id != c["tid"] or t.source_node_id != c["node"] or \
            t.transfer_priority != c["prio"]:
        return "transfer header decoded wrong: %r" % t
    if kind == "P":
        exp = [transport.f32_from_f16(transport.f16_from_f32(transport.cast(
            c[k], m._fields[f]._type))) for k, f in (("yaw", "yaw"), ("pitch", "pitch"),
                                                      ("dist", "distance"))]
        got = [m.yaw, m.pitch, m.distance]
        if m.sensor_id != c["sensor"] or m.reading_type != c["type"] or m.flags != c["flags"]:
            return "integer fields decoded wrong: %s" % dronecan.to_yaml(m)
        for e, g in zip(exp, got):
            if not same_f16(e, g):
                return "float field decoded wrong: %r vs %r" % (g, e)
    elif kind == "S":
        if (m.uptime_sec, m.health, m.mode, m.sub_mode, m.vendor_specific_status_code) != \
                (c["up"], c["health"], c["mode"], c["sub"], c["vendor"]):
            return "NodeStatus decoded wrong: %s" % dronecan.to_yaml(m)
    else:
        if t.dest_node_id != c["dst"] or t.service_not_message is not True or \
                t.request_not_response:
            return "service header decoded wrong"
        if bytes(m.name) != c["name"] or bytes(m.hardware_version.unique_id) != c["uid"] or \
                m.software_version.image_crc != c["crc"] or \
                m.software_version.vcs_commit != c["vcs"] or m.status.uptime_sec != c["up"] or \
                len(m.hardware_version.certificate_of_authenticity) != 0:
            return "GetNodeInfo decoded wrong: %s" % dronecan.to_yaml(m)
    return None


def main():
    dump = sys.argv[1]
    n_random = int(sys.argv[2]) if len(sys.argv) > 2 else 2000
    seed = int(os.environ.get("OCC_SEED", random.SystemRandom().randrange(1 << 31)))
    print("golden: seed %d (set OCC_SEED to repeat)" % seed)
    rng = random.Random(seed)
    cases = []
    # The note's golden examples first.
    cases.append(("P", prox_case(rng, dict(prio=31, node=100, tid=0, sensor=1, type=2, flags=0,
                                            yaw=45.0, pitch=0.0, dist=3.5))))
    cases.append(("S", status_case(rng, dict(prio=31, node=100, tid=0, up=1, health=0, mode=0,
                                              sub=0, vendor=0))))
    for v in FLOAT_EDGES:
        cases.append(("P", prox_case(rng, dict(yaw=v, pitch=-v if not math.isnan(v) else v,
                                                dist=v))))
    for _ in range(n_random):
        cases.append(("P", prox_case(rng)))
    for _ in range(n_random // 4):
        cases.append(("S", status_case(rng)))
    for _ in range(n_random // 8):
        cases.append(("I", info_case(rng)))
    cases.append(("I", info_case(rng, dict(name=b"org.occmap.obstacles"))))
    cases.append(("I", info_case(rng, dict(name=b"x" * 80))))

    inp = "".join(c_line(k, c) + "\n" for k, c in cases)
    res = subprocess.run([dump], input=inp.encode(), stdout=subprocess.PIPE, check=True)
    ours = res.stdout.decode().splitlines()
    if len(ours) != len(cases):
        print("golden: FAIL: %d cases, %d answers" % (len(cases), len(ours)))
        return 1
    bad = 0
    frames_total = 0
    per_kind = {}
    for (kind, c), line in zip(cases, ours):
        want = frames_text(py_frames(kind, c))
        per_kind[kind] = per_kind.get(kind, 0) + 1
        frames_total += len(want.split())
        err = None
        if line != want:
            err = "bytes differ\n    pydronecan %s\n    occmap     %s" % (want, line)
        else:
            err = check_decoded(kind, c, parse_frames(line))
        if err:
            bad += 1
            if bad <= 10:
                print("golden: FAIL %s %r: %s" % (kind, c, err))
    print("golden: %d cases (Proximity %d, NodeStatus %d, GetNodeInfo %d), %d frames; "
          "%d mismatches" % (len(cases), per_kind.get("P", 0), per_kind.get("S", 0),
                             per_kind.get("I", 0), frames_total, bad))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
