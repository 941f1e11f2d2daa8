/* SPDX-License-Identifier: BSD-3-Clause */
/* build_tlog.c - `occmap build --tlog FILE`: DISTANCE_SENSOR / OBSTACLE_DISTANCE(_3D) readings
 * of a telemetry log into the map with the log's poses (port/posix/tlog_ranges.c). */
#include <string.h>

#include "build_tlog.h"
#include "cli.h"
#include "occmap/host/occ_file.h"
#include "occmap/host/occ_tlog_ranges.h"

static void print_text(const occ_map_t *map, const occ_tlog_ranges_stats_t *st)
{
    occ_map_stats_t ms;
    occ_map_stats(map, &ms);
    cli_print_stats_text(stdout, map, &ms);
    printf("log               %llu records, %llu good frames, %llu bad (skipped)\n",
           (unsigned long long)st->records, (unsigned long long)st->frames_ok,
           (unsigned long long)st->frames_bad);
    printf("poses             %u (ATTITUDE %u, positions %u from msg %u)%s\n", st->poses,
           st->attitudes, st->positions, st->position_source,
           st->no_horizontal_fix ? ", no horizontal fix: held at the origin" : "");
    printf("readings          %u translated, %u integrated, %u without a pose, %u refused by "
           "the insert\n", st->range_msgs, st->integrated, st->no_pose, st->insert_errors);
    printf("refused           %u own, %u malformed, %u unsupported; %u invalid, %u unknown "
           "elements\n", st->tr.own_refused, st->tr.malformed, st->tr.unsupported,
           st->tr.invalid_readings, st->tr.unknown_elements);
    printf("beams             %zu hit, %zu no return, %zu invalid, %zu too close, %zu bad; "
           "%zu rays, %zu voxel updates\n", st->sum.beams_hit, st->sum.beams_no_return,
           st->sum.beams_invalid, st->sum.beams_too_close, st->sum.beams_bad, st->sum.rays,
           st->sum.insert.voxels_updated);
    printf("span              %.1f s of log\n",
           (double)(st->t_last_us - st->t_first_us) / 1e6);
}

static void print_json(const occ_map_t *map, const occ_tlog_ranges_stats_t *st)
{
    occ_map_stats_t ms;
    occ_map_stats(map, &ms);
    printf("{");
    cli_print_stats_json(stdout, map, &ms);
    printf(", \"records\": %llu, \"frames_ok\": %llu, \"frames_bad\": %llu, \"poses\": %u,"
           " \"attitudes\": %u, \"positions\": %u, \"position_msg\": %u,"
           " \"no_horizontal_fix\": %s, \"readings\": %u, \"integrated\": %u, \"no_pose\": %u,"
           " \"insert_errors\": %u, \"own_refused\": %u, \"malformed\": %u, \"unsupported\": %u,"
           " \"invalid_readings\": %u, \"unknown_elements\": %u, \"beams_hit\": %zu,"
           " \"beams_no_return\": %zu, \"beams_invalid\": %zu, \"beams_too_close\": %zu,"
           " \"beams_bad\": %zu, \"rays\": %zu, \"voxels_updated\": %zu}\n",
           (unsigned long long)st->records, (unsigned long long)st->frames_ok,
           (unsigned long long)st->frames_bad, st->poses, st->attitudes, st->positions,
           st->position_source, st->no_horizontal_fix ? "true" : "false", st->range_msgs,
           st->integrated, st->no_pose, st->insert_errors, st->tr.own_refused, st->tr.malformed,
           st->tr.unsupported, st->tr.invalid_readings, st->tr.unknown_elements,
           st->sum.beams_hit, st->sum.beams_no_return, st->sum.beams_invalid,
           st->sum.beams_too_close, st->sum.beams_bad, st->sum.rays,
           st->sum.insert.voxels_updated);
}

int build_tlog(occ_map_t *map, const char *tlog, bool json, const char *out_path)
{
    const occ_tlog_ranges_config_t cfg = occ_tlog_ranges_config_default();
    const occ_insert_params_t params = occ_insert_params_default();
    occ_tlog_ranges_stats_t st;
    char msg[512] = "";
    const occ_err_t e = occ_tlog_integrate_ranges(map, tlog, &cfg, &params, NULL, NULL, &st, msg,
                                                  sizeof msg);
    if (e != OCC_OK) {
        cli_error("build", "%s: %s (%s)", tlog, msg[0] != '\0' ? msg : "cannot integrate",
                  occ_err_str(e));
        return 1;
    }
    if (json) {
        print_json(map, &st);
    } else {
        print_text(map, &st);
    }
    if (out_path != NULL) {
        const occ_err_t se = occ_file_save(out_path, map, msg, sizeof msg);
        if (se != OCC_OK) {
            cli_error("build", "cannot save %s: %s (%s)", out_path, msg, occ_err_str(se));
            return 1;
        }
    }
    return 0;
}
