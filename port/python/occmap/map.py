# SPDX-License-Identifier: BSD-3-Clause
"""occmap.Map: one occ_map_t on an arena owned by the Python object. Every method is one or a
few C calls (occ_core.h, occ_integrate.h, occ_depth.h, occ_query.h, occ_sectors.h, occ_io.h);
no map logic is repeated here. Units as in C: metres, radians, log-odds; map frame z up."""
import ctypes as C
import os
from collections import namedtuple
from pathlib import Path

import numpy as np

from . import _convert as V
from . import _structs as S
from ._lib import IO_BUF_WRITE, check, lib, vec3
from .errors import OccIOError, OccArgError, error_for

Collision = namedtuple("Collision", "safe outside node")
RayHit = namedtuple("RayHit", "hit stop key end")
Sectors = namedtuple("Sectors", "distance_cm d_occ_m d_unk_m nodes_read")

SCRATCH_CAP = 1 << 30  # scratch offered to one insert at most (the C call compacts its sets)


def _config(**options):
    """occ_map_config_default() with keyword overrides (field names of occ_map_config_t)."""
    return V.set_fields(lib.occ_map_config_default(), options, "config")


class Map:
    """A probabilistic occupancy octree (OctoMap / UFOMap model) in a fixed arena.

    Map(resolution_m, arena_bytes, depth_levels=16, hit=..., miss=..., clamp_min=...,
    clamp_max=..., free_max=..., occupied_min=...): the config fields of occ_map_config_t,
    OctoMap's defaults for those not given. The arena is allocated once (numpy, not zeroed) and
    never grows: a write that does not fit raises OccNoMemError and changes nothing.
    As the C map, a Map is not thread-safe (ctypes releases the GIL during a call): serialize
    access to one Map; distinct maps are independent."""

    def __init__(self, resolution_m=0.1, arena_bytes=64 << 20, **config):
        cfg = _config(resolution_m=float(resolution_m), **config)
        self._new_arena(arena_bytes)
        check(lib.occ_map_init(self._ref, C.byref(cfg), self._arena_ptr, self._arena.size),
              "occ_map_init")
        self.load_info = None

    def _new_arena(self, arena_bytes):
        if not isinstance(arena_bytes, (int, np.integer)) or arena_bytes < 0:
            raise ValueError(f"arena_bytes: expected an integer >= 0, got {arena_bytes!r}")
        self._arena = np.empty(int(arena_bytes), dtype=np.uint8)
        self._arena_ptr = self._arena.ctypes.data if arena_bytes else None
        self._map = S.MapT()
        self._ref = C.byref(self._map)
        self._scratch = np.empty(0, dtype=np.uint8)

    # ---- files and bytes (occ_io.h; the file access is Python's) --------------------------
    @classmethod
    def load(cls, path, arena_bytes=None, *, extra_bytes=16 << 20, **config):
        """Load a .bt / .ot / .occ file (format from its content). The arena is the bytes the
        file needs plus extra_bytes of headroom unless arena_bytes is given. `config` gives the
        sensor model for OctoMap files (.bt leaves get clamp_min / clamp_max); the resolution
        and depth come from the file. OccIOError, OccFormatError (detail: byte offset),
        OccUnsupportedError, OccNoMemError."""
        try:
            data = Path(path).read_bytes()
        except OSError as e:
            raise OccIOError("i/o error", f"{path}: {e.strerror or e}") from e
        return cls.from_bytes(data, arena_bytes, extra_bytes=extra_bytes, **config)

    @classmethod
    def from_bytes(cls, data, arena_bytes=None, *, extra_bytes=16 << 20, **config):
        """Load from a bytes-like object (occ_io_probe, then occ_io_load)."""
        base = _config(**config)
        buf = bytes(data)
        info = S.IoInfo()
        _io_check(lib.occ_io_probe(buf, len(buf), C.byref(base), C.byref(info)), info)
        if arena_bytes is None:
            arena_bytes = info.arena_bytes_needed + int(extra_bytes)
        self = cls.__new__(cls)
        self._new_arena(arena_bytes)
        _io_check(lib.occ_io_load(self._ref, C.byref(base), self._arena_ptr, self._arena.size,
                                  buf, len(buf), C.byref(info)), info)
        self.load_info = _info_dict(info)
        return self

    def to_bytes(self, format="occ"):
        """The map serialized as 'bt', 'ot' or 'occ' (occ_io_write into a buffer of the size a
        counting pass gives). OccUnsupportedError for OctoMap formats at depth != 16."""
        fmt = V.enum(V.FORMATS, format, "format")
        n = C.c_size_t(0)
        check(lib.occ_io_write(self._ref, fmt, None, None, C.byref(n)), "occ_io_write (count)")
        out = C.create_string_buffer(max(n.value, 1))
        sink = S.IoBuf(C.cast(out, C.c_void_p), n.value, 0)
        check(lib.occ_io_write(self._ref, fmt, IO_BUF_WRITE, C.byref(sink), C.byref(n)),
              "occ_io_write")
        return out.raw[:sink.len]

    def save(self, path, format=None):
        """Write the map atomically (temporary file, fsync, rename) in the format of the
        extension (.bt, .ot, .occ; case-insensitive) or `format`. OccArgError for an unknown
        extension; OccIOError when the file cannot be written (the old file is kept)."""
        path = Path(path)
        if format is None:
            format = path.suffix[1:].lower()
            if format not in V.FORMATS:
                raise OccArgError("invalid argument", f"{path}: extension not .bt, .ot or .occ")
        data = self.to_bytes(format)
        tmp = path.with_name(f"{path.name}.tmp.{os.getpid()}")
        try:
            with open(tmp, "wb") as f:
                f.write(data)
                f.flush()
                os.fsync(f.fileno())
            os.replace(tmp, path)
            dfd = os.open(path.parent, os.O_RDONLY)
            try:
                os.fsync(dfd)
            finally:
                os.close(dfd)
        except OSError as e:
            tmp.unlink(missing_ok=True)
            raise OccIOError("i/o error", f"{path}: {e.strerror or e}") from e
        return len(data)

    # ---- writing ----------------------------------------------------------------------------
    def clear(self):
        """Forget all content (occ_map_clear)."""
        lib.occ_map_clear(self._ref)

    def update(self, point, delta_logodds):
        """Add delta_logodds to the voxel at `point` (occ_map_update): OctoMap's updateNode."""
        check(lib.occ_map_update(self._ref, vec3(point), float(delta_logodds)), "occ_map_update")

    def _insert_params(self, method, max_range_m, fast_n, fast_d, super_k):
        p = lib.occ_insert_params_default()
        p.method = V.enum(V.METHODS, method, "method")
        p.max_range_m = float(max_range_m)
        opts = {k: v for k, v in (("fast_n", fast_n), ("fast_d", fast_d), ("super_k", super_k))
                if v is not None}
        return V.set_fields(p, opts, "insert")

    def _scratch_of(self, nbytes):
        nbytes = min(int(nbytes), SCRATCH_CAP)
        if self._scratch.size < nbytes:
            self._scratch = np.empty(nbytes, dtype=np.uint8)
        return (self._scratch.ctypes.data if self._scratch.size else None), self._scratch.size

    def insert_cloud(self, origin, points, *, max_range_m=-1.0, method="simple", fast_n=None,
                     fast_d=None, super_k=None):
        """Integrate one scan from sensor position `origin` (occ_map_insert_cloud): `points` an
        N x 3 float32 array (others are converted) in the map frame, metres. OctoMap's
        insertPointCloud semantics; method 'simple', 'discrete', 'fast_discrete', 'super_rays'.
        Scratch is sized with occ_insert_scratch_bytes_scan. All or nothing: on OccNoMemError
        the map is unchanged. Returns occ_insert_result_t's counters as a dict."""
        pts = V.points(points)
        o = vec3(origin, "origin")
        params = self._insert_params(method, max_range_m, fast_n, fast_d, super_k)
        need = lib.occ_insert_scratch_bytes_scan(self._ref, C.byref(o), pts.ctypes.data,
                                                 pts.shape[0], C.byref(params))
        scratch, nscratch = self._scratch_of(need)
        res = S.InsertResult()
        check(lib.occ_map_insert_cloud(self._ref, C.byref(o), pts.ctypes.data, pts.shape[0],
                                       C.byref(params), scratch, nscratch, C.byref(res)),
              "occ_map_insert_cloud")
        return res.to_dict()

    def insert_depth(self, depth, intrinsics, position, quaternion=(1.0, 0.0, 0.0, 0.0), *,
                     min_range_m=0.0, max_range_m=4.0, pixel_step=1, depth_scale_m=0.001,
                     method="simple", super_k=None):
        """Integrate one depth frame (occ_map_insert_depth). `depth`: H x W numpy, uint16
        (metres = raw * depth_scale_m, 0 = no reading) or float32 metres (NaN = no reading,
        +Inf = no return). intrinsics (fx, fy, cx, cy) in pixels; the camera pose
        map_from_camera: position (metres) and quaternion (w, x, y, z) of the optical frame
        (x right, y down, z forward). method: as insert_cloud's, or 'projective' (the
        projection integrator of occ_integrate.h, fastest for dense frames). Returns
        occ_depth_result_t's counters as a dict."""
        img = np.asarray(depth)
        fmt = {np.dtype(np.uint16): 0, np.dtype(np.float32): 1}.get(img.dtype)
        if fmt is None or img.ndim != 2:
            raise ValueError(f"depth: expected a 2-D uint16 or float32 array, got "
                             f"{img.ndim}-D {img.dtype}")
        if img.strides[1] != img.itemsize or img.strides[0] < 0:
            img = np.ascontiguousarray(img)
        fx, fy, cx, cy = (float(v) for v in intrinsics)
        image = S.DepthImage(img.ctypes.data, fmt, img.shape[1], img.shape[0], img.strides[0],
                             float(depth_scale_m))
        dp = V.set_fields(S.DepthParams(S.Pinhole(fx, fy, cx, cy), float(min_range_m),
                                        float(max_range_m)), {"pixel_step": pixel_step}, "depth")
        pose = S.Pose(vec3(position, "position"), V.quat(quaternion))
        params = self._insert_params(method, -1.0, None, None, super_k)
        need = lib.occ_depth_scratch_bytes(self._ref, image.width, image.height, dp.pixel_step,
                                           dp.max_range_m, C.byref(params))
        scratch, nscratch = self._scratch_of(need)
        res = S.DepthResult()
        check(lib.occ_map_insert_depth(self._ref, C.byref(image), C.byref(dp), C.byref(pose),
                                       C.byref(params), scratch, nscratch, C.byref(res)),
              "occ_map_insert_depth")
        return res.to_dict()

    # ---- reading ----------------------------------------------------------------------------
    def state_at(self, points):
        """States (UNKNOWN 0, FREE 1, OCCUPIED 2: occ_state_t) of the voxels holding the points,
        an array of shape points.shape[:-1] (uint8). UNKNOWN for NaN, Inf or off-map points,
        never FREE by error. One C call for all the points (occ_map_states_at: a lookup cursor
        that re-descends only below the key bits that changed, so points in spatial sequence,
        as a slice's rows, cost least). On geb079, 200k points: 20-30 ms in random order, 2-4
        ms as slice rows (a Python loop of single C calls: 0.5-1 us per point)."""
        arr = np.ascontiguousarray(points, dtype=np.float32)
        if arr.ndim == 0 or arr.shape[-1] != 3:
            raise ValueError(f"points: expected an array of shape (..., 3), got {arr.shape}")
        n = arr.size // 3
        out = np.empty(arr.shape[:-1], dtype=np.uint8)
        check(lib.occ_map_states_at(self._ref, arr.ctypes.data, n, out.ctypes.data),
              "occ_map_states_at")
        return out

    def _count(self, make, *args):
        vol = S.Volume()
        check(make(C.byref(vol), *args), make.__name__)
        cnt = S.QueryCounts()
        check(lib.occ_query_count(self._ref, C.byref(vol), C.byref(cnt)), "occ_query_count")
        return cnt.to_dict()

    def count_sphere(self, center, radius_m):
        """Voxels inside the sphere by state: dict occupied, free, unknown (ints) and outside
        (the volume leaves the map) (occ_query_count)."""
        return self._count(lib.occ_volume_sphere, vec3(center, "center"), float(radius_m))

    def count_capsule(self, a, b, radius_m):
        return self._count(lib.occ_volume_capsule, vec3(a, "a"), vec3(b, "b"), float(radius_m))

    def count_aabb(self, lo, hi):
        return self._count(lib.occ_volume_aabb, vec3(lo, "lo"), vec3(hi, "hi"))

    def count_segment(self, a, b):
        return self._count(lib.occ_volume_segment, vec3(a, "a"), vec3(b, "b"))

    def collide_sphere(self, center, radius_m, unknown="unsafe"):
        """Is the sphere free of OCCUPIED voxels (and, with unknown='unsafe', the default, of
        UNKNOWN ones and off-map space)? occ_collide_sphere. Returns Collision(safe, outside,
        node: the first blocking node as a dict when not safe and not outside)."""
        col = S.Collision()
        check(lib.occ_collide_sphere(self._ref, vec3(center, "center"), float(radius_m),
                                     V.policy(unknown), C.byref(col)), "occ_collide_sphere")
        return _collision(col)

    def collide_capsule(self, a, b, radius_m, unknown="unsafe"):
        """A sphere of radius_m swept from a to b (occ_collide_capsule); as collide_sphere."""
        col = S.Collision()
        check(lib.occ_collide_capsule(self._ref, vec3(a, "a"), vec3(b, "b"), float(radius_m),
                                      V.policy(unknown), C.byref(col)), "occ_collide_capsule")
        return _collision(col)

    def cast_ray(self, origin, direction, *, max_range_m=-1.0, ignore_unknown=False):
        """OctoMap's castRay (occ_cast_ray): RayHit(hit, stop ('hit', 'max_range', 'unknown',
        'map_edge'), key (3 ints), end (voxel centre, float32[3]))."""
        r = S.RayResult()
        check(lib.occ_cast_ray(self._ref, vec3(origin, "origin"), vec3(direction, "direction"),
                               bool(ignore_unknown), float(max_range_m), C.byref(r)),
              "occ_cast_ray")
        return RayHit(r.hit, V.RAY_STOPS[r.stop], tuple(r.key.k),
                      np.array([r.end.x, r.end.y, r.end.z], dtype=np.float32))

    def sectors(self, position, yaw_rad=0.0, *, quaternion=None, **config):
        """Nearest obstacle per horizontal sector around the vehicle (occ_sectors_compute).
        Pose: position (metres) and yaw (ENU: 0 = east, counter-clockwise) or a quaternion
        (w, x, y, z) map_from_body. `config`: fields of occ_sectors_config_t (n_sectors,
        increment_deg, angle_offset_deg, band_below_m, band_above_m, min_distance_cm,
        max_distance_cm, unknown_as_distance, map_ned, ignore_ground, ground_clearance_m).
        Returns Sectors(distance_cm uint16[n] (65535 unknown, max + 1 free), d_occ_m, d_unk_m
        float32[n], nodes_read)."""
        cfg = V.set_fields(lib.occ_sectors_config_default(), config, "sectors")
        q = V.quat(quaternion) if quaternion is not None else \
            lib.occ_quat_from_euler(0.0, 0.0, float(yaw_rad))
        pose = S.Pose(vec3(position, "position"), q)
        out = S.Sectors()
        check(lib.occ_sectors_compute(self._ref, C.byref(pose), C.byref(cfg), C.byref(out)),
              "occ_sectors_compute")
        n = out.n
        return Sectors(np.array(out.distance_cm[:n], dtype=np.uint16),
                       np.array(out.d_occ_m[:n], dtype=np.float32),
                       np.array(out.d_unk_m[:n], dtype=np.float32), out.nodes_read)

    # ---- diagnostics ------------------------------------------------------------------------
    def stats(self):
        """occ_map_stats: pool counters, leaf and voxel counts, volumes, bbox (dict)."""
        st = S.MapStats()
        lib.occ_map_stats(self._ref, C.byref(st))
        return st.to_dict()

    def check(self):
        """occ_map_check: raises OccCorruptError when an invariant is broken."""
        check(lib.occ_map_check(self._ref), "occ_map_check")

    def __repr__(self):
        used = (self._map.inner.used, self._map.leaf.used)
        return (f"occmap.Map(resolution_m={self.resolution_m:g}, depth_levels={self.depth_levels},"
                f" arena_bytes={self.arena_bytes}, inner/leaf blocks used={used})")

    @property
    def config(self):
        return self._map.cfg.to_dict()

    @property
    def resolution_m(self):
        return self._map.cfg.resolution_m

    @property
    def depth_levels(self):
        return self._map.cfg.depth_levels

    @property
    def arena_bytes(self):
        return self._map.arena_bytes

    @property
    def oom_count(self):
        return self._map.oom_count

    def plot_slice(self, z, ax=None, *, bounds=None):
        """Horizontal slice at height z (metres) with matplotlib: black occupied, white free,
        grey unknown, one pixel per voxel column; bounds (xmin, xmax, ymin, ymax) default to the
        map's observed bbox. Returns the AxesImage (on `ax`, or a new figure's axes)."""
        from .plot import plot_slice
        return plot_slice(self, z, ax, bounds)


def _collision(col):
    node = col.node.to_dict() if not col.safe and not col.outside else None
    return Collision(bool(col.safe), bool(col.outside), node)


def _info_dict(info):
    d = info.to_dict()
    d["tree_id"] = info.tree_id.decode("ascii", "replace")
    d["error"] = (info.error or b"").decode("ascii", "replace")
    d["format"] = {v: k for k, v in V.FORMATS.items()}.get(info.format, "unknown")
    return d


def _io_check(code, info):
    """A reader's error with its reason and byte offset."""
    if code != 0:
        reason = (info.error or b"").decode("ascii", "replace")
        detail = reason + (f" at byte {info.error_offset}" if code == -4 else "")
        raise error_for(code, lib.occ_err_str(code).decode("ascii", "replace"), detail)
