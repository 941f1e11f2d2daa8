/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * occ_socketcan.h - Linux SocketCAN for the DroneCAN node (port/posix/socketcan.c). Host only:
 * a CAN_RAW socket; a firmware build gives the node its own transmit hook (occ_can_iface_t in
 * occmap/occ_dronecan.h, example in port/baremetal/can_hooks.c).
 */
#ifndef OCC_SOCKETCAN_H_INCLUDED
#define OCC_SOCKETCAN_H_INCLUDED

#include <stddef.h>
#include <stdint.h>
#include <stdbool.h>

#include "occmap/occ_core.h"
#include "occmap/occ_dronecan.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Receive filter: a frame passes when (frame id & mask) == (id & mask) and its EXT flag equals
 * `ext` (classic 11-bit vs 29-bit ids). */
typedef struct {
    uint32_t id, mask;
    bool ext;
} occ_can_filter_t;

#define OCC_CAN_MAX_FILTERS 16u

/* SocketCAN (port/posix/socketcan.c): one non-blocking CAN_RAW socket bound to one interface. */
typedef struct {
    int fd;                /* -1 when closed */
    bool fd_frames;        /* CAN FD frames enabled on this socket */
    uint32_t tx_full;      /* sends refused with EAGAIN / ENOBUFS */
    uint32_t rx_errors;    /* error frames received */
} occ_socketcan_t;

/* Open `ifname` (e.g. "vcan0", "can0"), non-blocking, error frames enabled (bus-off, controller,
 * protocol, tx timeout, lost arbitration come back from occ_socketcan_recv() as
 * OCC_CAN_FLAG_ERR frames). `fd_frames` asks for CAN FD (fails with OCC_ERR_UNSUPPORTED when the
 * interface cannot). OCC_ERR_IO when the kernel has no CAN (errno in `msg`). */
occ_err_t occ_socketcan_open(occ_socketcan_t *s, const char *ifname, bool fd_frames, char *msg,
                             size_t msg_len);
/* Replace the receive filters (n = 0: receive nothing but error reports; filters NULL with
 * n = 0 as well). n <= OCC_CAN_MAX_FILTERS. */
occ_err_t occ_socketcan_set_filters(occ_socketcan_t *s, const occ_can_filter_t *filters, size_t n);
/* Send without blocking: OCC_OK, OCC_ERR_NOMEM when the queue is full (counted in tx_full),
 * OCC_ERR_ARG for an FD frame on a classic socket or a bad length, OCC_ERR_IO otherwise. */
occ_err_t occ_socketcan_send(occ_socketcan_t *s, const occ_can_frame_t *frame);
/* Wait up to `timeout_ms` (0: poll, < 0: forever) for one frame. *got = false on timeout. */
occ_err_t occ_socketcan_recv(occ_socketcan_t *s, occ_can_frame_t *frame, int timeout_ms,
                             bool *got);
void occ_socketcan_close(occ_socketcan_t *s);
/* The transmit hook for the DroneCAN node (tx_space unknown). */
occ_can_iface_t occ_socketcan_iface(occ_socketcan_t *s);

#ifdef __cplusplus
}
#endif
#endif
