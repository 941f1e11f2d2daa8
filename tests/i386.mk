# SPDX-License-Identifier: BSD-3-Clause
# tests/i386.mk - every module's unit tests with a 32-bit size_t (issue 16, section 2).
# The library, the test support, the POSIX port and every tests/test_*.c are built again with
# -m32 into $(BUILD)/asan32 with the same ASan + UBSan flags as build/asan, and each binary runs in
# `make test` beside its 64-bit twin: the runner counts its tests (TEST_BINS_EXTRA), and the
# _i386 suffix keeps the two apart in its lines and logs (build/test-logs/test_xxx_i386.log).
# Debian 12 multiarch: the deps rule adds the i386 architecture when a pkg:i386 is missing.
# lib32asan8 / lib32ubsan1 come with gcc-12-multilib. liboctomap-dev:i386 cannot be installed
# beside the amd64 one (both ship /usr/share/octomap/octomap-config-version.cmake, different
# bytes), so the oracles take the (same-version, arch-independent) amd64 headers and link the
# i386 runtime library by its soname.
APT_PKGS += gcc-multilib g++-multilib libcmocka-dev:i386 liboctomap1.9:i386 libccd-dev:i386 \
            libpng-dev:i386
I386_LIBS = $(patsubst -loctomap,-l:liboctomap.so.1.9,$(patsubst -loctomath,-l:liboctomath.so.1.9,$(HOST_LIBS)))

I386_DIR := $(BUILD)/asan32
# SSE2 arithmetic (FLT_EVAL_METHOD 0) as on x86-64 and the Cortex-M4's FPU: i386's default x87
# keeps intermediates in 80 bits, which moves keys on voxel borders (computeRayKeys and the
# discretized centres then differ from OctoMap's by a voxel). What this build is for is the
# 32-bit size_t and pointers, not a third floating-point model.
I386_CFLAGS := -m32 -msse2 -mfpmath=sse
I386_LIB_SRC := $(OCC_CORE_SRC) $(OCC_FEED_SRC) $(OCC_CCD_SRC)
I386_SUPPORT_OBJ := $(patsubst %.c,$(I386_DIR)/host/%.o,$(patsubst %.cpp,$(I386_DIR)/host/%.o,$(TEST_SUPPORT_SRC)))
I386_PORT_OBJ := $(PORT_SRC:%.c=$(I386_DIR)/host/%.o)
I386_BINS := $(TEST_C:tests/%.c=$(I386_DIR)/bin/%_i386)

$(I386_DIR)/lib/%.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(ASAN_CFLAGS) $(I386_CFLAGS) $(EXTRA_CFLAGS) -MMD -MP -c $< -o $@
$(I386_DIR)/host/%.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(HOST_WARN) -O1 -g $(SAN) $(INC) -DOCC_TESTING=1 $(I386_CFLAGS) $(EXTRA_CFLAGS) -MMD -MP -c $< -o $@
$(I386_DIR)/host/%.o: %.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(CXXWARN) -O1 -g $(SAN) $(INC) -I/usr/include/eigen3 $(I386_CFLAGS) -MMD -MP -c $< -o $@
$(I386_DIR)/libocc.a: $(I386_LIB_SRC:%.c=$(I386_DIR)/lib/%.o)
	@rm -f $@
	$(AR) rcs $@ $^
$(I386_DIR)/bin/%_i386: $(I386_DIR)/host/tests/%.o $(I386_SUPPORT_OBJ) $(I386_PORT_OBJ) $(I386_DIR)/libocc.a
	@mkdir -p $(dir $@)
	$(CXX) $(I386_CFLAGS) $(SAN) -o $@ $^ $(I386_LIBS)

# The generated MAVLink headers come first, as for the 64-bit objects (mavlink.mk is read after
# this fragment, hence the second expansion of its variable).
.SECONDEXPANSION:
$(OCC_FEED_SRC:%.c=$(I386_DIR)/lib/%.o) $(PORT_SRC:%.c=$(I386_DIR)/host/%.o) \
  $(TEST_C:%.c=$(I386_DIR)/host/%.o): $$(MAVGEN_STAMP)

TEST_BINS_EXTRA += $(I386_BINS)
i386-build: $(I386_BINS)
.PHONY: i386-build

# The oracles (ORACLE_SRC, top Makefile) with ORACLE_FLAGS: optimized, no sanitizer.
$(ORACLE_SRC:%.cpp=$(I386_DIR)/host/%.o): $(I386_DIR)/host/%.o: %.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(CXXWARN) $(ORACLE_FLAGS) $(INC) -I/usr/include/eigen3 $(I386_CFLAGS) -MMD -MP -c $< -o $@
