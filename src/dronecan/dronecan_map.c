/* SPDX-License-Identifier: BSD-3-Clause */
/* dronecan_map.c - the DroneCAN node fed from a map and a pose through the sector module. */
#include "occmap/occ_dronecan.h"

static bool within(uint64_t now_us, uint64_t stamp_us, uint32_t max_age_us)
{
    /* A stamp from the future (clock skew) counts as fresh. */
    return stamp_us >= now_us || now_us - stamp_us <= max_age_us;
}

occ_err_t occ_dronecan_poll_map(occ_dronecan_node_t *node, uint64_t now_us, const occ_map_t *map,
                                uint64_t map_stamp_us, const occ_pose_t *pose,
                                uint64_t pose_stamp_us, const occ_sectors_config_t *sectors_cfg)
{
    if (node == NULL || sectors_cfg == NULL) {
        return OCC_ERR_ARG;
    }
    occ_dronecan_view_t view;
    view.have_map = map != NULL;
    view.fresh = view.have_map && pose != NULL &&
                 within(now_us, map_stamp_us, node->cfg.stale_after_us) &&
                 within(now_us, pose_stamp_us, node->cfg.stale_after_us);
    view.sectors = NULL;
    view.sectors_cfg = sectors_cfg;
    const bool due = !node->priv.started || now_us >= node->next_proximity_us;
    occ_err_t se = OCC_OK;
    if (view.fresh && due) {
        se = occ_sectors_compute(map, pose, sectors_cfg, &node->priv.sectors);
        if (se != OCC_OK) {
            view.fresh = false; /* e.g. the vehicle left the map: say NO_DATA, keep NodeStatus */
        }
    }
    if (view.fresh) {
        view.sectors = &node->priv.sectors; /* only read when due, i.e. just computed */
    }
    const occ_err_t pe = occ_dronecan_poll(node, now_us, &view);
    return (se != OCC_OK) ? se : pe;
}
