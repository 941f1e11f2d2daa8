/* SPDX-License-Identifier: BSD-3-Clause */
/* cmd_info.c - `occmap info MAP [--json]`: the file's format, header and reader warnings, and
 * the map statistics of the loaded map. */
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "occmap/host/occ_file.h"

static const char *format_name(const occ_format_t f)
{
    switch (f) {
    case OCC_FORMAT_BT: return "bt";
    case OCC_FORMAT_OT: return "ot";
    case OCC_FORMAT_SNAPSHOT: return "occ";
    case OCC_FORMAT_UNKNOWN:
    default: return "unknown";
    }
}

static const struct {
    uint32_t bit;
    const char *name;
} warn_names[] = {
    {OCC_IO_WARN_TREE_TYPE, "tree_type_read_as_OcTree"},
    {OCC_IO_WARN_EXTRA_SKIPPED, "color_bytes_skipped"},
    {OCC_IO_WARN_QUANTIZED, "values_quantized"},
    {OCC_IO_WARN_CLAMPED, "values_clamped"},
    {OCC_IO_WARN_TRAILING, "trailing_bytes_ignored"},
    {OCC_IO_WARN_LEGACY_ID, "legacy_id"},
    {OCC_IO_WARN_UNKNOWN_KEY, "unknown_header_keyword"},
    {OCC_IO_WARN_INNER_VALUE, "inner_values_recomputed"},
};

static void usage(void)
{
    printf("usage: occmap info MAP [--json]\n"
           "  MAP is a .bt, .ot or .occ file (the format is taken from the content).\n"
           "  Prints the format, the header, reader warnings and the map statistics.\n");
}

/* The file's header facts and warnings, then the map statistics. */
static void print_info(const char *path, const occ_io_info_t *info, const occ_map_t *map,
                       const int json)
{
    occ_map_stats_t st;
    occ_map_stats(map, &st);
    if (json) {
        printf("{\"file\": \"%s\", \"format\": \"%s\", \"tree_id\": \"%s\", \"file_bytes\": %zu, "
               "\"file_nodes\": %llu, \"warnings\": [",
               path, format_name(info->format), info->tree_id, info->bytes_used,
               (unsigned long long)info->nodes);
        int first = 1;
        for (size_t i = 0; i < sizeof warn_names / sizeof warn_names[0]; i++) {
            if ((info->warnings & warn_names[i].bit) != 0u) {
                printf("%s\"%s\"", first ? "" : ", ", warn_names[i].name);
                first = 0;
            }
        }
        printf("], ");
        cli_print_stats_json(stdout, map, &st);
        printf("}\n");
    } else {
        printf("file              %s\n", path);
        printf("format            %s%s%s\n", format_name(info->format),
               info->tree_id[0] != '\0' ? ", id " : "", info->tree_id);
        printf("file nodes        %llu (%zu bytes read)\n", (unsigned long long)info->nodes,
               info->bytes_used);
        for (size_t i = 0; i < sizeof warn_names / sizeof warn_names[0]; i++) {
            if ((info->warnings & warn_names[i].bit) != 0u) {
                printf("warning           %s\n", warn_names[i].name);
            }
        }
        cli_print_stats_text(stdout, map, &st);
    }
}

int cmd_info(int argc, char **argv)
{
    const char *path = NULL;
    int json = 0;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            usage();
            return 0;
        } else if (strcmp(argv[i], "--json") == 0) {
            json = 1;
        } else if (argv[i][0] != '-' && path == NULL) {
            path = argv[i];
        } else {
            cli_error("info", "unexpected argument '%s'", argv[i]);
            return 2;
        }
    }
    if (path == NULL) {
        usage();
        return 2;
    }
    occ_map_t map;
    void *arena = NULL;
    occ_io_info_t info;
    char msg[512];
    const occ_err_t e = occ_file_load_alloc(path, NULL, &map, 0u, &arena, &info, msg, sizeof msg);
    if (e != OCC_OK) {
        cli_error("info", "%s", msg);
        return 1;
    }
    print_info(path, &info, &map, json);
    free(arena);
    return 0;
}
