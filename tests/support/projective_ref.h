/* SPDX-License-Identifier: BSD-3-Clause */
/* projective_ref.h - brute-force oracle of OCC_INSERT_PROJECTIVE's per-voxel rule
 * (occ_integrate.h): no pyramid, no walk; every voxel of the cube of half-edge max range around
 * the camera is classified by projecting its centre, every pixel's end point is a hit. */
#ifndef OCC_PROJECTIVE_REF_H_INCLUDED
#define OCC_PROJECTIVE_REF_H_INCLUDED

#include "occmap/occmap.h"
#include "occmap/occ_pose.h"

/* The frame's voxel updates, sorted by code, unique, hit bit set for hits (hits win), in a
 * malloc'd array (*codes; the caller frees it). Returns the count. *n_hits: hit voxels. */
size_t projref_codes(const occ_map_t *map, const occ_proj_image_t *im,
                     const occ_proj_camera_t *cam, occ_code_t **codes, size_t *n_hits);

/* The camera's rotation columns from a pose, as occ_map_insert_depth builds them
 * (occ_pose_rotate of the camera's unit axes): map = r * camera + t. */
void projref_rotation_of(const occ_pose_t *pose, float r[3][3]);

/* Sort codes by voxel (the hit bit aside) and collapse each voxel's to one (a hit wins), in
 * place, as occ_map_observe_codes takes them. Returns the count. */
size_t projref_sort_unique(occ_code_t *codes, size_t n);

/* The end points of the frame's pixels with a reading within [min, max] range, as points in
 * the map frame (t + d r (a, b, 1): for OctoMap's insertPointCloud, not the rule's voxels) in a
 * malloc'd array. Returns the count. */
size_t projref_end_points(const occ_proj_image_t *im, const occ_proj_camera_t *cam,
                          occ_vec3_t **pts);

/* The rule's end-point voxels (occ_integrate.h: per axis the camera's key plus the floor of
 * d (U_a + V_a) + F_a, in float), one per pixel with a hit inside the map, in a malloc'd array.
 * Returns the count. */
size_t projref_end_keys(const occ_map_t *map, const occ_proj_image_t *im,
                        const occ_proj_camera_t *cam, occ_key_t **keys);

#endif
