/* SPDX-License-Identifier: BSD-3-Clause */
/* link.c - read, write, wait and close for every POSIX link kind. */
#include <errno.h>
#include <poll.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "occmap/host/occ_link_posix.h"

occ_err_t occ_link_read(occ_link_t *l, uint8_t *buf, size_t cap, size_t *n)
{
    if (l == NULL || buf == NULL || n == NULL || l->fd < 0) {
        return OCC_ERR_ARG;
    }
    *n = 0;
    ssize_t got;
    if (l->kind == OCC_LINK_SERIAL) {
        got = read(l->fd, buf, cap);
    } else {
        struct sockaddr_storage from;
        socklen_t from_len = sizeof from;
        got = recvfrom(l->fd, buf, cap, 0, (struct sockaddr *)&from, &from_len);
        if (got >= 0 && l->kind == OCC_LINK_UDP_LISTEN && from_len <= sizeof l->peer) {
            memcpy(l->peer, &from, from_len);
            l->peer_len = (uint32_t)from_len;
            l->have_peer = true;
        }
    }
    if (got < 0) {
        if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) {
            return OCC_OK;
        }
        /* A UDP client gets ECONNREFUSED after an ICMP "port unreachable": not fatal. */
        if (errno == ECONNREFUSED) {
            return OCC_OK;
        }
        l->io_errors++;
        return OCC_ERR_IO;
    }
    *n = (size_t)got;
    l->rx_bytes += (uint64_t)got;
    return OCC_OK;
}

occ_err_t occ_link_write(occ_link_t *l, const uint8_t *data, size_t n)
{
    if (l == NULL || data == NULL || l->fd < 0) {
        return OCC_ERR_ARG;
    }
    if (!l->have_peer) {
        l->tx_dropped++;
        return OCC_OK;
    }
    ssize_t put;
    if (l->kind == OCC_LINK_SERIAL) {
        put = write(l->fd, data, n);
    } else {
        put = sendto(l->fd, data, n, 0, (const struct sockaddr *)(const void *)l->peer,
                     (socklen_t)l->peer_len);
    }
    if (put < 0) {
        if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR || errno == ENOBUFS ||
            errno == ECONNREFUSED) {
            l->tx_dropped++;
            return OCC_OK;
        }
        l->io_errors++;
        return OCC_ERR_IO;
    }
    if ((size_t)put < n) {
        l->tx_dropped++; /* a serial buffer took part of the frame: the peer resyncs */
    }
    l->tx_bytes += (uint64_t)put;
    return OCC_OK;
}

bool occ_link_wait(occ_link_t *l, uint64_t timeout_us)
{
    if (l == NULL || l->fd < 0) {
        return false;
    }
    struct pollfd p;
    p.fd = l->fd;
    p.events = POLLIN;
    p.revents = 0;
    const uint64_t ms = (timeout_us + 999u) / 1000u;
    const int rc = poll(&p, 1, ms > 1000000u ? 1000000 : (int)ms);
    return rc > 0 && (p.revents & POLLIN) != 0;
}

void occ_link_close(occ_link_t *l)
{
    if (l != NULL && l->fd >= 0) {
        (void)close(l->fd);
        l->fd = -1;
        l->kind = OCC_LINK_NONE;
    }
}
