/* SPDX-License-Identifier: BSD-3-Clause */
/* run_depth.c - the depth directory `occmap run` replays: depth.txt's entries that have their
 * PNG, stamped with autopilot time, and the camera (intrinsics, range, step, mount). */
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "build_depth.h"
#include "cli.h"
#include "run.h"

static bool file_exists(const char *dir, const char *name)
{
    char path[4096];
    struct stat sb;
    (void)snprintf(path, sizeof path, "%s/%s", dir, name);
    return stat(path, &sb) == 0 && S_ISREG(sb.st_mode);
}

/* body FLU <- camera optical: the mount (x, y, z, roll, pitch, yaw in degrees: body <- mount
 * frame, FLU) composed with mount FLU <- optical (optical z = forward, x = -left, y = -up). */
static occ_pose_t mount_pose(const float m[6])
{
    const float d2r = 0.017453292519943295f;
    occ_pose_t mount;
    mount.p.x = m[0];
    mount.p.y = m[1];
    mount.p.z = m[2];
    mount.q = occ_quat_from_euler(m[3] * d2r, m[4] * d2r, m[5] * d2r);
    const occ_pose_t flu_from_optical = {{0.0f, 0.0f, 0.0f}, {0.5f, -0.5f, 0.5f, -0.5f}};
    return occ_pose_compose(&mount, &flu_from_optical);
}

static void set_camera(run_depth_t *d, const run_opts_t *o)
{
    const occ_depth_camera_t cam = build_depth_camera_for(o->depth_dir);
    d->depth_scale_m = 1.0f / cam.depth_scale;
    d->params.intrinsics.fx = o->have_intrinsics ? o->intrinsics[0] : cam.fx;
    d->params.intrinsics.fy = o->have_intrinsics ? o->intrinsics[1] : cam.fy;
    d->params.intrinsics.cx = o->have_intrinsics ? o->intrinsics[2] : cam.cx;
    d->params.intrinsics.cy = o->have_intrinsics ? o->intrinsics[3] : cam.cy;
    d->params.min_range_m = o->depth_min_m;
    d->params.max_range_m = o->depth_max_m;
    d->params.pixel_step = o->stride;
    d->body_from_camera = mount_pose(o->mount);
}

int run_depth_open(run_depth_t *d, const run_opts_t *o)
{
    memset(d, 0, sizeof *d);
    d->dir = o->depth_dir;
    char path[4096], msg[512] = "";
    (void)snprintf(path, sizeof path, "%s/depth.txt", o->depth_dir);
    occ_tum_depth_entry_t *e = NULL;
    size_t n = 0;
    const occ_err_t err = occ_tum_read_depth_list(path, &e, &n, msg, sizeof msg);
    if (err != OCC_OK || n == 0u) {
        cli_error("run", "%s: %s", path, err != OCC_OK ? msg : "no entries");
        free(e);
        return 1;
    }
    d->frames = calloc(n, sizeof *d->frames);
    if (d->frames == NULL) {
        free(e);
        return 1;
    }
    const uint64_t t_ref = e[0].t_us - 1000000u; /* T_REF = first timestamp - 1 s */
    for (size_t i = 0; i < n; i++) {
        if ((o->max_frames == 0u || d->n < o->max_frames) && file_exists(o->depth_dir, e[i].file)) {
            run_frame_t *const f = &d->frames[d->n++];
            f->index = i;
            f->remote_us = e[i].t_us - t_ref;
            memcpy(f->file, e[i].file, sizeof f->file);
        }
    }
    d->n_listed = n;
    free(e);
    if (d->n == 0u) {
        cli_error("run", "%s: none of its %zu PNGs is in the directory", path, n);
        run_depth_close(d);
        return 1;
    }
    set_camera(d, o);
    return 0;
}

void run_depth_close(run_depth_t *d)
{
    free(d->frames);
    d->frames = NULL;
    d->n = 0;
}
