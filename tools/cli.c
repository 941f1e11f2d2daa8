/* SPDX-License-Identifier: BSD-3-Clause */
/* cli.c - helpers shared by the subcommands: argument parsing and statistics output. */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"

int cli_parse_floats(const char *s, float *out, const int n)
{
    for (int i = 0; i < n; i++) {
        char *end = NULL;
        errno = 0;
        const float v = strtof(s, &end);
        if (end == s || errno != 0 || !isfinite(v)) {
            return 0;
        }
        out[i] = v;
        s = end;
        if (i + 1 < n) {
            if (*s != ',') {
                return 0;
            }
            s++;
        }
    }
    return *s == '\0';
}

bool cli_parse_float_in(const char *s, const float lo, const float hi, float *out)
{
    float v;
    if (!cli_parse_floats(s, &v, 1) || v < lo || v > hi) {
        return false;
    }
    *out = v;
    return true;
}

bool cli_parse_u32(const char *s, const uint32_t lo, const uint32_t hi, uint32_t *out)
{
    char *end = NULL;
    errno = 0;
    const unsigned long v = strtoul(s, &end, 10);
    if (end == s || *end != '\0' || errno != 0 || s[0] == '-' || v < lo || v > hi) {
        return false;
    }
    *out = (uint32_t)v;
    return true;
}

int cli_parse_size(const char *s, size_t *out)
{
    char *end = NULL;
    errno = 0;
    const unsigned long long v = strtoull(s, &end, 10);
    if (end == s || errno != 0 || s[0] == '-') {
        return 0;
    }
    unsigned long long mul = 1;
    if (*end == 'K' || *end == 'k') {
        mul = 1024ull;
        end++;
    } else if (*end == 'M' || *end == 'm') {
        mul = 1024ull * 1024ull;
        end++;
    } else if (*end == 'G' || *end == 'g') {
        mul = 1024ull * 1024ull * 1024ull;
        end++;
    }
    if (*end != '\0' || v > (unsigned long long)SIZE_MAX / mul) {
        return 0;
    }
    *out = (size_t)(v * mul);
    return 1;
}

void cli_error(const char *cmd, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "occmap %s: ", cmd);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
}

/* Shortest "%.*g" of `v` (up to max_digits) that reads back as `v` (as a float if is_float). */
static const char *json_number(char *buf, const double v, const int max_digits, const int is_float)
{
    if (!isfinite(v)) {
        snprintf(buf, CLI_NUM_CHARS, "null");
        return buf;
    }
    for (int digits = 1; digits <= max_digits; digits++) {
        snprintf(buf, CLI_NUM_CHARS, "%.*g", digits, v);
        const double back = strtod(buf, NULL);
        const double want = is_float ? (double)(float)back : back;
        if (!(want < v) && !(want > v)) {
            break;
        }
    }
    return buf;
}

const char *cli_json_double(char *buf, const double v)
{
    return json_number(buf, v, 17, 0);
}

const char *cli_json_float(char *buf, const float v)
{
    return json_number(buf, (double)v, 9, 1);
}

void cli_print_stats_json(FILE *f, const occ_map_t *map, const occ_map_stats_t *st)
{
    char res[CLI_NUM_CHARS], occ[CLI_NUM_CHARS], fre[CLI_NUM_CHARS];
    fprintf(f, "\"resolution_m\": %s, \"depth_levels\": %u, \"inner_nodes\": %llu, "
               "\"leaf_nodes\": %llu, \"occupied_leaves\": %llu, \"free_leaves\": %llu, "
               "\"occupied_voxels\": %llu, \"free_voxels\": %llu, "
               "\"occupied_volume_m3\": %s, \"free_volume_m3\": %s, \"memory_bytes\": %zu, ",
            cli_json_float(res, map->cfg.resolution_m), (unsigned)map->cfg.depth_levels,
            (unsigned long long)st->inner_nodes, (unsigned long long)st->leaf_nodes,
            (unsigned long long)st->occupied_leaves, (unsigned long long)st->free_leaves,
            (unsigned long long)st->occupied_voxels, (unsigned long long)st->free_voxels,
            cli_json_double(occ, st->occupied_volume_m3), cli_json_double(fre, st->free_volume_m3),
            st->bytes_used);
    if (st->has_known) {
        const float box[6] = {st->bbox_min.x, st->bbox_min.y, st->bbox_min.z,
                              st->bbox_max.x, st->bbox_max.y, st->bbox_max.z};
        char b[6][CLI_NUM_CHARS];
        for (int i = 0; i < 6; i++) {
            cli_json_float(b[i], box[i]);
        }
        fprintf(f, "\"bbox_min\": [%s, %s, %s], \"bbox_max\": [%s, %s, %s]", b[0], b[1], b[2],
                b[3], b[4], b[5]);
    } else {
        fprintf(f, "\"bbox_min\": null, \"bbox_max\": null");
    }
}

void cli_print_stats_text(FILE *f, const occ_map_t *map, const occ_map_stats_t *st)
{
    fprintf(f, "resolution        %.4g m, %u levels\n", (double)map->cfg.resolution_m,
            (unsigned)map->cfg.depth_levels);
    fprintf(f, "nodes             %llu (%llu inner, %llu leaves)\n", (unsigned long long)st->nodes,
            (unsigned long long)st->inner_nodes, (unsigned long long)st->leaf_nodes);
    fprintf(f, "leaves            %llu occupied, %llu free\n",
            (unsigned long long)st->occupied_leaves, (unsigned long long)st->free_leaves);
    fprintf(f, "volume            %.6f m3 occupied, %.6f m3 free\n", st->occupied_volume_m3,
            st->free_volume_m3);
    fprintf(f, "memory            %zu bytes (%u inner + %u leaf blocks), peak %zu, arena %zu\n",
            st->bytes_used, st->inner_used, st->leaf_used, st->bytes_peak, st->arena_bytes);
    if (st->has_known) {
        fprintf(f, "bbox              (%.3f, %.3f, %.3f) .. (%.3f, %.3f, %.3f) m\n",
                (double)st->bbox_min.x, (double)st->bbox_min.y, (double)st->bbox_min.z,
                (double)st->bbox_max.x, (double)st->bbox_max.y, (double)st->bbox_max.z);
    }
}

void cli_host_unique_id(uint8_t id[16], const uint32_t node_id)
{
    uint32_t h = 2166136261u;
    char host[64] = "";
    (void)gethostname(host, sizeof host - 1u);
    const size_t hl = strlen(host);
    for (size_t k = 0; k < 16u; k++) {
        const unsigned ch = k < hl ? (unsigned)(unsigned char)host[k] : (unsigned)(k + node_id);
        h = (h ^ ch) * 16777619u;
        id[k] = (uint8_t)(h >> 24);
    }
}
