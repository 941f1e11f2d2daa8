/* SPDX-License-Identifier: BSD-3-Clause */
/* fd_wait.h - the non-blocking receive loops of the POSIX ports share one rule for a failed read. */
#ifndef OCC_PORT_FD_WAIT_H_INCLUDED
#define OCC_PORT_FD_WAIT_H_INCLUDED

/* Call right after a read on `fd` returned < 0 (errno still set). Returns 1: read again
 * (interrupted, or data arrived within *timeout_ms; *timeout_ms is then 0 so the caller reads
 * once more and never busy-loops), 0: nothing to read (return "no frame"), -1: a real I/O error. */
int occ_fd_wait_after_failed_read(int fd, int *timeout_ms);

#endif
