/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * occ_link_posix.h - byte links to the autopilot on a POSIX host (port/posix/udp.c, serial.c,
 * link.c): UDP (client and udpin-style server) and serial (termios), all non-blocking. Host only:
 * file descriptors and sockets; a firmware build writes its UART through occ_port_uart_write()
 * (occmap/occ_port.h) instead.
 */
#ifndef OCC_LINK_POSIX_H_INCLUDED
#define OCC_LINK_POSIX_H_INCLUDED

#include <stddef.h>
#include <stdint.h>
#include <stdbool.h>

#include "occmap/occ_core.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    OCC_LINK_NONE = 0,
    OCC_LINK_UDP_CLIENT,  /* sends to a fixed HOST:PORT, reads datagrams from anyone */
    OCC_LINK_UDP_LISTEN,  /* bound to a port; sends to whoever sent last (before that: drops) */
    OCC_LINK_SERIAL       /* a tty in raw mode, 8N1, no flow control */
} occ_link_kind_t;

typedef struct {
    occ_link_kind_t kind;
    int fd;
    bool have_peer;
    uint32_t peer_len;
    uint8_t peer[128];    /* struct sockaddr_storage of the destination */
    uint64_t rx_bytes, tx_bytes;
    uint32_t tx_dropped;  /* writes with no peer yet or a full socket/tty buffer */
    uint32_t io_errors;   /* failed OS calls after opening */
} occ_link_t;

/* UDP client: resolve HOST (name or address) and PORT; binds an ephemeral local port.
 * OCC_ERR_ARG (bad host), OCC_ERR_IO (socket). `msg` gets the reason. */
occ_err_t occ_link_udp_connect(occ_link_t *l, const char *host, uint16_t port, char *msg,
                               size_t msg_len);
/* UDP server ("udpin"): bind `bind_host` (NULL = all interfaces) : port. */
occ_err_t occ_link_udp_listen(occ_link_t *l, const char *bind_host, uint16_t port, char *msg,
                              size_t msg_len);
/* Serial: open `dev` at `baud` (50..4000000 where the OS supports it), raw 8N1. OCC_ERR_ARG for
 * an unsupported baud rate, OCC_ERR_IO. */
occ_err_t occ_link_serial_open(occ_link_t *l, const char *dev, uint32_t baud, char *msg,
                               size_t msg_len);

/* Read what is available (never blocks): *n = bytes read (0 if none). UDP: one datagram per
 * call (truncated to cap); a listen link remembers its sender as the peer. OCC_ERR_IO. */
occ_err_t occ_link_read(occ_link_t *l, uint8_t *buf, size_t cap, size_t *n);
/* Write one frame (UDP: one datagram). Never blocks: a frame that does not fit now is dropped
 * and counted (tx_dropped), as a radio link would. OCC_ERR_IO on a hard error. */
occ_err_t occ_link_write(occ_link_t *l, const uint8_t *data, size_t n);
/* Wait up to timeout_us for input (poll). true if readable. */
bool occ_link_wait(occ_link_t *l, uint64_t timeout_us);
void occ_link_close(occ_link_t *l);

#ifdef __cplusplus
}
#endif
#endif
