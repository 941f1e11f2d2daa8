# SPDX-License-Identifier: BSD-3-Clause
# occmap - one entry point.
#   make          build/libocc.a and build/occmap (release, -O3)
#   make test     install what is missing, then every test under ASan+UBSan, cross, symbol check
#   make demo     the main job (see README)
#   make bench    benchmarks against OctoMap in the same run
#   make cross    the core for Cortex-M4F and Cortex-M0+, size table and worst stack frame
#   make fuzz     the fuzz harnesses (bounded time)
#   make clean    remove build products (keeps build/venv and build/cache: slow to remake)
#
# Fragments: src/sources.mk lists the core files (firmware Makefiles include it); every
# tests/*.mk, tools/*.mk, bench/*.mk and port/*.mk adds its own rules and variables.

.DEFAULT_GOAL := all
SHELL := /bin/bash
BUILD := build
CC := gcc
CXX := g++
AR := ar

WARN := -std=c99 -pedantic-errors -Wall -Wextra -Werror -Wconversion -Wsign-conversion \
        -Wdouble-promotion -Wshadow -Wcast-qual -Wstrict-prototypes -Wmissing-prototypes \
        -Wvla -Wundef -Wswitch-enum -Wfloat-equal -fno-common
# Host programs (tools, tests, ports) are C99 with the same warnings but may use POSIX.
HOST_WARN := $(WARN) -D_POSIX_C_SOURCE=200809L -D_DEFAULT_SOURCE
CXXWARN := -std=c++14 -Wall -Wextra -Werror -Wno-deprecated-copy -Wno-class-memaccess
SAN := -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer
INC := -Iinclude -Isrc
# Firmware objects (make cross) see only the portable public headers: FW_INC holds copies of include/occmap/*.h
# without host/, so a firmware source that includes a host-only header does not compile.
FW_INC_DIR := $(BUILD)/fwinc
FW_HEADERS := $(patsubst include/%,$(FW_INC_DIR)/%,$(wildcard include/occmap/*.h))
FW_INC := -I$(FW_INC_DIR) -Isrc
# Live asserts for test builds of the core: OCC_ASSERT -> mock_assert (libcmocka's in CMocka
# tests; other programs linking such a build include tests/support/occ_assert_abort.h). Release
# and cross builds keep OCC_ASSERT at nothing. Defined before the fragments so they can use it.
OCC_TEST_ASSERTS := -iquote tests/support -DOCC_CONFIG_HEADER='"occ_test_config.h"'

# Package lists: fragments append. apt is only called when something is missing; a package
# named pkg:ARCH (tests/i386.mk) adds ARCH to dpkg's architectures first if it is not there.
APT_PKGS := build-essential libcmocka-dev liboctomap-dev octomap-tools libccd-dev libeigen3-dev \
            libpng-dev gcc-arm-none-eabi libnewlib-arm-none-eabi bzip2 python3-venv \
            qemu-system-arm valgrind clang
PIP_PKGS := pymavlink==2.4.50 dronecan==1.0.27 python-can==4.3.1
VENV := $(BUILD)/venv
PY := $(VENV)/bin/python

include src/sources.mk

# Extra libraries every host test and tool links with (fragments may append).
HOST_LIBS := -loctomap -loctomath -lccd -lpng -lcmocka -lm -lpthread

# Objects every fragment may add to: TEST_SUPPORT_SRC (tests/support), PORT_SRC (port/posix),
# TOOL_SRC (tools/*.c), TEST_STEPS (phony targets run by `make test`, each a counted test),
# DEMO_STEPS, BENCH_STEPS, FUZZ_STEPS.
PORT_SRC := $(wildcard port/posix/*.c)
TOOL_SRC := $(wildcard tools/*.c)
TEST_SUPPORT_SRC := $(wildcard tests/support/*.c tests/support/*.cpp)
TEST_C := $(wildcard tests/test_*.c)
# Test oracles (tests/support) that run millions of reference checks: plain OctoMap/Eigen code,
# built with ORACLE_FLAGS (optimized, no sanitizer) in every test build (here and tests/i386.mk)
# while the core and the test drivers keep ASan+UBSan, so the tests take seconds.
ORACLE_SRC := tests/support/oracle_query.cpp
ORACLE_FLAGS := -O2 -g
TEST_STEPS := cross symcheck
DEMO_STEPS :=
BENCH_STEPS :=
FUZZ_STEPS :=

-include $(wildcard port/*.mk tests/*.mk tools/*.mk bench/*.mk)

# ---- deps ------------------------------------------------------------------------------------
DEPS_STAMP := $(BUILD)/.deps-ok
deps: $(DEPS_STAMP)
$(DEPS_STAMP): Makefile $(wildcard port/*.mk tests/*.mk tools/*.mk bench/*.mk)
	@mkdir -p $(BUILD)
	@missing=""; for p in $(APT_PKGS); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q "install ok installed" || missing="$$missing $$p"; \
	done; \
	if [ -n "$$missing" ]; then \
	  echo "deps: installing$$missing"; \
	  export DEBIAN_FRONTEND=noninteractive; \
	  for a in $$(printf '%s\n' $$missing | sed -n 's/^[^:]*:\([a-z0-9]*\)$$/\1/p' | sort -u); do \
	    { dpkg --print-architecture; dpkg --print-foreign-architectures; } | grep -qx "$$a" || \
	      { echo "deps: adding architecture $$a"; dpkg --add-architecture "$$a"; }; \
	  done; \
	  apt-get update -q && apt-get install -y -q --no-install-recommends $$missing; \
	fi
	@if [ ! -x $(PY) ] || ! $(PY) -c "import pymavlink, dronecan" 2>/dev/null \
	    || [ "$$(cat $(VENV)/.pins 2>/dev/null)" != "$(PIP_PKGS)" ]; then \
	  echo "deps: creating $(VENV) with $(PIP_PKGS)"; \
	  (python3 -m venv $(VENV) || /usr/bin/python3 -m venv $(VENV)) && \
	  $(PY) -m pip install -q $(PIP_PKGS) && echo "$(PIP_PKGS)" > $(VENV)/.pins; \
	fi
	@touch $@

# ---- the library (release and sanitizer builds) ------------------------------------------------
# The host release builds use -O3 (the firmware builds use -Os, firmware.mk). Measured against
# -O2 with bench/ab_split.cpp linked to this library built both ways (make BUILD=<dir>
# REL_OPT=-O2, its symbols renamed old_*): PROJECTIVE new/old 0.937 and 0.939 where the same
# library on both sides gave 0.980 (where code lands moves a run by that much), the exact
# integrators 0.96 to 0.99; the same maps (no fast-math; ISO C mode contracts nothing). Most of
# it is the pixel pass's row loops. Against -O2 (old half built by bench/ab_split.mk),
# -O3 -funroll-loops measured 0.998 and -O3 with LTO 1.011; against -O3, -falign-functions=64
# -falign-loops=32 0.996 and -march=x86-64-v2 1.022: none of them. Nor another compiler or a
# profile: clang 14 -O3 (CC=clang) measured 1.072 on SIMPLE scan.dat 0.1 m and 1.116 on
# PROJECTIVE; gcc -fprofile-use trained on the same two cases 1.004 and 0.993 (7 and 9 rounds,
# both halves built through this Makefile, the old one renamed old_*).
REL_OPT := -O3
REL_CFLAGS := $(WARN) $(REL_OPT) -g $(INC)
ASAN_CFLAGS := $(WARN) -O1 -g $(SAN) $(INC) -DOCC_TESTING=1 $(OCC_TEST_ASSERTS)

# The projective integrator's lane loops (src/integrate/projective_*.c) are written to be
# vectorised; GCC 12's -O2 cost model ("very cheap") keeps every loop scalar that needs a scalar
# epilogue or a float select, so those files ask for -O3's model (the default of REL_OPT, kept
# for a build with another); and with trapping math GCC will not if-convert a select whose
# condition is a float compare (the library never reads the floating-point exception flags:
# the results are the same).
PROJ_VEC_CFLAGS := -fvect-cost-model=dynamic -fno-trapping-math
$(BUILD)/rel/./src/integrate/projective%.o $(BUILD)/pic/./src/integrate/projective%.o: \
    REL_CFLAGS += $(PROJ_VEC_CFLAGS)
$(BUILD)/rel/%.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(REL_CFLAGS) $(EXTRA_CFLAGS) -MMD -MP -c $< -o $@
$(BUILD)/asan/%.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(ASAN_CFLAGS) $(EXTRA_CFLAGS) -MMD -MP -c $< -o $@
$(BUILD)/relhost/%.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(HOST_WARN) -O2 -g $(INC) $(EXTRA_CFLAGS) -MMD -MP -c $< -o $@
$(BUILD)/asanhost/%.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(HOST_WARN) -O1 -g $(SAN) $(INC) -DOCC_TESTING=1 $(EXTRA_CFLAGS) -MMD -MP -c $< -o $@
$(BUILD)/asanhost/%.o: %.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(CXXWARN) -O1 -g $(SAN) $(INC) -I/usr/include/eigen3 -MMD -MP -c $< -o $@
$(BUILD)/relhost/%.o: %.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(CXXWARN) -O2 -g $(INC) -I/usr/include/eigen3 -MMD -MP -c $< -o $@
$(ORACLE_SRC:%.cpp=$(BUILD)/asanhost/%.o): $(BUILD)/asanhost/%.o: %.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(CXXWARN) $(ORACLE_FLAGS) $(INC) -I/usr/include/eigen3 -MMD -MP -c $< -o $@

LIB_SRC := $(OCC_CORE_SRC) $(OCC_FEED_SRC) $(OCC_CCD_SRC)
$(BUILD)/libocc.a: $(LIB_SRC:%.c=$(BUILD)/rel/%.o)
	@rm -f $@
	$(AR) rcs $@ $^
# The shared library for hosts (Python bindings, install): the release objects built with -fPIC.
$(BUILD)/pic/%.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(REL_CFLAGS) -fPIC $(EXTRA_CFLAGS) -MMD -MP -c $< -o $@
$(BUILD)/libocc.so: $(LIB_SRC:%.c=$(BUILD)/pic/%.o)
	$(CC) -shared -Wl,-soname,libocc.so.0 -o $@ $^ -lccd -lm
$(BUILD)/asan/libocc.a: $(LIB_SRC:%.c=$(BUILD)/asan/%.o)
	@rm -f $@
	$(AR) rcs $@ $^

# The command-line tool: tools/*.c + port/posix, release build.
$(BUILD)/occmap: $(TOOL_SRC:%.c=$(BUILD)/relhost/%.o) $(PORT_SRC:%.c=$(BUILD)/relhost/%.o) $(BUILD)/libocc.a
	$(CXX) -o $@ $^ $(HOST_LIBS)

all: $(DEPS_STAMP) $(BUILD)/libocc.a $(BUILD)/occmap

# ---- tests -------------------------------------------------------------------------------------
# Fragments add binaries built elsewhere (tests/i386.mk: the same tests with a 32-bit size_t).
TEST_BINS := $(TEST_C:tests/%.c=$(BUILD)/asan/tests/bin/%) $(TEST_BINS_EXTRA)
TEST_SUPPORT_OBJ := $(patsubst %.c,$(BUILD)/asanhost/%.o,$(patsubst %.cpp,$(BUILD)/asanhost/%.o,$(TEST_SUPPORT_SRC)))
TEST_PORT_OBJ := $(PORT_SRC:%.c=$(BUILD)/asanhost/%.o)

$(BUILD)/asan/tests/bin/%: $(BUILD)/asanhost/tests/%.o $(TEST_SUPPORT_OBJ) $(TEST_PORT_OBJ) $(BUILD)/asan/libocc.a
	@mkdir -p $(dir $@)
	$(CXX) $(SAN) -o $@ $^ $(HOST_LIBS)

test-build: $(DEPS_STAMP) $(TEST_BINS) $(BUILD)/occmap $(TEST_BUILD_EXTRA)

# Each step prints PASS/FAIL lines the runner counts; the runner prints "N passed, N failed,
# N skipped" (a step skips with exit 77 and a "SKIP: reason" line; under CI=true a skip fails).
# The build runs one job per core unless the caller gave -j (CI's plain `make test` on 2 cores
# builds in half the time); the tests themselves then run one at a time, undisturbed.
TEST_JOBS ?= $(shell nproc 2>/dev/null || echo 2)
TEST_J = $(if $(filter -j%,$(MAKEFLAGS)),,-j$(TEST_JOBS))
test: $(DEPS_STAMP)
	@$(MAKE) --no-print-directory $(TEST_J) test-build
	@bash tests/run_all.sh $(BUILD) "$(TEST_BINS)" "$(TEST_STEPS)"

# ---- cross (Cortex-M) ---------------------------------------------------------------------------
CROSS_CC := arm-none-eabi-gcc
CROSS_COMMON := $(WARN) -Os -ffunction-sections -fdata-sections -ffreestanding -fstack-usage $(FW_INC)
CROSS_M4 := -mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard
CROSS_M0 := -mcpu=cortex-m0plus -mthumb -mfloat-abi=soft
CROSS_SRC := $(OCC_CORE_SRC) $(OCC_FEED_SRC)

$(FW_INC_DIR)/occmap/%.h: include/occmap/%.h
	@mkdir -p $(dir $@)
	cp $< $@
$(BUILD)/cross/m4/%.o: %.c | $(FW_HEADERS)
	@mkdir -p $(dir $@)
	$(CROSS_CC) $(CROSS_COMMON) $(CROSS_M4) $(EXTRA_CFLAGS) -MMD -MP -c $< -o $@
$(BUILD)/cross/m0/%.o: %.c | $(FW_HEADERS)
	@mkdir -p $(dir $@)
	$(CROSS_CC) $(CROSS_COMMON) $(CROSS_M0) $(EXTRA_CFLAGS) -MMD -MP -c $< -o $@

cross-objs: $(DEPS_STAMP) $(CROSS_SRC:%.c=$(BUILD)/cross/m4/%.o) $(CROSS_SRC:%.c=$(BUILD)/cross/m0/%.o) $(CROSS_EXTRA)
cross: cross-objs
	@mkdir -p $(BUILD)/fw
	@CROSS_M4_FLAGS="$(CROSS_M4)" CROSS_M0_FLAGS="$(CROSS_M0)" bash tests/cross_report.sh $(BUILD)/cross \
	  $(BUILD)/fw/stack.json

# The core must not reach for the heap, stdio or process exit.
symcheck: $(BUILD)/libocc.a cross-objs
	@bash tests/symcheck.sh $(BUILD)/rel/src $(BUILD)/cross/m4/src

# ---- other entry points (fragments add steps) -----------------------------------------------------
demo: all $(DEMO_STEPS)
# bench: a fresh build/bench/rows, every step, then the one table made of their rows
# (bench/table.mk): after the steps, whatever -j runs them in parallel.
bench: all
	@rm -rf $(BENCH_ROWS_DIR) && mkdir -p $(BENCH_ROWS_DIR)
	@$(MAKE) --no-print-directory $(BENCH_STEPS)
	@$(MAKE) --no-print-directory bench-table
fuzz: $(DEPS_STAMP) $(FUZZ_STEPS)

clean:
	rm -rf $(filter-out $(BUILD)/venv $(BUILD)/cache,$(wildcard $(BUILD)/*)) $(BUILD)/.deps-ok
distclean:
	rm -rf $(BUILD)

.PHONY: all deps test test-build cross cross-objs symcheck demo bench fuzz clean distclean
.PRECIOUS: %.o
-include $(shell find $(BUILD) -name '*.d' 2>/dev/null)
