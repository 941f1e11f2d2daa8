/* SPDX-License-Identifier: BSD-3-Clause */
/* socketcan.c - Linux SocketCAN port: one non-blocking CAN_RAW socket, classic and FD frames. */
#include <errno.h>
#include <net/if.h>
#include <poll.h>
#include <stdio.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>

#include "occmap/host/occ_socketcan.h"

#include "fd_wait.h"

#ifndef CANFD_FDF
#define CANFD_FDF 0x04
#endif

static void set_msg(char *msg, size_t len, const char *what, const char *ifname, int err)
{
    if (msg != NULL && len > 0u) {
        (void)snprintf(msg, len, "socketcan %s: %s: %s", ifname, what, strerror(err));
    }
}

occ_err_t occ_socketcan_open(occ_socketcan_t *s, const char *ifname, bool fd_frames, char *msg,
                             size_t msg_len)
{
    if (s == NULL || ifname == NULL || strlen(ifname) >= IFNAMSIZ) {
        return OCC_ERR_ARG;
    }
    memset(s, 0, sizeof *s);
    s->fd = -1;
    const int fd = socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
    if (fd < 0) {
        set_msg(msg, msg_len, "socket(PF_CAN)", ifname, errno);
        return OCC_ERR_IO;
    }
    struct ifreq ifr;
    memset(&ifr, 0, sizeof ifr);
    memcpy(ifr.ifr_name, ifname, strlen(ifname) + 1u);
    if (ioctl(fd, SIOCGIFINDEX, &ifr) < 0) {
        set_msg(msg, msg_len, "no such interface", ifname, errno);
        (void)close(fd);
        return OCC_ERR_IO;
    }
    if (fd_frames) {
        const int on = 1;
        if (setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FD_FRAMES, &on, sizeof on) < 0) {
            set_msg(msg, msg_len, "CAN_RAW_FD_FRAMES", ifname, errno);
            (void)close(fd);
            return OCC_ERR_UNSUPPORTED;
        }
    }
    const can_err_mask_t errs = CAN_ERR_TX_TIMEOUT | CAN_ERR_LOSTARB | CAN_ERR_CRTL |
                                CAN_ERR_PROT | CAN_ERR_TRX | CAN_ERR_ACK | CAN_ERR_BUSOFF |
                                CAN_ERR_BUSERROR | CAN_ERR_RESTARTED;
    if (setsockopt(fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &errs, sizeof errs) < 0) {
        set_msg(msg, msg_len, "CAN_RAW_ERR_FILTER", ifname, errno);
        (void)close(fd);
        return OCC_ERR_IO;
    }
    struct sockaddr_can addr;
    memset(&addr, 0, sizeof addr);
    addr.can_family = AF_CAN;
    addr.can_ifindex = ifr.ifr_ifindex;
    if (bind(fd, (struct sockaddr *)&addr, sizeof addr) < 0) {
        set_msg(msg, msg_len, "bind", ifname, errno);
        (void)close(fd);
        return OCC_ERR_IO;
    }
    s->fd = fd;
    s->fd_frames = fd_frames;
    return OCC_OK;
}

occ_err_t occ_socketcan_set_filters(occ_socketcan_t *s, const occ_can_filter_t *filters, size_t n)
{
    if (s == NULL || s->fd < 0 || n > OCC_CAN_MAX_FILTERS || (filters == NULL && n > 0u)) {
        return OCC_ERR_ARG;
    }
    struct can_filter kf[OCC_CAN_MAX_FILTERS];
    for (size_t i = 0; i < n; i++) {
        const uint32_t idmask = filters[i].ext ? CAN_EFF_MASK : CAN_SFF_MASK;
        kf[i].can_id = (filters[i].id & idmask) | (filters[i].ext ? CAN_EFF_FLAG : 0u);
        /* Match the EXT flag and never RTR frames. */
        kf[i].can_mask = (filters[i].mask & idmask) | CAN_EFF_FLAG | CAN_RTR_FLAG;
    }
    if (setsockopt(s->fd, SOL_CAN_RAW, CAN_RAW_FILTER, n > 0u ? kf : NULL,
                   (socklen_t)(n * sizeof kf[0])) < 0) {
        return OCC_ERR_IO;
    }
    return OCC_OK;
}

static bool fd_len_valid(unsigned len)
{
    static const unsigned ok[] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 16, 20, 24, 32, 48, 64};
    for (size_t i = 0; i < sizeof ok / sizeof ok[0]; i++) {
        if (ok[i] == len) {
            return true;
        }
    }
    return false;
}

occ_err_t occ_socketcan_send(occ_socketcan_t *s, const occ_can_frame_t *f)
{
    if (s == NULL || s->fd < 0 || f == NULL || (f->flags & OCC_CAN_FLAG_ERR) != 0u) {
        return OCC_ERR_ARG;
    }
    const bool is_fd = (f->flags & OCC_CAN_FLAG_FD) != 0u;
    if ((is_fd && (!s->fd_frames || !fd_len_valid(f->len))) || (!is_fd && f->len > 8u)) {
        return OCC_ERR_ARG;
    }
    struct canfd_frame kf;
    memset(&kf, 0, sizeof kf);
    const bool ext = (f->flags & OCC_CAN_FLAG_EXT) != 0u;
    kf.can_id = ext ? ((f->id & CAN_EFF_MASK) | CAN_EFF_FLAG) : (f->id & CAN_SFF_MASK);
    if (!is_fd && (f->flags & OCC_CAN_FLAG_RTR) != 0u) {
        kf.can_id |= CAN_RTR_FLAG;
    }
    kf.len = f->len;
    if (is_fd) {
        kf.flags = (uint8_t)(CANFD_FDF | (((f->flags & OCC_CAN_FLAG_BRS) != 0u) ? CANFD_BRS : 0));
    }
    memcpy(kf.data, f->data, f->len);
    const size_t mtu = is_fd ? CANFD_MTU : CAN_MTU;
    const ssize_t w = write(s->fd, &kf, mtu);
    if (w == (ssize_t)mtu) {
        return OCC_OK;
    }
    if (w < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == ENOBUFS)) {
        s->tx_full++;
        return OCC_ERR_NOMEM;
    }
    return (w < 0 && errno == EINVAL) ? OCC_ERR_ARG : OCC_ERR_IO;
}

static uint32_t map_error(const struct canfd_frame *kf)
{
    const canid_t c = kf->can_id & CAN_ERR_MASK;
    uint32_t e = 0;
    if ((c & CAN_ERR_BUSOFF) != 0u) {
        e |= OCC_CAN_ERR_BUS_OFF;
    }
    if ((c & CAN_ERR_CRTL) != 0u &&
        (kf->data[1] & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE)) != 0u) {
        e |= OCC_CAN_ERR_PASSIVE;
    }
    if ((c & CAN_ERR_TX_TIMEOUT) != 0u) {
        e |= OCC_CAN_ERR_TX_TIMEOUT;
    }
    if ((c & CAN_ERR_LOSTARB) != 0u) {
        e |= OCC_CAN_ERR_LOST_ARB;
    }
    if ((c & (CAN_ERR_PROT | CAN_ERR_ACK | CAN_ERR_BUSERROR)) != 0u) {
        e |= OCC_CAN_ERR_PROTOCOL;
    }
    return e != 0u ? e : OCC_CAN_ERR_OTHER;
}

occ_err_t occ_socketcan_recv(occ_socketcan_t *s, occ_can_frame_t *f, int timeout_ms, bool *got)
{
    if (got != NULL) {
        *got = false;
    }
    if (s == NULL || s->fd < 0 || f == NULL || got == NULL) {
        return OCC_ERR_ARG;
    }
    for (;;) {
        struct canfd_frame kf;
        const ssize_t r = read(s->fd, &kf, sizeof kf);
        if (r < 0) {
            const int w = occ_fd_wait_after_failed_read(s->fd, &timeout_ms);
            if (w < 0) {
                return OCC_ERR_IO;
            }
            if (w == 0) {
                return OCC_OK;
            }
            continue;
        }
        if (r != (ssize_t)CAN_MTU && r != (ssize_t)CANFD_MTU) {
            return OCC_ERR_IO;
        }
        memset(f, 0, sizeof *f);
        if ((kf.can_id & CAN_ERR_FLAG) != 0u) {
            f->flags = OCC_CAN_FLAG_ERR;
            f->id = map_error(&kf);
            f->len = (uint8_t)(kf.len > 8u ? 8u : kf.len);
            memcpy(f->data, kf.data, f->len);
            s->rx_errors++;
            *got = true;
            return OCC_OK;
        }
        const bool ext = (kf.can_id & CAN_EFF_FLAG) != 0u;
        f->id = kf.can_id & (ext ? CAN_EFF_MASK : CAN_SFF_MASK);
        f->flags = (uint8_t)(ext ? OCC_CAN_FLAG_EXT : 0u);
        if (r == (ssize_t)CANFD_MTU) {
            f->flags = (uint8_t)(f->flags | OCC_CAN_FLAG_FD);
            if ((kf.flags & CANFD_BRS) != 0u) { /* kernel 6.x also sets CANFD_FDF: test bits */
                f->flags = (uint8_t)(f->flags | OCC_CAN_FLAG_BRS);
            }
        } else if ((kf.can_id & CAN_RTR_FLAG) != 0u) {
            f->flags = (uint8_t)(f->flags | OCC_CAN_FLAG_RTR);
        }
        f->len = (uint8_t)(kf.len > OCC_CAN_MAX_DATA ? OCC_CAN_MAX_DATA : kf.len);
        memcpy(f->data, kf.data, f->len);
        *got = true;
        return OCC_OK;
    }
}

void occ_socketcan_close(occ_socketcan_t *s)
{
    if (s != NULL && s->fd >= 0) {
        (void)close(s->fd);
        s->fd = -1;
    }
}

static occ_err_t socketcan_tx(void *user, const occ_can_frame_t *f)
{
    return occ_socketcan_send(user, f);
}

occ_can_iface_t occ_socketcan_iface(occ_socketcan_t *s)
{
    occ_can_iface_t i = {socketcan_tx, NULL, s};
    return i;
}
