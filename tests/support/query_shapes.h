/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * query_shapes.h - random bounding volumes for the query tests, built twice from the same
 * numbers: as an occ_volume_t (the core's constructors) and as an Eigen oracle shape.
 */
#ifndef OCC_QUERY_SHAPES_H_INCLUDED
#define OCC_QUERY_SHAPES_H_INCLUDED

#include "occmap/occmap.h"
#include "oracle_query.h"

typedef struct {
    occ_volume_t vol;
    oracle_q_shape_t *oracle;
    const char *name;
    char desc[200];
} qs_shape_t;

/* xorshift64* */
uint64_t qs_rand(uint64_t *st);
double qs_uniform(uint64_t *st, double lo, double hi);
/* Seed from OCC_SEED or the clock; prints "<test>: seed N". */
uint64_t qs_seed(const char *test);

/* A random volume of kind `kind` (occ_volume_kind_t) around the map of `map` (coordinates up to
 * `reach` m from the origin; some centres snapped to node borders, sizes up to `max_size` m).
 * Returns false if the core constructor refused (a test failure). */
bool qs_random_shape(uint64_t *st, const occ_map_t *map, int kind, double reach, double max_size,
                     qs_shape_t *out);
void qs_free(qs_shape_t *s);

#endif
