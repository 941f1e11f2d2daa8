# SPDX-License-Identifier: BSD-3-Clause
# tests/foundation.mk - extras of the foundation tests (issue 3):
#  * build/data/foundation/scan.dat: OctoMap's real scan for test_tree_octomap (its own copy, so
#    this fragment does not depend on another fragment's rule; the test prefers build/data/scan.dat).
#  * test-morton-bmi2: test_morton.c built a second time against a BMI2 build of morton.c (symbols
#    renamed bmi2_*), comparing both paths with brute force; skipped when the CPU has no bmi2.
#  * test-variant-float: the core rebuilt with -DOCC_VALUE_FLOAT=1 and the tree, pool, corruption
#    and OctoMap oracle tests run against it (the issue: the oracle test passes with both).
#  * test-variant-rayf: the core with -DOCC_RAY_DOUBLE=0 (firmware key arithmetic) against OctoMap.
#  * test-variant-noshared: the core with -DOCC_SHARED=0 (issue 20) and test_shared, tree, pool.

FOUNDATION_SCAN := $(BUILD)/data/foundation/scan.dat
FOUNDATION_SCAN_BZ2 := /usr/share/doc/liboctomap-dev/examples/data/scan.dat.bz2
FOUNDATION_HAVE_BMI2 := $(shell grep -qw bmi2 /proc/cpuinfo 2>/dev/null && echo 1)

$(FOUNDATION_SCAN): | $(BUILD)/.deps-ok
	@mkdir -p $(dir $@)
	bzcat $(FOUNDATION_SCAN_BZ2) > $@.tmp && mv $@.tmp $@

TEST_BUILD_EXTRA += $(FOUNDATION_SCAN)

# ---- Morton: the BMI2 path ----------------------------------------------------------------------
FOUNDATION_DIR := $(BUILD)/asan/foundation
MORTON_BMI2_BIN := $(FOUNDATION_DIR)/bin/test_morton_bmi2

$(FOUNDATION_DIR)/morton_bmi2.o: src/core/morton.c include/occmap/occmap.h
	@mkdir -p $(dir $@)
	$(CC) $(ASAN_CFLAGS) -DOCC_USE_BMI2=1 -mbmi2 -c $< -o $@.raw.o
	@syms=$$(nm --defined-only -g $@.raw.o | awk '{print $$3}'); args=""; \
	for s in $$syms; do args="$$args --redefine-sym $$s=bmi2_$$s"; done; \
	objcopy $$args $@.raw.o $@ && rm -f $@.raw.o

$(FOUNDATION_DIR)/test_morton_bmi2.o: tests/test_morton.c include/occmap/occmap.h src/core/tree_internal.h \
    tests/support/seeded_rng.h
	@mkdir -p $(dir $@)
	$(CC) $(HOST_WARN) -O1 -g $(SAN) $(INC) -DOCC_TESTING=1 -DTEST_MORTON_BMI2=1 -c $< -o $@

$(MORTON_BMI2_BIN): $(FOUNDATION_DIR)/test_morton_bmi2.o $(FOUNDATION_DIR)/morton_bmi2.o $(BUILD)/asan/libocc.a
	@mkdir -p $(dir $@)
	$(CC) $(SAN) -o $@ $^ -lcmocka -lm

test-morton-bmi2: $(MORTON_BMI2_BIN)
	@if [ "$(FOUNDATION_HAVE_BMI2)" = 1 ]; then \
	  CMOCKA_MESSAGE_OUTPUT=STDOUT $(MORTON_BMI2_BIN); \
	else echo "SKIP: this CPU has no bmi2 (portable path tested by test_morton)"; exit 77; fi

# ---- compile-time variants of the core --------------------------------------------------------
# $(1) name, $(2) flags, $(3) tests. Each variant rebuilds every core file with the flags and runs
# the listed tests against it (test binaries are compiled with the same flags).
define FOUNDATION_VARIANT
$(1)_DIR := $(BUILD)/asan-$(1)
$(1)_BINS := $$(patsubst %,$(BUILD)/asan-$(1)/bin/%,$(3))

$(BUILD)/asan-$(1)/core/%.o: %.c
	@mkdir -p $$(dir $$@)
	$$(CC) $$(ASAN_CFLAGS) $(2) -MMD -MP -c $$< -o $$@
$(BUILD)/asan-$(1)/host/%.o: %.c
	@mkdir -p $$(dir $$@)
	$$(CC) $$(HOST_WARN) -O1 -g $$(SAN) $$(INC) -DOCC_TESTING=1 $(2) -MMD -MP -c $$< -o $$@
$(BUILD)/asan-$(1)/libocc.a: $$(OCC_CORE_SRC:%.c=$(BUILD)/asan-$(1)/core/%.o)
	@rm -f $$@
	$$(AR) rcs $$@ $$^
$(BUILD)/asan-$(1)/bin/%: $(BUILD)/asan-$(1)/host/tests/%.o $(BUILD)/asan-$(1)/host/tests/support/shadow_grid.o \
                    $(BUILD)/asan-$(1)/host/port/posix/scan_xyz.o $(BUILD)/asanhost/tests/support/oracle_tree.o \
                    $(BUILD)/asan-$(1)/libocc.a
	@mkdir -p $$(dir $$@)
	$$(CXX) $$(SAN) -o $$@ $$^ -loctomap -loctomath -lcmocka -lm

test-variant-$(1): $$($(1)_BINS) $(FOUNDATION_SCAN)
	@rc=0; for b in $$($(1)_BINS); do \
	  echo "== $$$$b ($(2), OCC_TEST_QUICK=1)"; OCC_TEST_QUICK=1 CMOCKA_MESSAGE_OUTPUT=STDOUT $$$$b || rc=1; \
	done; exit $$$$rc

TEST_STEPS += test-variant-$(1)
TEST_BUILD_EXTRA += $$($(1)_BINS)
.PHONY: test-variant-$(1)
endef

# The issue: "the OctoMap oracle test passes with both" value types.
$(eval $(call FOUNDATION_VARIANT,float,-DOCC_VALUE_FLOAT=1,test_tree_shadow test_tree_octomap test_pool test_corrupt))
# Issue 22: the compact 8-bit value mode runs the core suite too (tests comparing against OctoMap
# compare occupancy states / values within the 8-bit step there), plus its own arithmetic test.
V8_TESTS := test_value test_tree_shadow test_tree_octomap test_pool test_corrupt test_packed
$(eval $(call FOUNDATION_VARIANT,v8,-DOCC_VALUE_BITS=8,$(V8_TESTS)))
# The firmware's float-only key arithmetic, against OctoMap within the documented border bound.
$(eval $(call FOUNDATION_VARIANT,rayf,-DOCC_RAY_DOUBLE=0,test_tree_octomap))
# Issue 20: the core without the shared-map mode (-DOCC_SHARED=0: no publish test in the write
# paths); test_shared checks occ_map_share() answers OCC_ERR_UNSUPPORTED and the rest refuses.
$(eval $(call FOUNDATION_VARIANT,noshared,-DOCC_SHARED=0,test_shared test_tree_shadow test_pool))

TEST_STEPS += test-morton-bmi2
TEST_BUILD_EXTRA += $(MORTON_BMI2_BIN)
.PHONY: test-morton-bmi2

# ---- make cross: the core for Cortex-M4F once more with the 8-bit values (issue 22) -----------
# Objects only (no size table or stack budget of their own: the 16-bit build is the reference);
# proves the compact mode builds warning-free for the flight controller.
CROSS_V8_DIR := $(BUILD)/cross-v8/m4
$(CROSS_V8_DIR)/%.o: %.c | $(FW_HEADERS)
	@mkdir -p $(dir $@)
	$(CROSS_CC) $(CROSS_COMMON) $(CROSS_M4) -DOCC_VALUE_BITS=8 -MMD -MP -c $< -o $@
CROSS_EXTRA += $(OCC_CORE_SRC:%.c=$(CROSS_V8_DIR)/%.o)

# ---- the 8-bit mode under the integration, file and query tests (issue 22) --------------------
# These tests link the whole support set (fixtures and C++ oracles read occ_map_t, whose layout
# follows the value type), so every support and port object is rebuilt with the flag too.
V8I_TESTS := test_integrate test_io_snapshot test_io_octomap test_query test_raycast test_castray
V8I_BINS := $(patsubst %,$(BUILD)/asan-v8/bin/%,$(V8I_TESTS))
# (in an archive, so a test pulls only what it uses; the MAVLink-header users are left out.)
V8I_NO_MAV := $(basename $(shell grep -lE '^\#include "((ardupilotmega|common|standard|minimal)/|support/mav_frames.h)' \
  port/*/*.c tests/support/*.c 2>/dev/null))
V8I_SUPPORT_OBJ := $(filter-out $(V8I_NO_MAV:%=$(BUILD)/asan-v8/host/%.o), \
               $(patsubst %.c,$(BUILD)/asan-v8/host/%.o,$(patsubst %.cpp,$(BUILD)/asan-v8/host/%.o,$(TEST_SUPPORT_SRC))) \
               $(PORT_SRC:%.c=$(BUILD)/asan-v8/host/%.o))
V8I_SUPPORT := $(BUILD)/asan-v8/libsupport.a
$(V8I_SUPPORT): $(V8I_SUPPORT_OBJ)
	@rm -f $@
	$(AR) rcs $@ $^
$(BUILD)/asan-v8/host/%.o: %.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(CXXWARN) -O1 -g $(SAN) $(INC) -I/usr/include/eigen3 -DOCC_VALUE_BITS=8 -MMD -MP -c $< -o $@
$(BUILD)/asan-v8/libocc-all.a: $(patsubst %.c,$(BUILD)/asan-v8/core/%.o,$(OCC_CORE_SRC) $(OCC_CCD_SRC))
	@rm -f $@
	$(AR) rcs $@ $^
$(V8I_BINS): $(BUILD)/asan-v8/bin/%: $(BUILD)/asan-v8/host/tests/%.o $(V8I_SUPPORT) $(BUILD)/asan-v8/libocc-all.a
	@mkdir -p $(dir $@)
	$(CXX) $(SAN) -o $@ $^ $(HOST_LIBS)
test-variant-v8i: $(V8I_BINS) $(FOUNDATION_SCAN)
	@rc=0; for b in $(V8I_BINS); do \
	  echo "== $$b (-DOCC_VALUE_BITS=8, OCC_TEST_QUICK=1)"; OCC_TEST_QUICK=1 CMOCKA_MESSAGE_OUTPUT=STDOUT $$b || rc=1; \
	done; exit $$rc
TEST_STEPS += test-variant-v8i
TEST_BUILD_EXTRA += $(V8I_BINS)
.PHONY: test-variant-v8i
