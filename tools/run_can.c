/* SPDX-License-Identifier: BSD-3-Clause */
/* run_can.c - the DroneCAN front end of `occmap run` (run_can.h). */
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"
#include "run_can.h"
#include "run_link.h"
#include "run_ranges.h"

#define RX_PER_TURN 256u /* frames taken per loop turn: the rest waits for the next (~20 ms) */

static occ_err_t bus_open(run_can_t *c, const char *spec, char *msg, size_t len)
{
    uint32_t bus = 0;
    if (strncmp(spec, "mcast:", 6) == 0) {
        c->use_mcast = true;
        if (!cli_parse_u32(spec + 6, 0, 255, &bus)) {
            (void)snprintf(msg, len, "mcast:BUS wants BUS 0..255");
            return OCC_ERR_ARG;
        }
        const occ_err_t e = occ_can_mcast_open(&c->mc, (unsigned)bus, true, msg, len);
        c->iface = occ_can_mcast_iface(&c->mc);
        return e;
    }
    occ_err_t e = occ_socketcan_open(&c->sc, spec, false, msg, len);
    c->iface = occ_socketcan_iface(&c->sc);
    const occ_can_filter_t all_ext = {0, 0, true};
    if (e == OCC_OK) {
        e = occ_socketcan_set_filters(&c->sc, &all_ext, 1);
    }
    return e;
}

int run_can_open(run_can_t *c, const run_opts_t *o)
{
    char msg[256] = "";
    memset(c, 0, sizeof *c);
    c->sc.fd = -1;
    if (bus_open(c, o->can, msg, sizeof msg) != OCC_OK) {
        cli_error("run", "--can %s: %s", o->can, msg);
        return 1;
    }
    occ_dronecan_config_t nc = occ_dronecan_config_default();
    nc.node_id = (uint8_t)o->can_node_id;
    nc.proximity_period_us = (uint32_t)(1e6 / (double)o->fa.rate_hz);
    nc.stale_after_us = o->pose_timeout_ms * 1000u;
    cli_host_unique_id(nc.unique_id, o->can_node_id);
    if (occ_dronecan_init(&c->node, &nc, &c->iface) != OCC_OK ||
        occ_dronecan_range_rx_init(&c->rx, o->can_mounts, o->n_can_mounts) != OCC_OK) {
        cli_error("run", "bad --can-node-id or --can-range-mount");
        run_can_close(c);
        return 1;
    }
    return 0;
}

void run_can_close(run_can_t *c)
{
    if (c->use_mcast) {
        occ_can_mcast_close(&c->mc);
    } else {
        occ_socketcan_close(&c->sc);
    }
}

/* A placed Measurement as one BODY beam on its mount, queued for the mapping thread. */
static void take_reading(run_link_t *l, run_can_t *c, const occ_dronecan_range_reading_t *r,
                         uint64_t now)
{
    static occ_mav_beams_t b; /* link thread only */
    if (!r->beam.valid) {
        c->invalid++;
        return;
    }
    memset(&b, 0, sizeof b);
    b.sensor_id = r->msg.sensor_id;
    b.time_us = r->msg.timestamp_us;
    b.frame = OCC_MAV_BEAMS_BODY;
    b.mount = r->mount->body_from_sensor;
    b.n = 1;
    b.beam[0] = r->beam;
    c->readings++;
    run_ranges_queue(l->st, l->st->ranges, &b, now, RUN_SRC_CAN);
}

static occ_err_t bus_recv(run_can_t *c, occ_can_frame_t *f, bool *got)
{
    return c->use_mcast ? occ_can_mcast_recv(&c->mc, f, 0, got)
                        : occ_socketcan_recv(&c->sc, f, 0, got);
}

void run_can_poll(run_link_t *l, run_can_t *c, uint64_t now, bool fresh)
{
    bool got = true;
    for (unsigned i = 0; i < RX_PER_TURN && got; i++) {
        occ_can_frame_t f;
        if (bus_recv(c, &f, &got) != OCC_OK || !got) {
            break;
        }
        occ_dronecan_range_reading_t r;
        bool done = false;
        (void)occ_dronecan_range_rx_frame(&c->rx, &f, now, &r, &done);
        if (done) {
            take_reading(l, c, &r, now);
        }
        (void)occ_dronecan_ingest(&c->node, &f, now);
    }
    if (now < c->node.next_proximity_us && now < c->node.next_status_us) {
        return; /* nothing due: no map view taken */
    }
    occ_pose_t pose;
    const bool pose_ok = occ_mav_feed_pose(l->feed, now, &pose);
    run_view_t view;
    run_read_begin(l->guard, RUN_READER_FEED, &view); /* the link thread's one reader slot */
    const occ_err_t e = occ_dronecan_poll_map(&c->node, now, view.map, fresh ? now : 0u,
                                              pose_ok ? &pose : NULL, pose_ok ? now : 0u,
                                              &l->feed->cfg.sectors);
    run_read_end(l->guard, &view);
    c->poll_errors += e != OCC_OK;
}

void run_can_print(FILE *f, const run_can_t *c)
{
    const occ_dronecan_stats_t *const s = &c->node.stats;
    fprintf(f, "\"can\": {\"readings\": %llu, \"invalid\": %llu, \"unknown_sensor\": %u, "
            "\"crc_errors\": %u, \"sequence_errors\": %u, \"proximity_sent\": %u, "
            "\"tx_full\": %u, \"tx_errors\": %u, \"bus_off\": %u, \"poll_errors\": %u}",
            (unsigned long long)c->readings, (unsigned long long)c->invalid,
            c->rx.unknown_sensor, c->rx.crc_errors, c->rx.sequence_errors, s->proximity_sent,
            s->tx_full, s->tx_errors, s->bus_off, c->poll_errors);
}
