/* SPDX-License-Identifier: BSD-3-Clause */
/* cmd_query.c - occmap query: collision checks, ray casts and obstacle distances on a map file,
 * one query or a batch. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "occmap/host/occ_file.h"

#define DEFAULT_HEAP 65536u /* --distance: nearest-search heap entries */

static void usage(FILE *f)
{
    fprintf(f,
            "usage: occmap query MAP (--sphere x,y,z,r | --aabb x0,y0,z0,x1,y1,z1 |\n"
            "                         --capsule x0,y0,z0,x1,y1,z1,r | --ray x,y,z,dx,dy,dz,max_m |\n"
            "                         --distance x,y,z,max_m [--heap N] | --point x,y,z)\n"
            "                        [--unknown safe|unsafe] [--json]\n"
            "       occmap query MAP --batch FILE --json   (one query per line, same syntax)\n"
            "Answers whether the volume is free of occupied voxels (and of unknown ones with\n"
            "--unknown unsafe, the default), with counts of occupied and unknown voxels inside it.\n"
            "A ray is OctoMap's castRay (unknown voxels stop it unless --unknown safe); its counts\n"
            "are over the segment from the origin to max_m along the direction.\n"
            "A distance is to the nearest blocking voxel within max_m: \"found\" with the distance,\n"
            "\"none\" (nothing within max_m), or \"undecided\" (the search's heap of N entries,\n"
            "default %u, overflowed: exit 1, treat as an obstacle at 0).\n"
            "A point is the state of the voxel holding it (occ_map_state_at): \"unknown\",\n"
            "\"free\" or \"occupied\"; unknown off the map.\n", DEFAULT_HEAP);
}

typedef struct {
    enum { Q_NONE, Q_SPHERE, Q_AABB, Q_CAPSULE, Q_RAY, Q_DISTANCE, Q_POINT } kind;
    float v[7];
    unsigned heap; /* --distance: nearest-search heap entries */
    occ_unknown_policy_t policy;
    bool json;
} query_t;

/* Parse options argv[0..argc) into q; returns an error message or NULL. */
static const char *parse(int argc, char **argv, query_t *q)
{
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        const char *val = i + 1 < argc ? argv[i + 1] : NULL;
        int n = 0;
        int kind = Q_NONE;
        if (strcmp(a, "--json") == 0) {
            q->json = true;
            continue;
        } else if (strcmp(a, "--unknown") == 0) {
            if (val == NULL) return "--unknown needs safe or unsafe";
            if (strcmp(val, "safe") == 0) q->policy = OCC_UNKNOWN_SAFE;
            else if (strcmp(val, "unsafe") == 0) q->policy = OCC_UNKNOWN_UNSAFE;
            else return "--unknown takes safe or unsafe";
            i++;
            continue;
        } else if (strcmp(a, "--sphere") == 0) {
            kind = Q_SPHERE;
            n = 4;
        } else if (strcmp(a, "--aabb") == 0) {
            kind = Q_AABB;
            n = 6;
        } else if (strcmp(a, "--capsule") == 0) {
            kind = Q_CAPSULE;
            n = 7;
        } else if (strcmp(a, "--ray") == 0) {
            kind = Q_RAY;
            n = 7;
        } else if (strcmp(a, "--distance") == 0) {
            kind = Q_DISTANCE;
            n = 4;
        } else if (strcmp(a, "--point") == 0) {
            kind = Q_POINT;
            n = 3;
        } else if (strcmp(a, "--heap") == 0) {
            char *end = NULL;
            const unsigned long h = val != NULL ? strtoul(val, &end, 10) : 0ul;
            if (val == NULL || end == val || *end != '\0' || h == 0ul || h > (1ul << 24)) {
                return "--heap takes a count 1..16777216";
            }
            q->heap = (unsigned)h;
            i++;
            continue;
        } else {
            return "unknown option";
        }
        if (q->kind != Q_NONE) return "give one of --sphere, --aabb, --capsule, --ray, --distance, --point";
        if (val == NULL || !cli_parse_floats(val, q->v, n)) return "malformed numbers";
        q->kind = kind;
        i++;
    }
    return q->kind == Q_NONE ? "give one of --sphere, --aabb, --capsule, --ray, --distance, --point" : NULL;
}

static occ_vec3_t vec(const float *p)
{
    occ_vec3_t v = {p[0], p[1], p[2]};
    return v;
}

/* --distance: the three answers of occ_distance_to_obstacle; 1 unless found or none. */
static int run_distance(const occ_map_t *map, const query_t *q, FILE *out)
{
    static const char *const names[] = {"undecided", "found", "none"};
    occ_nearest_entry_t *const heap = malloc((size_t)q->heap * sizeof *heap);
    float dist = 0.0f;
    occ_obstacle_t res = OCC_OBSTACLE_UNDECIDED;
    const occ_err_t e = heap == NULL ? OCC_ERR_NOMEM
                                     : occ_distance_to_obstacle(map, vec(q->v), q->v[3], q->policy,
                                                                heap, q->heap, &dist, &res);
    free(heap);
    if (e != OCC_OK && e != OCC_ERR_NOMEM) { /* bad input: no answer at all */
        if (q->json) fprintf(out, "{\"error\": \"%s\"}\n", occ_err_str(e));
        else fprintf(stderr, "occmap query: %s\n", occ_err_str(e));
        return 1;
    }
    if (q->json) {
        fprintf(out, "{\"obstacle\": \"%s\", \"distance_m\": %.6g", names[res], (double)dist);
        if (e != OCC_OK) fprintf(out, ", \"error\": \"%s\"", occ_err_str(e));
        fprintf(out, "}\n");
    } else if (res == OCC_OBSTACLE_FOUND) {
        fprintf(out, "obstacle at %.6g m\n", (double)dist);
    } else if (res == OCC_OBSTACLE_NONE) {
        fprintf(out, "no obstacle within %.6g m\n", (double)dist);
    } else {
        fprintf(out, "UNDECIDED (%s): treat as an obstacle here\n", occ_err_str(e));
    }
    return e == OCC_OK ? 0 : 1;
}

/* Run one query and print its answer; returns 0 or 1 (error, printed). */
/* The query's volume (a ray: its segment up to the range, after casting it into *ray). */
static occ_err_t make_volume(const occ_map_t *map, const query_t *q, occ_volume_t *vol,
                             occ_ray_result_t *ray)
{
    switch (q->kind) {
    case Q_SPHERE:
        return occ_volume_sphere(vol, vec(q->v), q->v[3]);
    case Q_AABB:
        return occ_volume_aabb(vol, vec(q->v), vec(q->v + 3));
    case Q_CAPSULE:
        return occ_volume_capsule(vol, vec(q->v), vec(q->v + 3), q->v[6]);
    case Q_RAY: {
        const occ_vec3_t o = vec(q->v), d = vec(q->v + 3);
        const float len = sqrtf(d.x * d.x + d.y * d.y + d.z * d.z);
        if (!(len > 0.0f) || !(q->v[6] > 0.0f)) {
            return OCC_ERR_ARG;
        }
        occ_err_t e = occ_cast_ray(map, o, d, q->policy == OCC_UNKNOWN_SAFE, q->v[6], ray);
        if (e == OCC_OK) {
            const float s = q->v[6] / len;
            const occ_vec3_t b = {o.x + d.x * s, o.y + d.y * s, o.z + d.z * s};
            e = occ_volume_segment(vol, o, b);
        }
        return e;
    }
    case Q_DISTANCE: /* run_distance */
    case Q_POINT:    /* run */
    case Q_NONE:
    default:
        return OCC_ERR_ARG;
    }
}

/* What a volume or ray query found. */
typedef struct {
    bool is_ray, collides;
    occ_ray_result_t ray;  /* is_ray */
    occ_collision_t col;   /* !is_ray */
    occ_query_counts_t cnt;
} answer_t;

static void print_answer(const query_t *q, const answer_t *r, FILE *out)
{
    static const char *const stops[] = {"hit", "max_range", "unknown", "map_edge"};
    const occ_ray_result_t *ray = &r->ray;
    if (q->json) {
        fprintf(out, "{\"collides\": %s, \"occupied_voxels\": %llu, \"unknown_voxels\": %llu",
                r->collides ? "true" : "false", (unsigned long long)r->cnt.occupied,
                (unsigned long long)r->cnt.unknown);
        if (r->is_ray) {
            fprintf(out, ", \"hit\": %s, \"hit_point\": ", ray->hit ? "true" : "false");
            if (ray->hit) {
                fprintf(out, "[%.4f, %.4f, %.4f]", (double)ray->end.x, (double)ray->end.y,
                        (double)ray->end.z);
            } else {
                fprintf(out, "null");
            }
            fprintf(out, ", \"stop\": \"%s\"", stops[ray->stop]);
        } else if (!r->col.safe) {
            fprintf(out, ", \"outside_map\": %s", r->col.outside ? "true" : "false");
        }
        fprintf(out, "}\n");
    } else {
        fprintf(out, "%s: %llu occupied, %llu unknown voxels inside",
                r->collides ? "COLLIDES" : "safe", (unsigned long long)r->cnt.occupied,
                (unsigned long long)r->cnt.unknown);
        if (r->is_ray) {
            if (ray->hit) {
                fprintf(out, "; ray hit at %.4f %.4f %.4f", (double)ray->end.x,
                        (double)ray->end.y, (double)ray->end.z);
            } else {
                fprintf(out, "; ray: no hit (%s)", stops[ray->stop]);
            }
        } else if (!r->col.safe && r->col.outside) {
            fprintf(out, "; leaves the map");
        }
        fprintf(out, "\n");
    }
}

static int run(const occ_map_t *map, const query_t *q, FILE *out)
{
    if (q->kind == Q_DISTANCE) {
        return run_distance(map, q, out);
    }
    if (q->kind == Q_POINT) {
        static const char *const states[] = {"unknown", "free", "occupied"};
        const char *const st = states[occ_map_state_at(map, vec(q->v))];
        if (q->json) fprintf(out, "{\"state\": \"%s\"}\n", st);
        else fprintf(out, "%s\n", st);
        return 0;
    }
    answer_t r;
    memset(&r, 0, sizeof r);
    r.is_ray = q->kind == Q_RAY;
    occ_volume_t vol;
    occ_err_t e = make_volume(map, q, &vol, &r.ray);
    if (e == OCC_OK && !r.is_ray) e = occ_collide_volume(map, &vol, q->policy, &r.col);
    if (e == OCC_OK) e = occ_query_count(map, &vol, &r.cnt);
    if (e != OCC_OK) {
        if (q->json) fprintf(out, "{\"error\": \"%s\"}\n", occ_err_str(e));
        else fprintf(stderr, "occmap query: %s\n", occ_err_str(e));
        return 1;
    }
    if (r.is_ray) {
        r.collides = r.ray.hit ||
                     (q->policy == OCC_UNKNOWN_UNSAFE && r.ray.stop == OCC_RAY_UNKNOWN);
    } else {
        r.collides = !r.col.safe;
    }
    print_answer(q, &r, out);
    return 0;
}

static int run_batch(const occ_map_t *map, const char *path, const query_t *defaults)
{
    FILE *f = strcmp(path, "-") == 0 ? stdin : fopen(path, "r");
    if (f == NULL) {
        cli_error("query", "cannot open %s", path);
        return 1;
    }
    char line[1024];
    int status = 0;
    while (fgets(line, sizeof line, f) != NULL) {
        char *argv[16];
        int argc = 0;
        for (char *tok = strtok(line, " \t\r\n"); tok != NULL && argc < 16; tok = strtok(NULL, " \t\r\n")) {
            argv[argc++] = tok;
        }
        if (argc == 0 || argv[0][0] == '#') continue;
        query_t q = *defaults;
        q.kind = Q_NONE;
        const char *err = parse(argc, argv, &q);
        if (err != NULL) {
            fprintf(stdout, "{\"error\": \"%s\"}\n", err);
            status = 1;
            continue;
        }
        q.json = true;
        status |= run(map, &q, stdout);
    }
    if (f != stdin) fclose(f);
    return status;
}

int cmd_query(int argc, char **argv)
{
    if (argc < 2 || strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0) {
        usage(argc < 2 ? stderr : stdout);
        return argc < 2 ? 2 : 0;
    }
    const char *map_path = argv[1];
    const char *batch = NULL;
    query_t q;
    memset(&q, 0, sizeof q);
    q.kind = Q_NONE;
    q.policy = OCC_UNKNOWN_UNSAFE;
    q.heap = DEFAULT_HEAP;
    /* Pull --batch FILE out; the rest is one query. */
    char *rest[64];
    int nrest = 0;
    for (int i = 2; i < argc; i++) {
        if (strcmp(argv[i], "--batch") == 0 && i + 1 < argc) {
            batch = argv[++i];
        } else if (nrest < 64) {
            rest[nrest++] = argv[i];
        }
    }
    if (batch == NULL) {
        const char *err = parse(nrest, rest, &q);
        if (err != NULL) {
            cli_error("query", "%s", err);
            usage(stderr);
            return 2;
        }
    } else {
        for (int i = 0; i < nrest; i++) {
            if (strcmp(rest[i], "--json") == 0) {
                q.json = true;
            } else if (strcmp(rest[i], "--unknown") == 0 && i + 1 < nrest) {
                q.policy = strcmp(rest[++i], "safe") == 0 ? OCC_UNKNOWN_SAFE : OCC_UNKNOWN_UNSAFE;
            } else {
                cli_error("query", "--batch takes only --json and --unknown");
                return 2;
            }
        }
    }
    occ_map_t map;
    void *arena = NULL;
    char msg[256] = "";
    const occ_err_t e = occ_file_load_alloc(map_path, NULL, &map, 0, &arena, NULL, msg, sizeof msg);
    if (e != OCC_OK) {
        cli_error("query", "%s: %s (%s)", map_path, occ_err_str(e), msg);
        return 1;
    }
    const int status = batch != NULL ? run_batch(&map, batch, &q) : run(&map, &q, stdout);
    free(arena);
    return status;
}
