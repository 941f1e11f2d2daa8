# SPDX-License-Identifier: BSD-3-Clause
"""The binding on the real maps against the C tool's answers (build/occmap info / query, one
process per batch) and against tools/octomap_bt.py, an independent pure-Python .bt reader."""
import ctypes as C
import json
import math

import numpy as np
import pytest

import occmap
from conftest import tool_json_lines

# occmap info --json keys that are occ_map_stats_t fields of the loaded map.
STAT_KEYS = ("inner_nodes", "leaf_nodes", "occupied_leaves", "free_leaves", "occupied_voxels",
             "free_voxels")
MAPS = ["geb079", "fr078"]


@pytest.fixture(scope="module", params=MAPS)
def real(request):
    path = request.getfixturevalue(request.param)
    return path, occmap.Map.load(path)


def test_stats_equal_occmap_info(real, tool):
    path, m = real
    want = tool_json_lines(tool, "info", path, "--json")[0]
    st = m.stats()
    for k in STAT_KEYS:
        assert st[k] == want[k], k
    assert m.load_info["nodes"] == want["file_nodes"]  # the file's, before pruning
    assert st["nodes"] == want["inner_nodes"] + want["leaf_nodes"]
    assert st["bytes_used"] == want["memory_bytes"]
    assert st["occupied_volume_m3"] == pytest.approx(want["occupied_volume_m3"], rel=1e-12)
    assert st["free_volume_m3"] == pytest.approx(want["free_volume_m3"], rel=1e-12)
    assert np.allclose(st["bbox_min"], want["bbox_min"], atol=1e-5)
    assert np.allclose(st["bbox_max"], want["bbox_max"], atol=1e-5)
    assert m.resolution_m == pytest.approx(want["resolution_m"])
    assert m.load_info["format"] == want["format"] and m.load_info["tree_id"] == want["tree_id"]
    m.check()


def _queries(m, n, seed):
    """Random spheres, capsules and rays in the map's bbox, half of them starting in free space
    (so that both answers occur under either policy); fixed seed: reproducible."""
    rng = np.random.default_rng(seed)
    st = m.stats()
    lo, hi = np.array(st["bbox_min"]), np.array(st["bbox_max"])
    cand = rng.uniform(lo, hi, (20_000, 3)).astype(np.float32)
    free = cand[m.state_at(cand) == occmap.FREE]
    out = []
    for i in range(n):
        a = free[i] if i % 2 else rng.uniform(lo, hi).astype(np.float32)
        b = rng.uniform(lo, hi).astype(np.float32)
        r = np.float32(rng.uniform(0.02, 0.4))
        if i % 3 == 0:
            out.append(("sphere", [*a, r]))
        elif i % 3 == 1:
            out.append(("capsule", [*a, *(a + (b - a) * np.float32(0.2)), r]))
        else:
            out.append(("ray", [*a, *(b - a), np.float32(rng.uniform(0.5, 12.0))]))
    return out


def _fmt(vals):
    return ",".join(repr(float(v)) for v in vals)


@pytest.mark.parametrize("unknown", ["unsafe", "safe"])
def test_queries_equal_occmap_query(real, tool, unknown, tmp_path):
    """Collision answers, voxel counts and ray results equal the C tool's, query for query."""
    path, m = real
    qs = _queries(m, 240, seed=23 if unknown == "unsafe" else 24)
    batch = tmp_path / "batch.txt"
    batch.write_text("".join(f"--{k} {_fmt(v)} --unknown {unknown}\n" for k, v in qs))
    answers = tool_json_lines(tool, "query", path, "--batch", batch, "--json")
    assert len(answers) == len(qs)
    kinds = {"collides": 0, "safe": 0}
    for (kind, v), want in zip(qs, answers):
        v = np.array(v, dtype=np.float32)
        if kind == "sphere":
            col = m.collide_sphere(v[:3], v[3], unknown=unknown)
            cnt = m.count_sphere(v[:3], v[3])
        elif kind == "capsule":
            col = m.collide_capsule(v[:3], v[3:6], v[6], unknown=unknown)
            cnt = m.count_capsule(v[:3], v[3:6], v[6])
        else:
            ray = m.cast_ray(v[:3], v[3:6], max_range_m=v[6], ignore_unknown=unknown == "safe")
            assert ray.hit == want["hit"], (kind, v, want)
            assert ray.stop == want["stop"]
            if ray.hit:
                assert np.allclose(ray.end, want["hit_point"], atol=5e-5)
            d = v[3:6] * (v[6] / np.sqrt(np.sum(v[3:6] ** 2, dtype=np.float32)))
            cnt = m.count_segment(v[:3], v[:3] + d)
            assert cnt["occupied"] == want["occupied_voxels"]
            continue
        assert (not col.safe) == want["collides"], (kind, v, want)
        assert col.outside == want.get("outside_map", False)
        assert cnt["occupied"] == want["occupied_voxels"]
        assert cnt["unknown"] == want["unknown_voxels"]
        kinds["collides" if want["collides"] else "safe"] += 1
    assert kinds["collides"] > 10 and kinds["safe"] > 10  # both answers were exercised


def test_state_at_equals_independent_reader(geb079):
    """state_at over 100k random points equals the leaf of tools/octomap_bt.py's tree that holds
    each point (its own key arithmetic in Python doubles), unknown where it has none."""
    import octomap_bt
    res, depth, leaves = octomap_bt.read_bt(str(geb079))
    m = occmap.Map.load(geb079)
    assert m.resolution_m == pytest.approx(res)
    lv = np.array(leaves, dtype=np.int64)  # kx, ky, kz, size (voxels), occupied
    rng = np.random.default_rng(79)
    st = m.stats()
    pts = rng.uniform(st["bbox_min"], st["bbox_max"], (100_000, 3)).astype(np.float32)
    got = m.state_at(pts)
    half = 1 << (depth - 1)
    keys = np.floor(pts.astype(np.float64) / res).astype(np.int64) + half
    want = np.zeros(len(pts), dtype=np.uint8)
    for size in np.unique(lv[:, 3]):  # the leaf of each size that would hold the point
        sel = lv[lv[:, 3] == size]
        codes = (sel[:, 0] << 42) | (sel[:, 1] << 21) | sel[:, 2]
        order = np.argsort(codes)
        codes, occ = codes[order], sel[order, 4]
        base = keys // size * size
        q = (base[:, 0] << 42) | (base[:, 1] << 21) | base[:, 2]
        i = np.minimum(np.searchsorted(codes, q), len(codes) - 1)
        hit = codes[i] == q
        want[hit] = np.where(occ[i[hit]] != 0, occmap.OCCUPIED, occmap.FREE)
    counts = np.bincount(got, minlength=3)
    assert min(counts) > 1000, counts  # all three states are present
    near_border = np.abs(pts / res - np.round(pts / res)) < 1e-4  # float vs double keys
    mismatch = (got != want) & ~near_border.any(axis=1)
    assert not mismatch.any(), pts[mismatch][:5]


def _state_probes(m, seed):
    """Points for state_at: random in the map's box grown by 10 % (every 64th far off the map),
    on voxel borders and one float32 ulp either side, rows of a horizontal slice (the cursor's
    best case: what plot_slice asks), and NaN / Inf in each coordinate."""
    rng = np.random.default_rng(seed)
    st = m.stats()
    lo, hi = np.array(st["bbox_min"]), np.array(st["bbox_max"])
    ext, res = hi - lo, float(m.resolution_m)
    rand = rng.uniform(lo - 0.1 * ext, hi + 0.1 * ext, (6000, 3))
    rand[63::64, 0] = rng.uniform(-1e6, 1e6, len(rand[63::64]))
    face = np.floor(rng.uniform(lo, hi, (1000, 3)) / res) * res  # a face on each axis
    faces = np.concatenate([np.nextafter(face.astype(np.float32), -np.inf),
                            face.astype(np.float32),
                            np.nextafter(face.astype(np.float32), np.inf)])
    xs = np.arange(lo[0], hi[0], res)[:80]
    ys = np.arange(lo[1], hi[1], res)[:50]
    gx, gy = np.meshgrid(xs, ys)
    rows = np.stack([gx, gy, np.full_like(gx, (lo[2] + hi[2]) / 2)], -1).reshape(-1, 3)
    bad = np.array([[v, 1.0, 1.0] for v in (np.nan, np.inf, -np.inf)] +
                   [[1.0, v, 1.0] for v in (np.nan, np.inf, -np.inf)] +
                   [[1.0, 1.0, v] for v in (np.nan, np.inf, -np.inf)])
    return np.concatenate([rand, faces, rows, bad]).astype(np.float32)


def test_state_at_is_one_batch_equal_to_single_lookups_and_occmap_query(real, tool, tmp_path,
                                                                         batch_calls):
    """state_at answers all the points with one C call (occ_map_states_at), and each answer
    equals the single-point calls (occ_map_state_at, a lookup cursor: one ctypes call per point
    here) and `occmap query --point` (a separate process); NaN / Inf / off-map: UNKNOWN."""
    from occmap import _structs as S
    from occmap._lib import lib
    path, m = real
    pts = _state_probes(m, seed=23)
    got = m.state_at(pts)
    assert batch_calls == [len(pts)]
    batch_calls.undo()  # the single-point functions back, for the references
    vec = [S.Vec3(*map(float, p)) for p in pts]
    single = np.array([lib.occ_map_state_at(m._ref, v) for v in vec], np.uint8)
    lk = S.Lookup()
    lib.occ_lookup_init(C.byref(lk), m._ref)
    cursor = np.array([lib.occ_lookup_state(C.byref(lk), v) for v in vec], np.uint8)
    assert (got == single).all(), pts[got != single][:5]
    assert (got == cursor).all(), pts[got != cursor][:5]
    finite = np.isfinite(pts).all(axis=1)
    assert (got[~finite] == occmap.UNKNOWN).all() and (~finite).sum() == 9
    assert (got[np.abs(pts).max(axis=1) > 1e5] == occmap.UNKNOWN).all()
    assert min(np.bincount(got, minlength=3)) > 100, np.bincount(got)  # all three states
    # The tool's number parser refuses subnormals (strtof's ERANGE): the ulp below / above 0.
    sub = ((pts != 0) & (np.abs(pts) < np.finfo(np.float32).tiny)).any(axis=1)
    asked = finite & ~sub
    batch = tmp_path / "points.txt"
    batch.write_text("".join(f"--point {_fmt(p)}\n" for p in pts[asked]))
    answers = tool_json_lines(tool, "query", path, "--batch", batch, "--json")
    names = {"unknown": occmap.UNKNOWN, "free": occmap.FREE, "occupied": occmap.OCCUPIED}
    want = np.array([names[a["state"]] for a in answers], np.uint8)
    assert len(want) == asked.sum() > 10_000
    assert (got[asked] == want).all(), pts[asked][got[asked] != want][:5]


def test_bt_round_trip_is_byte_identical(geb079):
    """geb079.bt is a pruned maximum-likelihood tree, as occmap writes one: the same bytes."""
    m = occmap.Map.load(geb079)
    assert m.to_bytes("bt") == geb079.read_bytes()


def test_bt_rewrite_keeps_the_voxels(fr078, tmp_path):
    """fr_078's file is not pruned (1.37 M nodes for 0.80 M): the rewrite is smaller, and the
    map read back from it is the same tree (canonical snapshot bytes equal)."""
    m = occmap.Map.load(fr078)
    out = tmp_path / "fr078.bt"
    n = m.save(out)
    assert n == out.stat().st_size < fr078.stat().st_size
    back = occmap.Map.load(out)
    assert back.to_bytes("occ") == m.to_bytes("occ")


def test_ot_file_loads_as_the_tool_reads_it(fr079_ot, tool):
    m = occmap.Map.load(fr079_ot)
    want = tool_json_lines(tool, "info", fr079_ot, "--json")[0]
    st = m.stats()
    for k in STAT_KEYS:
        assert st[k] == want[k], k
    assert m.load_info["format"] == "ot"


def test_sectors_equal_reference(geb079):
    """72 x 5 deg sectors in the FR-079 corridor against tools/sector_ref.py (the demo's
    independent reference: column footprints clipped to the wedges, Python doubles)."""
    import octomap_bt
    import sector_ref
    res, depth, leaves = octomap_bt.read_bt(str(geb079))
    m = occmap.Map.load(geb079)
    z, band, min_cm, max_cm, off = 0.6, 0.15, 20, 600, -20.0
    checked = 0
    for x, y, yaw in ((1.0, 0.0, 0.0), (6.5, 0.2, 1.2), (12.0, -0.3, -2.5), (20.0, 0.1, 3.0)):
        za, zb = sector_ref.ground_band(res, depth, leaves, x, y, z, band, band)
        sl = sector_ref.Slice(res, depth, leaves, za, zb)
        want, d_occ, d_unk = sector_ref.sectors(sl, x, y, yaw, off_deg=off, min_cm=min_cm,
                                                max_cm=max_cm)
        got = m.sectors((x, y, z), yaw, angle_offset_deg=off, band_below_m=band,
                        band_above_m=band, min_distance_cm=min_cm, max_distance_cm=max_cm)
        assert len(got.distance_cm) == 72
        bad = sector_ref.agree([int(v) for v in got.distance_cm], want, d_occ, d_unk, max_cm)
        assert not bad, (x, y, yaw, bad, [(int(got.distance_cm[k]), want[k]) for k in bad])
        checked += sum(1 for w in want if w <= max_cm)
    assert checked > 50  # most sectors saw a wall, not only "unknown"
