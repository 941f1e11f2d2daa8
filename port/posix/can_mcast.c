/* SPDX-License-Identifier: BSD-3-Clause */
/* can_mcast.c - CAN frames over UDP multicast, pydronecan `mcast:` / ArduPilot SITL format. */
#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <poll.h>
#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "occmap/host/occ_can_mcast.h"

#include "fd_wait.h"

#define HDR_LEN 10u
#define FLAG_CANFD 0x0001u

static void set_msg(char *msg, size_t len, const char *what, int err)
{
    if (msg != NULL && len > 0u) {
        (void)snprintf(msg, len, "can mcast: %s: %s", what, strerror(err));
    }
}

static void put16(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)(v & 0xFFu);
    p[1] = (uint8_t)((v >> 8) & 0xFFu);
}

static uint32_t get16(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8);
}

size_t occ_can_mcast_encode(const occ_can_frame_t *f, uint8_t *out, size_t cap)
{
    if (f == NULL || out == NULL || f->len > OCC_CAN_MAX_DATA || cap < HDR_LEN + f->len) {
        return 0;
    }
    put16(out, OCC_CAN_MCAST_MAGIC);
    put16(out + 4, ((f->flags & OCC_CAN_FLAG_FD) != 0u) ? FLAG_CANFD : 0u);
    const bool ext = (f->flags & OCC_CAN_FLAG_EXT) != 0u;
    const uint32_t id = (f->id & (ext ? OCC_CAN_EXT_ID_MASK : 0x7FFu)) | (ext ? 0x80000000u : 0u);
    for (unsigned i = 0; i < 4u; i++) {
        out[6u + i] = (uint8_t)(id >> (8u * i));
    }
    memcpy(out + HDR_LEN, f->data, f->len);
    const size_t n = HDR_LEN + f->len;
    put16(out + 2, occ_dronecan_crc16(0xFFFFu, out + 4, n - 4u));
    return n;
}

occ_err_t occ_can_mcast_decode(const uint8_t *pkt, size_t len, occ_can_frame_t *f)
{
    if (pkt == NULL || f == NULL) {
        return OCC_ERR_ARG;
    }
    if (len < HDR_LEN || len > HDR_LEN + OCC_CAN_MAX_DATA || get16(pkt) != OCC_CAN_MCAST_MAGIC ||
        get16(pkt + 2) != occ_dronecan_crc16(0xFFFFu, pkt + 4, len - 4u)) {
        return OCC_ERR_FORMAT;
    }
    const bool fd = (get16(pkt + 4) & FLAG_CANFD) != 0u;
    if (!fd && len > HDR_LEN + 8u) {
        return OCC_ERR_FORMAT;
    }
    uint32_t id = 0;
    for (unsigned i = 0; i < 4u; i++) {
        id |= (uint32_t)pkt[6u + i] << (8u * i);
    }
    memset(f, 0, sizeof *f);
    const bool ext = (id & 0x80000000u) != 0u;
    f->id = id & (ext ? OCC_CAN_EXT_ID_MASK : 0x7FFu);
    f->flags = (uint8_t)((ext ? OCC_CAN_FLAG_EXT : 0u) | (fd ? OCC_CAN_FLAG_FD : 0u));
    f->len = (uint8_t)(len - HDR_LEN);
    memcpy(f->data, pkt + HDR_LEN, f->len);
    return OCC_OK;
}

occ_err_t occ_can_mcast_open(occ_can_mcast_t *m, unsigned bus, bool loopback_only, char *msg,
                             size_t msg_len)
{
    if (m == NULL || bus > 255u) {
        return OCC_ERR_ARG;
    }
    memset(m, 0, sizeof *m);
    m->rx_fd = -1;
    m->tx_fd = -1;
    struct sockaddr_in group;
    memset(&group, 0, sizeof group);
    group.sin_family = AF_INET;
    group.sin_port = htons((uint16_t)OCC_CAN_MCAST_PORT);
    group.sin_addr.s_addr = htonl((239u << 24) | (65u << 16) | (82u << 8) | bus);
    struct in_addr ifaddr;
    ifaddr.s_addr = htonl(loopback_only ? INADDR_LOOPBACK : INADDR_ANY);

    const int rx = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    const int tx = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    const char *what = "socket";
    if (rx < 0 || tx < 0) {
        goto fail;
    }
    const int on = 1;
    what = "SO_REUSEADDR";
    if (setsockopt(rx, SOL_SOCKET, SO_REUSEADDR, &on, sizeof on) < 0) {
        goto fail;
    }
    what = "bind";
    if (bind(rx, (const struct sockaddr *)&group, sizeof group) < 0) {
        goto fail;
    }
    struct ip_mreq mreq;
    mreq.imr_multiaddr = group.sin_addr;
    mreq.imr_interface = ifaddr;
    what = "IP_ADD_MEMBERSHIP";
    if (setsockopt(rx, IPPROTO_IP, IP_ADD_MEMBERSHIP, &mreq, sizeof mreq) < 0) {
        goto fail;
    }
    what = "IP_MULTICAST_IF";
    if (loopback_only && setsockopt(tx, IPPROTO_IP, IP_MULTICAST_IF, &ifaddr, sizeof ifaddr) < 0) {
        goto fail;
    }
    /* TTL 0 never leaves the host; local members still get it through multicast loop. */
    const unsigned char ttl = (unsigned char)(loopback_only ? 0u : 1u);
    const unsigned char loop = 1u;
    what = "IP_MULTICAST_TTL/LOOP";
    if (setsockopt(tx, IPPROTO_IP, IP_MULTICAST_TTL, &ttl, sizeof ttl) < 0 ||
        setsockopt(tx, IPPROTO_IP, IP_MULTICAST_LOOP, &loop, sizeof loop) < 0) {
        goto fail;
    }
    what = "connect";
    if (connect(tx, (const struct sockaddr *)&group, sizeof group) < 0) {
        goto fail;
    }
    struct sockaddr_in me;
    socklen_t ml = sizeof me;
    what = "getsockname";
    if (getsockname(tx, (struct sockaddr *)&me, &ml) < 0) {
        goto fail;
    }
    m->rx_fd = rx;
    m->tx_fd = tx;
    m->tx_port = ntohs(me.sin_port);
    return OCC_OK;
fail:
    set_msg(msg, msg_len, what, errno);
    if (rx >= 0) {
        (void)close(rx);
    }
    if (tx >= 0) {
        (void)close(tx);
    }
    return OCC_ERR_IO;
}

occ_err_t occ_can_mcast_send(occ_can_mcast_t *m, const occ_can_frame_t *f)
{
    if (m == NULL || m->tx_fd < 0 || f == NULL || (f->flags & OCC_CAN_FLAG_ERR) != 0u) {
        return OCC_ERR_ARG;
    }
    uint8_t pkt[HDR_LEN + OCC_CAN_MAX_DATA];
    const size_t n = occ_can_mcast_encode(f, pkt, sizeof pkt);
    if (n == 0u) {
        return OCC_ERR_ARG;
    }
    const ssize_t w = send(m->tx_fd, pkt, n, MSG_DONTWAIT);
    if (w == (ssize_t)n) {
        return OCC_OK;
    }
    if (w < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == ENOBUFS)) {
        m->tx_full++;
        return OCC_ERR_NOMEM;
    }
    return OCC_ERR_IO;
}

occ_err_t occ_can_mcast_recv(occ_can_mcast_t *m, occ_can_frame_t *f, int timeout_ms, bool *got)
{
    if (got != NULL) {
        *got = false;
    }
    if (m == NULL || m->rx_fd < 0 || f == NULL || got == NULL) {
        return OCC_ERR_ARG;
    }
    for (;;) {
        uint8_t pkt[HDR_LEN + OCC_CAN_MAX_DATA + 1u];
        struct sockaddr_in from;
        socklen_t fl = sizeof from;
        const ssize_t r = recvfrom(m->rx_fd, pkt, sizeof pkt, 0, (struct sockaddr *)&from, &fl);
        if (r < 0) {
            const int w = occ_fd_wait_after_failed_read(m->rx_fd, &timeout_ms);
            if (w < 0) {
                return OCC_ERR_IO;
            }
            if (w == 0) {
                return OCC_OK;
            }
            continue;
        }
        if (ntohs(from.sin_port) == m->tx_port) {
            continue; /* our own packet, looped back */
        }
        if (occ_can_mcast_decode(pkt, (size_t)r, f) != OCC_OK) {
            m->rx_bad++;
            continue;
        }
        *got = true;
        return OCC_OK;
    }
}

void occ_can_mcast_close(occ_can_mcast_t *m)
{
    if (m == NULL) {
        return;
    }
    if (m->rx_fd >= 0) {
        (void)close(m->rx_fd);
    }
    if (m->tx_fd >= 0) {
        (void)close(m->tx_fd);
    }
    m->rx_fd = -1;
    m->tx_fd = -1;
}

static occ_err_t mcast_tx(void *user, const occ_can_frame_t *f)
{
    return occ_can_mcast_send(user, f);
}

occ_can_iface_t occ_can_mcast_iface(occ_can_mcast_t *m)
{
    occ_can_iface_t i = {mcast_tx, NULL, m};
    return i;
}
