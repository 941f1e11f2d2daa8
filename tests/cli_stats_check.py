#!/usr/bin/env python3
"""Checks `occmap stats --json` on the real scan against an independent computation in Python:
distinct endpoint voxels (OctoMap's key rule for OcTree(res) with the decimal res, double arithmetic), the pruned leaf count, the
inner node count, the occupied volume and the bounding box."""
import json
import math
import struct
import subprocess
import sys

def f32(x):
    return struct.unpack('f', struct.pack('f', x))[0]

def main():
    tool, scan = sys.argv[1], sys.argv[2]
    ok = True
    for res in (0.1, 0.05, 0.2):
        out = subprocess.run([tool, 'stats', '--scan', scan, '--res', str(res), '--json'],
                             check=True, capture_output=True, text=True).stdout
        got = json.loads(out)
        # The map's resolution is the decimal the user wrote (0.1f means 0.1, OcTree(0.1)),
        # so keys are floor(float(c) * (1 / 0.1)) in double, as OcTree(0.1).coordToKey.
        r = res
        inv = 1.0 / r
        voxels = set()
        with open(scan) as f:
            for line in f:
                p = line.split()
                if len(p) != 3:
                    continue
                voxels.add(tuple(int(math.floor(f32(float(c)) * inv)) + 32768 for c in p))
        # Full (prunable) nodes level by level, then leaves = full nodes whose parent is not full.
        full = [voxels]
        for _ in range(16):
            parents = {}
            for k in full[-1]:
                pk = (k[0] >> 1, k[1] >> 1, k[2] >> 1)
                parents[pk] = parents.get(pk, 0) + 1
            full.append({k for k, n in parents.items() if n == 8})
        leaves = 0
        for lvl, nodes in enumerate(full):
            up = full[lvl + 1] if lvl + 1 < len(full) else set()
            leaves += sum(1 for k in nodes if (k[0] >> 1, k[1] >> 1, k[2] >> 1) not in up)
        ancestors = 0
        cur = voxels
        for lvl in range(1, 17):
            cur = {(k[0] >> 1, k[1] >> 1, k[2] >> 1) for k in cur}
            ancestors += sum(1 for k in cur if k not in full[lvl]
                             and (lvl == 16 or (k[0] >> 1, k[1] >> 1, k[2] >> 1) not in full[lvl + 1]))
        lo = [min(k[i] for k in voxels) for i in range(3)]
        hi = [max(k[i] for k in voxels) for i in range(3)]
        exp = {
            'voxels_updated': len(voxels),
            'occupied_leaves': leaves,
            'leaf_nodes': leaves,
            'inner_nodes': ancestors,
            'free_leaves': 0,
        }
        for key, val in exp.items():
            if got[key] != val:
                print(f'FAIL res {res}: {key} = {got[key]}, expected {val}')
                ok = False
        vol = len(voxels) * r ** 3
        if abs(got['occupied_volume_m3'] - vol) > 1e-4 * vol:
            print(f'FAIL res {res}: occupied_volume_m3 {got["occupied_volume_m3"]} != {vol}')
            ok = False
        for i in range(3):
            bmin = (lo[i] - 32768) * r
            bmax = (hi[i] + 1 - 32768) * r
            if abs(got['bbox_min'][i] - bmin) > 1e-4 or abs(got['bbox_max'][i] - bmax) > 1e-4:
                print(f'FAIL res {res}: bbox axis {i}: {got["bbox_min"][i]}..{got["bbox_max"][i]}'
                      f' != {bmin}..{bmax}')
                ok = False
        print(f'res {res}: {len(voxels)} voxels, {leaves} leaves, {ancestors} inner nodes:'
              f' {"ok" if ok else "MISMATCH"}')
    return 0 if ok else 1

if __name__ == '__main__':
    sys.exit(main())
