/* cmd_build.c - `occmap build`: integrate recorded scans (scan.dat text, ScanGraph binary, TUM
 * depth frames) with one of the integrators and print the map statistics; -o saves the map. */
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cli.h"
#include "evict_cli.h"
#include "occmap/host/occ_file.h"
#include "occmap/host/occ_scan.h"

static void usage(void)
{
    printf("usage: occmap build (--scan FILE | --graph FILE | --depth-dir DIR) [--res R]\n"
           "         [--method simple|discrete|fast|superrays] [--n N] [--d D] [--k K]\n"
           "         [--max-range M] [--origin x,y,z] [--stride S] [--frames F]\n"
           "         [--arena-bytes N] [-o OUT.bt|.ot|.occ] [--json]\n"
           "  --scan FILE       plain 'x y z' points (OctoMap scan.dat), sensor at --origin (0,0,0)\n"
           "  --graph FILE      OctoMap binary ScanGraph: every node's scan with its pose\n"
           "  --depth-dir DIR   TUM RGB-D directory (my_association.txt + depth/*.png)\n"
           "  --res R           voxel edge in metres (default 0.1)\n"
           "  --method M        simple (default), discrete, fast (UFOMap, --n --d), superrays\n"
           "  --max-range M     clear only up to M metres, no hit beyond (default: unlimited)\n"
           "  --stride S        depth frames: use every S-th pixel in u and v (default 1)\n"
           "Prints the map statistics plus points, points_skipped, voxels_updated, integrate_ms\n"
           "(time inside occ_map_insert_cloud only).\n");
}

typedef struct {
    occ_scan_frame_t *frames;
    size_t n;
} scans_t;

static int load(const char *scan, const char *graph, const char *dir, const float origin[3],
                unsigned stride, size_t max_frames, scans_t *out)
{
    char msg[512] = "";
    occ_err_t e;
    if (scan != NULL) {
        out->frames = calloc(1, sizeof *out->frames);
        if (out->frames == NULL) {
            cli_error("build", "out of memory");
            return 1;
        }
        out->n = 1;
        e = occ_scan_read_xyz(scan, &out->frames[0].points, &out->frames[0].n_points, msg,
                              sizeof msg);
        out->frames[0].origin = (occ_vec3_t){origin[0], origin[1], origin[2]};
    } else if (graph != NULL) {
        e = occ_scan_read_graph(graph, &out->frames, &out->n, msg, sizeof msg);
    } else {
        e = occ_depth_read_tum_dir(dir, stride, max_frames, &out->frames, &out->n, msg,
                                   sizeof msg);
    }
    if (e != OCC_OK) {
        cli_error("build", "%s (%s)", msg[0] != '\0' ? msg : "cannot read input", occ_err_str(e));
        return 1;
    }
    return 0;
}

static bool parse_method(const char *s, occ_insert_method_t *m)
{
    static const struct {
        const char *name;
        occ_insert_method_t m;
    } tab[] = {{"simple", OCC_INSERT_SIMPLE},
               {"discrete", OCC_INSERT_DISCRETE},
               {"fast", OCC_INSERT_FAST_DISCRETE},
               {"superrays", OCC_INSERT_SUPER_RAYS}};
    for (size_t i = 0; i < sizeof tab / sizeof tab[0]; i++) {
        if (strcmp(s, tab[i].name) == 0) {
            *m = tab[i].m;
            return true;
        }
    }
    return false;
}

static double now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec * 1e3 + (double)t.tv_nsec / 1e6;
}

static bool parse_uint(const char *s, unsigned long max, unsigned long *out)
{
    char *end = NULL;
    const unsigned long v = strtoul(s, &end, 10);
    if (end == s || *end != '\0' || v > max) {
        return false;
    }
    *out = v;
    return true;
}

int cmd_build(int argc, char **argv)
{
    const char *scan = NULL, *graph = NULL, *dir = NULL, *out_path = NULL;
    float res = 0.1f, max_range = -1.0f, origin[3] = {0, 0, 0};
    int json = 0;
    unsigned long stride = 1, frames = 0, n = 0, d = 2, k = 4;
    size_t arena_bytes = (size_t)1 << 30;
    occ_insert_method_t method = OCC_INSERT_SIMPLE;
    evict_cli_t ev;
    evict_cli_init(&ev);
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const bool has = i + 1 < argc;
        const int ev_rc = evict_cli_parse(&ev, argc, argv, &i);
        if (ev_rc < 0) {
            return 2;
        }
        if (ev_rc > 0) {
            continue; /* --arena-bytes, --evict, --keep-radius */
        }
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            usage();
            return 0;
        } else if (strcmp(a, "--scan") == 0 && has) {
            scan = argv[++i];
        } else if (strcmp(a, "--graph") == 0 && has) {
            graph = argv[++i];
        } else if (strcmp(a, "--depth-dir") == 0 && has) {
            dir = argv[++i];
        } else if (strcmp(a, "--res") == 0 && has) {
            if (!cli_parse_floats(argv[++i], &res, 1) || !(res > 0.0f)) {
                cli_error("build", "bad --res '%s'", argv[i]);
                return 2;
            }
        } else if (strcmp(a, "--method") == 0 && has) {
            if (!parse_method(argv[++i], &method)) {
                cli_error("build", "bad --method '%s' (simple|discrete|fast|superrays)", argv[i]);
                return 2;
            }
        } else if (strcmp(a, "--max-range") == 0 && has) {
            if (!cli_parse_floats(argv[++i], &max_range, 1)) {
                cli_error("build", "bad --max-range '%s'", argv[i]);
                return 2;
            }
        } else if (strcmp(a, "--origin") == 0 && has) {
            if (!cli_parse_floats(argv[++i], origin, 3)) {
                cli_error("build", "bad --origin '%s' (x,y,z)", argv[i]);
                return 2;
            }
        } else if ((strcmp(a, "--n") == 0 || strcmp(a, "--d") == 0 || strcmp(a, "--k") == 0 ||
                    strcmp(a, "--stride") == 0 || strcmp(a, "--frames") == 0) &&
                   has) {
            unsigned long *const dst = a[2] == 'n' ? &n
                                       : a[2] == 'd' ? &d
                                       : a[2] == 'k' ? &k
                                       : a[2] == 's' ? &stride
                                                     : &frames;
            if (!parse_uint(argv[++i], 65535ul, dst)) {
                cli_error("build", "bad %s '%s'", a, argv[i]);
                return 2;
            }
        } else if (strcmp(a, "-o") == 0 && has) {
            out_path = argv[++i];
        } else if (strcmp(a, "--json") == 0) {
            json = 1;
        } else {
            cli_error("build", "unknown option '%s' (see --help)", a);
            return 2;
        }
    }
    if (evict_cli_finish(&ev) != 0) {
        return 2;
    }
    if (ev.fixed_arena) {
        arena_bytes = ev.arena_bytes; /* allocated exactly once, never grown */
    }
    if ((scan != NULL) + (graph != NULL) + (dir != NULL) != 1) {
        cli_error("build", "give exactly one of --scan, --graph, --depth-dir");
        return 2;
    }
    if (n > 255u || d > 20u) {
        cli_error("build", "--n must be <= 255 and --d <= 20");
        return 2;
    }
    scans_t in = {NULL, 0};
    if (load(scan, graph, dir, origin, (unsigned)stride, frames, &in) != 0) {
        return 1;
    }
    occ_map_config_t cfg = occ_map_config_default();
    cfg.resolution_m = res;
    void *const arena = malloc(arena_bytes);
    occ_map_t map;
    int rc = 0;
    occ_err_t e = arena != NULL ? occ_map_init(&map, &cfg, arena, arena_bytes) : OCC_ERR_NOMEM;
    if (e != OCC_OK) {
        cli_error("build", "cannot create the map (%s)", occ_err_str(e));
        occ_scan_frames_free(in.frames, in.n);
        free(arena);
        return e == OCC_ERR_NOMEM ? 1 : 2;
    }
    occ_insert_params_t p = occ_insert_params_default();
    p.method = method;
    p.max_range_m = max_range;
    p.fast_n = (uint8_t)n;
    p.fast_d = (uint8_t)d;
    p.super_k = (uint16_t)k;
    size_t need = 0, total_pts = 0;
    for (size_t i = 0; i < in.n; i++) {
        const size_t b = occ_insert_scratch_bytes_scan(&map, &in.frames[i].origin,
                                                       in.frames[i].points, in.frames[i].n_points,
                                                       &p);
        need = b > need ? b : need;
        total_pts += in.frames[i].n_points;
    }
    void *const scratch = malloc(need > 0u ? need : 1u);
    if (scratch == NULL) {
        cli_error("build", "cannot allocate %zu bytes of scratch", need);
        rc = 1;
    }
    occ_insert_result_t sum;
    memset(&sum, 0, sizeof sum);
    size_t scratch_peak = 0; /* the most scratch one scan wrote (of `need` allocated) */
    double ms = 0.0;
    const double t_start = now_ms();
    for (size_t i = 0; rc == 0 && i < in.n; i++) {
        occ_insert_result_t r;
        const double t0 = now_ms();
        e = evict_cli_insert(&ev, &map, &in.frames[i].origin, in.frames[i].points,
                             in.frames[i].n_points, &p, scratch, need, &r);
        ms += now_ms() - t0;
        if (e != OCC_OK) {
            cli_error("build", "scan %zu (%s): %s%s", i, in.frames[i].name, occ_err_str(e),
                      e == OCC_ERR_NOMEM ? " - try a larger --arena-bytes" : "");
            rc = 1;
            break;
        }
        sum.points_integrated += r.points_integrated;
        sum.points_skipped += r.points_skipped;
        sum.rays_cast += r.rays_cast;
        sum.rays_clipped += r.rays_clipped;
        sum.voxel_visits += r.voxel_visits;
        sum.voxels_updated += r.voxels_updated;
        sum.coarse_updated += r.coarse_updated;
        scratch_peak = r.scratch_used > scratch_peak ? r.scratch_used : scratch_peak;
        if (in.n > 1u && now_ms() - t_start > 1000.0) {
            fprintf(stderr, "\roccmap build: scan %zu/%zu, %.0f ms integrating", i + 1u, in.n,
                    ms);
            if (i + 1u == in.n) {
                fputc('\n', stderr);
            }
        }
    }
    if (rc == 0) {
        occ_map_stats_t st;
        occ_map_stats(&map, &st);
        static const char *const names[] = {"simple", "discrete", "fast", "superrays"};
        if (json) {
            printf("{");
            cli_print_stats_json(stdout, &map, &st);
            printf(", \"method\": \"%s\", \"scans\": %zu, \"points\": %zu, \"points_skipped\": %zu,"
                   " \"rays\": %zu, \"voxel_visits\": %zu, \"voxels_updated\": %zu,"
                   " \"coarse_updated\": %zu, \"scratch_bytes\": %zu, \"scratch_used\": %zu,"
                   " \"integrate_ms\": %.3f, ",
                   names[method], in.n, sum.points_integrated, sum.points_skipped, sum.rays_cast,
                   sum.voxel_visits, sum.voxels_updated, sum.coarse_updated, need, scratch_peak,
                   ms);
            evict_cli_print_json(stdout, &ev);
            printf("}\n");
        } else {
            cli_print_stats_text(stdout, &map, &st);
            printf("method            %s, %zu scan(s), %zu points (%zu skipped) of %zu\n",
                   names[method], in.n, sum.points_integrated, sum.points_skipped, total_pts);
            printf("integrated        %zu rays, %zu voxel visits, %zu voxel updates, %.1f ms\n",
                   sum.rays_cast, sum.voxel_visits, sum.voxels_updated, ms);
            printf("scratch           %zu bytes written at most, of %zu allocated (the bound)\n",
                   scratch_peak, need);
        }
        if (out_path != NULL) {
            char msg[512] = "";
            e = occ_file_save(out_path, &map, msg, sizeof msg);
            if (e != OCC_OK) {
                cli_error("build", "cannot save %s: %s (%s)", out_path, msg, occ_err_str(e));
                rc = 1;
            }
        }
    }
    free(scratch);
    free(arena);
    occ_scan_frames_free(in.frames, in.n);
    return rc;
}
