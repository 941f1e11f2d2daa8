/* SPDX-License-Identifier: BSD-3-Clause */
/* mavlink_hooks.c - the platform hooks of occ_port.h as weak defaults for a flight controller
 * image: the firmware links its own strong versions (a hardware timer, a UART TX FIFO). */
#include "occmap/occ_port.h"

__attribute__((weak)) uint64_t occ_port_clock_us(void)
{
    return 0u;
}

__attribute__((weak)) size_t occ_port_uart_write(const uint8_t *data, size_t n)
{
    (void)data;
    (void)n;
    return 0u;
}
