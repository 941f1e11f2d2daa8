/* SPDX-License-Identifier: BSD-3-Clause */
/* occmap - the command-line tool: dispatches to one file per subcommand. */
#include <stdio.h>
#include <string.h>
#include "cli.h"
#include "view.h"

static const struct {
    const char *name;
    cli_cmd_fn fn;
    const char *summary;
} commands[] = {
    {"stats", cmd_stats, "stats --scan FILE --res R [--json]: mark a scan's endpoints, print stats"},
    {"build", cmd_build, "build --scan FILE|--graph FILE|--depth-dir DIR --res R ...: integrate"},
    {"query", cmd_query, "query MAP --sphere|--aabb|--capsule|--ray ...: collision and ray queries"},
    {"info", cmd_info, "info MAP [--json]: format and statistics of a map file"},
    {"convert", cmd_convert, "convert IN OUT: between .bt, .ot and .occ"},
    {"feed", cmd_feed, "feed --map MAP --udp HOST:PORT ...: OBSTACLE_DISTANCE over MAVLink"},
    {"run", cmd_run, "run --udp HOST:PORT --depth-dir DIR ...: the onboard loop (map + feed)"},
    {"can-feed", cmd_can_feed, "can-feed --map MAP --socketcan IF|--mcast BUS ...: DroneCAN"},
    {"view", cmd_view, "view MAP -o OUT.html: the map in 3D, one page that opens offline"},
};

static void usage(FILE *f)
{
    fprintf(f, "usage: occmap COMMAND [OPTIONS]   (occmap COMMAND --help for details)\n\n");
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++) {
        fprintf(f, "  %s\n", commands[i].summary);
    }
}

int main(int argc, char **argv)
{
    if (argc < 2 || strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0) {
        usage(argc < 2 ? stderr : stdout);
        return argc < 2 ? 2 : 0;
    }
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++) {
        if (strcmp(argv[1], commands[i].name) == 0) {
            return commands[i].fn(argc - 1, argv + 1);
        }
    }
    fprintf(stderr, "occmap: unknown command '%s'\n", argv[1]);
    usage(stderr);
    return 2;
}
