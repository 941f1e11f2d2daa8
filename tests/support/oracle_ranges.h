/* SPDX-License-Identifier: BSD-3-Clause */
/* oracle_ranges.h - OctoMap's single-ray insert as the reference for range beams (C API of
 * oracle_ranges.cpp; trees from oracle_rays.h's oracle_ins_new). */
#ifndef OCC_ORACLE_RANGES_H_INCLUDED
#define OCC_ORACLE_RANGES_H_INCLUDED

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* insertRay(origin, end, max_range): free up to end and a hit at end; when max_range > 0 and
 * |end - origin| > max_range, free up to origin + normalized(end - origin) * max_range only. */
void oracle_ins_ray(void *t, const float origin[3], const float end[3], double max_range);
/* Voxels the tree's leaves cover (a leaf at level L covers 8^L), and of them occupied. */
void oracle_ins_volume(void *t, size_t *voxels, size_t *occupied);

#ifdef __cplusplus
}
#endif
#endif
