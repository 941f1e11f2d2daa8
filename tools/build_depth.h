/* SPDX-License-Identifier: BSD-3-Clause */
/* build_depth.h - `occmap build --depth-dir DIR`: the two TUM RGB-D directory layouts. */
#ifndef OCC_TOOLS_BUILD_DEPTH_H_INCLUDED
#define OCC_TOOLS_BUILD_DEPTH_H_INCLUDED

#include <stdio.h>

#include "occmap/host/occ_scan.h"

/* What was read: the layout, the camera used and the frames dropped for want of a pose. */
typedef struct {
    const char *layout;      /* "association" (my_association.txt) or "groundtruth" */
    occ_depth_camera_t cam;  /* intrinsics used */
    size_t frames_dropped;   /* groundtruth layout: frames the pose history refused */
} build_depth_info_t;

/* DIR with my_association.txt (poses per frame, freiburg2 intrinsics, as before), else DIR with
 * depth.txt + groundtruth.txt (poses interpolated by occ_pose_history; freiburg1 intrinsics when
 * the path names freiburg1 / fr1, else freiburg2). 0, or 1 after a message. */
int build_depth_load(const char *dir, unsigned stride, size_t max_frames,
                     occ_scan_frame_t **frames, size_t *n_frames, build_depth_info_t *info);

/* The TUM camera a sequence directory was taken with: freiburg1's when the path names
 * freiburg1 / fr1, else freiburg2's (also `occmap run --depth-dir`). */
occ_depth_camera_t build_depth_camera_for(const char *dir);

/* The info as JSON members (", \"depth_layout\": ..., \"frames_dropped\": N") or text lines. */
void build_depth_print_json(FILE *f, const build_depth_info_t *info);
void build_depth_print_text(FILE *f, const build_depth_info_t *info);

#endif
