/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * io_internal.h - what the readers and writers in src/io/io_*.c share: the tree builder (one
 * code path for the validating dry run and the real build), the buffered byte sink, the
 * OctoMap text header, and the per-format parsers/emitters.
 */
#ifndef OCC_IO_INTERNAL_H_INCLUDED
#define OCC_IO_INTERNAL_H_INCLUDED

#include "../core/tree_internal.h"

/* ---- builder (io_build.c) ----------------------------------------------------------------
 * Parsers describe a tree in preorder: open the root, set each child of the open node to a
 * uniform value (leaf) or open it, close nodes. With map == NULL nothing is written: the builder
 * only mirrors what the real build would allocate and prune, so the dry run's peaks are exactly
 * the real build's. Parsers guarantee: a slot is set at most once per node, a node opened at
 * level >= 1, every closed node got at least one child. */
typedef struct {
    uint32_t block;      /* real build: this node's child block */
    uint8_t level;       /* level of the open node */
    uint8_t slot;        /* its slot in the parent */
    uint8_t set;         /* children set so far */
    bool any_block;      /* dry run: some child kept a block */
    occ_value_t vmin, vmax;  /* dry run: over the children set so far */
} occ_build_frame_t;

typedef struct {
    occ_map_t *map;      /* NULL: dry run */
    uint8_t top;         /* root level (depth_levels) */
    uint8_t sp;          /* open nodes */
    bool root_uniform;   /* dry run: the root ended without children */
    occ_value_t root_value;
    uint32_t live_inner, live_leaf, peak_inner, peak_leaf;
    uint64_t nodes;
    occ_build_frame_t st[OCC_MAX_DEPTH + 1];
} occ_build_t;

void occi_build_begin(occ_build_t *b, occ_map_t *map, unsigned depth_levels);
void occi_build_root_uniform(occ_build_t *b, occ_value_t v);
void occi_build_open_root(occ_build_t *b);
void occi_build_open(occ_build_t *b, unsigned slot);
void occi_build_leaf(occ_build_t *b, unsigned slot, occ_value_t v);
void occi_build_close(occ_build_t *b);
static inline unsigned occ_build_level(const occ_build_t *b)
{
    return b->st[b->sp - 1u].level;
}

/* A parser drives a builder over the bytes: the same function for the dry run and the build. */
typedef struct {
    const uint8_t *buf;
    size_t len;
    size_t pos;
    const char *error;   /* reason on OCC_ERR_FORMAT */
    size_t error_offset;
    uint32_t warnings;
} occ_cursor_t;

static inline occ_err_t occ_cursor_fail(occ_cursor_t *c, size_t at, const char *why)
{
    c->error = why;
    c->error_offset = at;
    return OCC_ERR_FORMAT;
}

/* ---- buffered sink (io_sink.c) --------------------------------------------------------- */
#define OCC_SINK_BUF 128u
typedef struct {
    occ_io_write_fn fn;  /* NULL: count only */
    void *ctx;
    occ_err_t err;
    bool crc_on;
    uint32_t crc;
    size_t total;
    size_t fill;
    uint8_t buf[OCC_SINK_BUF];
} occ_sink_t;

void occi_sink_init(occ_sink_t *s, occ_io_write_fn fn, void *ctx);
void occi_sink_put(occ_sink_t *s, const void *data, size_t len);
void occi_sink_u8(occ_sink_t *s, uint8_t v);
void occi_sink_u16(occ_sink_t *s, uint16_t v);
void occi_sink_u32(occ_sink_t *s, uint32_t v);
void occi_sink_f32(occ_sink_t *s, float v);
void occi_sink_str(occ_sink_t *s, const char *str);
void occi_sink_dec(occ_sink_t *s, uint64_t v);
occ_err_t occi_sink_flush(occ_sink_t *s);

uint16_t occi_rd_u16(const uint8_t *p);
uint32_t occi_rd_u32(const uint8_t *p);
uint64_t occi_rd_u64(const uint8_t *p);
float occi_rd_f32(const uint8_t *p);

/* ---- OctoMap text header (io_header.c) ---------------------------------------------------- */
typedef struct {
    occ_format_t format;
    char id[32];
    uint64_t size;
    float res;
    size_t data_offset;
    uint32_t warnings;
} occ_om_header_t;

/* Parse as OctoMap's readHeader does. OCC_ERR_FORMAT with the cursor's error set. */
occ_err_t occi_om_header_parse(occ_cursor_t *c, occ_om_header_t *h);
/* Append the header OctoMap writes (res printed as iostream's default "%g"). */
occ_err_t occi_om_header_write(occ_sink_t *s, occ_format_t format, uint64_t size, float res);

/* ---- format bodies ---------------------------------------------------------------------- */
/* Parse the tree data of a .bt / .ot from c->pos, driving b. */
occ_err_t occi_bt_parse(occ_cursor_t *c, occ_build_t *b, uint64_t header_size, occ_value_t q_free,
                        occ_value_t q_occ);
occ_err_t occi_ot_parse(occ_cursor_t *c, occ_build_t *b, uint64_t header_size, size_t extra);
void occi_bt_emit(const occ_map_t *m, occ_sink_t *s, uint64_t *nodes);
void occi_ot_emit(const occ_map_t *m, occ_sink_t *s, uint64_t *nodes);

/* Snapshot (io_snapshot.c). */
typedef struct {
    occ_map_config_t cfg;
    uint8_t value_kind;
    uint32_t inner_blocks, leaf_blocks;
    uint64_t payload_bytes;
} occ_snap_header_t;
occ_err_t occi_snap_header_parse(occ_cursor_t *c, occ_snap_header_t *h);
occ_err_t occi_snap_parse(occ_cursor_t *c, occ_build_t *b, const occ_snap_header_t *h);
occ_err_t occi_snap_write(const occ_map_t *m, occ_sink_t *s);

#endif /* OCC_IO_INTERNAL_H_INCLUDED */
