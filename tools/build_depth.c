/* SPDX-License-Identifier: BSD-3-Clause */
/* build_depth.c - `occmap build --depth-dir DIR`: picks the TUM layout and the camera, reads the
 * frames (port/posix), reports the frames dropped for want of a pose. */
#include <string.h>

#include "build_depth.h"
#include "cli.h"
#include "occmap/host/occ_tum.h"

static bool file_exists(const char *dir, const char *name)
{
    char path[4096];
    (void)snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *const f = fopen(path, "r");
    if (f != NULL) {
        (void)fclose(f);
    }
    return f != NULL;
}

/* TUM names its sequences rgbd_dataset_freiburgN_...: the camera follows from the name. */
occ_depth_camera_t build_depth_camera_for(const char *dir)
{
    return strstr(dir, "freiburg1") != NULL || strstr(dir, "fr1") != NULL
               ? occ_depth_camera_tum_fr1()
               : occ_depth_camera_tum_fr2();
}

int build_depth_load(const char *dir, unsigned stride, size_t max_frames,
                     occ_scan_frame_t **frames, size_t *n_frames, build_depth_info_t *info)
{
    char msg[512] = "";
    occ_err_t e;
    memset(info, 0, sizeof *info);
    if (file_exists(dir, "my_association.txt") || !file_exists(dir, "depth.txt")) {
        info->layout = "association";
        info->cam = occ_depth_camera_tum_fr2();
        e = occ_depth_read_tum_dir(dir, stride, max_frames, frames, n_frames, msg, sizeof msg);
    } else {
        info->layout = "groundtruth";
        info->cam = build_depth_camera_for(dir);
        e = occ_depth_read_tum_sequence(dir, &info->cam, stride, max_frames, frames, n_frames,
                                        &info->frames_dropped, msg, sizeof msg);
    }
    if (e != OCC_OK) {
        cli_error("build", "%s (%s)", msg[0] != '\0' ? msg : "cannot read input", occ_err_str(e));
        return 1;
    }
    return 0;
}

void build_depth_print_json(FILE *f, const build_depth_info_t *info)
{
    fprintf(f, ", \"depth_layout\": \"%s\", \"intrinsics\": [%g, %g, %g, %g],"
               " \"frames_dropped\": %zu",
            info->layout, (double)info->cam.fx, (double)info->cam.fy, (double)info->cam.cx,
            (double)info->cam.cy, info->frames_dropped);
}

void build_depth_print_text(FILE *f, const build_depth_info_t *info)
{
    fprintf(f, "depth frames      %s layout, fx fy cx cy %g %g %g %g, %zu dropped (no pose)\n",
            info->layout, (double)info->cam.fx, (double)info->cam.fy, (double)info->cam.cx,
            (double)info->cam.cy, info->frames_dropped);
}
