/* SPDX-License-Identifier: BSD-3-Clause */
/* run_args.c - `occmap run`'s options: the loop loop of feed_args.c with the feed's shared and
 * sector options, plus the sensor, map, timing and output options of the onboard loop. */
#include <math.h>
#include <string.h>

#include "cli.h"
#include "run.h"

void run_args_usage(FILE *f)
{
    fprintf(f,
        "usage: occmap run (--udp HOST:PORT | --udp-listen [HOST:]PORT | --serial DEV:BAUD)\n"
        "                  [--depth-dir DIR] [options]\n"
        "The onboard loop: poses from the autopilot into a pose history on its clock (TIMESYNC),\n"
        "depth frames integrated with the pose at their own time by a mapping thread (the map's one\n"
        "writer) inside a fixed arena, OBSTACLE_DISTANCE (72 x 5 deg, MAV_FRAME_BODY_FRD) from the\n"
        "live map at --rate, a 1 Hz HEARTBEAT whose system_status says BOOT (nothing sent yet),\n"
        "ACTIVE (sending) or CRITICAL (stopped: stale pose or sensors), one JSON telemetry line a\n"
        "second. Ends at SIGINT/SIGTERM, after --duration, or with --exit-after-depth; saves -o then.\n"
        "Link and ids:\n"
        "  --udp HOST:PORT         send to HOST:PORT (an autopilot/SITL there), read its replies\n"
        "  --udp-listen [H:]PORT   wait for the autopilot to send first   --serial DEV:BAUD\n"
        "  --target-sysid 1 --target-compid 1   poses only from this autopilot (others counted)\n"
        "  --sysid 1 --compid 196  our ids (MAV_COMP_ID_OBSTACLE_AVOIDANCE)\n"
        "  --can IFACE             DroneCAN on SocketCAN IFACE (or mcast:BUS, pydronecan's UDP bus):\n"
        "                          range_sensor.Measurement in (placed by --can-range-mount, else\n"
        "                          counted unknown_sensor), Proximity + NodeStatus out\n"
        "  --can-node-id 100       our node id   --can-range-mount ID,x,y,z,roll,pitch,yaw,min,max\n"
        "                          body FLU <- sensor (m, deg; beam = sensor +x), range m (up to 8)\n"
        "  --config FILE           key = value lines, key an option without --, before the command\n"
        "                          line (which wins); flags: key = true; # comments; keys repeat\n"
        "  --pose-rate 50          Hz asked for LOCAL_POSITION_NED and ATTITUDE with\n"
        "                          MAV_CMD_SET_MESSAGE_INTERVAL, once a second until they arrive\n"
        "                          (refusals logged); 0: never ask\n"
        );
    fprintf(f,
        "Depth input (a TUM directory: depth.txt + depth/*.png, 16-bit, 5000 units per metre):\n"
        "  --depth-dir DIR         each frame is stamped with autopilot time t - T_REF (T_REF = the\n"
        "                          first depth.txt time - 1 s) and released when the autopilot clock\n"
        "                          (TIMESYNC offset) reaches it; entries without a PNG are skipped\n"
        "  --replay-speed 1        1: recorded timing; 0: as fast as the poses allow (tests)\n"
        "  --max-lag-ms 500        recorded timing: a frame the mapping reaches later than this after\n"
        "                          its time is dropped and counted (late), as a camera driver would\n"
        "  --depth-intrinsics fx,fy,cx,cy   default: TUM freiburg1's when DIR names fr1/freiburg1,\n"
        "                          else freiburg2's (520.9,521.0,325.1,249.7)\n"
        "  --depth-mount x,y,z,roll,pitch,yaw   body FLU <- camera mount, m and deg; 0,0,0,0,0,0:\n"
        "                          at the body origin looking forward (optical x right, y down, z fwd)\n"
        "  --depth-stride 1        every N-th pixel in u and v\n"
        "  --depth-method simple   simple (ray casting: OctoMap's insertPointCloud exactly) or\n"
        "                          projective (occ_integrate.h: by projection, 5-7x faster here;\n"
        "                          the loop demo's sectors agree with OctoMap on 97.7 %% of the\n"
        "                          observed ones for the pioneer frames but 60 %% for fr1_rpy,\n"
        "                          whose depth gaps are wider than a pixel)\n"
        "  --depth-max-frames N    replay only the first N frames that have a PNG (default all)\n"
        "  --depth-min-m 0 --depth-max-m 4   range kept; beyond max clears to max (OctoMap's rule)\n"
        "  --mavlink-ranges        also integrate DISTANCE_SENSOR / OBSTACLE_DISTANCE(_3D) from other\n"
        "                          components on the link, each with the pose at its own\n"
        "                          time_boot_ms / time_usec taken as the autopilot's clock (mapped\n"
        "                          through the TIMESYNC offset, as the poses) when that lies at most\n"
        "                          --sensor-timeout-ms before its arrival and not after it; else\n"
        "                          (no TIMESYNC yet, a sensor on its own clock) at its arrival\n"
        "                          (off by default: ArduPilot re-sends its proximity boundary, our\n"
        "                          own data, as DISTANCE_SENSOR). DroneCAN readings: at arrival\n"
        "  A frame is integrated with the pose interpolated at its time (gaps > 100 ms refused); a\n"
        "  frame with no pose for its time is dropped and counted by reason, never integrated.\n"
        "Map and memory:\n"
        "  --res 0.1               voxel edge, metres (ignored with --map: the file's)\n"
        "  --arena-bytes 128M      the whole map's arena (K/M/G), allocated once\n"
        "                          (plus two snapshot copies for the lock-free readers: 3x in all)\n"
        "  --keep-radius 3         when the arena is full, evict (robot-centric) outside this ball\n"
        "                          around the camera and retry; a frame that still does not fit is\n"
        "                          integrated in part (nearest pixels first: 1/2, 1/4, 1/8, 1/16 of\n"
        "                          them) and counted as partial, or dropped (nomem) and counted\n"
        "  --map FILE              a prior map (.bt .ot .occ) to start from\n"
        "  -o FILE                 save atomically at exit and every --save-every S seconds (0: exit)\n"
        );
    fprintf(f,
        "Feed (as `occmap feed`):\n"
        "  --rate 10 (--rate-hz)   OBSTACLE_DISTANCE per second\n"
        "  --min-m 0.2 --max-m 20  the range; --map-frame enu|ned (the map's frame, default enu)\n"
        "  --band-below-m 0.5 --band-above-m 0.5 [--band-m B] --ground-clearance-m 0.1\n"
        "  --no-ignore-ground --angle-offset-deg -20 --unknown no-data|distance\n"
        "  --pose-timeout-ms 500   no OBSTACLE_DISTANCE while the pose is older\n"
        "  --sensor-timeout-ms 1000  nor while any configured input - --depth-dir frames,\n"
        "                          --mavlink-ranges messages, --can readings of a mounted sensor -\n"
        "                          has had no sample integrated for this long (or none yet), each\n"
        "                          on its own (a live rangefinder does not hide a dead camera);\n"
        "                          either sends one STATUSTEXT (WARNING) when it starts and one\n"
        "                          (INFO) when it ends; telemetry: sensor_age_ms, stale_input\n"
        "  --3d                    after each OBSTACLE_DISTANCE, OBSTACLE_DISTANCE_3D (BODY_FRD, one\n"
        "                          time_boot_ms per batch) of the nearest occupied point above the\n"
        "                          band (obstacle_id 0) and below it (id 1), within --max-m\n"
        "Output:\n"
        "  --stats FILE            telemetry, one JSON line a second (default stderr); the first is\n"
        "                          {\"config\": ...}, the last {\"final\": ...} with map_check\n"
        "  --feed-log FILE         one JSON line per OBSTACLE_DISTANCE sent: time_usec, seq, version,\n"
        "                          frames / frames_dropped (depth.txt indices since the last line),\n"
        "                          frame_poses (map <- camera each frame was integrated with),\n"
        "                          pose [x y z qw qx qy qz] (map ENU, body FLU), distances, ...;\n"
        "                          with --3d obstacles_3d [[id, x, y, z (FRD m)], ...] as sent\n"
        "  --duration S            end after S seconds (0: until SIGINT/SIGTERM)\n"
        "  --exit-after-depth      end once every frame is integrated or dropped and one more\n"
        "                          OBSTACLE_DISTANCE was sent (or --sensor-timeout-ms passed)\n"
        "Exit status: 0; 1 i/o error or occ_map_check() failed at the end; 2 usage.\n");
}

static const char *const run_flags[] = {"--exit-after-depth", "--no-ignore-ground", "--3d",
                                        "--mavlink-ranges", NULL};

static void defaults(run_opts_t *o)
{
    memset(o, 0, sizeof *o);
    o->feed = occ_mav_feed_config_default();
    o->sysid = 1;
    o->compid = OCC_MAV_COMP_ID_OBSTACLE_AVOIDANCE;
    o->target_sysid = 1;
    o->target_compid = 1;
    o->stride = 1;
    o->depth_projective = false;
    o->depth_min_m = 0.0f;
    o->depth_max_m = 4.0f;
    o->res_m = 0.1f;
    o->arena_bytes = (size_t)128 << 20;
    o->pose_rate_hz = 50.0f;
    o->pose_timeout_ms = 500;
    o->sensor_timeout_ms = 1000;
    o->max_lag_ms = 500;
    o->replay_speed = 1u;
    o->keep_radius_m = 3.0f;
    o->can_node_id = 100;
}

/* --can-range-mount ID,x,y,z,roll,pitch,yaw,min,max: body FLU <- sensor (m, deg; the beam is
 * the sensor's +x), valid range in metres. One per sensor_id (checked by the receiver). */
static bool can_mount(run_opts_t *o, const char *v)
{
    float f[9];
    if (o->n_can_mounts == RUN_CAN_MOUNTS || !cli_parse_floats(v, f, 9) || !(f[0] >= 0.0f) ||
        f[0] > 255.0f || floorf(f[0]) < f[0] || !(f[7] >= 0.0f) || !(f[8] > f[7])) {
        return false;
    }
    occ_dronecan_range_mount_t *const m = &o->can_mounts[o->n_can_mounts];
    const float deg = 3.14159265358979f / 180.0f;
    m->sensor_id = (uint8_t)f[0];
    m->body_from_sensor.p = (occ_vec3_t){f[1], f[2], f[3]};
    m->body_from_sensor.q = occ_quat_from_euler(f[4] * deg, f[5] * deg, f[6] * deg);
    m->min_m = f[7];
    m->max_m = f[8];
    o->n_can_mounts++;
    return true;
}

bool run_args_is_flag(const char *opt)
{
    for (size_t i = 0; run_flags[i] != NULL; i++) {
        if (strcmp(opt, run_flags[i]) == 0) {
            return true;
        }
    }
    return false;
}

/* The link and the ids. */
static int link_option(run_opts_t *o, const char *a, const char *v)
{
    bool ok = true;
    if (strcmp(a, "--udp") == 0) {
        o->udp = v;
    } else if (strcmp(a, "--udp-listen") == 0) {
        o->udp_listen = v;
    } else if (strcmp(a, "--serial") == 0) {
        o->serial = v;
    } else if (strcmp(a, "--sysid") == 0) {
        ok = cli_parse_u32(v, 1, 255, &o->sysid);
    } else if (strcmp(a, "--compid") == 0) {
        ok = cli_parse_u32(v, 1, 255, &o->compid);
    } else if (strcmp(a, "--target-sysid") == 0) {
        ok = cli_parse_u32(v, 1, 255, &o->target_sysid);
    } else if (strcmp(a, "--target-compid") == 0) {
        ok = cli_parse_u32(v, 1, 255, &o->target_compid);
    } else if (strcmp(a, "--pose-rate") == 0) {
        ok = cli_parse_float_in(v, 0.0f, 1000.0f, &o->pose_rate_hz);
    } else if (strcmp(a, "--pose-timeout-ms") == 0) {
        ok = cli_parse_u32(v, 1, 60000, &o->pose_timeout_ms);
    } else if (strcmp(a, "--sensor-timeout-ms") == 0) {
        ok = cli_parse_u32(v, 1, 600000, &o->sensor_timeout_ms);
    } else if (strcmp(a, "--can") == 0) {
        o->can = v;
    } else if (strcmp(a, "--can-node-id") == 0) {
        ok = cli_parse_u32(v, 1, 127, &o->can_node_id);
    } else if (strcmp(a, "--can-range-mount") == 0) {
        ok = can_mount(o, v);
    } else if (strcmp(a, "--rate") == 0) {
        ok = cli_parse_float_in(v, 0.1f, 100.0f, &o->fa.rate_hz);
    } else if (strcmp(a, "--duration") == 0) {
        ok = cli_parse_float_in(v, 0.0f, 1e7f, &o->fa.duration_s);
        o->fa.duration_s = ok && o->fa.duration_s <= 0.0f ? -1.0f : o->fa.duration_s;
    } else {
        return FEED_OPT_UNKNOWN;
    }
    return ok ? FEED_OPT_OK : FEED_OPT_BAD_VALUE;
}

/* The depth input. */
static int depth_option(run_opts_t *o, const char *a, const char *v)
{
    bool ok = true;
    if (strcmp(a, "--depth-dir") == 0) {
        o->depth_dir = v;
    } else if (strcmp(a, "--depth-intrinsics") == 0) {
        ok = cli_parse_floats(v, o->intrinsics, 4) && o->intrinsics[0] > 0.0f &&
             o->intrinsics[1] > 0.0f;
        o->have_intrinsics = ok;
    } else if (strcmp(a, "--depth-mount") == 0) {
        ok = cli_parse_floats(v, o->mount, 6);
    } else if (strcmp(a, "--depth-max-frames") == 0) {
        ok = cli_parse_u32(v, 1, UINT32_MAX, &o->max_frames);
    } else if (strcmp(a, "--depth-method") == 0) {
        ok = strcmp(v, "projective") == 0 || strcmp(v, "simple") == 0;
        o->depth_projective = ok && strcmp(v, "projective") == 0;
    } else if (strcmp(a, "--depth-stride") == 0) {
        ok = cli_parse_u32(v, 1, 64, &o->stride);
    } else if (strcmp(a, "--depth-min-m") == 0) {
        ok = cli_parse_float_in(v, 0.0f, 100.0f, &o->depth_min_m);
    } else if (strcmp(a, "--depth-max-m") == 0) {
        ok = cli_parse_float_in(v, 0.05f, 100.0f, &o->depth_max_m);
    } else if (strcmp(a, "--max-lag-ms") == 0) {
        ok = cli_parse_u32(v, 0, 3600000, &o->max_lag_ms);
    } else if (strcmp(a, "--replay-speed") == 0) {
        ok = cli_parse_u32(v, 0, 1, &o->replay_speed);
    } else {
        return FEED_OPT_UNKNOWN;
    }
    return ok ? FEED_OPT_OK : FEED_OPT_BAD_VALUE;
}

/* The map, memory and output. */
static int map_option(run_opts_t *o, const char *a, const char *v)
{
    bool ok = true;
    if (strcmp(a, "--res") == 0) {
        ok = cli_parse_float_in(v, 0.001f, 100.0f, &o->res_m);
    } else if (strcmp(a, "--arena-bytes") == 0) {
        ok = cli_parse_size(v, &o->arena_bytes) != 0;
    } else if (strcmp(a, "--keep-radius") == 0) {
        ok = cli_parse_float_in(v, 0.0f, 1000.0f, &o->keep_radius_m);
    } else if (strcmp(a, "-o") == 0) {
        o->out_path = v;
    } else if (strcmp(a, "--save-every") == 0) {
        ok = cli_parse_float_in(v, 0.0f, 1e6f, &o->save_every_s);
    } else if (strcmp(a, "--stats") == 0) {
        o->stats_path = v;
    } else if (strcmp(a, "--feed-log") == 0) {
        o->feed_log_path = v;
    } else {
        return FEED_OPT_UNKNOWN;
    }
    return ok ? FEED_OPT_OK : FEED_OPT_BAD_VALUE;
}

static int run_option(void *ctx, const char *a, const char *v)
{
    run_opts_t *const o = ctx;
    if (v == NULL) {
        if (strcmp(a, "--exit-after-depth") == 0) {
            o->exit_after_depth = true;
        } else if (strcmp(a, "--3d") == 0) {
            o->obstacle_3d = true;
        } else if (strcmp(a, "--mavlink-ranges") == 0) {
            o->mavlink_ranges = true;
        } else {
            o->feed.sectors.ignore_ground = false;
        }
        return FEED_OPT_OK;
    }
    int r = feed_args_sector_option(&o->feed.sectors, a, v);
    r = r != FEED_OPT_UNKNOWN ? r : link_option(o, a, v);
    r = r != FEED_OPT_UNKNOWN ? r : depth_option(o, a, v);
    return r != FEED_OPT_UNKNOWN ? r : map_option(o, a, v);
}

int run_args_parse(run_opts_t *o, int argc, char **argv)
{
    defaults(o);
    if (run_config_expand(argc, argv, &argc, &argv) != 0) {
        return 2;
    }
    const feed_cmd_t cmd = {"run", run_args_usage, run_flags, run_option, o};
    const int parsed = feed_args_parse(&o->fa, &cmd, argc, argv);
    if (parsed != FEED_ARGS_RUN) {
        return parsed;
    }
    const int n_links = (o->udp != NULL) + (o->udp_listen != NULL) + (o->serial != NULL);
    if (n_links != 1) {
        cli_error("run", "needs exactly one of --udp, --udp-listen, --serial");
        run_args_usage(stderr);
        return 2;
    }
    if (o->depth_max_m <= o->depth_min_m || (o->exit_after_depth && o->depth_dir == NULL)) {
        cli_error("run", "--depth-max-m must exceed --depth-min-m; --exit-after-depth needs "
                  "--depth-dir");
        return 2;
    }
    return RUN_ARGS_GO;
}
