/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * occ_port.h - the portable hooks a platform provides to the front ends' glue: a monotonic
 * microsecond clock and a non-blocking UART write. The core (src/) never includes this header;
 * tools and firmware glue call these functions and hand bytes and times to the pure-C feeds.
 *
 *  - port/posix:     occ_port_clock_us() on CLOCK_MONOTONIC. The byte links to the autopilot
 *                    (UDP, serial) are host-only: occmap/host/occ_link_posix.h.
 *  - port/baremetal: weak occ_port_clock_us() and occ_port_uart_write() that a firmware
 *                    overrides with its timer and UART driver (defaults: time 0, nothing sent).
 */
#ifndef OCC_PORT_H_INCLUDED
#define OCC_PORT_H_INCLUDED

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Microseconds of a monotonic clock (never goes back; arbitrary origin). O(1), thread-safe. */
uint64_t occ_port_clock_us(void);

/* Bare metal: queue `n` bytes on the autopilot UART without blocking; returns the bytes taken
 * (the weak default takes none). Not provided on POSIX (use occ_link_write() of
 * occmap/host/occ_link_posix.h). */
size_t occ_port_uart_write(const uint8_t *data, size_t n);

#ifdef __cplusplus
}
#endif
#endif
