/* SPDX-License-Identifier: BSD-3-Clause */
/* serial.c - a raw, non-blocking termios serial link (8N1, no flow control). */
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <termios.h>
#include <unistd.h>

#include "occmap/host/occ_link_posix.h"

static bool baud_code(uint32_t baud, speed_t *code)
{
    static const struct { uint32_t baud; speed_t code; } table[] = {
        {9600u, B9600}, {19200u, B19200}, {38400u, B38400}, {57600u, B57600},
        {115200u, B115200}, {230400u, B230400},
#ifdef B460800
        {460800u, B460800},
#endif
#ifdef B921600
        {921600u, B921600},
#endif
#ifdef B1500000
        {1500000u, B1500000},
#endif
#ifdef B2000000
        {2000000u, B2000000},
#endif
    };
    for (size_t i = 0; i < sizeof table / sizeof table[0]; i++) {
        if (table[i].baud == baud) {
            *code = table[i].code;
            return true;
        }
    }
    return false;
}

occ_err_t occ_link_serial_open(occ_link_t *l, const char *dev, uint32_t baud, char *msg,
                               size_t msg_len)
{
    if (l == NULL || dev == NULL) {
        return OCC_ERR_ARG;
    }
    memset(l, 0, sizeof *l);
    l->fd = -1;
    speed_t code;
    if (!baud_code(baud, &code)) {
        if (msg != NULL && msg_len > 0u) {
            (void)snprintf(msg, msg_len, "unsupported baud rate %u", (unsigned)baud);
        }
        return OCC_ERR_ARG;
    }
    const int fd = open(dev, O_RDWR | O_NOCTTY | O_NONBLOCK);
    if (fd < 0) {
        if (msg != NULL && msg_len > 0u) {
            (void)snprintf(msg, msg_len, "%s: %s", dev, strerror(errno));
        }
        return OCC_ERR_IO;
    }
    struct termios t;
    if (tcgetattr(fd, &t) != 0) {
        if (msg != NULL && msg_len > 0u) {
            (void)snprintf(msg, msg_len, "%s: not a tty (%s)", dev, strerror(errno));
        }
        (void)close(fd);
        return OCC_ERR_IO;
    }
    cfmakeraw(&t);
    t.c_cflag &= (tcflag_t)~(CSTOPB | PARENB | CRTSCTS);
    t.c_cflag |= (tcflag_t)(CLOCAL | CREAD | CS8);
    t.c_cc[VMIN] = 0;
    t.c_cc[VTIME] = 0;
    if (cfsetispeed(&t, code) != 0 || cfsetospeed(&t, code) != 0 ||
        tcsetattr(fd, TCSANOW, &t) != 0) {
        if (msg != NULL && msg_len > 0u) {
            (void)snprintf(msg, msg_len, "%s: %s", dev, strerror(errno));
        }
        (void)close(fd);
        return OCC_ERR_IO;
    }
    (void)tcflush(fd, TCIOFLUSH);
    l->fd = fd;
    l->kind = OCC_LINK_SERIAL;
    l->have_peer = true;
    return OCC_OK;
}
