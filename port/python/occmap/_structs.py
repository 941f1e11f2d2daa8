# SPDX-License-Identifier: BSD-3-Clause
"""ctypes mirrors of the public C structs (include/occmap/*.h), field for field in the header's
order, for the default build (OCC_VALUE_FLOAT=0: occ_value_t is int16_t). tests/test_layout.py
compiles a C program that prints sizeof and offsetof of every field listed here and compares, so
a header change cannot silently break the binding."""
import ctypes as C

value_t = C.c_int16  # occ_value_t with OCC_VALUE_FLOAT=0 (fixed-point log-odds, 1/1024 steps)
enum_t = C.c_int     # C enums are int on every ABI libocc.so is built for
MAX_DEPTH = 21       # OCC_MAX_DEPTH
SECTORS_MAX = 72     # OCC_SECTORS_MAX
SECTORS_STACK = 8 * (MAX_DEPTH + 2)  # OCC_SECTORS_STACK


class Struct(C.Structure):
    """Base: the C type name (for the layout test) and a dict view of the public fields."""
    c_name = ""

    def to_dict(self):
        """Public fields as Python values; vectors and keys as tuples."""
        out = {}
        for name, _ in self._fields_:
            if name == "priv":
                continue
            v = getattr(self, name)
            if isinstance(v, Vec3):
                v = (v.x, v.y, v.z)
            elif isinstance(v, Key):
                v = tuple(v.k)
            elif isinstance(v, Struct):
                v = v.to_dict()
            elif isinstance(v, C.Array):
                v = [x.to_dict() if isinstance(x, Struct) else x for x in v]
            out[name] = v
        return out


def _s(c_name, fields, base=Struct):
    return type(c_name, (base,), {"c_name": c_name, "_fields_": fields})


# ---- occ_core.h ----
Vec3 = _s("occ_vec3_t", [("x", C.c_float), ("y", C.c_float), ("z", C.c_float)])
Key = _s("occ_key_t", [("k", C.c_uint32 * 3)])
MapConfig = _s("occ_map_config_t", [
    ("resolution_m", C.c_float), ("depth_levels", C.c_uint8), ("hit", C.c_float),
    ("miss", C.c_float), ("clamp_min", C.c_float), ("clamp_max", C.c_float),
    ("free_max", C.c_float), ("occupied_min", C.c_float)])
PoolPriv = _s("occ_pool_priv", [("free_head", C.c_uint32)])
Pool = _s("occ_pool_t", [
    ("used", C.c_uint32), ("peak", C.c_uint32), ("hwm", C.c_uint32), ("free_count", C.c_uint32),
    ("priv", PoolPriv)])
MapPriv = _s("occ_map_priv", [
    ("q_hit", value_t), ("q_miss", value_t), ("q_clamp_min", value_t), ("q_clamp_max", value_t),
    ("q_free_max", value_t), ("q_occ_min", value_t), ("arena", C.c_void_p),
    ("block_budget", C.c_uint32), ("geo_res", C.c_double), ("geo_inv", C.c_double),
    ("geo_res_f", C.c_float), ("geo_inv_f", C.c_float), ("root_child", C.c_uint32),
    ("root_value", value_t), ("root_flags", C.c_uint8), ("shared", C.c_void_p)])
MapT = _s("occ_map_t", [
    ("cfg", MapConfig), ("arena_bytes", C.c_size_t), ("inner", Pool), ("leaf", Pool),
    ("oom_count", C.c_uint32), ("write_gen", C.c_uint32), ("priv", MapPriv)])
MapStats = _s("occ_map_stats_t", [
    ("inner_used", C.c_uint32), ("inner_peak", C.c_uint32), ("leaf_used", C.c_uint32),
    ("leaf_peak", C.c_uint32), ("inner_capacity", C.c_uint32), ("leaf_capacity", C.c_uint32),
    ("oom_count", C.c_uint32), ("bytes_used", C.c_size_t), ("bytes_peak", C.c_size_t),
    ("arena_bytes", C.c_size_t), ("occupied_leaves", C.c_uint64), ("free_leaves", C.c_uint64),
    ("unknown_band_leaves", C.c_uint64), ("occupied_voxels", C.c_uint64),
    ("free_voxels", C.c_uint64), ("nodes", C.c_uint64), ("inner_nodes", C.c_uint64),
    ("leaf_nodes", C.c_uint64), ("occupied_volume_m3", C.c_double),
    ("free_volume_m3", C.c_double), ("has_known", C.c_bool), ("bbox_min", Vec3),
    ("bbox_max", Vec3)])
Node = _s("occ_node_t", [
    ("key", Key), ("level", C.c_uint8), ("observed", C.c_bool), ("flags", C.c_uint8),
    ("state", enum_t), ("logodds", C.c_float), ("children", C.c_uint32), ("gen", C.c_uint32)])

# ---- occ_pose.h ----
Quat = _s("occ_quat_t", [("w", C.c_float), ("x", C.c_float), ("y", C.c_float), ("z", C.c_float)])
Pose = _s("occ_pose_t", [("p", Vec3), ("q", Quat)])

# ---- occ_integrate.h ----
InsertParams = _s("occ_insert_params_t", [
    ("method", enum_t), ("max_range_m", C.c_float), ("fast_n", C.c_uint8), ("fast_d", C.c_uint8),
    ("super_k", C.c_uint16), ("auto_evict", C.c_void_p), ("auto_evict_state", C.c_void_p),
    ("proj_noise_rel", C.c_float)])
InsertResult = _s("occ_insert_result_t", [(n, C.c_size_t) for n in (
    "points_integrated", "points_skipped", "rays_clipped", "rays_no_hit", "rays_cast",
    "voxel_visits", "voxels_updated", "voxels_free", "voxels_occupied", "voxels_changed",
    "coarse_updated", "scratch_used")])

# ---- occ_depth.h ----
DepthImage = _s("occ_depth_image_t", [
    ("data", C.c_void_p), ("format", enum_t), ("width", C.c_uint32), ("height", C.c_uint32),
    ("row_stride_bytes", C.c_size_t), ("depth_scale_m", C.c_float)])
Pinhole = _s("occ_pinhole_t", [("fx", C.c_float), ("fy", C.c_float), ("cx", C.c_float),
                               ("cy", C.c_float)])
DepthParams = _s("occ_depth_params_t", [
    ("intrinsics", Pinhole), ("min_range_m", C.c_float), ("max_range_m", C.c_float),
    ("pixel_step", C.c_uint32)])
DepthResult = _s("occ_depth_result_t", [(n, C.c_size_t) for n in (
    "pixels_sampled", "pixels_no_reading", "pixels_too_close", "pixels_beyond_max", "points",
    "scratch_points")] + [("insert", InsertResult)])

# ---- occ_query.h ----
_Sphere = _s("occ_vol_sphere", [("c", Vec3), ("r", C.c_float)])
_Obb = _s("occ_vol_obb", [("c", Vec3), ("axis", Vec3 * 3), ("half", C.c_float * 3)])
_Capsule = _s("occ_vol_capsule", [("a", Vec3), ("b", Vec3), ("r", C.c_float)])
_Frustum = _s("occ_vol_frustum", [
    ("n", Vec3 * 6), ("d", C.c_float * 6), ("corner", Vec3 * 8), ("left", Vec3), ("up", Vec3),
    ("origin", Vec3)])


class _VolumeUnion(C.Union):
    c_name = "occ_vol_union"
    _fields_ = [("sphere", _Sphere), ("obb", _Obb), ("capsule", _Capsule),
                ("frustum", _Frustum)]


Volume = _s("occ_volume_t", [("kind", enum_t), ("bmin", Vec3), ("bmax", Vec3),
                             ("u", _VolumeUnion)])
QueryCounts = _s("occ_query_counts_t", [
    ("occupied", C.c_uint64), ("free", C.c_uint64), ("unknown", C.c_uint64),
    ("outside", C.c_bool)])
QueryNode = _s("occ_query_node_t", [
    ("key", Key), ("level", C.c_uint8), ("uniform", C.c_bool), ("inside", C.c_bool),
    ("observed", C.c_bool), ("state", enum_t), ("flags", C.c_uint8), ("logodds", C.c_float),
    ("center", Vec3), ("size_m", C.c_float)])
Collision = _s("occ_collision_t", [("safe", C.c_bool), ("outside", C.c_bool),
                                   ("node", QueryNode)])
RayResult = _s("occ_ray_result_t", [("hit", C.c_bool), ("stop", enum_t), ("key", Key),
                                    ("end", Vec3)])
Lookup = _s("occ_lookup_t", [
    ("map", C.c_void_p), ("key", Key), ("lu", C.c_uint8), ("valid", C.c_bool), ("val", value_t),
    ("blk", C.c_uint32 * (MAX_DEPTH + 1)), ("gen", C.c_uint32)])
LookupIndexPriv = _s("occ_lookup_index_priv", [
    ("cells", C.c_void_p), ("bricks", C.c_void_p), ("stride_y", C.c_size_t),
    ("stride_x", C.c_size_t), ("shift", C.c_uint8), ("gen", C.c_uint32), ("root", C.c_uint32),
    ("arena", C.c_void_p)])
LookupIndex = _s("occ_lookup_index_t", [
    ("map", C.c_void_p), ("level", C.c_uint8), ("lo", C.c_uint32 * 3), ("n", C.c_uint32 * 3),
    ("bytes", C.c_size_t), ("priv", LookupIndexPriv)])

# ---- occ_io.h ----
IoInfo = _s("occ_io_info_t", [
    ("format", enum_t), ("tree_id", C.c_char * 32), ("resolution_m", C.c_float),
    ("depth_levels", C.c_uint8), ("header_nodes", C.c_uint64), ("nodes", C.c_uint64),
    ("inner_blocks", C.c_uint32), ("leaf_blocks", C.c_uint32),
    ("peak_inner_blocks", C.c_uint32), ("peak_leaf_blocks", C.c_uint32),
    ("arena_bytes_needed", C.c_size_t), ("data_offset", C.c_size_t), ("bytes_used", C.c_size_t),
    ("error_offset", C.c_size_t), ("error", C.c_char_p), ("warnings", C.c_uint32),
    ("version", C.c_uint16), ("cfg", MapConfig)])
IoBuf = _s("occ_io_buf_t", [("data", C.c_void_p), ("cap", C.c_size_t), ("len", C.c_size_t)])

# ---- occ_sectors.h ----
SectorsConfig = _s("occ_sectors_config_t", [
    ("n_sectors", C.c_uint8), ("increment_deg", C.c_float), ("angle_offset_deg", C.c_float),
    ("band_below_m", C.c_float), ("band_above_m", C.c_float), ("min_distance_cm", C.c_uint16),
    ("max_distance_cm", C.c_uint16), ("unknown_as_distance", C.c_bool), ("map_ned", C.c_bool),
    ("ignore_ground", C.c_bool), ("ground_clearance_m", C.c_float)])
SectorsItem = _s("occ_sectors_item_t", [("node", Node), ("dmin", C.c_float)])
Sectors = _s("occ_sectors_t", [
    ("n", C.c_uint8), ("distance_cm", C.c_uint16 * SECTORS_MAX), ("nodes_read", C.c_uint32),
    ("leaves_used", C.c_uint32), ("d_occ_m", C.c_float * SECTORS_MAX),
    ("d_unk_m", C.c_float * SECTORS_MAX), ("ray_c", C.c_float * (SECTORS_MAX + 1)),
    ("ray_s", C.c_float * (SECTORS_MAX + 1)), ("stack", SectorsItem * SECTORS_STACK)])

# Every struct named after a C typedef: what the layout test checks (the nested anonymous ones
# are reached through their parents' dotted field paths).
PUBLIC = [Vec3, Key, MapConfig, Pool, MapT, MapStats, Node, Quat, Pose, InsertParams,
          InsertResult, DepthImage, Pinhole, DepthParams, DepthResult, Volume, QueryCounts,
          QueryNode, Collision, RayResult, Lookup, LookupIndex, IoInfo, IoBuf, SectorsConfig,
          SectorsItem, Sectors]
