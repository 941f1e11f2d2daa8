# The core's file lists. A firmware Makefile sets OCC_ROOT and includes this file.
OCC_ROOT ?= .
# The map (no OS, no heap). collide_ccd.c needs libccd and is kept apart for firmware builds.
OCC_CORE_SRC := $(filter-out $(OCC_ROOT)/src/map/collide_ccd.c,$(sort $(wildcard $(OCC_ROOT)/src/map/*.c)))
OCC_CCD_SRC := $(wildcard $(OCC_ROOT)/src/map/collide_ccd.c)
# What the vehicle is told: sectors, MAVLink, DroneCAN (public map API only).
OCC_FEED_SRC := $(sort $(wildcard $(OCC_ROOT)/src/feed/*.c))
OCC_INCLUDE_DIRS := $(OCC_ROOT)/include
