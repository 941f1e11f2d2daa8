# SPDX-License-Identifier: BSD-3-Clause
# geometry.mk - test_geometry.c a second time in the firmware's float key arithmetic
# (-DOCC_RAY_DOUBLE=0, issue 16 section 1): every occmap call must still name the same voxel on
# border points (keys may differ from OctoMap's only within ~1e-7 of a border). Reuses the
# rayf variant's objects (tests/foundation.mk: the core built with -DOCC_RAY_DOUBLE=0) and adds
# the sectors (src/sectors/sectors.c, with the pose it takes: src/sensors/pose.c) built the same way.
GEOMF_BIN := $(BUILD)/asan-rayf/bin/test_geometry_float
GEOMF_OBJS := $(BUILD)/asan-rayf/host/tests/test_geometry.o $(BUILD)/asanhost/tests/support/oracle_geom.o \
              $(OCC_CORE_SRC:%.c=$(BUILD)/asan-rayf/core/%.o) $(patsubst %.c,$(BUILD)/asan-rayf/core/%.o,$(filter %/sectors.c %/pose.c,$(OCC_FEED_SRC)))

$(GEOMF_BIN): $(GEOMF_OBJS)
	@mkdir -p $(dir $@)
	$(CXX) $(SAN) -o $@ $^ -loctomap -loctomath -lcmocka -lm

test-geometry-float: $(GEOMF_BIN)
	CMOCKA_MESSAGE_OUTPUT=STDOUT $(GEOMF_BIN)

TEST_STEPS += test-geometry-float
TEST_BUILD_EXTRA += $(GEOMF_BIN)
.PHONY: test-geometry-float
