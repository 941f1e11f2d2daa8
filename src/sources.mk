# SPDX-License-Identifier: BSD-3-Clause
# The library's file lists. A firmware Makefile sets OCC_ROOT and includes this file.
OCC_ROOT ?= .
# One folder per concern (README "Architecture"); dependencies point one way:
#   geom <- core <- {integrate, query, io, evict} <- front ends (sensors, sectors, mavlink,
#   dronecan). Front ends use the public headers only; sensors (poses, depth images, range
#   beams) is the input side, the other three tell the vehicle.
OCC_MAP_MODULES := geom core integrate query io evict
OCC_FRONT_MODULES := sensors sectors mavlink dronecan
# Per-module lists: OCC_SRC_core, OCC_SRC_query, ..., OCC_SRC_dronecan.
$(foreach m,$(OCC_MAP_MODULES) $(OCC_FRONT_MODULES),\
  $(eval OCC_SRC_$(m) := $(sort $(wildcard $(OCC_ROOT)/src/$(m)/*.c))))
# collide_ccd.c needs libccd (host only) and is kept apart for firmware builds.
OCC_CCD_SRC := $(wildcard $(OCC_ROOT)/src/query/collide_ccd.c)
# The map (no OS, no heap): every map module, without collide_ccd.c.
OCC_CORE_SRC := $(filter-out $(OCC_CCD_SRC),$(foreach m,$(OCC_MAP_MODULES),$(OCC_SRC_$(m))))
# The front ends: sensor input and what the vehicle is told (public map API only).
OCC_FEED_SRC := $(foreach m,$(OCC_FRONT_MODULES),$(OCC_SRC_$(m)))
# The portable public headers; include/occmap/host/ (POSIX, files, libccd) is for host builds.
OCC_INCLUDE_DIRS := $(OCC_ROOT)/include
