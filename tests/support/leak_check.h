/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * leak_check.h - the no-leak check every fixture teardown runs (lwIP memp's used == 0 per pool).
 * Header-only, so every test binary and every build variant of the tests has it without new
 * link rules.
 *
 * occ_map_clear() resets the pool counters, so "every pool at used == 0 after clear" cannot
 * fail. leak_check() looks before it clears:
 *  1. occ_map_check() holds;
 *  2. the blocks the tree reaches, counted with the public walk (a node with children owns one
 *     child block: a leaf block at level 1, an inner block above), equal each pool's `used`:
 *     a used block that no node reaches is a leak;
 *  3. it forgets the whole tree at the root level, which returns the blocks to the pools one by
 *     one; then every pool must be at used == 0 and occ_map_check() must still hold;
 *  4. it clears the map, so the next test starts from an empty one.
 * A map never initialized (a zeroed static, depth 0) has nothing to check.
 * Cost: a walk, plus the release, which is quadratic in the blocks under OCC_POOL_PARANOID (on in
 * test builds: each free scans the free list), so keep it to fixture-sized maps (<~10^4 blocks).
 * Returns 0, or -1 after printing what is wrong: a teardown returns it (CMocka then reports the
 * test as an ERROR), a test asserts it is 0.
 */
#ifndef OCC_LEAK_CHECK_H_INCLUDED
#define OCC_LEAK_CHECK_H_INCLUDED

#include <stdio.h>

#include "occmap/occmap.h"

static inline int leak_check_fail(const char *const what, const occ_map_t *const map)
{
    printf("leak check: %s (inner used %u, leaf used %u)\n", what, (unsigned)map->inner.used,
           (unsigned)map->leaf.used);
    fflush(stdout);
    return -1;
}

static inline int leak_check(occ_map_t *const map)
{
    if (map->cfg.depth_levels == 0u) {
        return 0;
    }
    if (occ_map_check(map) != OCC_OK) {
        return leak_check_fail("occ_map_check() fails before the teardown", map);
    }
    uint64_t reach_inner = 0u, reach_leaf = 0u;
    occ_walk_t w;
    occ_walk_node_t n;
    occ_walk_begin(&w, map);
    while (occ_walk_next(&w, &n)) {
        if (n.has_children) {
            if (n.level == 1u) {
                reach_leaf++;
            } else {
                reach_inner++;
            }
        }
    }
    if (reach_inner != map->inner.used || reach_leaf != map->leaf.used) {
        printf("leak check: the tree reaches %llu inner and %llu leaf blocks\n",
               (unsigned long long)reach_inner, (unsigned long long)reach_leaf);
        return leak_check_fail("used blocks that no node reaches (a leak)", map);
    }
    const occ_key_t origin = {{0u, 0u, 0u}};
    if (occ_map_forget_key(map, origin, map->cfg.depth_levels) != OCC_OK) {
        return leak_check_fail("forgetting the root failed", map);
    }
    if (map->inner.used != 0u || map->leaf.used != 0u) {
        return leak_check_fail("blocks still used after forgetting the whole tree", map);
    }
    if (occ_map_check(map) != OCC_OK) {
        return leak_check_fail("occ_map_check() fails after forgetting the whole tree", map);
    }
    occ_map_clear(map);
    return 0;
}

#endif /* OCC_LEAK_CHECK_H_INCLUDED */
