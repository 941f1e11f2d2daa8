/* SPDX-License-Identifier: BSD-3-Clause */
/* view.h - `occmap view MAP -o map.html` (cmd_view.c): the map as one self-contained HTML page.
 * view_voxels.c collects the nodes to draw, view_page.c writes the page (the rendering library
 * and the page's script inlined from an assets folder, the voxels as base64). */
#ifndef OCC_TOOLS_VIEW_H_INCLUDED
#define OCC_TOOLS_VIEW_H_INCLUDED

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include "occmap/occmap.h"

int cmd_view(int argc, char **argv);

/* Nodes of one kind: the first voxel's key (x, y, z) and the level of each (a pruned node is one
 * entry of edge resolution * 2^level). Heap arrays owned by the set (view_set_free). */
typedef struct {
    uint32_t *key;   /* 3 per node */
    uint8_t *level;
    size_t n, cap;
} view_set_t;

/* An axis-aligned box in metres (the observed bbox). */
typedef struct { occ_vec3_t lo, hi; } view_box_t;

typedef struct {
    view_set_t occupied; /* occupied leaves: OctoMap's leaf iterator's occupied count */
    view_set_t free;     /* free leaves */
    view_set_t unknown;  /* observed leaves in the unknown band, and never-observed children of
                          * observed inner nodes whose box lies inside the observed bbox */
    occ_map_stats_t stats;
} view_sets_t;

/* Walk the map once and fill `out` (zeroed first). OCC_ERR_NOMEM when malloc fails,
 * OCC_ERR_STATE when the walk was invalidated; on error every set is freed. O(nodes). */
occ_err_t view_collect(const occ_map_t *map, view_sets_t *out);
void view_sets_free(view_sets_t *s);

/* Standard base64 (RFC 4648, with padding) of `len` bytes to `f`. */
void view_base64(FILE *f, const uint8_t *data, size_t len);

/* Write the page for `map` and `sets` to `f`, inlining three.min.js, OrbitControls.js and
 * view_app.js from `assets_dir`. `title` is HTML-escaped. 0 ok; -1 (and `msg`) when an asset
 * cannot be read or memory runs out. */
int view_write_page(FILE *f, const occ_map_t *map, const view_sets_t *sets, const char *assets_dir,
                    const char *title, char *msg, size_t msg_len);

#endif
