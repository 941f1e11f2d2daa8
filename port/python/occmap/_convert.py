# SPDX-License-Identifier: BSD-3-Clause
"""Python values to C arguments: numpy point arrays, enums by name, checked small integers."""
import numpy as np

from . import _structs as S

UNKNOWN, FREE, OCCUPIED = 0, 1, 2  # occ_state_t
FORMATS = {"bt": 1, "ot": 2, "occ": 3}  # occ_format_t by file extension
METHODS = {"simple": 0, "discrete": 1, "fast_discrete": 2, "super_rays": 3, "projective": 4}
POLICIES = {"unsafe": 0, "safe": 1}  # occ_unknown_policy_t
RAY_STOPS = ("hit", "max_range", "unknown", "map_edge")  # occ_ray_stop_t


def points(a, what="points"):
    """(N, 3) C-contiguous float32 (the memory of N occ_vec3_t); a copy only when needed."""
    arr = np.ascontiguousarray(a, dtype=np.float32)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise ValueError(f"{what}: expected an N x 3 array, got shape {arr.shape}")
    return arr


def enum(table, value, what):
    try:
        return table[value]
    except (KeyError, TypeError):
        raise ValueError(f"{what}: expected one of {sorted(table)}, got {value!r}") from None


def policy(unknown):
    """'unsafe' (default: unknown and off-map space block) or 'safe'."""
    return enum(POLICIES, unknown, "unknown")


def set_fields(struct, values, what):
    """Assign keyword values to struct fields, refusing names the struct has not and integers
    that its C field would silently wrap (ctypes truncates)."""
    types = dict(struct._fields_)
    for name, v in values.items():
        if name not in types or name == "priv":
            raise TypeError(f"{what}: unknown option {name!r} (known: "
                            f"{', '.join(n for n in types if n != 'priv')})")
        t = types[name]
        if t in (S.C.c_uint8, S.C.c_uint16, S.C.c_uint32):
            bits = 8 * S.C.sizeof(t)
            if not isinstance(v, (int, np.integer)) or not 0 <= v < (1 << bits):
                raise ValueError(f"{what}.{name}: expected an integer 0..{(1 << bits) - 1}, "
                                 f"got {v!r}")
            v = int(v)
        setattr(struct, name, v)
    return struct


def quat(q):
    """(w, x, y, z) as occ_quat_t."""
    try:
        w, x, y, z = (float(c) for c in q)
    except (TypeError, ValueError):
        raise ValueError(f"quaternion: expected 4 numbers (w, x, y, z), got {q!r}") from None
    return S.Quat(w, x, y, z)
