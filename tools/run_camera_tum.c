/* SPDX-License-Identifier: BSD-3-Clause */
/* run_camera_tum.c - the TUM directory replay behind the camera hook (run_camera.h). */
#include <stdlib.h>

#include "run_camera.h"
#include "occmap/host/occ_scan.h"

static bool tum_next(void *ctx, const volatile int *stop, run_frame_t *f)
{
    run_camera_tum_t *const t = ctx;
    if (*stop || t->next >= t->d->n) {
        return false;
    }
    *f = t->d->frames[t->next++];
    return true;
}

static occ_err_t tum_pixels(void *ctx, const run_frame_t *f, uint16_t **px, uint32_t *w,
                            uint32_t *h)
{
    const run_camera_tum_t *const t = ctx;
    char path[4096], msg[256] = "";
    (void)snprintf(path, sizeof path, "%s/%s", t->d->dir, f->file);
    const occ_err_t e = occ_depth_read_png_image(path, px, w, h, msg, sizeof msg);
    if (e != OCC_OK) {
        fprintf(stderr, "occmap run: %s\n", msg);
    }
    return e;
}

void run_camera_tum(run_camera_t *cam, run_camera_tum_t *ctx, const run_depth_t *d)
{
    ctx->d = d;
    ctx->next = 0;
    cam->ctx = ctx;
    cam->next = tum_next;
    cam->pixels = tum_pixels;
    cam->params = d->params;
    cam->depth_scale_m = d->depth_scale_m;
    cam->body_from_camera = d->body_from_camera;
}
