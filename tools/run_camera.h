/* SPDX-License-Identifier: BSD-3-Clause */
/* run_camera.h - where a depth camera driver plugs into `occmap run`: the mapping thread pulls
 * frames through these two calls and knows nothing else about the source. The TUM directory
 * replay (run_camera_tum.c, --depth-dir) is one implementation; a live driver (V4L2, librealsense,
 * a ROS bridge) fills the same struct and is chosen in cmd_run.c.
 *
 * Contract for an implementation (both calls run on the mapping thread only):
 *  - next(ctx, stop, f): the next frame's header: f->index (a running count, for the feed log),
 *    f->remote_us (its exposure time on the AUTOPILOT's clock, microseconds: a live driver
 *    converts its capture stamp with the TIMESYNC offset, run_state_offset()); f->file is free
 *    for the driver's own use. A live driver blocks until a frame is exposed, checking *stop at
 *    least every 20 ms. false: the stream has ended (or *stop was set).
 *    With recorded timing (--replay-speed 1) the mapper waits until the autopilot clock reaches
 *    remote_us, so a live driver's frames (stamped in the past) are taken at once; frames more
 *    than --max-lag-ms behind are dropped as late.
 *  - pixels(ctx, f, px, w, h): that frame's depth, 16-bit raw units (0 = no return), row-major,
 *    w * h values in a malloc'd buffer the caller frees. OCC_OK, or an error (the frame is
 *    counted dropped: error). Called at most once per frame, only once the frame has a pose.
 *  - params (intrinsics, range, pixel step), depth_scale_m (metres per raw unit) and
 *    body_from_camera (body FLU <- camera optical frame) are fixed for the run. */
#ifndef OCC_TOOLS_RUN_CAMERA_H_INCLUDED
#define OCC_TOOLS_RUN_CAMERA_H_INCLUDED

#include "run.h"

typedef struct run_camera_s {
    void *ctx;
    bool (*next)(void *ctx, const volatile int *stop, run_frame_t *f);
    occ_err_t (*pixels)(void *ctx, const run_frame_t *f, uint16_t **px, uint32_t *w,
                        uint32_t *h);
    occ_depth_params_t params;
    float depth_scale_m;
    occ_pose_t body_from_camera;
} run_camera_t;

/* The TUM replay of an opened directory (run_depth_open): frames in file order. */
typedef struct {
    const run_depth_t *d;
    size_t next;
} run_camera_tum_t;

void run_camera_tum(run_camera_t *cam, run_camera_tum_t *ctx, const run_depth_t *d);

#endif
