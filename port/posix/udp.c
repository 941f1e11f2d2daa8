/* SPDX-License-Identifier: BSD-3-Clause */
/* udp.c - non-blocking UDP links: client (fixed destination) and udpin-style server. */
#include <errno.h>
#include <fcntl.h>
#include <netdb.h>
#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "occmap/host/occ_link_posix.h"

static void say(char *msg, size_t len, const char *what, const char *detail)
{
    if (msg != NULL && len > 0u) {
        (void)snprintf(msg, len, "%s: %s", what, detail);
    }
}

static occ_err_t resolve(const char *host, uint16_t port, bool passive, struct addrinfo **res,
                         char *msg, size_t msg_len)
{
    struct addrinfo hints;
    memset(&hints, 0, sizeof hints);
    hints.ai_family = AF_UNSPEC;
    hints.ai_socktype = SOCK_DGRAM;
    hints.ai_flags = passive ? AI_PASSIVE : 0;
    char ports[8];
    (void)snprintf(ports, sizeof ports, "%u", (unsigned)port);
    const int rc = getaddrinfo(host, ports, &hints, res);
    if (rc != 0) {
        say(msg, msg_len, host != NULL ? host : "*", gai_strerror(rc));
        return OCC_ERR_ARG;
    }
    return OCC_OK;
}

static int open_socket(const struct addrinfo *ai)
{
    const int fd = socket(ai->ai_family, ai->ai_socktype, ai->ai_protocol);
    if (fd < 0) {
        return -1;
    }
    const int flags = fcntl(fd, F_GETFL, 0);
    if (flags < 0 || fcntl(fd, F_SETFL, flags | O_NONBLOCK) != 0) {
        (void)close(fd);
        return -1;
    }
    return fd;
}

occ_err_t occ_link_udp_connect(occ_link_t *l, const char *host, uint16_t port, char *msg,
                               size_t msg_len)
{
    if (l == NULL || host == NULL || port == 0u) {
        return OCC_ERR_ARG;
    }
    memset(l, 0, sizeof *l);
    l->fd = -1;
    struct addrinfo *res = NULL;
    const occ_err_t e = resolve(host, port, false, &res, msg, msg_len);
    if (e != OCC_OK) {
        return e;
    }
    for (const struct addrinfo *ai = res; ai != NULL; ai = ai->ai_next) {
        if (ai->ai_addrlen > sizeof l->peer) {
            continue;
        }
        const int fd = open_socket(ai);
        if (fd < 0) {
            continue;
        }
        l->fd = fd;
        memcpy(l->peer, ai->ai_addr, ai->ai_addrlen);
        l->peer_len = (uint32_t)ai->ai_addrlen;
        l->have_peer = true;
        l->kind = OCC_LINK_UDP_CLIENT;
        break;
    }
    freeaddrinfo(res);
    if (l->fd < 0) {
        say(msg, msg_len, host, strerror(errno));
        return OCC_ERR_IO;
    }
    return OCC_OK;
}

occ_err_t occ_link_udp_listen(occ_link_t *l, const char *bind_host, uint16_t port, char *msg,
                              size_t msg_len)
{
    if (l == NULL) {
        return OCC_ERR_ARG;
    }
    memset(l, 0, sizeof *l);
    l->fd = -1;
    struct addrinfo *res = NULL;
    const occ_err_t e = resolve(bind_host, port, true, &res, msg, msg_len);
    if (e != OCC_OK) {
        return e;
    }
    int err = 0;
    for (const struct addrinfo *ai = res; ai != NULL; ai = ai->ai_next) {
        const int fd = open_socket(ai);
        if (fd < 0) {
            err = errno;
            continue;
        }
        const int one = 1;
        (void)setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
        if (bind(fd, ai->ai_addr, ai->ai_addrlen) != 0) {
            err = errno;
            (void)close(fd);
            continue;
        }
        l->fd = fd;
        l->kind = OCC_LINK_UDP_LISTEN;
        break;
    }
    freeaddrinfo(res);
    if (l->fd < 0) {
        say(msg, msg_len, "bind", strerror(err));
        return OCC_ERR_IO;
    }
    return OCC_OK;
}
