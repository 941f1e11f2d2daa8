/* SPDX-License-Identifier: BSD-3-Clause */
/* depth_fixture.h - what the depth tests share (header-only, one include per test binary): two
 * maps on malloc'd arenas, one scratch, OctoMap's sensor model, the leak check in teardown. */
#ifndef OCC_DEPTH_FIXTURE_H_INCLUDED
#define OCC_DEPTH_FIXTURE_H_INCLUDED

#include <stdlib.h>

#include "occmap/occmap.h"
#include "iotest.h"
#include "leak_check.h"

#define ARENA_BYTES ((size_t)48 << 20)
#define SCRATCH_BYTES ((size_t)48 << 20)

static uint8_t *arena_a, *arena_b, *scratch;
static occ_map_t map_a, map_b;

static int depth_setup(void **state)
{
    (void)state;
    arena_a = malloc(ARENA_BYTES);
    arena_b = malloc(ARENA_BYTES);
    scratch = malloc(SCRATCH_BYTES);
    return arena_a != NULL && arena_b != NULL && scratch != NULL ? 0 : -1;
}

static int depth_teardown(void **state)
{
    (void)state;
    const int rc = leak_check(&map_a) | leak_check(&map_b);
    free(arena_a);
    free(arena_b);
    free(scratch);
    return rc;
}

static void init_maps(float res)
{
    occ_map_config_t c = iotest_octomap_cfg();
    c.resolution_m = res;
    assert_int_equal(occ_map_init(&map_a, &c, arena_a, ARENA_BYTES), OCC_OK);
    assert_int_equal(occ_map_init(&map_b, &c, arena_b, ARENA_BYTES), OCC_OK);
}

#endif
