# SPDX-License-Identifier: BSD-3-Clause
# soak.mk - the long-flight soak (issue 9): `make soak` replays an hour of real sensor data
# at 10 Hz in a fixed arena (robot-centric and coarsening eviction) and measures the
# instructions per insert with callgrind; `make test` runs a one-minute version under ASan.
SOAK_BIN := $(BUILD)/soak/soak
SOAK_ASAN := $(BUILD)/soak/soak-asan
SOAK_DATA := $(BUILD)/data/scan.dat
SOAK_ARGS := --laser $(SOAK_DATA)

$(SOAK_BIN): $(BUILD)/relhost/tests/soak/soak.o $(PORT_SRC:%.c=$(BUILD)/relhost/%.o) $(BUILD)/libocc.a
	@mkdir -p $(dir $@)
	$(CXX) -o $@ $^ $(HOST_LIBS)
# The sanitizer build of the library for the soak drops the pools' paranoid double-free walk
# (OCC_POOL_PARANOID, on with OCC_TESTING): it walks the free list on every free, which makes a
# long run with heavy eviction quadratic. Everything else is the test build.
SOAK_LIB_SRC := $(OCC_CORE_SRC) $(OCC_FEED_SRC) $(OCC_CCD_SRC)
$(BUILD)/asansoak/%.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(WARN) -O1 -g $(SAN) $(INC) -DOCC_TESTING=1 $(OCC_TEST_ASSERTS) -DOCC_POOL_PARANOID=0 $(EXTRA_CFLAGS) -MMD -MP -c $< -o $@
$(BUILD)/asansoak/libocc.a: $(SOAK_LIB_SRC:%.c=$(BUILD)/asansoak/%.o)
	@rm -f $@
	$(AR) rcs $@ $^
$(SOAK_ASAN): $(BUILD)/asanhost/tests/soak/soak.o $(PORT_SRC:%.c=$(BUILD)/asanhost/%.o) $(BUILD)/asansoak/libocc.a
	@mkdir -p $(dir $@)
	$(CXX) $(SAN) -o $@ $^ $(HOST_LIBS)

# One hour of sensor time per eviction mode, then callgrind on 20 s of it (in a small arena,
# so eviction is running) for the instruction count per insert. COARSEN gets a 4x larger slice
# budget: its sweeps walk the already-coarse far blocks again, and with 4096 blocks per slice
# the slices fall behind the 10 Hz feed (14 automatic fallbacks of up to 1.4 s in an hour).
soak: $(DEPS_STAMP) $(SOAK_BIN) $(SOAK_DATA)
	$(SOAK_BIN) $(SOAK_ARGS) --seconds 3600 --evict coarsen --budget 16384
	$(SOAK_BIN) $(SOAK_ARGS) --seconds 3600 --evict robot --budget 4096
	bash tests/soak/callgrind.sh $(SOAK_BIN) $(BUILD)/soak $(SOAK_ARGS)

# The short version: one minute of sensor time under ASan+UBSan, a small arena so eviction
# runs from the first seconds.
TEST_BUILD_EXTRA += $(SOAK_ASAN)
TEST_STEPS += test-soak-short
test-soak-short: $(SOAK_ASAN) $(SOAK_DATA)
	$(SOAK_ASAN) $(SOAK_ARGS) --seconds 60 --res 0.1 --arena-bytes 3000000 --stride 16 \
	  --laser-step 48 --watermark 9000 --check-every 50 --quiet

.PHONY: soak test-soak-short
