/* SPDX-License-Identifier: BSD-3-Clause */
/* cmd_view.c - `occmap view MAP -o map.html [--assets DIR] [--title T]`: the map as one
 * self-contained HTML page (view_page.c) that opens offline in a browser. */
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"
#include "view.h"
#include "occmap/host/occ_file.h"

/* Where tools/view.mk put three.js and view_app.js (the build tree). An installed tool finds
 * them in PREFIX/share/occmap/view first (make install puts them there); --assets or the
 * OCCMAP_VIEW_ASSETS environment variable override both. */
#ifndef OCC_VIEW_ASSETS
#define OCC_VIEW_ASSETS "build/view"
#endif
#define VIEW_INSTALLED_ASSETS "/share/occmap/view"

/* "PREFIX/share/occmap/view" for this executable in PREFIX/bin (Linux: its path from
 * /proc/self/exe) when that folder holds three.min.js, else the build tree's folder. */
static const char *default_assets(char *buf, const size_t len)
{
    const ssize_t n = readlink("/proc/self/exe", buf, len - 1u);
    if (n > 0 && (size_t)n + sizeof VIEW_INSTALLED_ASSETS + sizeof "/three.min.js" < len) {
        buf[n] = '\0';
        char *bin = strrchr(buf, '/');
        if (bin != NULL) {
            *bin = '\0';
            char *prefix_end = strrchr(buf, '/');
            if (prefix_end != NULL) {
                strcpy(prefix_end, VIEW_INSTALLED_ASSETS "/three.min.js");
                if (access(buf, R_OK) == 0) {
                    prefix_end[sizeof VIEW_INSTALLED_ASSETS - 1u] = '\0';
                    return buf;
                }
            }
        }
    }
    return OCC_VIEW_ASSETS;
}

static void usage(void)
{
    printf("usage: occmap view MAP -o OUT.html [--assets DIR] [--title TEXT]\n"
           "  Writes one HTML page that opens offline: occupied leaves as cubes coloured by\n"
           "  height, free and unknown space behind toggles, the bounding box, orbit controls\n"
           "  (drag: rotate, right drag: pan, wheel: zoom).\n"
           "  --assets DIR  three.min.js, OrbitControls.js and view_app.js (default:\n"
           "                $OCCMAP_VIEW_ASSETS, else PREFIX/share/occmap/view for a tool\n"
           "                installed in PREFIX/bin, else %s,\n"
           "                made by `make view-assets`)\n"
           "  --title TEXT  the page's title (default: the map's file name)\n",
           OCC_VIEW_ASSETS);
}

typedef struct {
    const char *map, *out, *assets, *title;
} view_args_t;

/* 0 ok, 1 help printed, 2 usage error. `buf` holds the default assets path. */
static int parse_args(int argc, char **argv, view_args_t *a, char *buf, const size_t len)
{
    const char *env = getenv("OCCMAP_VIEW_ASSETS");
    *a = (view_args_t){NULL, NULL, env != NULL && env[0] != '\0' ? env : default_assets(buf, len),
                       NULL};
    for (int i = 1; i < argc; i++) {
        const int has_value = i + 1 < argc;
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            usage();
            return 1;
        } else if ((strcmp(argv[i], "-o") == 0 || strcmp(argv[i], "--out") == 0) && has_value) {
            a->out = argv[++i];
        } else if (strcmp(argv[i], "--assets") == 0 && has_value) {
            a->assets = argv[++i];
        } else if (strcmp(argv[i], "--title") == 0 && has_value) {
            a->title = argv[++i];
        } else if (argv[i][0] != '-' && a->map == NULL) {
            a->map = argv[i];
        } else {
            cli_error("view", "unexpected argument '%s' (or a missing value)", argv[i]);
            return 2;
        }
    }
    if (a->map == NULL || a->out == NULL) {
        usage();
        return 2;
    }
    if (a->title == NULL) {
        const char *slash = strrchr(a->map, '/');
        a->title = slash != NULL ? slash + 1 : a->map;
    }
    return 0;
}

/* Write the page to "<out>.tmp" and rename it over `out`: a failed run leaves no half page. */
static int write_out(const view_args_t *a, const occ_map_t *map, const view_sets_t *sets)
{
    char tmp[4096], msg[512] = "";
    snprintf(tmp, sizeof tmp, "%s.tmp", a->out);
    FILE *f = fopen(tmp, "wb");
    if (f == NULL) {
        cli_error("view", "cannot write %s", tmp);
        return 1;
    }
    const int rc = view_write_page(f, map, sets, a->assets, a->title, msg, sizeof msg);
    const int io_bad = ferror(f);
    const long bytes = ftell(f);
    if (fclose(f) != 0 || io_bad || rc != 0 || rename(tmp, a->out) != 0) {
        remove(tmp);
        cli_error("view", "%s", rc != 0 ? msg : "write failed");
        if (rc != 0) {
            fprintf(stderr, "  (assets folder: %s; `make view-assets` fetches three.js)\n",
                    a->assets);
        }
        return 1;
    }
    printf("view: wrote %s (%ld bytes): %zu occupied leaves, %zu free, %zu unknown; assets %s\n",
           a->out, bytes, sets->occupied.n, sets->free.n, sets->unknown.n, a->assets);
    return 0;
}

int cmd_view(int argc, char **argv)
{
    view_args_t a;
    static char assets[4096];
    const int prc = parse_args(argc, argv, &a, assets, sizeof assets);
    if (prc != 0) {
        return prc == 1 ? 0 : 2;
    }
    occ_map_t map;
    void *arena = NULL;
    char msg[512];
    if (occ_file_load_alloc(a.map, NULL, &map, 0u, &arena, NULL, msg, sizeof msg) != OCC_OK) {
        cli_error("view", "%s", msg);
        return 1;
    }
    view_sets_t sets;
    const occ_err_t e = view_collect(&map, &sets);
    int rc = 1;
    if (e != OCC_OK) {
        cli_error("view", "collecting the voxels: %s", occ_err_str(e));
    } else {
        rc = write_out(&a, &map, &sets);
        view_sets_free(&sets);
    }
    free(arena);
    return rc;
}
