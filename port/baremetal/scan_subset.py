#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""scan_subset.py - every STEP-th point of a plain `x y z` scan (OctoMap's scan.dat) as
little-endian float32 triples, for embed_bytes.py to put into a firmware image (make
test-shared-m4 replays part of the real scan on the emulated Cortex-M4; the output goes to
build/, never into the tree).

usage: scan_subset.py IN.dat OUT.bin STEP"""
import struct
import sys


def main():
    src, out, step = sys.argv[1], sys.argv[2], int(sys.argv[3])
    pts = []
    with open(src, encoding="ascii") as f:
        for line in f:
            w = line.split()
            try:
                pts.append(tuple(float(v) for v in w[:3]))
            except ValueError:
                continue  # a header line ("NODE ...")
    pts = [p for p in pts if len(p) == 3][::step]
    with open(out, "wb") as f:
        for p in pts:
            f.write(struct.pack("<3f", *p))
    print("scan_subset: %d of the points of %s (every %d-th) -> %s" % (len(pts), src, step, out))


if __name__ == "__main__":
    main()
