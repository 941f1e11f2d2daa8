/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * fuzz_reader.c - libFuzzer harness for one reader (FUZZ_FORMAT = OCC_FORMAT_BT, _OT or
 * _SNAPSHOT, set by tests/io.mk). Properties: no crash or sanitizer report on any input; an
 * input the reader accepts gives a map that passes occ_map_check(), whose rewrite in the same
 * format is accepted again; a refused input leaves the destination map untouched. The core is
 * built with live asserts (tests/io.mk): no input may break an internal invariant either.
 */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "occmap/occmap.h"
#include "../support/occ_assert_abort.h" /* a failed OCC_ASSERT is a finding: abort */

#ifndef FUZZ_FORMAT
#error "define FUZZ_FORMAT"
#endif

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static uint8_t arena[1u << 20] __attribute__((aligned(8)));
static uint8_t arena2[1u << 20] __attribute__((aligned(8)));
static uint8_t out[1u << 20];

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (occ_io_detect(data, size) != FUZZ_FORMAT) {
        return -1;  /* keep the corpus on this reader */
    }
    occ_map_t map;
    occ_map_config_t cfg = occ_map_config_default();
    if (occ_map_init(&map, &cfg, arena, sizeof arena) != OCC_OK) {
        abort();
    }
    occ_key_t k = {{32768u, 32768u, 32768u}};
    (void)occ_map_update_key(&map, k, 1.0f);
    const occ_map_t before = map;
    occ_io_info_t info;
    const occ_err_t e = occ_io_load(&map, NULL, arena, sizeof arena, data, size, &info);
    if (e != OCC_OK) {
        if (memcmp(&before, &map, sizeof map) != 0 || occ_map_check(&map) != OCC_OK) {
            abort();  /* a refused input changed the map */
        }
        return 0;
    }
    if (occ_map_check(&map) != OCC_OK) {
        abort();
    }
    occ_io_buf_t b = {out, sizeof out, 0u};
    size_t n = 0u;
    if (occ_io_write(&map, FUZZ_FORMAT, occ_io_buf_write, &b, &n) == OCC_OK) {
        occ_map_t again;
        if (occ_io_load(&again, NULL, arena2, sizeof arena2, out, b.len, &info) != OCC_OK ||
            occ_map_check(&again) != OCC_OK) {
            abort();  /* occmap's own output must read back */
        }
    }
    return 0;
}
