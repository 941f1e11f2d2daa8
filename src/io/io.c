/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * io.c - the public entry points of occ_io.h: detect, probe (validating dry run), load/read
 * (dry run, fit check on a scratch copy of the map struct, then the same parse building for
 * real, then one struct assignment), write (counting pass, then output).
 */
#include <string.h>

#include "io_internal.h"
#include "../core/shared_internal.h"

#define OM_DEPTH 16u

occ_format_t occ_io_detect(const void *const buf, const size_t len)
{
    static const char bt[] = "# Octomap OcTree binary file";
    static const char ot[] = "# Octomap OcTree file";
    const uint8_t *const p = (const uint8_t *)buf;
    if (p == NULL) {
        return OCC_FORMAT_UNKNOWN;
    }
    if (len >= 8u && memcmp(p, "OCCMAPSN", 8u) == 0) {
        return OCC_FORMAT_SNAPSHOT;
    }
    if (len >= sizeof bt - 1u && memcmp(p, bt, sizeof bt - 1u) == 0) {
        return OCC_FORMAT_BT;
    }
    if (len >= sizeof ot - 1u && memcmp(p, ot, sizeof ot - 1u) == 0) {
        return OCC_FORMAT_OT;
    }
    return OCC_FORMAT_UNKNOWN;
}

/* Everything one pass needs to know about the input. */
typedef struct {
    occ_format_t format;
    occ_om_header_t om;
    occ_snap_header_t snap;
    size_t extra;                /* .ot bytes per node after the value */
    occ_map_config_t cfg;        /* the config of the resulting map */
} parsed_t;

static void info_reset(occ_io_info_t *const info)
{
    memset(info, 0, sizeof *info);
    info->error = "";
}

static occ_err_t parse_header(occ_cursor_t *const c, parsed_t *const p,
                              const occ_map_config_t *const base, occ_io_info_t *const info)
{
    memset(p, 0, sizeof *p);
    p->format = occ_io_detect(c->buf, c->len);
    info->format = p->format;
    occ_err_t e;
    if (p->format == OCC_FORMAT_SNAPSHOT) {
        e = occi_snap_header_parse(c, &p->snap);
        if (e != OCC_OK) {
            return e;
        }
        p->cfg = p->snap.cfg;
        info->version = OCC_SNAPSHOT_VERSION;
        info->data_offset = OCC_SNAPSHOT_HEADER_BYTES;
    } else if (p->format == OCC_FORMAT_BT || p->format == OCC_FORMAT_OT) {
        e = occi_om_header_parse(c, &p->om);
        c->warnings |= p->om.warnings;
        memcpy(info->tree_id, p->om.id, sizeof info->tree_id);
        info->header_nodes = p->om.size;
        info->data_offset = p->om.data_offset;
        if (e != OCC_OK) {
            return e;
        }
        if (strcmp(p->om.id, "OcTree") == 0) {
            p->extra = 0u;
        } else if (strcmp(p->om.id, "ColorOcTree") == 0) {
            p->extra = 3u;  /* r, g, b */
            c->warnings |= OCC_IO_WARN_TREE_TYPE;
        } else if (strcmp(p->om.id, "OcTreeStamped") == 0) {
            p->extra = 0u;  /* 1.9.7's OcTreeNodeStamped does not serialize its time stamp */
            c->warnings |= OCC_IO_WARN_TREE_TYPE;
        } else {
            c->error = "unsupported tree type (id)";
            c->error_offset = 0u;
            return OCC_ERR_UNSUPPORTED;
        }
        if (p->format == OCC_FORMAT_OT && p->extra != 0u) {
            c->warnings |= OCC_IO_WARN_EXTRA_SKIPPED;
        }
        if (p->format == OCC_FORMAT_BT) {
            p->extra = 0u;  /* the compact layout is the same for every occupancy tree */
        }
        p->cfg = *base;
        p->cfg.resolution_m = p->om.res;
        p->cfg.depth_levels = (uint8_t)OM_DEPTH;
    } else {
        return occ_cursor_fail(c, 0u, "wrong magic: not .bt, .ot or .occ");
    }
    info->cfg = p->cfg;
    info->resolution_m = p->cfg.resolution_m;
    info->depth_levels = p->cfg.depth_levels;
    return OCC_OK;
}

static occ_err_t parse_body(occ_cursor_t *const c, const parsed_t *const p, occ_build_t *const b,
                            const occ_map_config_t *const model)
{
    occ_err_t e;
    switch (p->format) {
    case OCC_FORMAT_BT:
        e = occi_bt_parse(c, b, p->om.size, occ_value_from_logodds(model->clamp_min),
                          occ_value_from_logodds(model->clamp_max));
        break;
    case OCC_FORMAT_OT:
        e = occi_ot_parse(c, b, p->om.size, p->extra);
        break;
    case OCC_FORMAT_SNAPSHOT:
        e = occi_snap_parse(c, b, &p->snap);
        break;
    case OCC_FORMAT_UNKNOWN:
    default:
        e = OCC_ERR_FORMAT;
        break;
    }
    if (e == OCC_OK && p->format != OCC_FORMAT_SNAPSHOT && c->pos < c->len) {
        c->warnings |= OCC_IO_WARN_TRAILING;
    }
    return e;
}

/* One full pass (header + body) over the bytes; map == NULL is the dry run. */
static occ_err_t pass(const void *const buf, const size_t len, const occ_map_config_t *const base,
                      occ_map_t *const map, occ_io_info_t *const info, parsed_t *const p)
{
    occ_cursor_t c;
    c.buf = (const uint8_t *)buf;
    c.len = len;
    c.pos = 0u;
    c.error = "";
    c.error_offset = 0u;
    c.warnings = 0u;
    occ_build_t b;
    occ_err_t e = parse_header(&c, p, base, info);
    if (e == OCC_OK) {
        occi_build_begin(&b, map, p->cfg.depth_levels);
        /* .bt leaves take the clamp bounds of the destination's sensor model. */
        e = parse_body(&c, p, &b, map != NULL ? &map->cfg : base);
        info->nodes = b.nodes;
        info->inner_blocks = b.live_inner;
        info->leaf_blocks = b.live_leaf;
        info->peak_inner_blocks = b.peak_inner;
        info->peak_leaf_blocks = b.peak_leaf;
        info->arena_bytes_needed = OCC_ARENA_BYTES(b.peak_inner, b.peak_leaf);
        if (p->format == OCC_FORMAT_SNAPSHOT) {
            info->header_nodes = b.nodes;
        }
    }
    info->warnings = c.warnings;
    info->bytes_used = p->format == OCC_FORMAT_SNAPSHOT && e == OCC_OK ? len : c.pos;
    if (e != OCC_OK) {
        info->error = c.error != NULL && c.error[0] != '\0' ? c.error : occ_err_str(e);
        info->error_offset = c.error_offset;
    }
    return e;
}

occ_err_t occ_io_probe(const void *const buf, const size_t len, const occ_map_config_t *const base_cfg,
                       occ_io_info_t *const info)
{
    if (info == NULL) {
        return OCC_ERR_ARG;
    }
    info_reset(info);
    const occ_map_config_t base = base_cfg != NULL ? *base_cfg : occ_map_config_default();
    if (buf == NULL || !occi_map_config_ok(&base)) {
        info->error = "invalid argument";
        return OCC_ERR_ARG;
    }
    parsed_t p;
    return pass(buf, len, &base, NULL, info, &p);
}

/* Build into `tmp` (an initialized, empty map) after the dry run said it fits. */
static occ_err_t build(occ_map_t *const tmp, const void *const buf, const size_t len,
                       occ_io_info_t *const info)
{
    if (!occi_pool_can_supply(tmp, info->peak_inner_blocks, info->peak_leaf_blocks)) {
        info->error = "the map does not fit the arena";
        return OCC_ERR_NOMEM;
    }
    occ_io_info_t again;
    parsed_t p;
    const occ_err_t e = pass(buf, len, &tmp->cfg, tmp, &again, &p);
    OCC_ASSERT(e == OCC_OK);
    if (e != OCC_OK) {  /* cannot happen: the same bytes passed the dry run */
        occ_map_clear(tmp);
        *info = again;
    }
    return e;
}

occ_err_t occ_io_load(occ_map_t *const map, const occ_map_config_t *const base_cfg, void *const arena,
                      const size_t arena_bytes, const void *const buf, const size_t len,
                      occ_io_info_t *const info)
{
    occ_io_info_t local;
    /* cppcheck-suppress uninitvar ; only its address is taken here (cppcheck 2.10 flags &x of a fresh local) */
    occ_io_info_t *const inf = info != NULL ? info : &local;
    if (map == NULL || arena == NULL) {
        info_reset(inf);
        inf->error = "invalid argument";
        return OCC_ERR_ARG;
    }
    occ_err_t e = occ_io_probe(buf, len, base_cfg, inf);
    if (e != OCC_OK) {
        return e;
    }
    occ_map_t tmp;
    e = occ_map_init(&tmp, &inf->cfg, arena, arena_bytes);
    if (e != OCC_OK) {
        inf->error = e == OCC_ERR_NOMEM ? "the map does not fit the arena" : "invalid config";
        return e == OCC_ERR_ARG ? OCC_ERR_FORMAT : e;
    }
    e = build(&tmp, buf, len, inf);
    if (e == OCC_OK || e != OCC_ERR_NOMEM) {
        *map = tmp;
    }
    return e;
}

occ_err_t occ_io_read(occ_map_t *const map, const void *const buf, const size_t len,
                      occ_io_info_t *const info)
{
    occ_io_info_t local;
    /* cppcheck-suppress uninitvar ; only its address is taken here (cppcheck 2.10 flags &x of a fresh local) */
    occ_io_info_t *const inf = info != NULL ? info : &local;
    if (map == NULL) {
        info_reset(inf);
        inf->error = "invalid argument";
        return OCC_ERR_ARG;
    }
    occ_err_t e = occ_io_probe(buf, len, &map->cfg, inf);
    if (e != OCC_OK) {
        return e;
    }
    if (inf->cfg.resolution_m < map->cfg.resolution_m ||
        map->cfg.resolution_m < inf->cfg.resolution_m ||
        inf->cfg.depth_levels != map->cfg.depth_levels) {
        inf->error = "resolution or depth differs from the map's";
        return OCC_ERR_ARG;
    }
    /* The clear and the build happen on a copy that is not shared; a shared map publishes the
     * result once, as one version (occ_shared.h), and nothing on NOMEM. */
    occ_map_t tmp = *map;
    tmp.priv.shared = NULL;
    occ_map_clear(&tmp);
    e = build(&tmp, buf, len, inf);
    if (e == OCC_OK || e != OCC_ERR_NOMEM) {
        occi_map_replace(map, &tmp);
        if (map->priv.shared != NULL) {
            occi_shared_rebuilt(map); /* built unmarked: every snapshot copies it whole */
        }
    }
    return e;
}

uint64_t occ_io_octomap_nodes(const occ_map_t *const map, const occ_format_t format)
{
    if (map == NULL) {
        return 0u;
    }
    occ_sink_t counter;
    occi_sink_init(&counter, NULL, NULL);
    uint64_t nodes = 0u;
    if (format == OCC_FORMAT_BT) {
        occi_bt_emit(map, &counter, &nodes);
    } else if (format == OCC_FORMAT_OT) {
        occi_ot_emit(map, &counter, &nodes);
    }
    return nodes;
}

occ_err_t occ_io_write(const occ_map_t *const map, const occ_format_t format,
                       const occ_io_write_fn fn, void *const ctx, size_t *const bytes_out)
{
    if (bytes_out != NULL) {
        *bytes_out = 0u;
    }
    if (map == NULL) {
        return OCC_ERR_ARG;
    }
    occ_sink_t s;
    occi_sink_init(&s, fn, ctx);
    occ_err_t e;
    if (format == OCC_FORMAT_SNAPSHOT) {
        e = occi_snap_write(map, &s);
    } else if (format == OCC_FORMAT_BT || format == OCC_FORMAT_OT) {
        if (map->cfg.depth_levels != OM_DEPTH) {
            return OCC_ERR_UNSUPPORTED;
        }
        const uint64_t nodes = occ_io_octomap_nodes(map, format);
        e = occi_om_header_write(&s, format, nodes, map->cfg.resolution_m);
        if (e == OCC_OK) {
            uint64_t again = 0u;
            if (format == OCC_FORMAT_BT) {
                occi_bt_emit(map, &s, &again);
            } else {
                occi_ot_emit(map, &s, &again);
            }
            e = occi_sink_flush(&s);
        }
    } else {
        return OCC_ERR_ARG;
    }
    if (bytes_out != NULL) {
        *bytes_out = s.total;
    }
    return e;
}
