/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * occ_io.h - map serialization on caller byte buffers and write callbacks (never files; see
 * occ_file.h for the POSIX helpers). Part of the manual; included by occmap.h.
 *
 * Formats
 *  - OCC_FORMAT_BT  OctoMap's compact binary (.bt) as liboctomap 1.9.7 writes it: the text header
 *    "# Octomap OcTree binary file", comment lines, "id OcTree", "size N", "res R", "data", then
 *    per inner node (preorder from the root) two bytes of 2-bit child codes (01 free leaf,
 *    10 occupied leaf, 11 inner, 00 absent; child 0 in the low bits of the first byte).
 *    Reading: a free leaf gets cfg.clamp_min, an occupied leaf cfg.clamp_max (as OctoMap's
 *    readBinary). Writing: the maximum-likelihood tree (OCCUPIED -> occupied, every other
 *    observed value -> free, unknown-band values therefore become free), fully pruned, as
 *    OctoMap's writeBinary (toMaxLikelihood + prune) produces it.
 *  - OCC_FORMAT_OT  OctoMap's full format (.ot): header "# Octomap OcTree file" ..., then per node
 *    (preorder) its float log-odds (little endian), for ColorOcTree 3 colour bytes (OctoMap
 *    1.9.7's OcTreeStamped writes no time stamp: its records are OcTree's), then one byte
 *    child mask (bit i = child i exists).
 *    Reading keeps leaf values (inner values are recomputed as the max of their children,
 *    which is what OctoMap stores); colours are skipped (OCC_IO_WARN_EXTRA_SKIPPED).
 *    Writing emits OcTree records.
 *  - OCC_FORMAT_SNAPSHOT  occmap's own format (.occ): a 64-byte header (magic "OCCMAPSN",
 *    version, value encoding, depth, resolution and the whole config, block counts, payload
 *    length), the tree in preorder (per node with children: observed mask, has-children mask,
 *    the raw values of its childless observed children) and a CRC-32 of everything before it.
 *    Raw values are stored, so a snapshot round trip is exact in either value build.
 *
 * Exactness (fixed-point build, the default): node values are round(logodds * 1024), so .bt
 * round trips are byte-identical (only clamp values are involved); .ot values that are
 * multiples of 1/1024 (everything occmap writes) round-trip byte-identically; other float
 * log-odds are quantized (error <= 1/2048, OCC_IO_WARN_QUANTIZED) and siblings that become
 * equal are pruned, so the tree OctoMap reads back equals the original leaf for leaf within
 * 1/2048. With OCC_VALUE_FLOAT=1 every .ot value round-trips bit-exactly. With OCC_VALUE_BITS=8
 * the step is 1/36 (error <= 1/72, values saturate to +-127/36 with OCC_IO_WARN_CLAMPED), and
 * .occ files of the 16-bit/float kinds and of the 8-bit kind are refused by the other family
 * with OCC_ERR_UNSUPPORTED (occ_core.h). Output is canonical
 * (fully pruned, inner value = max of children); where OctoMap's own file is not (unpruned .ot),
 * the rewrite describes the same voxels with fewer nodes.
 *
 * OctoMap files always describe a depth-16 tree centred on the origin: they load into, and
 * are written from, maps with depth_levels == 16 only (OCC_ERR_UNSUPPORTED otherwise).
 *
 * Safety: readers never trust input. A reader validates the whole input in a first pass that
 * touches no map and counts the pool blocks the result needs at its peak; only then does it
 * build. On any error the destination map is exactly as before: OCC_ERR_FORMAT (corrupt or
 * truncated bytes; info->error_offset is the byte offset of the problem), OCC_ERR_NOMEM (the
 * tree does not fit the arena; nothing is half loaded), OCC_ERR_UNSUPPORTED (a tree type other
 * than OcTree / ColorOcTree / OcTreeStamped, a legacy headerless .bt, a depth other than 16).
 * Stack use is bounded (no recursion; fixed stacks of OCC_MAX_DEPTH + 1 entries).
 * Work: O(input bytes) per pass, two passes. Writers: O(nodes) per pass, two passes (the
 * header states the node count); .bt with a non-empty unknown band may rescan subtrees.
 */
#ifndef OCC_IO_H_INCLUDED
#define OCC_IO_H_INCLUDED

#include "occmap/occ_core.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    OCC_FORMAT_UNKNOWN = 0,
    OCC_FORMAT_BT = 1,
    OCC_FORMAT_OT = 2,
    OCC_FORMAT_SNAPSHOT = 3
} occ_format_t;

#define OCC_SNAPSHOT_VERSION 1u
#define OCC_SNAPSHOT_HEADER_BYTES 64u

/* Warnings (bits of occ_io_info_t.warnings): the input was read, but not literally. */
#define OCC_IO_WARN_TREE_TYPE 0x01u     /* id ColorOcTree / OcTreeStamped read as an OcTree */
#define OCC_IO_WARN_EXTRA_SKIPPED 0x02u /* .ot: per-node colour bytes skipped */
#define OCC_IO_WARN_QUANTIZED 0x04u     /* a float value was rounded to the fixed-point step */
#define OCC_IO_WARN_CLAMPED 0x08u       /* a value outside the value range was saturated */
#define OCC_IO_WARN_TRAILING 0x10u      /* bytes after the tree were ignored */
#define OCC_IO_WARN_LEGACY_ID 0x20u     /* header "id 1" (old OctoMap), read as OcTree */
#define OCC_IO_WARN_UNKNOWN_KEY 0x40u   /* an unknown header keyword was skipped (as OctoMap) */
#define OCC_IO_WARN_INNER_VALUE 0x80u   /* .ot: a stored inner value was not the max of its
                                         * children (occmap recomputes it) */

/* What a reader found. All fields are set by every reader call, also on error (as far as the
 * input was understood). */
typedef struct {
    occ_format_t format;
    char tree_id[32];            /* OctoMap "id" (NUL-terminated), "" for snapshots */
    float resolution_m;          /* from the file */
    uint8_t depth_levels;        /* 16 for OctoMap files */
    uint64_t header_nodes;       /* OctoMap "size"; snapshots: nodes stored */
    uint64_t nodes;              /* nodes read from the data (OctoMap's size() of the file) */
    uint32_t inner_blocks;       /* blocks the loaded map holds */
    uint32_t leaf_blocks;
    uint32_t peak_inner_blocks;  /* blocks needed at the peak of loading (>= the above) */
    uint32_t peak_leaf_blocks;
    size_t arena_bytes_needed;   /* OCC_ARENA_BYTES(peak_inner_blocks, peak_leaf_blocks) */
    size_t data_offset;          /* first byte of the tree data */
    size_t bytes_used;           /* bytes consumed (header + data [+ CRC]) */
    size_t error_offset;         /* OCC_ERR_FORMAT: byte offset of the problem */
    const char *error;           /* on error: a constant English reason, else "" */
    uint32_t warnings;           /* OCC_IO_WARN_* */
    uint16_t version;            /* snapshot version */
    occ_map_config_t cfg;        /* the config the map gets: snapshots store theirs; OctoMap
                                  * files: the base config with the file's resolution, depth 16 */
} occ_io_info_t;

/* Format of a byte buffer by its magic (first line / 8 bytes); OCC_FORMAT_UNKNOWN otherwise.
 * O(1). */
occ_format_t occ_io_detect(const void *buf, size_t len);

/* Validate `buf` completely without touching any map: header, structure, values, CRC, node
 * count, and the pool blocks a load needs. `base_cfg` gives the sensor model used for OctoMap
 * files (.bt leaf values are its clamp bounds); NULL means occ_map_config_default().
 * Returns OCC_OK, OCC_ERR_ARG (NULL buf/info, or an invalid base_cfg), OCC_ERR_FORMAT,
 * OCC_ERR_UNSUPPORTED. Fills `info`. O(len), no writes except `info`. */
occ_err_t occ_io_probe(const void *buf, size_t len, const occ_map_config_t *base_cfg,
                       occ_io_info_t *info);

/* Initialize `map` on `arena` from the bytes (probe, check fit, then build). The map gets the
 * file's resolution and depth (snapshots: the stored config; OctoMap files: `base_cfg` or the
 * defaults for the sensor model). On any error `map` and the arena are untouched, so a map that
 * already lived on this arena is still valid. Errors: those of occ_io_probe, OCC_ERR_ARG
 * (NULL map/arena, or the stored config is rejected by occ_map_init -> reported as
 * OCC_ERR_FORMAT for snapshots), OCC_ERR_NOMEM (the tree does not fit `arena_bytes`; see
 * info->arena_bytes_needed). `info` may be NULL. O(len). An init: a shared map (occ_shared.h)
 * comes back unshared, so load a shared map with occ_io_read(). */
occ_err_t occ_io_load(occ_map_t *map, const occ_map_config_t *base_cfg, void *arena,
                      size_t arena_bytes, const void *buf, size_t len, occ_io_info_t *info);

/* Replace the content of an initialized `map` with the bytes, keeping its config and arena.
 * The file's resolution must equal map->cfg.resolution_m (as floats) and its depth the map's,
 * else OCC_ERR_ARG. .bt leaves get the map's clamp bounds. Errors as occ_io_load; on error the
 * map is unchanged. `info` may be NULL. O(len). A shared map (occ_shared.h) publishes the
 * new content as one version (never the cleared map in between). */
occ_err_t occ_io_read(occ_map_t *map, const void *buf, size_t len, occ_io_info_t *info);

/* Byte sink of the writers: consume `len` bytes (len > 0). Return OCC_OK, or an error that the
 * writer passes back unchanged (it stops at once). */
typedef occ_err_t (*occ_io_write_fn)(void *ctx, const void *data, size_t len);

/* A sink into a caller buffer: appends; OCC_ERR_NOMEM when `cap` would be exceeded (len then
 * holds what fitted). Use with ctx = pointer to occ_io_buf_t. */
typedef struct {
    uint8_t *data;
    size_t cap;
    size_t len;
} occ_io_buf_t;
occ_err_t occ_io_buf_write(void *ctx, const void *data, size_t len);

/* Serialize `map` in `format` through `fn` (NULL: only count). `bytes_out` (may be NULL) gets
 * the bytes produced (or that would be). Errors: OCC_ERR_ARG (NULL map, unknown format),
 * OCC_ERR_UNSUPPORTED (OctoMap format and depth_levels != 16, or a resolution outside
 * [1e-6, 1e6) m that the header cannot state), or the sink's error. The map is never written.
 * Output is produced in chunks of at most 128 bytes. O(nodes), two passes (the header states
 * the node count / payload length first). */
occ_err_t occ_io_write(const occ_map_t *map, occ_format_t format, occ_io_write_fn fn, void *ctx,
                       size_t *bytes_out);

/* Nodes an OctoMap tree written from `map` has (the "size" header line): .bt counts the
 * maximum-likelihood pruned tree. O(nodes). 0 for an empty map. */
uint64_t occ_io_octomap_nodes(const occ_map_t *map, occ_format_t format);

/* CRC-32 (IEEE 802.3, reflected, as zlib's crc32): start with crc = 0, chain by passing the
 * previous result. O(len). */
uint32_t occ_crc32(uint32_t crc, const void *data, size_t len);

/* ---- Budgets (issue 24) -------------------------------------------------------------------
 * Worst call-chain stack, Cortex-M4F / Cortex-M0+ (GCC 12 -Os, newlib nano; make cross checks
 * every line below against -fcallgraph-info), and the work per call. Callbacks (CAN tx, I/O
 * sinks) add their own stack. Instruction counts on a real map: README, Firmware.
 *   occ_io_load, occ_io_read: stack <= 1,472 / 1,472 B; work: two passes over the input bytes
 *       (O(len)), no recursion
 *   occ_io_probe: stack <= 960 / 1,024 B; work: one pass over the input bytes, no map
 *   occ_io_write: stack <= 896 / 896 B; work: two passes over the nodes; output in chunks of <= 128
 *       B
 *   occ_io_octomap_nodes: stack <= 704 / 704 B; work: one pass over the nodes
 *   occ_io_detect, occ_io_buf_write, occ_crc32: stack <= 64 / 64 B; work: O(1) / O(len)
 */

#ifdef __cplusplus
}
#endif
#endif /* OCC_IO_H_INCLUDED */
