/* SPDX-License-Identifier: BSD-3-Clause */
/* sectors_ref.h - what the sectors tests share (tests/support/sectors_ref.c, prefix sref_): the
 * fixture (one static map, its arena and one output) and the brute-force reference of
 * occ_sectors_compute(): every voxel column in the search box, each footprint clipped against
 * each sector's wedge (polygon clipping in double). */
#ifndef OCC_SECTORS_REF_H_INCLUDED
#define OCC_SECTORS_REF_H_INCLUDED

#include "occmap/occ_sectors.h"

extern occ_map_t sref_map;     /* the fixture's map (8 MiB static arena) */
extern occ_sectors_t sref_sect; /* the output sref_compare() and the tests fill (large: static) */
extern unsigned sref_seed;      /* printed with every mismatch; the caller sets it */

/* CMocka setup: sref_map at 0.1 m, default depth. */
int sref_setup(void **state);
/* CMocka teardown: leak_check() of sref_map. */
int sref_teardown(void **state);
/* sref_map again at `res` metres and `depth` levels (a failure fails the test). */
void sref_reinit(float res, unsigned depth);

/* The vehicle level at (x, y, z) with heading yaw (map frame): the pose the sectors take. */
occ_pose_t sref_at_yaw(float x, float y, float z, float yaw);
void sref_set_yaw(occ_pose_t *p, float yaw);
/* The heading of the body x axis, in double for the reference (ZYX yaw). */
double sref_yaw_of(const occ_pose_t *p);
/* The key of sref_map's voxel holding (x, y, z) (a failure fails the test). */
void sref_key_at(double x, double y, double z, occ_key_t *k);

/* occ_sectors_compute(&sref_map, p, cfg, &sref_sect) against the reference, with 1 cm of slack
 * for float vs double; a kind may differ only on a (near) tie or at the edge of the search
 * radius. Prints each mismatch (with `what` and sref_seed); returns the number of mismatching
 * sectors. */
unsigned sref_compare(const occ_pose_t *p, const occ_sectors_config_t *cfg, const char *what);

#endif /* OCC_SECTORS_REF_H_INCLUDED */
