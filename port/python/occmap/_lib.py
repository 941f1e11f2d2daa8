# SPDX-License-Identifier: BSD-3-Clause
"""Finds and loads libocc.so and declares the C prototypes used by the binding.

Search order: $OCCMAP_LIB (a path to the .so); libocc.so next to this package (a plain
`pip install port/python` copies the repo's build/libocc.so there); build/libocc.so of the
repository this package sits in (an editable install, or running from the tree); the system's
linker path (ctypes.util.find_library("occ"), after `make install`)."""
import ctypes as C
import ctypes.util
import os
from pathlib import Path

from . import _structs as S
from .errors import error_for

P = C.POINTER


def _candidates():
    """Paths (checked for existence) and, last, a bare soname for the dynamic linker."""
    env = os.environ.get("OCCMAP_LIB")
    if env:
        yield env
        return  # an explicit choice is never silently replaced by another library
    here = Path(__file__).resolve().parent
    yield str(here / "libocc.so")
    for up in here.parents:  # port/python/occmap -> the repository root's build/
        yield str(up / "build" / "libocc.so")
    found = ctypes.util.find_library("occ")
    if found:
        yield found


def _load():
    tried = []
    for path in _candidates():
        tried.append(path)
        if "/" in path and not os.path.exists(path):
            continue
        return C.CDLL(path), path
    raise ImportError("occmap: libocc.so not found (set OCCMAP_LIB, or run `make build/libocc.so`)"
                      "; tried: " + ", ".join(tried))


lib, LIB_PATH = _load()

# name: (restype, argtypes). Pointers to structs as POINTER(struct), buffers as c_void_p.
_PROTOS = {
    "occ_err_str": (C.c_char_p, [C.c_int]),
    "occ_map_config_default": (S.MapConfig, []),
    "occ_map_init": (C.c_int, [P(S.MapT), P(S.MapConfig), C.c_void_p, C.c_size_t]),
    "occ_map_clear": (None, [P(S.MapT)]),
    "occ_map_check": (C.c_int, [P(S.MapT)]),
    "occ_map_stats": (None, [P(S.MapT), P(S.MapStats)]),
    "occ_map_state_at": (C.c_int, [P(S.MapT), S.Vec3]),
    "occ_map_update": (C.c_int, [P(S.MapT), S.Vec3, C.c_float]),
    "occ_lookup_init": (None, [P(S.Lookup), P(S.MapT)]),
    "occ_lookup_state": (C.c_int, [P(S.Lookup), S.Vec3]),
    "occ_map_states_at": (C.c_int, [P(S.MapT), C.c_void_p, C.c_size_t, C.c_void_p]),
    "occ_insert_params_default": (S.InsertParams, []),
    "occ_insert_scratch_bytes_scan": (C.c_size_t, [P(S.MapT), P(S.Vec3), C.c_void_p, C.c_size_t,
                                                   P(S.InsertParams)]),
    "occ_map_insert_cloud": (C.c_int, [P(S.MapT), P(S.Vec3), C.c_void_p, C.c_size_t,
                                       P(S.InsertParams), C.c_void_p, C.c_size_t,
                                       P(S.InsertResult)]),
    "occ_depth_scratch_bytes": (C.c_size_t, [P(S.MapT), C.c_uint32, C.c_uint32, C.c_uint32,
                                             C.c_float, P(S.InsertParams)]),
    "occ_map_insert_depth": (C.c_int, [P(S.MapT), P(S.DepthImage), P(S.DepthParams), P(S.Pose),
                                       P(S.InsertParams), C.c_void_p, C.c_size_t,
                                       P(S.DepthResult)]),
    "occ_quat_from_euler": (S.Quat, [C.c_float, C.c_float, C.c_float]),
    "occ_volume_sphere": (C.c_int, [P(S.Volume), S.Vec3, C.c_float]),
    "occ_volume_capsule": (C.c_int, [P(S.Volume), S.Vec3, S.Vec3, C.c_float]),
    "occ_volume_aabb": (C.c_int, [P(S.Volume), S.Vec3, S.Vec3]),
    "occ_volume_segment": (C.c_int, [P(S.Volume), S.Vec3, S.Vec3]),
    "occ_query_count": (C.c_int, [P(S.MapT), P(S.Volume), P(S.QueryCounts)]),
    "occ_collide_sphere": (C.c_int, [P(S.MapT), S.Vec3, C.c_float, C.c_int, P(S.Collision)]),
    "occ_collide_capsule": (C.c_int, [P(S.MapT), S.Vec3, S.Vec3, C.c_float, C.c_int,
                                      P(S.Collision)]),
    "occ_cast_ray": (C.c_int, [P(S.MapT), S.Vec3, S.Vec3, C.c_bool, C.c_float, P(S.RayResult)]),
    "occ_sectors_config_default": (S.SectorsConfig, []),
    "occ_sectors_compute": (C.c_int, [P(S.MapT), P(S.Pose), P(S.SectorsConfig), P(S.Sectors)]),
    "occ_io_probe": (C.c_int, [C.c_void_p, C.c_size_t, P(S.MapConfig), P(S.IoInfo)]),
    "occ_io_load": (C.c_int, [P(S.MapT), P(S.MapConfig), C.c_void_p, C.c_size_t, C.c_void_p,
                              C.c_size_t, P(S.IoInfo)]),
    "occ_io_write": (C.c_int, [P(S.MapT), C.c_int, C.c_void_p, C.c_void_p, P(C.c_size_t)]),
}
for _name, (_res, _args) in _PROTOS.items():
    _fn = getattr(lib, _name)
    _fn.restype = _res
    _fn.argtypes = _args

# The caller-buffer sink of occ_io.h, passed to occ_io_write as a plain function pointer.
IO_BUF_WRITE = C.cast(lib.occ_io_buf_write, C.c_void_p)


def err_text(code):
    return lib.occ_err_str(code).decode("ascii", "replace")


def check(code, detail=""):
    """Raise the OccError subclass for a non-zero occ_err_t."""
    if code != 0:
        raise error_for(code, err_text(code), detail)


def vec3(v, what="point"):
    """A 3-vector (any sequence or array) as occ_vec3_t; ValueError when it is not 3 numbers."""
    try:
        x, y, z = (float(c) for c in v)
    except (TypeError, ValueError):
        raise ValueError(f"{what}: expected 3 numbers, got {v!r}") from None
    return S.Vec3(x, y, z)
