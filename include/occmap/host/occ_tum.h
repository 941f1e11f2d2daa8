/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * occ_tum.h - TUM RGB-D sequence directories on a POSIX host (port/posix/tum_sequence.c):
 * DIR/depth.txt ("timestamp depth/file.png") and DIR/groundtruth.txt ("timestamp tx ty tz qx qy
 * qz qw", the camera's optical frame in the world, 100 Hz motion capture). Each depth frame gets
 * its pose by occ_pose_history_at() at the frame's time (linear position, slerp rotation); a
 * frame the history refuses (a capture gap, outside the ground truth) is dropped and counted.
 * Host side only: arrays are malloc'd, free them with free() / occ_scan_frames_free().
 */
#ifndef OCC_TUM_H_INCLUDED
#define OCC_TUM_H_INCLUDED

#include "occmap/host/occ_scan.h"
#include "occmap/occ_pose.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Interpolation limits for TUM ground truth: samples more than 100 ms apart (10 periods of the
 * 100 Hz capture) do not interpolate; no extrapolation past the last sample. */
#define OCC_TUM_MAX_GAP_US 100000u

/* The freiburg1 Kinect's calibrated intrinsics (TUM: 517.3 516.5 318.6 255.3, value / 5000 m). */
occ_depth_camera_t occ_depth_camera_tum_fr1(void);

/* One line of depth.txt. */
typedef struct {
    uint64_t t_us;   /* timestamp, microseconds (seconds x 1e6, rounded) */
    char file[96];   /* relative to the directory, e.g. "depth/1305031229.528784.png" */
} occ_tum_depth_entry_t;

/* Parse a depth.txt: '#' lines skipped; entries in file order (strictly increasing times, else
 * OCC_ERR_FORMAT). OCC_ERR_IO (cannot open), OCC_ERR_FORMAT (`msg` names the line),
 * OCC_ERR_NOMEM. */
occ_err_t occ_tum_read_depth_list(const char *path, occ_tum_depth_entry_t **entries, size_t *n,
                                  char *msg, size_t msg_len);

/* Parse a groundtruth.txt into pose samples (t_us, map_from_camera; the file's x y z w
 * quaternion as w x y z). Errors as above; a pose occ_pose_check() refuses is OCC_ERR_FORMAT. */
occ_err_t occ_tum_read_groundtruth(const char *path, occ_pose_sample_t **samples, size_t *n,
                                   char *msg, size_t msg_len);

/* Fill `h` (initialised with cap >= n) with the samples: OCC_OK, or the first push's error. */
occ_err_t occ_tum_history_fill(occ_pose_history_t *h, const occ_pose_sample_t *samples, size_t n);

/* A whole sequence directory as frames in the map frame (occ_depth_read_png with the
 * interpolated pose and `cam`, every `stride`-th pixel): entries whose PNG is not in the
 * directory are skipped (not counted), entries the history refuses are dropped and counted in
 * *n_dropped. At most max_frames frames (0: all). OCC_ERR_IO (no depth.txt / groundtruth.txt,
 * or no frame left), OCC_ERR_FORMAT, OCC_ERR_NOMEM and the PNG errors. */
occ_err_t occ_depth_read_tum_sequence(const char *dir, const occ_depth_camera_t *cam,
                                      unsigned stride, size_t max_frames,
                                      occ_scan_frame_t **frames, size_t *n_frames,
                                      size_t *n_dropped, char *msg, size_t msg_len);

#ifdef __cplusplus
}
#endif
#endif
