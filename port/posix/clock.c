/* SPDX-License-Identifier: BSD-3-Clause */
/* clock.c - the monotonic microsecond clock on POSIX. */
#include <time.h>

#include "occmap/occ_port.h"

uint64_t occ_port_clock_us(void)
{
    struct timespec ts;
    if (clock_gettime(CLOCK_MONOTONIC, &ts) != 0) {
        return 0;
    }
    return (uint64_t)ts.tv_sec * 1000000u + (uint64_t)ts.tv_nsec / 1000u;
}
