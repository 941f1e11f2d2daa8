/* SPDX-License-Identifier: BSD-3-Clause */
/* scan_xyz.c - the plain "x y z" point file reader (OctoMap's scan.dat). */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "occmap/host/occ_scan.h"

static void set_msg(char *msg, size_t len, const char *path, unsigned long line, const char *what)
{
    if (msg != NULL && len > 0u) {
        (void)snprintf(msg, len, "%s:%lu: %s", path, line, what);
    }
}

occ_err_t occ_scan_read_xyz(const char *path, occ_vec3_t **points, size_t *n, char *msg,
                            size_t msg_len)
{
    if (path == NULL || points == NULL || n == NULL) {
        return OCC_ERR_ARG;
    }
    *points = NULL;
    *n = 0;
    FILE *const f = fopen(path, "r");
    if (f == NULL) {
        set_msg(msg, msg_len, path, 0, strerror(errno));
        return OCC_ERR_IO;
    }
    size_t cap = 0, count = 0;
    occ_vec3_t *buf = NULL;
    char line[512];
    unsigned long lineno = 0;
    occ_err_t err = OCC_OK;
    while (fgets(line, sizeof line, f) != NULL) {
        lineno++;
        if (strchr(line, '\n') == NULL && !feof(f)) {
            set_msg(msg, msg_len, path, lineno, "line too long");
            err = OCC_ERR_FORMAT;
            break;
        }
        const char *s = line;
        while (*s == ' ' || *s == '\t' || *s == '\r') {
            s++;
        }
        if (*s == '\n' || *s == '\0' || *s == '#') {
            continue;
        }
        float x, y, z;
        char tail;
        if (sscanf(s, "%f %f %f %c", &x, &y, &z, &tail) != 3) {
            set_msg(msg, msg_len, path, lineno, "expected three numbers 'x y z'");
            err = OCC_ERR_FORMAT;
            break;
        }
        if (count == cap) {
            const size_t new_cap = cap == 0u ? 4096u : cap * 2u;
            occ_vec3_t *const grown = realloc(buf, new_cap * sizeof *grown);
            if (grown == NULL) {
                err = OCC_ERR_NOMEM;
                break;
            }
            buf = grown;
            cap = new_cap;
        }
        buf[count].x = x;
        buf[count].y = y;
        buf[count].z = z;
        count++;
    }
    if (err == OCC_OK && ferror(f)) {
        set_msg(msg, msg_len, path, lineno, "read error");
        err = OCC_ERR_IO;
    }
    (void)fclose(f);
    if (err != OCC_OK) {
        free(buf);
        return err;
    }
    *points = buf;
    *n = count;
    return OCC_OK;
}
