# SPDX-License-Identifier: BSD-3-Clause
"""numpy in and out: integration against hand-computed voxels, insert_depth against its own
definition (back-projection + insert_cloud), byte and file round trips in the three formats."""
import numpy as np
import pytest

import occmap

RES = 0.1
HALF = 1 << 15  # 2^(depth-1) at depth 16


def _wall_map(arena=32 << 20):
    """Rays from the origin voxel's centre to a wall of points at x = 2.05 (y, z in +-1 m)."""
    m = occmap.Map(RES, arena)
    g = (np.arange(-10, 10) + 0.5) * RES
    yy, zz = np.meshgrid(g, g)
    pts = np.stack([np.full(yy.size, 2.05), yy.ravel(), zz.ravel()], axis=1).astype(np.float32)
    return m, m.insert_cloud((0.05, 0.05, 0.05), pts), pts


def test_one_ray_marks_hand_computed_voxels():
    """Origin voxel key 32768 to the end voxel 32778 on x: 10 free voxels, 1 occupied."""
    m = occmap.Map(RES, 1 << 20)
    r = m.insert_cloud((0.05, 0.05, 0.05), np.array([[1.05, 0.05, 0.05]], np.float32))
    assert (r["points_integrated"], r["voxels_free"], r["voxels_occupied"]) == (1, 10, 1)
    xs = (np.arange(-2, 14) + 0.5) * RES
    states = m.state_at(np.stack([xs, np.full_like(xs, 0.05), np.full_like(xs, 0.05)], 1))
    want = [occmap.UNKNOWN] * 2 + [occmap.FREE] * 10 + [occmap.OCCUPIED] + [occmap.UNKNOWN] * 3
    assert states.tolist() == want
    st = m.stats()
    assert (st["free_voxels"], st["occupied_voxels"]) == (10, 1)
    assert st["occupied_volume_m3"] == pytest.approx(RES ** 3, rel=1e-12)
    m.check()


def test_cloud_input_forms_give_the_same_map():
    """float64 and strided views are converted (no per-point Python loop in the call); the map
    is the one the float32 array gives."""
    m32, r32, pts = _wall_map()
    assert r32["voxels_occupied"] == 400 and r32["points_integrated"] == 400
    want = m32.to_bytes("occ")
    m64 = occmap.Map(RES, 32 << 20)
    m64.insert_cloud(np.array([0.05, 0.05, 0.05]), pts.astype(np.float64))
    assert m64.to_bytes("occ") == want
    both = np.repeat(pts, 2, axis=0)
    mv = occmap.Map(RES, 32 << 20)
    mv.insert_cloud([0.05, 0.05, 0.05], both[::2])  # a non-contiguous view
    assert mv.to_bytes("occ") == want
    for bad in (pts[:, :2], pts.ravel(), np.zeros((2, 3, 3), np.float32)):
        with pytest.raises(ValueError):
            m32.insert_cloud((0, 0, 0), bad)


def test_state_at_keeps_the_leading_shape():
    m, _, pts = _wall_map()
    grid = np.broadcast_to(pts[:6].reshape(2, 3, 3), (4, 2, 3, 3))
    got = m.state_at(grid)
    assert got.shape == (4, 2, 3) and got.dtype == np.uint8
    assert (got == occmap.OCCUPIED).all()
    assert m.state_at(np.zeros((0, 3))).shape == (0,)
    nan = m.state_at(np.array([[np.nan, 0, 0], [1e9, 0, 0]]))
    assert nan.tolist() == [occmap.UNKNOWN, occmap.UNKNOWN]  # never FREE by error


@pytest.mark.parametrize("dtype", [np.uint16, np.float32])
def test_insert_depth_equals_backprojection_and_insert_cloud(dtype):
    """occ_depth.h: the map is, voxel for voxel, that of the back-projected valid pixels
    inserted with insert_cloud (same max range). Camera at p looking along +z (identity q)."""
    h, w = 24, 32
    fx, fy, cx, cy = 28.0, 27.0, 15.5, 11.5
    rng = np.random.default_rng(7)
    metres = rng.uniform(0.8, 3.5, (h, w)).astype(np.float32)
    metres[rng.random((h, w)) < 0.1] = 0.0  # no reading
    metres[:3, :] = 6.0                      # beyond max range: cleared to it, no hit
    scale = 0.001
    raw = np.round(metres / scale).astype(np.uint16) if dtype is np.uint16 else metres
    d = raw.astype(np.float32) * np.float32(scale) if dtype is np.uint16 else raw
    p = np.array([0.31, -0.22, 0.13], np.float32)
    a = occmap.Map(RES, 64 << 20)
    r = a.insert_depth(raw, (fx, fy, cx, cy), p, (1, 0, 0, 0), min_range_m=0.2, max_range_m=4.0,
                       depth_scale_m=scale)
    v, u = np.nonzero(d > 0)
    dv = d[v, u]
    c = np.stack([(u.astype(np.float32) - np.float32(cx)) * dv / np.float32(fx),
                  (v.astype(np.float32) - np.float32(cy)) * dv / np.float32(fy), dv], axis=1)
    b = occmap.Map(RES, 64 << 20)
    rc = b.insert_cloud(p, (c + p).astype(np.float32), max_range_m=4.0)
    assert r["points"] == len(c) and r["pixels_no_reading"] == h * w - len(c)
    assert r["pixels_beyond_max"] == 3 * w - np.count_nonzero(d[:3] == 0)
    assert r["insert"]["voxels_occupied"] == rc["voxels_occupied"] > 100
    assert a.to_bytes("occ") == b.to_bytes("occ")


@pytest.mark.parametrize("fmt", ["occ", "ot", "bt"])
def test_byte_round_trips(fmt):
    m, _, _ = _wall_map()
    data = m.to_bytes(fmt)
    back = occmap.Map.from_bytes(data)
    assert back.to_bytes(fmt) == data
    assert back.load_info["format"] == fmt
    pts = np.random.default_rng(3).uniform(-0.5, 2.5, (20_000, 3)).astype(np.float32)
    assert (back.state_at(pts) == m.state_at(pts)).all()
    keys = ["occupied_voxels", "free_voxels", "bbox_min", "bbox_max", "occupied_volume_m3"]
    if fmt != "bt":  # .bt keeps the states; the log-odds become clamp values (may prune more)
        keys += ["nodes", "inner_nodes", "leaf_nodes", "occupied_leaves", "free_leaves"]
    assert {k: back.stats()[k] for k in keys} == {k: m.stats()[k] for k in keys}
    if fmt == "occ":
        assert back.config == m.config


def test_save_and_load_files(tmp_path):
    m, _, _ = _wall_map()
    for name in ("w.bt", "w.ot", "w.occ", "W.OCC"):
        n = m.save(tmp_path / name)
        assert (tmp_path / name).stat().st_size == n
        back = occmap.Map.load(tmp_path / name)
        assert back.stats()["occupied_voxels"] == m.stats()["occupied_voxels"] == 400
    assert sorted(p.name for p in tmp_path.iterdir()) == ["W.OCC", "w.bt", "w.occ", "w.ot"]
    m.save(tmp_path / "explicit.map", format="ot")
    assert occmap.Map.load(tmp_path / "explicit.map").load_info["format"] == "ot"


def test_collision_and_ray_against_the_wall():
    m, _, _ = _wall_map()
    ray = m.cast_ray((0.05, 0.05, 0.05), (1, 0, 0))
    assert ray.hit and ray.stop == "hit" and ray.key == (HALF + 20, HALF, HALF)
    assert np.allclose(ray.end, (2.05, 0.05, 0.05))
    assert m.collide_sphere((1.0, 0.05, 0.05), 0.3).safe  # free along the ray bundle
    hit = m.collide_sphere((2.0, 0.05, 0.05), 0.1)
    assert not hit.safe and not hit.outside and hit.node["state"] == occmap.OCCUPIED
    assert not m.collide_capsule((0.5, 0.05, 0.05), (2.5, 0.05, 0.05), 0.05).safe
    assert m.count_aabb((2.0, -1.0, -1.0), (2.1, 1.0, 1.0))["occupied"] == 400


def test_depth_pose_quaternion_is_w_first():
    """README's camera mount q = (0.5, -0.5, 0.5, -0.5) (w, x, y, z) turns the optical axis z
    into map +x: the centre pixel at 2 m from (0.05, 0.05, 0.05) hits the voxel at x = 2.05."""
    m = occmap.Map(RES, 8 << 20)
    r = m.insert_depth(np.array([[2000]], np.uint16), (100.0, 100.0, 0.0, 0.0),
                       (0.05, 0.05, 0.05), (0.5, -0.5, 0.5, -0.5), max_range_m=5.0)
    assert r["points"] == 1 and r["insert"]["voxels_occupied"] == 1
    assert m.state_at([[2.05, 0.05, 0.05], [1.05, 0.05, 0.05]]).tolist() == \
        [occmap.OCCUPIED, occmap.FREE]


def test_insert_depth_projective():
    """method='projective' (OCC_INSERT_PROJECTIVE): a wall 2 m ahead of a 16 x 16 camera reads
    occupied where the centre pixels end, free at 1 m in front of it, unknown 0.5 m behind."""
    m = occmap.Map(RES, 8 << 20)
    img = np.full((16, 16), 2.0, np.float32)
    r = m.insert_depth(img, (20.0, 20.0, 7.5, 7.5), (0.05, 0.05, 0.05), (0.5, -0.5, 0.5, -0.5),
                       max_range_m=3.0, method="projective")
    assert r["points"] == 256 and r["insert"]["voxels_occupied"] > 0
    assert m.state_at([[2.05, 0.05, 0.05], [1.05, 0.05, 0.05], [2.55, 0.05, 0.05]]).tolist() == \
        [occmap.OCCUPIED, occmap.FREE, occmap.UNKNOWN]


def test_sectors_yaw_equals_its_quaternion():
    m, _, _ = _wall_map()
    yaw = 0.3
    a = m.sectors((0.05, 0.05, 0.05), yaw, band_below_m=0.05, band_above_m=0.05)
    b = m.sectors((0.05, 0.05, 0.05), quaternion=(np.cos(yaw / 2), 0, 0, np.sin(yaw / 2)),
                  band_below_m=0.05, band_above_m=0.05)
    assert (a.distance_cm == b.distance_cm).all() and len(a.distance_cm) == 72
    c = m.sectors((0.05, 0.05, 0.05), -yaw, band_below_m=0.05, band_above_m=0.05)
    assert (a.distance_cm != c.distance_cm).any()  # the heading matters
