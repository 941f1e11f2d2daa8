/* cli.c - helpers shared by the subcommands: argument parsing and statistics output. */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

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

void cli_print_stats_json(FILE *f, const occ_map_t *map, const occ_map_stats_t *st)
{
    fprintf(f, "\"resolution_m\": %.6g, \"depth_levels\": %u, \"inner_nodes\": %llu, "
               "\"leaf_nodes\": %llu, \"occupied_leaves\": %llu, \"free_leaves\": %llu, "
               "\"occupied_volume_m3\": %.6g, \"free_volume_m3\": %.6g, \"memory_bytes\": %zu, ",
            (double)map->cfg.resolution_m, (unsigned)map->cfg.depth_levels,
            (unsigned long long)st->inner_nodes, (unsigned long long)st->leaf_nodes,
            (unsigned long long)st->occupied_leaves, (unsigned long long)st->free_leaves,
            (double)st->occupied_volume_m3, (double)st->free_volume_m3, st->bytes_used);
    if (st->has_known) {
        fprintf(f, "\"bbox_min\": [%.6g, %.6g, %.6g], \"bbox_max\": [%.6g, %.6g, %.6g]",
                (double)st->bbox_min.x, (double)st->bbox_min.y, (double)st->bbox_min.z,
                (double)st->bbox_max.x, (double)st->bbox_max.y, (double)st->bbox_max.z);
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
    fprintf(f, "volume            %.3f m3 occupied, %.3f m3 free\n",
            (double)st->occupied_volume_m3, (double)st->free_volume_m3);
    fprintf(f, "memory            %zu bytes (%u inner + %u leaf blocks), peak %zu, arena %zu\n",
            st->bytes_used, st->inner_used, st->leaf_used, st->bytes_peak, st->arena_bytes);
    if (st->has_known) {
        fprintf(f, "bbox              (%.3f, %.3f, %.3f) .. (%.3f, %.3f, %.3f) m\n",
                (double)st->bbox_min.x, (double)st->bbox_min.y, (double)st->bbox_min.z,
                (double)st->bbox_max.x, (double)st->bbox_max.y, (double)st->bbox_max.z);
    }
}
