/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * occ_scan.h - reading recorded point clouds on a POSIX host (port/posix). Host side only:
 * these functions allocate the returned arrays with malloc; free them with free().
 */
#ifndef OCC_SCAN_H_INCLUDED
#define OCC_SCAN_H_INCLUDED

#include "occmap/occmap.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Read a plain-text point file: one "x y z" per line (metres; OctoMap's scan.dat). Blank lines
 * and lines starting with '#' are skipped; OctoMap's "NODE x y z roll pitch yaw" pose lines are
 * rejected (use the graph reader). On success *points (malloc'd) holds *n points.
 * OCC_ERR_IO (cannot open/read), OCC_ERR_FORMAT (a malformed line: `msg` names the line number),
 * OCC_ERR_NOMEM. */
occ_err_t occ_scan_read_xyz(const char *path, occ_vec3_t **points, size_t *n, char *msg,
                            size_t msg_len);

/* ---- scans with a pose (port/posix/scan_graph.c, port/posix/depth_png.c) ------------------ */
/* One scan in the map frame: points transformed by the sensor pose, origin = pose translation. */
typedef struct {
    occ_vec3_t origin;      /* sensor position, map frame, metres */
    occ_vec3_t *points;     /* malloc'd, map frame */
    size_t n_points;
    float pose_t[3];        /* the stored pose: translation (metres) ... */
    float pose_q[4];        /* ... and rotation quaternion (w, x, y, z), sensor -> map */
    char name[64];          /* e.g. "node 0" or the depth file name */
} occ_scan_frame_t;

/* Free what a reader below returned (NULL is fine). */
void occ_scan_frames_free(occ_scan_frame_t *frames, size_t n);

/* Read OctoMap's binary ScanGraph (e.g. spherical_scan.graph): u32 node count; per node a
 * Pointcloud (u32 n, n x [i32 3, 3 x f64]), a Pose6D (i32 3 + 3 x f64 translation, i32 4 +
 * 4 x f64 quaternion w x y z) and a u32 id; then u32 edge count and per edge u32 first id, u32
 * second id, a Pose6D constraint and an f64 weight (checked: ids must name nodes; not returned).
 * Host byte order (little-endian files). Each node becomes a frame in the map frame (OctoMap's
 * insertPointCloud(ScanNode) semantics: points transformed by the pose, origin its translation).
 * OCC_ERR_IO (cannot open/read), OCC_ERR_FORMAT (truncated, bad counts, bad edge ids, trailing
 * bytes: `msg` names the byte offset), OCC_ERR_NOMEM. */
occ_err_t occ_scan_read_graph(const char *path, occ_scan_frame_t **frames, size_t *n_frames,
                              char *msg, size_t msg_len);

/* Depth camera intrinsics and depth scale (TUM freiburg2: 520.9 521.0 325.1 249.7, 5000). */
typedef struct {
    float fx, fy, cx, cy;
    float depth_scale;  /* raw value / depth_scale = metres; raw 0 = no reading */
} occ_depth_camera_t;

occ_depth_camera_t occ_depth_camera_tum_fr2(void);

/* Read one 16-bit grayscale PNG depth image and back-project every `stride`-th pixel (in u and
 * v; 1 = all) with a reading: camera frame x = (u - cx) d / fx, y = (v - cy) d / fy, z = d,
 * then p = R(q) x + t into the map frame (q = w x y z). OCC_ERR_IO, OCC_ERR_FORMAT (not a
 * 16-bit gray PNG, truncated or corrupt: `msg` gives libpng's reason and the byte offset
 * reached), OCC_ERR_NOMEM. */
occ_err_t occ_depth_read_png(const char *path, const occ_depth_camera_t *cam, const float t[3],
                             const float q[4], unsigned stride, occ_scan_frame_t *frame,
                             char *msg, size_t msg_len);

/* The raw pixels of a 16-bit grayscale PNG (host byte order, row stride width * 2): *pixels
 * (malloc'd, free() it), *width, *height. Errors as occ_depth_read_png(). */
occ_err_t occ_depth_read_png_image(const char *path, uint16_t **pixels, uint32_t *width,
                                   uint32_t *height, char *msg, size_t msg_len);

/* A TUM RGB-D directory: DIR/my_association.txt (lines "rgb_file depth_file tx ty tz qx qy qz
 * qw", '#' comments) and the depth PNGs it names; lines whose depth file is absent are skipped
 * (the shared data holds 10 of its frames). At most max_frames frames (0: all), in file order.
 * OCC_ERR_IO (no association file, or no frame found), OCC_ERR_FORMAT (a malformed line: `msg`
 * names it), OCC_ERR_NOMEM, and the PNG errors above. */
occ_err_t occ_depth_read_tum_dir(const char *dir, unsigned stride, size_t max_frames,
                                 occ_scan_frame_t **frames, size_t *n_frames, char *msg,
                                 size_t msg_len);

#ifdef __cplusplus
}
#endif
#endif
