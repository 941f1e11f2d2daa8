/* SPDX-License-Identifier: BSD-3-Clause */
/* dronecan.c - DroneCAN messages (Proximity, NodeStatus, GetNodeInfo) and the obstacle node. */
#include <math.h>
#include <string.h>

#include "occmap/occ_dronecan.h"

#define NAME_MAX_BYTES 80u

size_t occ_dronecan_encode_proximity(const occ_dronecan_proximity_t *msg, uint8_t out[8])
{
    memset(out, 0, 8);
    if (msg == NULL) {
        return 8;
    }
    occ_dronecan_put_bits(out, 0, 8, msg->sensor_id);
    occ_dronecan_put_bits(out, 8, 3, (uint64_t)((unsigned)msg->reading_type & 7u));
    occ_dronecan_put_bits(out, 11, 5, (uint64_t)(msg->flags & 0x1Fu));
    occ_dronecan_put_bits(out, 16, 16, occ_float16_from_float(msg->yaw_deg));
    occ_dronecan_put_bits(out, 32, 16, occ_float16_from_float(msg->pitch_deg));
    occ_dronecan_put_bits(out, 48, 16, occ_float16_from_float(msg->distance_m));
    return 8;
}

size_t occ_dronecan_encode_node_status(const occ_dronecan_node_status_t *msg, uint8_t out[7])
{
    memset(out, 0, 7);
    if (msg == NULL) {
        return 7;
    }
    occ_dronecan_put_bits(out, 0, 32, msg->uptime_sec);
    occ_dronecan_put_bits(out, 32, 2, (uint64_t)(msg->health & 3u));
    occ_dronecan_put_bits(out, 34, 3, (uint64_t)(msg->mode & 7u));
    occ_dronecan_put_bits(out, 37, 3, (uint64_t)(msg->sub_mode & 7u));
    occ_dronecan_put_bits(out, 40, 16, msg->vendor_status);
    return 7;
}

size_t occ_dronecan_encode_node_info(const occ_dronecan_node_info_t *info, uint8_t *out,
                                     size_t cap)
{
    if (info == NULL || out == NULL || cap < OCC_DRONECAN_MAX_PAYLOAD) {
        return 0;
    }
    memset(out, 0, OCC_DRONECAN_MAX_PAYLOAD);
    (void)occ_dronecan_encode_node_status(&info->status, out);
    size_t n = 7;
    out[n++] = info->sw_major;
    out[n++] = info->sw_minor;
    out[n++] = info->sw_optional_flags;
    occ_dronecan_put_bits(out, 8u * n, 32, info->vcs_commit);
    n += 4u;
    occ_dronecan_put_bits(out, 8u * n, 64, info->image_crc);
    n += 8u;
    out[n++] = info->hw_major;
    out[n++] = info->hw_minor;
    memcpy(out + n, info->unique_id, 16);
    n += 16u;
    out[n++] = 0; /* certificate_of_authenticity: empty, 8-bit length (not the last field) */
    /* name is the last field: tail array optimization, no length prefix. */
    if (info->name != NULL) {
        for (size_t i = 0; i < NAME_MAX_BYTES && info->name[i] != '\0'; i++) {
            out[n++] = (uint8_t)info->name[i];
        }
    }
    return n;
}

occ_dronecan_config_t occ_dronecan_config_default(void)
{
    occ_dronecan_config_t c;
    memset(&c, 0, sizeof c);
    c.node_id = 0;
    c.sensor_id = 0;
    c.priority = 24;
    c.proximity_period_us = 100000u;
    c.status_period_us = 1000000u;
    c.stale_after_us = 500000u;
    c.pitch_deg = 0.0f;
    c.name = "org.occmap.obstacles";
    c.sw_major = 0;
    c.sw_minor = 1;
    return c;
}

occ_err_t occ_dronecan_init(occ_dronecan_node_t *node, const occ_dronecan_config_t *cfg,
                            const occ_can_iface_t *iface)
{
    if (node == NULL || cfg == NULL || iface == NULL || iface->tx == NULL) {
        return OCC_ERR_ARG;
    }
    if (cfg->node_id < 1u || cfg->node_id > 127u || cfg->priority > 31u ||
        cfg->proximity_period_us == 0u || cfg->status_period_us == 0u ||
        cfg->status_period_us > 1000000u || !isfinite(cfg->pitch_deg)) {
        return OCC_ERR_ARG;
    }
    memset(node, 0, sizeof *node);
    node->cfg = *cfg;
    node->priv.iface = *iface;
    node->health = OCC_NODE_HEALTH_ERROR;
    node->mode = OCC_NODE_MODE_INITIALIZATION;
    return OCC_OK;
}

/* Send one transfer and keep the books. The transfer id advances once any frame went out, so a
 * receiver never sees two different transfers with the same id back to back. */
static occ_err_t send_counted(occ_dronecan_node_t *node, uint32_t can_id, uint64_t sig,
                              uint8_t *tid, const uint8_t *payload, size_t len)
{
    size_t sent = 0;
    const occ_err_t e = occ_dronecan_send_transfer(&node->priv.iface, can_id, sig,
                                                   (uint8_t)(*tid & OCC_DRONECAN_TAIL_TID),
                                                   payload, len, &sent);
    node->stats.tx_frames += (uint32_t)sent;
    if (e == OCC_OK || sent > 0u) {
        *tid = (uint8_t)((*tid + 1u) & OCC_DRONECAN_TAIL_TID);
    }
    if (e == OCC_OK) {
        node->stats.tx_transfers++;
    } else if (e == OCC_ERR_NOMEM) {
        node->stats.tx_full++;
    } else if (e == OCC_ERR_IO) {
        node->stats.tx_errors++;
    }
    return e;
}

occ_err_t occ_dronecan_publish_proximity(occ_dronecan_node_t *node,
                                         const occ_dronecan_proximity_t *msg)
{
    if (node == NULL || msg == NULL) {
        return OCC_ERR_ARG;
    }
    uint8_t payload[8];
    (void)occ_dronecan_encode_proximity(msg, payload);
    const uint32_t id = occ_dronecan_msg_id(node->cfg.priority, OCC_DRONECAN_PROXIMITY_ID,
                                            node->cfg.node_id);
    const occ_err_t e = send_counted(node, id, OCC_DRONECAN_PROXIMITY_SIG, &node->priv.tid_proximity,
                                     payload, sizeof payload);
    if (e == OCC_OK) {
        node->stats.proximity_sent++;
    }
    return e;
}

occ_err_t occ_dronecan_publish_status(occ_dronecan_node_t *node, uint64_t now_us)
{
    if (node == NULL) {
        return OCC_ERR_ARG;
    }
    const uint64_t up_us = (node->priv.started && now_us > node->priv.start_us) ? now_us - node->priv.start_us : 0u;
    occ_dronecan_node_status_t st;
    st.uptime_sec = (uint32_t)(up_us / 1000000u);
    st.health = node->health;
    st.mode = node->mode;
    st.sub_mode = 0;
    st.vendor_status = node->last_obstacles;
    uint8_t payload[7];
    (void)occ_dronecan_encode_node_status(&st, payload);
    const uint32_t id = occ_dronecan_msg_id(node->cfg.priority, OCC_DRONECAN_NODESTATUS_ID,
                                            node->cfg.node_id);
    return send_counted(node, id, OCC_DRONECAN_NODESTATUS_SIG, &node->priv.tid_status, payload,
                        sizeof payload);
}

/* Body yaw of sector i's centre in (-180, 180]. */
static float sector_yaw_deg(const occ_sectors_config_t *cfg, unsigned i)
{
    float y = fmodf(cfg->angle_offset_deg + (float)i * cfg->increment_deg, 360.0f);
    if (y > 180.0f) {
        y -= 360.0f;
    } else if (y <= -180.0f) {
        y += 360.0f;
    }
    return y;
}

/* Worst of two results: a driver error beats a full queue beats OK. */
static occ_err_t worse(occ_err_t a, occ_err_t b)
{
    if (a == OCC_ERR_IO || b == OCC_ERR_IO) {
        return OCC_ERR_IO;
    }
    return (a != OCC_OK) ? a : b;
}

occ_err_t occ_dronecan_publish_sectors(occ_dronecan_node_t *node, const occ_sectors_t *sectors,
                                       const occ_sectors_config_t *cfg, size_t *sent)
{
    if (sent != NULL) {
        *sent = 0;
    }
    if (node == NULL || sectors == NULL || cfg == NULL || sectors->n > OCC_SECTORS_MAX) {
        return OCC_ERR_ARG;
    }
    occ_err_t res = OCC_OK;
    uint16_t obstacles = 0;
    for (unsigned i = 0; i < sectors->n; i++) {
        const uint16_t d = sectors->distance_cm[i];
        if (d == UINT16_MAX || d >= cfg->max_distance_cm) {
            continue; /* unknown, or observed free up to the range limit */
        }
        obstacles++;
        occ_dronecan_proximity_t m;
        m.sensor_id = node->cfg.sensor_id;
        m.reading_type = OCC_PROX_GOOD;
        m.flags = 0;
        m.yaw_deg = sector_yaw_deg(cfg, i);
        m.pitch_deg = node->cfg.pitch_deg;
        m.distance_m = (float)d / 100.0f;
        const occ_err_t e = occ_dronecan_publish_proximity(node, &m);
        if (e == OCC_OK && sent != NULL) {
            (*sent)++;
        }
        if (e == OCC_ERR_ARG) {
            return e;
        }
        res = worse(res, e);
    }
    node->last_obstacles = obstacles;
    return res;
}

static uint64_t next_due(uint64_t due, uint64_t now, uint32_t period)
{
    /* Keep the cadence; after a long gap restart it from now instead of bursting. */
    due += period;
    return (due <= now) ? now + period : due;
}

occ_err_t occ_dronecan_poll(occ_dronecan_node_t *node, uint64_t now_us,
                            const occ_dronecan_view_t *view)
{
    if (node == NULL || view == NULL) {
        return OCC_ERR_ARG;
    }
    const bool good = view->have_map && view->fresh;
    if (good && (view->sectors == NULL || view->sectors_cfg == NULL)) {
        return OCC_ERR_ARG;
    }
    if (!node->priv.started) {
        node->priv.started = true;
        node->priv.start_us = now_us;
        node->next_proximity_us = now_us;
        node->next_status_us = now_us;
    }
    node->health = (uint8_t)(!view->have_map ? OCC_NODE_HEALTH_ERROR
                             : (!view->fresh ? OCC_NODE_HEALTH_WARNING : OCC_NODE_HEALTH_OK));
    node->mode = (uint8_t)(view->have_map ? OCC_NODE_MODE_OPERATIONAL
                                          : OCC_NODE_MODE_INITIALIZATION);
    occ_err_t res = OCC_OK;
    if (now_us >= node->next_proximity_us) {
        node->next_proximity_us = next_due(node->next_proximity_us, now_us,
                                           node->cfg.proximity_period_us);
        if (good) {
            res = worse(res, occ_dronecan_publish_sectors(node, view->sectors, view->sectors_cfg,
                                                          NULL));
        } else {
            occ_dronecan_proximity_t m;
            memset(&m, 0, sizeof m);
            m.sensor_id = node->cfg.sensor_id;
            m.reading_type = view->have_map ? OCC_PROX_NO_DATA : OCC_PROX_NOT_CONNECTED;
            node->last_obstacles = 0;
            res = worse(res, occ_dronecan_publish_proximity(node, &m));
        }
    }
    if (now_us >= node->next_status_us) {
        node->next_status_us = next_due(node->next_status_us, now_us, node->cfg.status_period_us);
        res = worse(res, occ_dronecan_publish_status(node, now_us));
    }
    return res;
}

static occ_err_t answer_node_info(occ_dronecan_node_t *node, uint8_t priority, uint8_t dst,
                                  uint8_t tid, uint64_t now_us)
{
    occ_dronecan_node_info_t info;
    memset(&info, 0, sizeof info);
    const uint64_t up_us = (node->priv.started && now_us > node->priv.start_us) ? now_us - node->priv.start_us : 0u;
    info.status.uptime_sec = (uint32_t)(up_us / 1000000u);
    info.status.health = node->health;
    info.status.mode = node->mode;
    info.status.vendor_status = node->last_obstacles;
    info.sw_major = node->cfg.sw_major;
    info.sw_minor = node->cfg.sw_minor;
    info.sw_optional_flags = (node->cfg.vcs_commit != 0u) ? 1u : 0u;
    info.vcs_commit = node->cfg.vcs_commit;
    info.hw_major = node->cfg.hw_major;
    info.hw_minor = node->cfg.hw_minor;
    memcpy(info.unique_id, node->cfg.unique_id, sizeof info.unique_id);
    info.name = node->cfg.name;
    uint8_t payload[OCC_DRONECAN_MAX_PAYLOAD];
    const size_t len = occ_dronecan_encode_node_info(&info, payload, sizeof payload);
    const uint32_t id = occ_dronecan_svc_id(priority, OCC_DRONECAN_GETNODEINFO_ID, false, dst,
                                            node->cfg.node_id);
    uint8_t t = tid;
    const occ_err_t e = send_counted(node, id, OCC_DRONECAN_GETNODEINFO_SIG, &t, payload, len);
    if (e == OCC_OK) {
        node->stats.node_info_answered++;
    }
    return e;
}

occ_err_t occ_dronecan_ingest(occ_dronecan_node_t *node, const occ_can_frame_t *frame,
                              uint64_t now_us)
{
    if (node == NULL || frame == NULL) {
        return OCC_ERR_ARG;
    }
    node->stats.rx_frames++;
    if ((frame->flags & OCC_CAN_FLAG_ERR) != 0u) {
        node->stats.rx_bus_errors++;
        if ((frame->id & OCC_CAN_ERR_BUS_OFF) != 0u) {
            node->stats.bus_off++;
        }
        return OCC_OK;
    }
    const uint32_t id = frame->id;
    const bool is_service = (id & 0x80u) != 0u;
    const bool is_request = (id & 0x8000u) != 0u;
    const uint8_t service_id = (uint8_t)((id >> 16) & 0xFFu);
    const uint8_t dst = (uint8_t)((id >> 8) & 0x7Fu);
    const uint8_t src = (uint8_t)(id & 0x7Fu);
    if ((frame->flags & (OCC_CAN_FLAG_EXT | OCC_CAN_FLAG_RTR)) != OCC_CAN_FLAG_EXT ||
        frame->len == 0u || frame->len > OCC_CAN_MAX_DATA || !is_service || !is_request ||
        service_id != OCC_DRONECAN_GETNODEINFO_ID || dst != node->cfg.node_id || src == 0u) {
        node->stats.rx_ignored++;
        return OCC_OK;
    }
    const uint8_t tail = frame->data[frame->len - 1u];
    const uint8_t se = OCC_DRONECAN_TAIL_START | OCC_DRONECAN_TAIL_END;
    if ((tail & se) != se || (tail & OCC_DRONECAN_TAIL_TOGGLE) != 0u) {
        node->stats.rx_ignored++; /* the request is empty: it is always one frame */
        return OCC_OK;
    }
    return answer_node_info(node, (uint8_t)((id >> 24) & 0x1Fu), src,
                            (uint8_t)(tail & OCC_DRONECAN_TAIL_TID), now_us);
}
