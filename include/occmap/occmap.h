/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * occmap.h - the whole portable map API, one include. It holds no declarations: each chapter is
 * a header of its own, and each chapter includes only occ_core.h (or nothing), so no header
 * includes another in a cycle.
 *
 *   occ_core.h       the map: configuration, keys, reading and writing voxels, pools, statistics,
 *                    the health check, errors (start here: it is the manual's first chapter)
 *   occ_integrate.h  point clouds and rays into the map (integrators, super rays, fast-discrete)
 *   occ_query.h      volumes, iterator, lookup, nearest obstacle, collision, castRay, info gain
 *   occ_io.h         OctoMap .bt/.ot and snapshot readers and writers, byte sinks
 *   occ_evict.h      eviction around the vehicle
 *   occ_shared.h     one writer, many wait-free readers on views of published versions
 *
 * Front ends have their own headers (occ_sectors.h, occ_mavlink.h, occ_dronecan.h); occ_port.h
 * holds the platform hooks (clock, UART). Host-only APIs (files, scan readers, libccd, POSIX links,
 * SocketCAN, CAN over multicast) are under occmap/host/, which a firmware build does not see.
 */
#ifndef OCC_OCCMAP_H_INCLUDED
#define OCC_OCCMAP_H_INCLUDED

#include "occmap/occ_core.h"
#include "occmap/occ_integrate.h"
#include "occmap/occ_query.h"
#include "occmap/occ_io.h"
#include "occmap/occ_evict.h"
#include "occmap/occ_shared.h"

#endif /* OCC_OCCMAP_H_INCLUDED */
