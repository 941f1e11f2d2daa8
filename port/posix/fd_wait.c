/* SPDX-License-Identifier: BSD-3-Clause */
/* fd_wait.c - what a non-blocking receive does after a failed read. */
#include <errno.h>
#include <poll.h>

#include "fd_wait.h"

int occ_fd_wait_after_failed_read(const int fd, int *const timeout_ms)
{
    if (errno == EINTR) {
        return 1;
    }
    if (errno != EAGAIN && errno != EWOULDBLOCK) {
        return -1;
    }
    if (*timeout_ms == 0) {
        return 0;
    }
    struct pollfd p = {fd, POLLIN, 0};
    const int pr = poll(&p, 1, *timeout_ms);
    if (pr < 0 && errno != EINTR) {
        return -1;
    }
    if (pr == 0) {
        return 0;
    }
    *timeout_ms = 0; /* one more read, then give up: no busy loop */
    return 1;
}
