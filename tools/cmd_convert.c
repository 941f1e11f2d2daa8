/* SPDX-License-Identifier: BSD-3-Clause */
/* cmd_convert.c - `occmap convert IN OUT`: between .bt, .ot and .occ (IN by content, OUT by
 * extension), saved atomically. */
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "occmap/host/occ_file.h"

static void usage(void)
{
    printf("usage: occmap convert IN OUT\n"
           "  IN: .bt, .ot or .occ (format from the content); OUT: format from its extension.\n"
           "  .bt keeps the maximum-likelihood state (free/occupied), .ot the log-odds,\n"
           "  .occ everything (config and raw values). The output is written atomically.\n");
}

int cmd_convert(int argc, char **argv)
{
    const char *in = NULL, *out = NULL;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            usage();
            return 0;
        } else if (argv[i][0] == '-') {
            cli_error("convert", "unknown option '%s'", argv[i]);
            return 2;
        } else if (in == NULL) {
            in = argv[i];
        } else if (out == NULL) {
            out = argv[i];
        } else {
            cli_error("convert", "too many arguments");
            return 2;
        }
    }
    if (in == NULL || out == NULL) {
        usage();
        return 2;
    }
    const occ_format_t fmt = occ_file_format_of(out);
    if (fmt == OCC_FORMAT_UNKNOWN) {
        cli_error("convert", "%s: unknown extension (use .bt, .ot or .occ)", out);
        return 2;
    }
    occ_map_t map;
    void *arena = NULL;
    occ_io_info_t info;
    char msg[512];
    occ_err_t e = occ_file_load_alloc(in, NULL, &map, 0u, &arena, &info, msg, sizeof msg);
    if (e != OCC_OK) {
        cli_error("convert", "%s", msg);
        return 1;
    }
    if (info.warnings != 0u) {
        fprintf(stderr, "occmap convert: %s: reader warnings 0x%x (see occmap info)\n", in,
                (unsigned)info.warnings);
    }
    size_t bytes = 0u;
    e = occ_file_save_as(out, &map, fmt, &bytes, msg, sizeof msg);
    free(arena);
    if (e != OCC_OK) {
        cli_error("convert", "%s", msg);
        return 1;
    }
    printf("%s (%llu nodes) -> %s (%zu bytes)\n", in, (unsigned long long)info.nodes, out, bytes);
    return 0;
}
