/* SPDX-License-Identifier: BSD-3-Clause */
/* test_scan_readers.c - the ScanGraph and depth-PNG readers on the real files and on corrupted
 * copies (truncated at every kind of field, bad counts, bad ids, trailing bytes, not a PNG). */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "occmap/host/occ_scan.h"

#define GRAPH "/usr/share/doc/liboctomap-dev/examples/data/spherical_scan.graph"
#define TUM_DIR "../shared/data/depth/tum_fr2_pioneer_slam2"

static char tmpdir[256];

static unsigned char *slurp(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (f == NULL) {
        return NULL;
    }
    fseek(f, 0, SEEK_END);
    const long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *b = malloc((size_t)n + 1u);
    assert_non_null(b);
    assert_int_equal(fread(b, 1, (size_t)n, f), (size_t)n);
    fclose(f);
    *len = (size_t)n;
    return b;
}

static void spit(const char *path, const void *data, size_t len)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(data, 1, len, f), len);
    fclose(f);
}

static void test_graph_real(void **state)
{
    (void)state;
    occ_scan_frame_t *f = NULL;
    size_t n = 0;
    char msg[256] = "";
    const occ_err_t e = occ_scan_read_graph(GRAPH, &f, &n, msg, sizeof msg);
    if (e == OCC_ERR_IO) {
        printf("SKIP: %s\n", msg);
        skip();
    }
    assert_int_equal(e, OCC_OK);
    assert_int_equal(n, 1);
    assert_int_equal(f[0].n_points, 10201);
    /* Pose (1, 0, -0.5), identity rotation (read from the file by hand): origin and the first
     * point (3.2941854, -1.5250701, 1.7037624) shifted by the translation. */
    assert_true(fabsf(f[0].origin.x - 1.0f) < 1e-6f && fabsf(f[0].origin.z + 0.5f) < 1e-6f);
    assert_true(fabsf(f[0].points[0].x - 4.2941854f) < 1e-5f);
    assert_true(fabsf(f[0].points[0].y + 1.5250701f) < 1e-5f);
    assert_true(fabsf(f[0].points[0].z - 1.2037624f) < 1e-5f);
    occ_scan_frames_free(f, n);
}

static occ_err_t read_graph_bytes(const unsigned char *b, size_t len, char *msg, size_t ml)
{
    char path[300];
    snprintf(path, sizeof path, "%s/g.graph", tmpdir);
    spit(path, b, len);
    occ_scan_frame_t *f = NULL;
    size_t n = 0;
    const occ_err_t e = occ_scan_read_graph(path, &f, &n, msg, ml);
    occ_scan_frames_free(f, n);
    return e;
}

static void test_graph_corrupt(void **state)
{
    (void)state;
    size_t len = 0;
    unsigned char *b = slurp(GRAPH, &len);
    if (b == NULL) {
        printf("SKIP: %s missing\n", GRAPH);
        skip();
    }
    char msg[256];
    /* Truncated anywhere: inside the counts, a point, the pose, the id, the edge count. */
    const size_t cuts[] = {0, 2, 4, 6, 8, 9, 40, 1000, len - 72, len - 40, len - 8, len - 5,
                           len - 1};
    for (size_t i = 0; i < sizeof cuts / sizeof cuts[0]; i++) {
        msg[0] = '\0';
        assert_int_equal(read_graph_bytes(b, cuts[i], msg, sizeof msg), OCC_ERR_FORMAT);
        assert_non_null(strstr(msg, "byte "));
    }
    /* Absurd node / point counts. */
    unsigned char *c = malloc(len + 200u);
    memcpy(c, b, len);
    const uint32_t big = 0x7FFFFFFFu;
    memcpy(c, &big, 4);
    assert_int_equal(read_graph_bytes(c, len, msg, sizeof msg), OCC_ERR_FORMAT);
    assert_non_null(strstr(msg, "byte 0"));
    memcpy(c, b, len);
    memcpy(c + 4, &big, 4);
    assert_int_equal(read_graph_bytes(c, len, msg, sizeof msg), OCC_ERR_FORMAT);
    /* A vector with a dimension other than 3. */
    memcpy(c, b, len);
    c[8] = 4;
    assert_int_equal(read_graph_bytes(c, len, msg, sizeof msg), OCC_ERR_FORMAT);
    assert_non_null(strstr(msg, "byte 8"));
    /* NaN coordinate. */
    memcpy(c, b, len);
    const double nan_v = NAN;
    memcpy(c + 12, &nan_v, 8);
    assert_int_equal(read_graph_bytes(c, len, msg, sizeof msg), OCC_ERR_FORMAT);
    /* Trailing garbage. */
    memcpy(c, b, len);
    c[len] = 1;
    assert_int_equal(read_graph_bytes(c, len + 1u, msg, sizeof msg), OCC_ERR_FORMAT);
    assert_non_null(strstr(msg, "trailing"));
    /* One edge naming node 7, which does not exist; then a valid edge 0 -> 0. */
    memcpy(c, b, len);
    const uint32_t one = 1, id0 = 0, id7 = 7;
    memcpy(c + len - 4, &one, 4);
    size_t off = len;
    memcpy(c + off, &id0, 4);
    memcpy(c + off + 4, &id7, 4);
    memcpy(c + off + 8, b + len - 72, 64); /* a valid Pose6D: the node's own */
    const double w = 1.0;
    memcpy(c + off + 72, &w, 8);
    assert_int_equal(read_graph_bytes(c, len + 80u, msg, sizeof msg), OCC_ERR_FORMAT);
    assert_non_null(strstr(msg, "node"));
    memcpy(c + off + 4, &id0, 4);
    assert_int_equal(read_graph_bytes(c, len + 80u, msg, sizeof msg), OCC_OK);
    /* Missing file. */
    occ_scan_frame_t *f = NULL;
    size_t n = 0;
    assert_int_equal(occ_scan_read_graph("/nonexistent/x.graph", &f, &n, msg, sizeof msg),
                     OCC_ERR_IO);
    free(c);
    free(b);
}

static void test_depth_real(void **state)
{
    (void)state;
    occ_scan_frame_t *f = NULL;
    size_t n = 0;
    char msg[256] = "";
    const occ_err_t e = occ_depth_read_tum_dir(TUM_DIR, 1, 2, &f, &n, msg, sizeof msg);
    if (e == OCC_ERR_IO) {
        printf("SKIP: %s\n", msg);
        skip();
    }
    assert_int_equal(e, OCC_OK);
    assert_int_equal(n, 2);
    for (size_t i = 0; i < n; i++) {
        assert_true(f[i].n_points > 100000u && f[i].n_points <= 640u * 480u);
        /* Every point at most 65535/5000 m from the camera, and in front of it. */
        float maxd = 0.0f;
        for (size_t j = 0; j < f[i].n_points; j++) {
            const float dx = f[i].points[j].x - f[i].origin.x;
            const float dy = f[i].points[j].y - f[i].origin.y;
            const float dz = f[i].points[j].z - f[i].origin.z;
            const float d = sqrtf(dx * dx + dy * dy + dz * dz);
            maxd = d > maxd ? d : maxd;
        }
        assert_true(maxd < 13.2f * 1.5f);
        printf("  %s: %zu points, origin (%.3f %.3f %.3f), farthest %.2f m\n", f[i].name,
               f[i].n_points, (double)f[i].origin.x, (double)f[i].origin.y,
               (double)f[i].origin.z, (double)maxd);
    }
    /* Back-projection by hand for one pixel with the identity pose. */
    char png[600];
    snprintf(png, sizeof png, "%s/depth/%s", TUM_DIR, f[0].name);
    const float t0[3] = {0, 0, 0}, q0[4] = {1, 0, 0, 0};
    const occ_depth_camera_t cam = occ_depth_camera_tum_fr2();
    occ_scan_frame_t one;
    assert_int_equal(occ_depth_read_png(png, &cam, t0, q0, 1, &one, msg, sizeof msg), OCC_OK);
    assert_int_equal(one.n_points, f[0].n_points);
    /* Every point satisfies x = (u - cx) z / fx for an integer u in 0..639. */
    for (size_t j = 0; j < one.n_points; j += 997u) {
        const occ_vec3_t p = one.points[j];
        const float u = p.x * cam.fx / p.z + cam.cx, v = p.y * cam.fy / p.z + cam.cy;
        assert_true(fabsf(u - roundf(u)) < 1e-2f && u > -0.5f && u < 639.5f);
        assert_true(fabsf(v - roundf(v)) < 1e-2f && v > -0.5f && v < 479.5f);
        assert_true(p.z > 0.0f);
    }
    free(one.points);
    /* Stride 4: a sixteenth of the pixels. */
    occ_scan_frame_t sub;
    assert_int_equal(occ_depth_read_png(png, &cam, t0, q0, 4, &sub, msg, sizeof msg), OCC_OK);
    assert_true(sub.n_points * 12u < f[0].n_points && sub.n_points * 20u > f[0].n_points);
    free(sub.points);
    occ_scan_frames_free(f, n);
}

static void test_depth_corrupt(void **state)
{
    (void)state;
    char png[600];
    occ_scan_frame_t *fr = NULL;
    size_t nf = 0;
    char msg[256] = "";
    if (occ_depth_read_tum_dir(TUM_DIR, 8, 1, &fr, &nf, msg, sizeof msg) != OCC_OK) {
        printf("SKIP: %s\n", msg);
        skip();
    }
    snprintf(png, sizeof png, "%s/depth/%s", TUM_DIR, fr[0].name);
    occ_scan_frames_free(fr, nf);
    size_t len = 0;
    unsigned char *b = slurp(png, &len);
    assert_non_null(b);
    const float t0[3] = {0, 0, 0}, q0[4] = {1, 0, 0, 0};
    const occ_depth_camera_t cam = occ_depth_camera_tum_fr2();
    char path[300];
    snprintf(path, sizeof path, "%s/d.png", tmpdir);
    const size_t cuts[] = {0, 5, 20, 60, len / 2u, len - 20u};
    for (size_t i = 0; i < sizeof cuts / sizeof cuts[0]; i++) {
        spit(path, b, cuts[i]);
        occ_scan_frame_t f;
        msg[0] = '\0';
        assert_int_equal(occ_depth_read_png(path, &cam, t0, q0, 1, &f, msg, sizeof msg),
                         OCC_ERR_FORMAT);
        assert_non_null(strstr(msg, "byte"));
        printf("  cut at %zu: %s\n", cuts[i], msg);
    }
    /* A flipped bit in the image data: libpng's CRC check fires. */
    b[len / 3u] ^= 0x10u;
    spit(path, b, len);
    occ_scan_frame_t f;
    assert_int_equal(occ_depth_read_png(path, &cam, t0, q0, 1, &f, msg, sizeof msg),
                     OCC_ERR_FORMAT);
    /* A text file. */
    spit(path, "hello world, not a png", 22);
    assert_int_equal(occ_depth_read_png(path, &cam, t0, q0, 1, &f, msg, sizeof msg),
                     OCC_ERR_FORMAT);
    assert_int_equal(occ_depth_read_png("/nonexistent.png", &cam, t0, q0, 1, &f, msg, sizeof msg),
                     OCC_ERR_IO);
    free(b);
    /* A malformed association line names its line number. */
    char dir[300], assoc[400];
    snprintf(dir, sizeof dir, "%s/tum", tmpdir);
    assert_int_equal(mkdir(dir, 0700), 0);
    snprintf(assoc, sizeof assoc, "%s/my_association.txt", dir);
    spit(assoc, "# comment\nrgb/a.png depth/a.png 1 2 3 0 0 0 1\nrgb/b.png depth/b.png 1 2\n", 73);
    occ_scan_frame_t *fs = NULL;
    size_t n = 0;
    assert_int_equal(occ_depth_read_tum_dir(dir, 1, 0, &fs, &n, msg, sizeof msg), OCC_ERR_FORMAT);
    assert_non_null(strstr(msg, "line 3"));
    /* No frame present at all. */
    spit(assoc, "rgb/a.png depth/a.png 1 2 3 0 0 0 1\n", 36);
    assert_int_equal(occ_depth_read_tum_dir(dir, 1, 0, &fs, &n, msg, sizeof msg), OCC_ERR_IO);
}

int main(void)
{
    snprintf(tmpdir, sizeof tmpdir, "/tmp/occ_scanrd_XXXXXX");
    if (mkdtemp(tmpdir) == NULL) {
        return 1;
    }
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_graph_real),
        cmocka_unit_test(test_graph_corrupt),
        cmocka_unit_test(test_depth_real),
        cmocka_unit_test(test_depth_corrupt),
    };
    const int rc = cmocka_run_group_tests(tests, NULL, NULL);
    char cmd[400];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    if (system(cmd) != 0) {
        return 1;
    }
    return rc;
}
