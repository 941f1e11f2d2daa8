#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""octomap_bt.py - a small independent reader of OctoMap's compact .bt files (pure Python), for
the demo's cross-check of occmap's sector distances. Not used by occmap itself.

read_bt(path) -> (res, depth, leaves) with leaves = list of (kx, ky, kz, size_voxels, occupied)
in OctoMap keys (key = floor(x / res) + 2^(depth-1)). Unknown space is simply absent.
Node stream (OcTree::readBinaryNode): per inner node two bytes, two bits per child i:
(bit 2i, bit 2i+1) = (1,0) free leaf, (0,1) occupied leaf, (1,1) inner node, (0,0) unknown.
Children are visited depth-first in order 0..7 (bit 0 of i = x, bit 1 = y, bit 2 = z)."""
import sys


def read_bt(path):
    with open(path, "rb") as f:
        data = f.read()
    pos = 0
    res = None
    size = None
    ident = None
    while True:
        end = data.index(b"\n", pos)
        line = data[pos:end].decode("ascii", "replace").strip()
        pos = end + 1
        if line.startswith("#") or not line:
            continue
        key, _, val = line.partition(" ")
        if key == "id":
            ident = val.strip()
        elif key == "res":
            res = float(val)
        elif key == "size":
            size = int(val)
        elif key == "data":
            break
    if ident != "OcTree" or res is None:
        raise ValueError("%s: not an OcTree .bt file" % path)
    depth = 16
    leaves = []
    if not size:
        return res, depth, leaves
    # Explicit stack of (kx, ky, kz, level) for inner nodes whose bytes come next.
    stack = [(0, 0, 0, depth)]
    while stack:
        kx, ky, kz, level = stack.pop()
        b = data[pos] | (data[pos + 1] << 8)
        pos += 2
        half = 1 << (level - 1)
        inner = []
        for i in range(8):
            bits = (b >> (2 * i)) & 3
            if bits == 0:
                continue
            cx = kx + (half if i & 1 else 0)
            cy = ky + (half if i & 2 else 0)
            cz = kz + (half if i & 4 else 0)
            if bits == 1:      # bit 2i set only: free
                leaves.append((cx, cy, cz, half, False))
            elif bits == 2:    # bit 2i+1 only: occupied
                leaves.append((cx, cy, cz, half, True))
            else:
                inner.append((cx, cy, cz, level - 1))
        stack.extend(reversed(inner))  # depth-first, child 0 first
    return res, depth, leaves


if __name__ == "__main__":
    r, d, lv = read_bt(sys.argv[1])
    occ = sum(1 for l in lv if l[4])
    half = 1 << (d - 1)
    lo = [min(l[a] for l in lv) for a in range(3)]
    hi = [max(l[a] + l[3] for l in lv) for a in range(3)]
    print("res %g depth %d leaves %d occupied %d" % (r, d, len(lv), occ))
    print("bbox min", [(k - half) * r for k in lo], "max", [(k - half) * r for k in hi])
