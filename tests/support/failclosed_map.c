/* SPDX-License-Identifier: BSD-3-Clause */
/* failclosed_map.c - the map the fail-closed tests share (see failclosed_map.h). */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "failclosed_map.h"

void fc_make_map(occ_map_t *const map, uint8_t *const arena, const size_t arena_bytes)
{
    const occ_map_config_t cfg = occ_map_config_default();
    assert_int_equal(occ_map_init(map, &cfg, arena, arena_bytes), OCC_OK);
    assert_int_equal(occ_map_update(map, P_OCC, 3.0f), OCC_OK);
    for (int x = -5; x < 5; x++) {
        for (int y = -5; y < 5; y++) {
            const occ_vec3_t p = v3(0.1f * (float)x + 0.05f, 0.1f * (float)y + 0.05f, 0.05f);
            assert_int_equal(occ_map_update(map, p, -1.0f), OCC_OK);
        }
    }
    assert_int_equal(occ_map_check(map), OCC_OK);
    assert_int_equal(occ_map_state_at(map, P_OCC), OCC_STATE_OCCUPIED);
    assert_int_equal(occ_map_state_at(map, P_FREE), OCC_STATE_FREE);
}

occ_key_t fc_key_of(const occ_map_t *const map, const occ_vec3_t p)
{
    occ_key_t k;
    assert_int_equal(occ_map_key(map, p, &k), OCC_OK);
    return k;
}

int fc_forget_all(occ_map_t *const map)
{
    const occ_key_t zero = {{0u, 0u, 0u}};
    if (occ_map_check(map) != OCC_OK ||
        occ_map_forget_key(map, zero, map->cfg.depth_levels) != OCC_OK ||
        occ_map_check(map) != OCC_OK) {
        return -1;
    }
    return map->inner.used == 0u && map->leaf.used == 0u ? 0 : -1;
}

void fc_assert_unknown_node(const occ_node_t *const n)
{
    assert_false(n->observed);
    assert_int_equal(n->state, OCC_STATE_UNKNOWN);
    assert_int_equal(n->children, OCC_NONE);
    assert_true((n->flags & OCC_NODE_HAS_UNKNOWN) != 0u);
    assert_true((n->flags & (OCC_NODE_HAS_FREE | OCC_NODE_HAS_OCCUPIED)) == 0u);
}
