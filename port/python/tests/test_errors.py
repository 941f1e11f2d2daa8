# SPDX-License-Identifier: BSD-3-Clause
"""C error codes become OccError subclasses named after the C enumerators; a refused call
leaves the map as it was (its bytes) and never reads as safe."""
import numpy as np
import pytest

import occmap
from occmap import errors


def _err(exc_info, cls, name):
    e = exc_info.value
    assert type(e) is cls and e.name == name and e.code == errors.BY_CODE[e.code].code
    assert str(e).startswith(name + ": ")
    return e


def test_every_code_has_its_class_and_the_c_text():
    from occmap._lib import err_text
    assert sorted(errors.BY_CODE) == list(range(-10, 0))
    for code, cls in errors.BY_CODE.items():
        e = errors.error_for(code, err_text(code))
        assert isinstance(e, occmap.OccError) and type(e) is cls
        assert e.name == errors.CODES[code] and err_text(code) in str(e)
    assert err_text(-3) == "out of memory (pool or buffer)"
    odd = errors.error_for(-99, err_text(-99))  # a code this binding does not know still raises
    assert type(odd) is occmap.OccError and odd.code == -99


@pytest.mark.parametrize("cfg", [dict(resolution_m=-0.1), dict(resolution_m=float("nan")),
                                 dict(hit=-1.0), dict(clamp_min=4.0), dict(depth_levels=0),
                                 dict(depth_levels=22)])
def test_bad_config_is_occ_err_arg(cfg):
    with pytest.raises(occmap.OccArgError) as ei:
        occmap.Map(**{"resolution_m": 0.1, **cfg})
    assert isinstance(_err(ei, occmap.OccArgError, "OCC_ERR_ARG"), ValueError)


def test_python_side_refusals():
    with pytest.raises(ValueError):
        occmap.Map(0.1, depth_levels=16 + 256)  # would wrap to 16 in a uint8_t: refused
    with pytest.raises(TypeError):
        occmap.Map(0.1, resolution=0.1)  # misspelt option
    with pytest.raises(ValueError):
        occmap.Map(0.1, arena_bytes=-1)
    m = occmap.Map(0.1, 1 << 20)
    with pytest.raises(ValueError):
        m.collide_sphere((0, 0), 1.0)
    with pytest.raises(ValueError):
        m.collide_sphere((0, 0, 0), 1.0, unknown="maybe")
    with pytest.raises(ValueError):
        m.insert_cloud((0, 0, 0), np.zeros((3, 3)), method="fastest")


def test_nomem_leaves_the_map_unchanged():
    m = occmap.Map(0.1, 4096)  # a few dozen blocks
    m.insert_cloud((0, 0, 0), np.array([[0.5, 0.0, 0.0]], np.float32))
    before = m.to_bytes("occ")
    pts = np.random.default_rng(1).uniform(-3, 3, (500, 3)).astype(np.float32)
    with pytest.raises(occmap.OccNoMemError) as ei:
        m.insert_cloud((0, 0, 0), pts)
    assert isinstance(_err(ei, occmap.OccNoMemError, "OCC_ERR_NOMEM"), MemoryError)
    assert m.to_bytes("occ") == before and m.oom_count == 1
    m.check()


def test_loading_errors(tmp_path, geb079):
    with pytest.raises(occmap.OccIOError) as ei:
        occmap.Map.load(tmp_path / "absent.bt")
    assert isinstance(_err(ei, occmap.OccIOError, "OCC_ERR_IO"), OSError)
    data = geb079.read_bytes()
    with pytest.raises(occmap.OccFormatError) as ei:
        occmap.Map.from_bytes(data[:len(data) // 2])  # truncated
    e = _err(ei, occmap.OccFormatError, "OCC_ERR_FORMAT")
    assert "at byte" in e.detail
    with pytest.raises(occmap.OccFormatError):
        occmap.Map.from_bytes(b"not a map at all\n")
    with pytest.raises(occmap.OccNoMemError):
        occmap.Map.from_bytes(data, arena_bytes=1 << 16)
    snap = occmap.Map(0.1, 1 << 20, depth_levels=12).to_bytes("occ")
    assert occmap.Map.from_bytes(snap).depth_levels == 12
    with pytest.raises(occmap.OccUnsupportedError) as ei:
        occmap.Map(0.1, 1 << 20, depth_levels=12).to_bytes("bt")  # OctoMap files are depth 16
    _err(ei, occmap.OccUnsupportedError, "OCC_ERR_UNSUPPORTED")
    with pytest.raises(occmap.OccArgError):
        occmap.Map(0.1, 1 << 20).save(tmp_path / "map.xyz")
    assert not any(tmp_path.iterdir())


def test_query_errors_fail_closed():
    m = occmap.Map(0.1, 1 << 20)
    far = (1e6, 0.0, 0.0)  # outside the depth-16 map (+-3276.8 m)
    with pytest.raises(occmap.OccRangeError) as ei:
        m.cast_ray(far, (1, 0, 0))
    _err(ei, occmap.OccRangeError, "OCC_ERR_RANGE")
    with pytest.raises(occmap.OccArgError):
        m.cast_ray((0, 0, 0), (0, 0, 0))  # zero direction
    with pytest.raises(occmap.OccArgError):
        m.collide_sphere((0, 0, 0), -1.0)
    with pytest.raises(occmap.OccArgError):
        m.collide_capsule((0, 0, 0), (np.inf, 0, 0), 0.1)
    with pytest.raises(occmap.OccArgError):
        m.insert_cloud((np.nan, 0, 0), np.zeros((1, 3), np.float32))
    with pytest.raises(occmap.OccRangeError):
        m.sectors(far)
    with pytest.raises(occmap.OccArgError):
        m.sectors((0, 0, 0), n_sectors=0)
    with pytest.raises(occmap.OccArgError):
        m.sectors((0, 0, 0), quaternion=(2, 0, 0, 0))  # not a unit quaternion
    with pytest.raises(occmap.OccArgError):
        m.insert_depth(np.ones((4, 4), np.uint16), (1, 1, 2, 2), (0, 0, 0), pixel_step=0)
    # unknown space is never safe by default; an empty map blocks everything
    assert not m.collide_sphere((0, 0, 0), 0.5).safe
    assert m.collide_sphere((0, 0, 0), 0.5, unknown="safe").safe
    assert (m.sectors((0, 0, 0)).distance_cm == 65535).all()
