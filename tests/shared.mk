# SPDX-License-Identifier: BSD-3-Clause
# shared.mk - one writer, many readers (issue 20). tests/test_shared.c and
# tests/test_shared_stress.c run as ordinary CMocka binaries (ASan+UBSan); this fragment adds
# the stress test under ThreadSanitizer (its own build of the library in build/tsan/: 0 races,
# 0 mismatches), and a longer run of both builds to `make soak`.
TSAN := -fsanitize=thread -fno-omit-frame-pointer
# The pools' paranoid double-free walk (OCC_TESTING) is quadratic under heavy eviction: off here,
# as in the soak build; the asserts stay live.
TSAN_CFLAGS := $(WARN) -O1 -g $(TSAN) $(INC) -DOCC_TESTING=1 $(OCC_TEST_ASSERTS) -DOCC_POOL_PARANOID=0
TSAN_LIB_SRC := $(OCC_CORE_SRC) $(OCC_FEED_SRC)
TSAN_HOST_SRC := tests/test_shared_stress.c tests/support/shared_replay.c port/posix/depth_png.c \
  port/posix/scan_xyz.c port/posix/scan_graph.c
SHARED_TSAN_BIN := $(BUILD)/tsan/tests/bin/test_shared_stress

$(BUILD)/tsan/%.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(TSAN_CFLAGS) $(EXTRA_CFLAGS) -MMD -MP -c $< -o $@
$(BUILD)/tsanhost/%.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(HOST_WARN) -O1 -g $(TSAN) $(INC) -DOCC_TESTING=1 $(EXTRA_CFLAGS) -MMD -MP -c $< -o $@
$(BUILD)/tsan/libocc.a: $(TSAN_LIB_SRC:%.c=$(BUILD)/tsan/%.o)
	@rm -f $@
	$(AR) rcs $@ $^
$(SHARED_TSAN_BIN): $(TSAN_HOST_SRC:%.c=$(BUILD)/tsanhost/%.o) $(BUILD)/tsan/libocc.a
	@mkdir -p $(dir $@)
	$(CC) $(TSAN) -o $@ $^ -lpng -lcmocka -lm -lpthread

TEST_BUILD_EXTRA += $(SHARED_TSAN_BIN)
TEST_STEPS += test-shared-tsan
# halt_on_error: the first race fails the step (TSan's exit code 66); the run is bounded (3 s).
test-shared-tsan: $(SHARED_TSAN_BIN) $(BUILD)/data/scan.dat
	TSAN_OPTIONS="halt_on_error=1 exitcode=66" OCC_STRESS_SECONDS=3 $(SHARED_TSAN_BIN)

SOAK_STEPS_SHARED := soak-shared
soak: $(SOAK_STEPS_SHARED)
soak-shared: $(SHARED_TSAN_BIN) $(BUILD)/asan/tests/bin/test_shared_stress $(BUILD)/data/scan.dat
	TSAN_OPTIONS="halt_on_error=1 exitcode=66" OCC_STRESS_SECONDS=120 $(SHARED_TSAN_BIN)
	OCC_STRESS_SECONDS=120 $(BUILD)/asan/tests/bin/test_shared_stress

.PHONY: test-shared-tsan soak-shared
