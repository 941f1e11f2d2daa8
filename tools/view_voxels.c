/* SPDX-License-Identifier: BSD-3-Clause */
/* view_voxels.c - the nodes `occmap view` draws, from one walk over the map. */
#include <stdlib.h>
#include <string.h>

#include "view.h"

static int set_push(view_set_t *s, const occ_key_t key, const unsigned level)
{
    if (s->n == s->cap) {
        const size_t cap = s->cap == 0u ? 4096u : s->cap * 2u;
        uint32_t *k = realloc(s->key, cap * 3u * sizeof *k);
        if (k == NULL) {
            return -1;
        }
        s->key = k;
        uint8_t *l = realloc(s->level, cap);
        if (l == NULL) {
            return -1;
        }
        s->level = l;
        s->cap = cap;
    }
    memcpy(&s->key[3u * s->n], key.k, sizeof key.k);
    s->level[s->n] = (uint8_t)level;
    s->n++;
    return 0;
}

/* The box of the node (first voxel `key`, `level`) lies inside the observed bbox. */
static bool inside_bbox(const occ_map_t *map, const view_box_t *box, const occ_key_t key,
                        const unsigned level)
{
    const occ_vec3_t c = occ_map_key_center(map, key, level);
    const float h = 0.5f * occ_map_node_size(map, level);
    return c.x - h >= box->lo.x && c.x + h <= box->hi.x && c.y - h >= box->lo.y &&
           c.y + h <= box->hi.y && c.z - h >= box->lo.z && c.z + h <= box->hi.z;
}

/* Never-observed children of an observed inner node: unknown pockets inside the mapped space. */
static int push_unobserved_children(const occ_map_t *map, const view_box_t *box,
                                    const occ_walk_node_t *node, view_set_t *unknown)
{
    const unsigned cl = (unsigned)node->level - 1u;
    for (unsigned i = 0; i < 8u; i++) {
        occ_key_t ck = node->key;
        for (unsigned a = 0; a < 3u; a++) {
            ck.k[a] += ((i >> a) & 1u) << cl;
        }
        occ_node_info_t info;
        if (occ_map_read_key(map, ck, cl, &info) == OCC_OK && !info.observed &&
            inside_bbox(map, box, ck, cl) && set_push(unknown, ck, cl) != 0) {
            return -1;
        }
    }
    return 0;
}

void view_sets_free(view_sets_t *s)
{
    view_set_t *sets[3] = {&s->occupied, &s->free, &s->unknown};
    for (size_t i = 0; i < 3u; i++) {
        free(sets[i]->key);
        free(sets[i]->level);
        memset(sets[i], 0, sizeof *sets[i]);
    }
}

occ_err_t view_collect(const occ_map_t *map, view_sets_t *out)
{
    memset(out, 0, sizeof *out);
    occ_map_stats(map, &out->stats);
    const view_box_t box = {out->stats.bbox_min, out->stats.bbox_max};
    occ_walk_t w;
    occ_walk_node_t node;
    occ_walk_begin(&w, map);
    int rc = 0;
    while (rc == 0 && occ_walk_next(&w, &node)) {
        if (node.has_children) {
            rc = push_unobserved_children(map, &box, &node, &out->unknown);
        } else if ((node.flags & OCC_NODE_HAS_OCCUPIED) != 0u) {
            rc = set_push(&out->occupied, node.key, node.level);
        } else if ((node.flags & OCC_NODE_HAS_FREE) != 0u) {
            rc = set_push(&out->free, node.key, node.level);
        } else {
            rc = set_push(&out->unknown, node.key, node.level);
        }
    }
    const occ_err_t e = rc != 0 ? OCC_ERR_NOMEM : occ_walk_status(&w);
    if (e != OCC_OK) {
        view_sets_free(out);
    }
    return e;
}

void view_base64(FILE *f, const uint8_t *data, const size_t len)
{
    static const char tab[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    char quad[4];
    for (size_t i = 0; i < len; i += 3u) {
        const size_t left = len - i;
        const uint32_t v = (uint32_t)data[i] << 16 | (left > 1u ? (uint32_t)data[i + 1u] << 8 : 0u) |
                           (left > 2u ? (uint32_t)data[i + 2u] : 0u);
        quad[0] = tab[(v >> 18) & 63u];
        quad[1] = tab[(v >> 12) & 63u];
        quad[2] = left > 1u ? tab[(v >> 6) & 63u] : '=';
        quad[3] = left > 2u ? tab[v & 63u] : '=';
        fwrite(quad, 1, 4, f);
    }
}
