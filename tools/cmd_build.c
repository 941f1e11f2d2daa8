/* SPDX-License-Identifier: BSD-3-Clause */
/* cmd_build.c - `occmap build`: integrate recorded scans (scan.dat text, ScanGraph binary, TUM
 * depth frames) with one of the integrators and print the map statistics; -o saves the map. */
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "build_depth.h"
#include "build_tlog.h"
#include "cli.h"
#include "evict_cli.h"
#include "occmap/host/occ_file.h"
#include "occmap/host/occ_scan.h"

static void usage(void)
{
    printf("usage: occmap build (--scan FILE | --graph FILE | --depth-dir DIR | --tlog FILE)\n"
           "         [--res R]"
           "         [--method simple|discrete|fast|superrays] [--n N] [--d D] [--k K]\n"
           "         [--max-range M] [--origin x,y,z] [--stride S] [--frames F]\n"
           "         [--arena-bytes N] [-o OUT.bt|.ot|.occ] [--json]\n"
           "  --scan FILE       plain 'x y z' points (OctoMap scan.dat), sensor at --origin (0,0,0)\n"
           "  --graph FILE      OctoMap binary ScanGraph: every node's scan with its pose\n"
           "  --depth-dir DIR   TUM RGB-D directory: my_association.txt + depth/*.png, or a\n"
           "                    sequence: depth.txt + groundtruth.txt (poses interpolated;\n"
           "                    frames without a pose are dropped and counted)\n"
           "  --tlog FILE       MAVLink telemetry log: DISTANCE_SENSOR / OBSTACLE_DISTANCE\n"
           "                    readings with the log's poses (README: --tlog)\n"
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
    build_depth_info_t depth; /* --depth-dir: layout, camera, frames dropped */
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
        return build_depth_load(dir, stride, max_frames, &out->frames, &out->n, &out->depth);
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

/* What the command line asks for. */
typedef struct {
    const char *scan, *graph, *dir, *out_path; /* one input; -o */
    const char *tlog;                          /* --tlog: build_tlog.c */
    float res, max_range, origin[3];
    bool json;
    uint32_t stride, frames, n, d, k;
    occ_insert_method_t method;
    evict_cli_t ev; /* --arena-bytes, --evict, --keep-radius */
} build_opts_t;

static void build_opts_init(build_opts_t *o)
{
    memset(o, 0, sizeof *o);
    o->res = 0.1f;
    o->max_range = -1.0f;
    o->stride = 1;
    o->d = 2;
    o->k = 4;
    o->method = OCC_INSERT_SIMPLE;
    evict_cli_init(&o->ev);
}

/* --n --d --k --stride --frames: the integer option `a` names, or NULL. */
static uint32_t *count_option(build_opts_t *o, const char *a)
{
    static const char *const names[] = {"--n", "--d", "--k", "--stride", "--frames"};
    uint32_t *const dst[] = {&o->n, &o->d, &o->k, &o->stride, &o->frames};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        if (strcmp(a, names[i]) == 0) {
            return dst[i];
        }
    }
    return NULL;
}

/* An option with the value v: 0, or 2 after a message (-1: not one of these). */
static int value_option(build_opts_t *o, const char *a, const char *v)
{
    uint32_t *const count = count_option(o, a);
    if (strcmp(a, "--scan") == 0) {
        o->scan = v;
    } else if (strcmp(a, "--graph") == 0) {
        o->graph = v;
    } else if (strcmp(a, "--depth-dir") == 0) {
        o->dir = v;
    } else if (strcmp(a, "--tlog") == 0) {
        o->tlog = v;
    } else if (strcmp(a, "-o") == 0) {
        o->out_path = v;
    } else if (strcmp(a, "--res") == 0) {
        if (!cli_parse_floats(v, &o->res, 1) || !(o->res > 0.0f)) {
            cli_error("build", "bad --res '%s'", v);
            return 2;
        }
    } else if (strcmp(a, "--method") == 0) {
        if (!parse_method(v, &o->method)) {
            cli_error("build", "bad --method '%s' (simple|discrete|fast|superrays)", v);
            return 2;
        }
    } else if (strcmp(a, "--max-range") == 0) {
        if (!cli_parse_floats(v, &o->max_range, 1)) {
            cli_error("build", "bad --max-range '%s'", v);
            return 2;
        }
    } else if (strcmp(a, "--origin") == 0) {
        if (!cli_parse_floats(v, o->origin, 3)) {
            cli_error("build", "bad --origin '%s' (x,y,z)", v);
            return 2;
        }
    } else if (count != NULL) {
        if (!cli_parse_u32(v, 0, 65535u, count)) {
            cli_error("build", "bad %s '%s'", a, v);
            return 2;
        }
    } else {
        return -1;
    }
    return 0;
}

/* The flags that do not fit together. 0, or 2 after a message. */
static int check_opts(const build_opts_t *o)
{
    if (evict_cli_finish(&o->ev) != 0) {
        return 2;
    }
    if ((o->scan != NULL) + (o->graph != NULL) + (o->dir != NULL) + (o->tlog != NULL) != 1) {
        cli_error("build", "give exactly one of --scan, --graph, --depth-dir, --tlog");
        return 2;
    }
    if (o->n > 255u || o->d > 20u) {
        cli_error("build", "--n must be <= 255 and --d <= 20");
        return 2;
    }
    return 0;
}

/* argv into `o`: -1 to go on, or the exit status (0 after --help, 2 after a message). */
static int parse_args(build_opts_t *o, int argc, char **argv)
{
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const int ev_rc = evict_cli_parse(&o->ev, argc, argv, &i);
        if (ev_rc != 0) {
            if (ev_rc < 0) {
                return 2;
            }
            continue; /* --arena-bytes, --evict, --keep-radius */
        }
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            usage();
            return 0;
        }
        if (strcmp(a, "--json") == 0) {
            o->json = true;
            continue;
        }
        const int rc = i + 1 < argc ? value_option(o, a, argv[i + 1]) : -1;
        if (rc < 0) {
            cli_error("build", "unknown option '%s' (see --help)", a);
            return 2;
        }
        if (rc > 0) {
            return rc;
        }
        i++;
    }
    const int rc = check_opts(o);
    return rc != 0 ? rc : -1;
}

/* The map in one malloc'ed arena (--arena-bytes exactly, else 1 GiB). 0, or the exit status
 * after a message (*arena freed). */
static int make_map(const build_opts_t *o, occ_map_t *map, void **arena)
{
    const size_t arena_bytes = o->ev.fixed_arena ? o->ev.arena_bytes : (size_t)1 << 30;
    occ_map_config_t cfg = occ_map_config_default();
    cfg.resolution_m = o->res;
    *arena = malloc(arena_bytes); /* allocated exactly once, never grown */
    const occ_err_t e = *arena != NULL ? occ_map_init(map, &cfg, *arena, arena_bytes)
                                       : OCC_ERR_NOMEM;
    if (e != OCC_OK) {
        cli_error("build", "cannot create the map (%s)", occ_err_str(e));
        free(*arena);
        *arena = NULL;
        return e == OCC_ERR_NOMEM ? 1 : 2;
    }
    return 0;
}

/* What the integration did, summed over the scans. */
typedef struct {
    occ_insert_result_t sum;
    size_t total_pts;    /* points in the input */
    size_t need;         /* the scratch bound allocated: the most any scan can need */
    size_t scratch_peak; /* the most scratch one scan wrote */
    double ms;           /* time inside the inserts */
} build_result_t;

static void add_result(build_result_t *b, const occ_insert_result_t *r)
{
    b->sum.points_integrated += r->points_integrated;
    b->sum.points_skipped += r->points_skipped;
    b->sum.rays_cast += r->rays_cast;
    b->sum.rays_clipped += r->rays_clipped;
    b->sum.voxel_visits += r->voxel_visits;
    b->sum.voxels_updated += r->voxels_updated;
    b->sum.coarse_updated += r->coarse_updated;
    b->scratch_peak = r->scratch_used > b->scratch_peak ? r->scratch_used : b->scratch_peak;
}

/* Every scan into the map with the scratch bound allocated once. 0, or 1 after a message. */
static int integrate(build_opts_t *o, occ_map_t *map, const scans_t *in,
                     const occ_insert_params_t *p, build_result_t *b)
{
    for (size_t i = 0; i < in->n; i++) {
        const occ_scan_frame_t *f = &in->frames[i];
        const size_t need = occ_insert_scratch_bytes_scan(map, &f->origin, f->points,
                                                          f->n_points, p);
        b->need = need > b->need ? need : b->need;
        b->total_pts += f->n_points;
    }
    void *const scratch = malloc(b->need > 0u ? b->need : 1u);
    if (scratch == NULL) {
        cli_error("build", "cannot allocate %zu bytes of scratch", b->need);
        return 1;
    }
    int rc = 0;
    const double t_start = now_ms();
    for (size_t i = 0; i < in->n; i++) {
        const occ_scan_frame_t *f = &in->frames[i];
        occ_insert_result_t r;
        const double t0 = now_ms();
        const occ_err_t e = evict_cli_insert(&o->ev, map, &f->origin, f->points, f->n_points,
                                             p, scratch, b->need, &r);
        b->ms += now_ms() - t0;
        if (e != OCC_OK) {
            cli_error("build", "scan %zu (%s): %s%s", i, f->name, occ_err_str(e),
                      e == OCC_ERR_NOMEM ? " - try a larger --arena-bytes" : "");
            rc = 1;
            break;
        }
        add_result(b, &r);
        if (in->n > 1u && now_ms() - t_start > 1000.0) {
            fprintf(stderr, "\roccmap build: scan %zu/%zu, %.0f ms integrating", i + 1u, in->n,
                    b->ms);
            if (i + 1u == in->n) {
                fputc('\n', stderr);
            }
        }
    }
    free(scratch);
    return rc;
}

static void print_result(const build_opts_t *o, const occ_map_t *map, const scans_t *in,
                         const build_result_t *b)
{
    static const char *const names[] = {"simple", "discrete", "fast", "superrays"};
    const occ_insert_result_t *sum = &b->sum;
    occ_map_stats_t st;
    occ_map_stats(map, &st);
    if (o->json) {
        printf("{");
        cli_print_stats_json(stdout, map, &st);
        printf(", \"method\": \"%s\", \"scans\": %zu, \"points\": %zu, \"points_skipped\": %zu,"
               " \"rays\": %zu, \"voxel_visits\": %zu, \"voxels_updated\": %zu,"
               " \"coarse_updated\": %zu, \"scratch_bytes\": %zu, \"scratch_used\": %zu,"
               " \"integrate_ms\": %.3f, ",
               names[o->method], in->n, sum->points_integrated, sum->points_skipped,
               sum->rays_cast, sum->voxel_visits, sum->voxels_updated, sum->coarse_updated,
               b->need, b->scratch_peak, b->ms);
        evict_cli_print_json(stdout, &o->ev);
        if (o->dir != NULL) {
            build_depth_print_json(stdout, &in->depth);
        }
        printf("}\n");
    } else {
        cli_print_stats_text(stdout, map, &st);
        printf("method            %s, %zu scan(s), %zu points (%zu skipped) of %zu\n",
               names[o->method], in->n, sum->points_integrated, sum->points_skipped,
               b->total_pts);
        printf("integrated        %zu rays, %zu voxel visits, %zu voxel updates, %.1f ms\n",
               sum->rays_cast, sum->voxel_visits, sum->voxels_updated, b->ms);
        printf("scratch           %zu bytes written at most, of %zu allocated (the bound)\n",
               b->scratch_peak, b->need);
        if (o->dir != NULL) {
            build_depth_print_text(stdout, &in->depth);
        }
    }
}

/* The map into the scans, printed and (-o) saved. 0, or 1 after a message. */
static int build_map(build_opts_t *o, occ_map_t *map, const scans_t *in)
{
    occ_insert_params_t p = occ_insert_params_default();
    p.method = o->method;
    p.max_range_m = o->max_range;
    p.fast_n = (uint8_t)o->n;
    p.fast_d = (uint8_t)o->d;
    p.super_k = (uint16_t)o->k;
    build_result_t b;
    memset(&b, 0, sizeof b);
    if (integrate(o, map, in, &p, &b) != 0) {
        return 1;
    }
    print_result(o, map, in, &b);
    if (o->out_path != NULL) {
        char msg[512] = "";
        const occ_err_t e = occ_file_save(o->out_path, map, msg, sizeof msg);
        if (e != OCC_OK) {
            cli_error("build", "cannot save %s: %s (%s)", o->out_path, msg, occ_err_str(e));
            return 1;
        }
    }
    return 0;
}

int cmd_build(int argc, char **argv)
{
    build_opts_t o;
    build_opts_init(&o);
    const int parsed = parse_args(&o, argc, argv);
    if (parsed >= 0) {
        return parsed;
    }
    if (o.tlog != NULL) {
        occ_map_t map;
        void *arena = NULL;
        int rc = make_map(&o, &map, &arena);
        rc = rc == 0 ? build_tlog(&map, o.tlog, o.json, o.out_path) : rc;
        free(arena);
        return rc;
    }
    scans_t in;
    memset(&in, 0, sizeof in);
    if (load(o.scan, o.graph, o.dir, o.origin, (unsigned)o.stride, o.frames, &in) != 0) {
        return 1;
    }
    occ_map_t map;
    void *arena = NULL;
    int rc = make_map(&o, &map, &arena);
    if (rc == 0) {
        rc = build_map(&o, &map, &in);
    }
    free(arena);
    occ_scan_frames_free(in.frames, in.n);
    return rc;
}
