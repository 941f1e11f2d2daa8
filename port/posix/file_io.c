/* SPDX-License-Identifier: BSD-3-Clause */
/* file_io.c - map files on POSIX: whole-file reads, format by extension, atomic saves. */
#include <errno.h>
#include <fcntl.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#include "occmap/occmap.h"
#include "occmap/host/occ_file.h"

static void say(char *const msg, const size_t msg_len, const char *const fmt, ...)
{
    if (msg == NULL || msg_len == 0u) {
        return;
    }
    va_list ap;
    va_start(ap, fmt);
    (void)vsnprintf(msg, msg_len, fmt, ap);
    va_end(ap);
}

occ_format_t occ_file_format_of(const char *const path)
{
    if (path == NULL) {
        return OCC_FORMAT_UNKNOWN;
    }
    const char *const dot = strrchr(path, '.');
    if (dot == NULL || strchr(dot, '/') != NULL) {
        return OCC_FORMAT_UNKNOWN;
    }
    if (strcasecmp(dot, ".bt") == 0) {
        return OCC_FORMAT_BT;
    }
    if (strcasecmp(dot, ".ot") == 0) {
        return OCC_FORMAT_OT;
    }
    if (strcasecmp(dot, ".occ") == 0) {
        return OCC_FORMAT_SNAPSHOT;
    }
    return OCC_FORMAT_UNKNOWN;
}

occ_err_t occ_file_read_all(const char *const path, uint8_t **const data, size_t *const len,
                            char *const msg, const size_t msg_len)
{
    if (path == NULL || data == NULL || len == NULL) {
        say(msg, msg_len, "invalid argument");
        return OCC_ERR_ARG;
    }
    *data = NULL;
    *len = 0u;
    const int fd = open(path, O_RDONLY);
    if (fd < 0) {
        say(msg, msg_len, "%s: %s", path, strerror(errno));
        return OCC_ERR_IO;
    }
    struct stat st;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        say(msg, msg_len, "%s: not a regular file", path);
        (void)close(fd);
        return OCC_ERR_IO;
    }
    const size_t n = (size_t)st.st_size;
    uint8_t *const buf = (uint8_t *)malloc(n > 0u ? n : 1u);
    if (buf == NULL) {
        say(msg, msg_len, "%s: out of memory for %zu bytes", path, n);
        (void)close(fd);
        return OCC_ERR_NOMEM;
    }
    size_t got = 0u;
    while (got < n) {
        const ssize_t r = read(fd, buf + got, n - got);
        if (r < 0 && errno == EINTR) {
            continue;
        }
        if (r <= 0) {
            say(msg, msg_len, "%s: read failed: %s", path, r < 0 ? strerror(errno) : "short file");
            free(buf);
            (void)close(fd);
            return OCC_ERR_IO;
        }
        got += (size_t)r;
    }
    (void)close(fd);
    *data = buf;
    *len = n;
    return OCC_OK;
}

static void say_io(char *const msg, const size_t msg_len, const char *const path, const occ_err_t e,
                   const occ_io_info_t *const info)
{
    if (e == OCC_ERR_FORMAT) {
        say(msg, msg_len, "%s: %s at byte %zu", path, info->error, info->error_offset);
    } else if (e == OCC_ERR_NOMEM) {
        say(msg, msg_len, "%s: %s (needs %zu arena bytes)", path, info->error,
            info->arena_bytes_needed);
    } else {
        say(msg, msg_len, "%s: %s", path, info->error[0] != '\0' ? info->error : occ_err_str(e));
    }
}

occ_err_t occ_file_probe(const char *const path, const occ_map_config_t *const base_cfg,
                         occ_io_info_t *const info, char *const msg, const size_t msg_len)
{
    uint8_t *buf;
    size_t len;
    occ_err_t e = occ_file_read_all(path, &buf, &len, msg, msg_len);
    if (e != OCC_OK) {
        return e;
    }
    e = occ_io_probe(buf, len, base_cfg, info);
    free(buf);
    if (e != OCC_OK && info != NULL) {
        say_io(msg, msg_len, path, e, info);
    }
    return e;
}

occ_err_t occ_file_load_info(const char *const path, const occ_map_config_t *const base_cfg,
                             occ_map_t *const map, void *const arena, const size_t arena_bytes,
                             occ_io_info_t *const info, char *const msg, const size_t msg_len)
{
    occ_io_info_t local;
    occ_io_info_t *const inf = info != NULL ? info : &local;
    uint8_t *buf;
    size_t len;
    occ_err_t e = occ_file_read_all(path, &buf, &len, msg, msg_len);
    if (e != OCC_OK) {
        return e;
    }
    e = occ_io_load(map, base_cfg, arena, arena_bytes, buf, len, inf);
    free(buf);
    if (e != OCC_OK) {
        say_io(msg, msg_len, path, e, inf);
    }
    return e;
}

occ_err_t occ_file_load(const char *const path, const occ_map_config_t *const base_cfg,
                        occ_map_t *const map, void *const arena, const size_t arena_bytes,
                        char *const msg, const size_t msg_len)
{
    return occ_file_load_info(path, base_cfg, map, arena, arena_bytes, NULL, msg, msg_len);
}

occ_err_t occ_file_load_alloc(const char *const path, const occ_map_config_t *const base_cfg,
                              occ_map_t *const map, const size_t extra_bytes, void **const arena_out,
                              occ_io_info_t *const info, char *const msg, const size_t msg_len)
{
    occ_io_info_t local;
    occ_io_info_t *const inf = info != NULL ? info : &local;
    if (arena_out == NULL || map == NULL) {
        say(msg, msg_len, "invalid argument");
        return OCC_ERR_ARG;
    }
    *arena_out = NULL;
    uint8_t *buf;
    size_t len;
    occ_err_t e = occ_file_read_all(path, &buf, &len, msg, msg_len);
    if (e != OCC_OK) {
        return e;
    }
    e = occ_io_probe(buf, len, base_cfg, inf);
    if (e == OCC_OK) {
        const size_t bytes = inf->arena_bytes_needed + extra_bytes + OCC_ARENA_BYTES(1, 1);
        void *const arena = malloc(bytes);
        if (arena == NULL) {
            say(msg, msg_len, "%s: out of memory for a %zu-byte arena", path, bytes);
            free(buf);
            return OCC_ERR_NOMEM;
        }
        e = occ_io_load(map, base_cfg, arena, bytes, buf, len, inf);
        if (e == OCC_OK) {
            *arena_out = arena;
        } else {
            free(arena);
        }
    }
    free(buf);
    if (e != OCC_OK) {
        say_io(msg, msg_len, path, e, inf);
    }
    return e;
}

static occ_err_t fd_write(void *const ctx, const void *const data, const size_t len)
{
    const int fd = *(const int *)ctx;
    const uint8_t *p = (const uint8_t *)data;
    size_t left = len;
    while (left > 0u) {
        const ssize_t w = write(fd, p, left);
        if (w < 0 && errno == EINTR) {
            continue;
        }
        if (w <= 0) {
            return OCC_ERR_IO;
        }
        p += w;
        left -= (size_t)w;
    }
    return OCC_OK;
}

/* fsync the directory holding `path` so the rename itself is durable. */
static void sync_dir(const char *const path)
{
    char dir[4096];
    const char *const slash = strrchr(path, '/');
    if (slash == NULL) {
        (void)snprintf(dir, sizeof dir, ".");
    } else if (slash == path) {
        (void)snprintf(dir, sizeof dir, "/");
    } else {
        (void)snprintf(dir, sizeof dir, "%.*s", (int)(slash - path), path);
    }
    const int fd = open(dir, O_RDONLY);
    if (fd >= 0) {
        (void)fsync(fd);
        (void)close(fd);
    }
}

occ_err_t occ_file_save_as(const char *const path, const occ_map_t *const map,
                           const occ_format_t format, size_t *const bytes, char *const msg,
                           const size_t msg_len)
{
    if (bytes != NULL) {
        *bytes = 0u;
    }
    if (path == NULL || map == NULL) {
        say(msg, msg_len, "invalid argument");
        return OCC_ERR_ARG;
    }
    if (format == OCC_FORMAT_UNKNOWN) {
        say(msg, msg_len, "%s: unknown extension (use .bt, .ot or .occ)", path);
        return OCC_ERR_ARG;
    }
    if (format != OCC_FORMAT_SNAPSHOT && map->cfg.depth_levels != 16u) {
        say(msg, msg_len, "%s: OctoMap files need depth_levels 16 (map has %u)", path,
            (unsigned)map->cfg.depth_levels);
        return OCC_ERR_UNSUPPORTED;
    }
    char tmp[4096];
    const int n = snprintf(tmp, sizeof tmp, "%s.tmp.%ld", path, (long)getpid());
    if (n < 0 || (size_t)n >= sizeof tmp) {
        say(msg, msg_len, "%s: path too long", path);
        return OCC_ERR_ARG;
    }
    int fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd < 0) {
        say(msg, msg_len, "%s: %s", tmp, strerror(errno));
        return OCC_ERR_IO;
    }
    size_t written = 0u;
    occ_err_t e = occ_io_write(map, format, fd_write, &fd, &written);
    if (e == OCC_OK && fsync(fd) != 0) {
        e = OCC_ERR_IO;
    }
    if (close(fd) != 0 && e == OCC_OK) {
        e = OCC_ERR_IO;
    }
    if (e == OCC_OK && rename(tmp, path) != 0) {
        e = OCC_ERR_IO;
    }
    if (e != OCC_OK) {
        say(msg, msg_len, "%s: save failed: %s (%s)", path, occ_err_str(e),
            errno != 0 ? strerror(errno) : "");
        (void)unlink(tmp);
        return e;
    }
    sync_dir(path);
    if (bytes != NULL) {
        *bytes = written;
    }
    return OCC_OK;
}

occ_err_t occ_file_save(const char *const path, const occ_map_t *const map, char *const msg,
                        const size_t msg_len)
{
    return occ_file_save_as(path, map, occ_file_format_of(path), NULL, msg, msg_len);
}
