/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * occ_can_mcast.h - CAN frames over UDP multicast for the DroneCAN node (port/posix/can_mcast.c),
 * the transport of pydronecan's `mcast:` driver and ArduPilot SITL. Host only: sockets.
 */
#ifndef OCC_CAN_MCAST_H_INCLUDED
#define OCC_CAN_MCAST_H_INCLUDED

#include <stddef.h>
#include <stdint.h>
#include <stdbool.h>

#include "occmap/occ_core.h"
#include "occmap/occ_dronecan.h"

#ifdef __cplusplus
extern "C" {
#endif

/* CAN over UDP multicast (port/posix/can_mcast.c), the format of pydronecan's `mcast:` driver and
 * ArduPilot SITL: group 239.65.82.<bus>, port 57732, packet = u16 magic 0x2934, u16 CRC-16-CCITT
 * of the rest, u16 flags (1 = FD), u32 id (bit 31 = extended), data; little endian. */
typedef struct {
    int rx_fd, tx_fd;
    uint16_t tx_port;          /* our sender's port: our own packets are dropped on receive */
    uint32_t tx_full, rx_bad;  /* sends refused (EAGAIN), packets dropped (magic, CRC, size) */
} occ_can_mcast_t;

#define OCC_CAN_MCAST_PORT 57732u
#define OCC_CAN_MCAST_MAGIC 0x2934u

/* Join bus 0..255 on the loopback interface when `loopback_only`, else on the default one. */
occ_err_t occ_can_mcast_open(occ_can_mcast_t *m, unsigned bus, bool loopback_only, char *msg,
                             size_t msg_len);
/* Encode / decode one packet (pure functions, used by the tests). encode returns the length
 * (10 + len) or 0 when `cap` is too small; decode returns OCC_ERR_FORMAT for a bad packet. */
size_t occ_can_mcast_encode(const occ_can_frame_t *frame, uint8_t *out, size_t cap);
occ_err_t occ_can_mcast_decode(const uint8_t *pkt, size_t len, occ_can_frame_t *frame);
occ_err_t occ_can_mcast_send(occ_can_mcast_t *m, const occ_can_frame_t *frame);
occ_err_t occ_can_mcast_recv(occ_can_mcast_t *m, occ_can_frame_t *frame, int timeout_ms,
                             bool *got);
void occ_can_mcast_close(occ_can_mcast_t *m);
occ_can_iface_t occ_can_mcast_iface(occ_can_mcast_t *m);

#ifdef __cplusplus
}
#endif
#endif
