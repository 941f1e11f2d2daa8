/* SPDX-License-Identifier: BSD-3-Clause */
/* mavlink_internal.h - what the MAVLink front end's files share (not public). */
#ifndef OCC_MAVLINK_INTERNAL_H_INCLUDED
#define OCC_MAVLINK_INTERNAL_H_INCLUDED

#include "occmap/occ_mavlink.h"

/* Copy frame f's payload into a generated struct of `size` bytes, zero-filling what MAVLink 2
 * trimmed; false for NULL or a frame of another message id. */
bool occi_mav_load(const occ_mav_frame_t *f, uint32_t msgid, void *dst, size_t size);

#endif
