/* SPDX-License-Identifier: BSD-3-Clause */
/* oracle_geom.h - OctoMap's voxel geometry for the C tests (oracle_geom.cpp): the resolution a
 * user writes for a float one, and OcTree(that).coordToKeyChecked / keyToCoord. */
#ifndef OCC_ORACLE_GEOM_H_INCLUDED
#define OCC_ORACLE_GEOM_H_INCLUDED

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The shortest decimal that reads back as (float)res (0.1f -> 0.1). */
double oracle_geom_user_res(double res);
/* OcTree(oracle_geom_user_res(res_f)).coordToKeyChecked(x, y, z): 1 and the key, 0 outside. */
int oracle_geom_key(float res_f, float x, float y, float z, uint32_t key[3]);
/* float(OcTree(...).keyToCoord(key, 16 - level)) per axis (depth 16). */
void oracle_geom_center(float res_f, const uint32_t key[3], unsigned level, float out[3]);

#ifdef __cplusplus
}
#endif

#endif
