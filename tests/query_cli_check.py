#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""query_cli_check.py - `occmap query` on geb079.bt: every answer is valid JSON with the documented
keys; one query gives the same object alone and inside --batch; the unknown policy behaves as
documented (far outside the scanned space: unknown voxels, so unsafe by default and safe with
--unknown safe); a ray along a direction hits at a voxel centre on the grid; a point gives the
state of its voxel (agreeing with a box of zero size there), in batches too; bad input is an
error line and a non-zero exit.  usage: query_cli_check.py OCCMAP MAP"""
import json
import subprocess
import sys
import tempfile

occmap, path = sys.argv[1], sys.argv[2]
RES = 0.08  # geb079's resolution (checked below through the ray's hit point)


def run(args, rc=0):
    p = subprocess.run([occmap, "query", path] + args, capture_output=True, text=True)
    if p.returncode != rc:
        sys.exit(f"FAIL: {args}: exit {p.returncode}, stderr {p.stderr}")
    return p.stdout


queries = [
    "--sphere 0,0,0.5,0.25",
    "--sphere 1.5,-0.5,0.8,0.4 --unknown safe",
    "--aabb -1,-1,0,1,1,1",
    "--capsule 0,0,0.5,2,0,0.5,0.2",
    "--ray 0,0,0.5,1,0.2,0,10 --unknown safe",
    "--ray 0,0,0.5,0,1,0,10",
    "--sphere 500,500,500,0.3",
    "--sphere 500,500,500,0.3 --unknown safe",
]
single = []
for q in queries:
    out = run(q.split() + ["--json"]).strip().splitlines()
    assert len(out) == 1, out
    obj = json.loads(out[0])
    for k in ("collides", "occupied_voxels", "unknown_voxels"):
        assert k in obj, (q, obj)
    if "--ray" in q:
        assert "hit" in obj and "hit_point" in obj, obj
        if obj["hit"]:
            # a voxel centre: (k + 0.5) * res
            for c in obj["hit_point"]:
                f = c / RES - 0.5
                assert abs(f - round(f)) < 1e-3, (q, obj)
    single.append(obj)

far_unsafe, far_safe = single[-2], single[-1]
assert far_unsafe["collides"] and far_unsafe["occupied_voxels"] == 0 and far_unsafe["unknown_voxels"] > 0, far_unsafe
assert not far_safe["collides"], far_safe

with tempfile.NamedTemporaryFile("w", suffix=".txt", delete=False) as f:
    f.write("# comment line\n\n" + "\n".join(queries) + "\n--bogus 1\n")
    batch = f.name
lines = run(["--batch", batch, "--json"], rc=1).strip().splitlines()
assert len(lines) == len(queries) + 1, lines
for q, s, line in zip(queries, single, lines):
    b = json.loads(line)
    assert b == s, (q, s, b)
assert "error" in json.loads(lines[-1])

run(["--sphere", "0,0,0,-1", "--json"], rc=1)
run(["--sphere", "0,0,nan,1"], rc=2)
run(["--sphere", "0,0,0,1", "--aabb", "0,0,0,1,1,1"], rc=2)
text = run(["--sphere", "500,500,500,0.3"])
assert text.startswith("COLLIDES"), text
# --distance: the three answers. Found agrees with the sphere check at that radius (2 cm either
# side); far outside the scan nothing blocks with unknown free, and the unknown point itself
# blocks at 0 by default; a 1-entry heap overflows: undecided, exit 1, never "none".
near = json.loads(run(["--distance", "0,0,0.5,3", "--unknown", "safe", "--json"]))
assert near["obstacle"] == "found" and 0.05 < near["distance_m"] < 3, near
for r, hit in ((near["distance_m"] + 0.02, True), (near["distance_m"] - 0.02, False)):
    s = json.loads(run(["--sphere", f"0,0,0.5,{r}", "--unknown", "safe", "--json"]))
    assert s["collides"] == hit, (r, s, near)
none = json.loads(run(["--distance", "500,500,500,1", "--unknown", "safe", "--json"]))
assert none == {"obstacle": "none", "distance_m": 1}, none
here = json.loads(run(["--distance", "500,500,500,1", "--json"]))
assert here == {"obstacle": "found", "distance_m": 0}, here
undecided = json.loads(run(["--distance", "0,0,0.5,3", "--heap", "1", "--json"], rc=1))
assert undecided["obstacle"] == "undecided" and undecided["distance_m"] == 0, undecided
assert "error" in undecided, undecided
assert run(["--distance", "0,0,0.5,3", "--heap", "1"], rc=1).startswith("UNDECIDED")
assert "error" in json.loads(run(["--distance", "0,0,0.5,-1", "--json"], rc=1))
run(["--distance", "0,0,0.5,3", "--heap", "0"], rc=2)
with tempfile.NamedTemporaryFile("w", suffix=".txt", delete=False) as f:
    f.write("--distance 0,0,0.5,3 --unknown safe\n--distance 0,0,0.5,3 --heap 1\n")
    dbatch = f.name
dl = [json.loads(x) for x in run(["--batch", dbatch, "--json"], rc=1).strip().splitlines()]
assert dl == [near, undecided], dl
# --point: the state of the voxel holding the point. The ray's hit voxel is occupied; a point in
# the scanned corridor free, one beside it and one off the map unknown; each agrees with the voxel
# count of a box of zero size at the point (another code path); batch lines equal single ones.
hit = [s for q, s in zip(queries, single) if q.startswith("--ray 0,0,0.5,0,1,0")][0]["hit_point"]
points = {",".join(map(str, hit)): "occupied", "1,0,1": "free", "1,7.3,1": "unknown",
          "1e5,0,0": "unknown"}
for p, want in points.items():
    got = json.loads(run(["--point", p, "--json"]))
    assert got == {"state": want}, (p, got)
    assert run(["--point", p]).strip() == want
    if want != "unknown" or p == "1,7.3,1":
        box = json.loads(run(["--aabb", f"{p},{p}", "--json"]))
        assert (box["occupied_voxels"], box["unknown_voxels"]) == \
            {"occupied": (1, 0), "free": (0, 0), "unknown": (0, 1)}[want], (p, box)
with tempfile.NamedTemporaryFile("w", suffix=".txt", delete=False) as f:
    f.write("".join(f"--point {p}\n" for p in points))
    pbatch = f.name
pl = [json.loads(x) for x in run(["--batch", pbatch, "--json"]).strip().splitlines()]
assert pl == [{"state": w} for w in points.values()], pl
run(["--point", "1,nan,1"], rc=2)
run(["--point", "1,0"], rc=2)
print(f"PASS query cli: {len(queries)} queries, batch identical, policies and errors as documented, "
      f"distance found/none/undecided, point states")
