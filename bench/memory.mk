# SPDX-License-Identifier: BSD-3-Clause
# bench/memory.mk - bytes per stored voxel, occmap vs OctoMap's memoryUsage(), on the real scan.
# Two binaries: memory (the default 16-bit values) and memory8 (the same bench and a library
# rebuilt with -DOCC_VALUE_BITS=8 in build/rel8); rows go to build/bench/rows/memory.json and
# memory8.json (issue 22).
BENCH_MEMORY_BIN := $(BUILD)/bench/memory
BENCH_MEMORY8_BIN := $(BUILD)/bench/memory8
MEMORY8_FLAGS := -DOCC_VALUE_BITS=8

$(BENCH_MEMORY_BIN): $(BUILD)/relhost/bench/memory.o $(BUILD)/relhost/port/posix/scan_xyz.o $(BUILD)/libocc.a
	@mkdir -p $(dir $@)
	$(CXX) -o $@ $^ -loctomap -loctomath -lm

$(BUILD)/rel8/%.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(REL_CFLAGS) $(MEMORY8_FLAGS) -MMD -MP -c $< -o $@
$(BUILD)/rel8/libocc.a: $(OCC_CORE_SRC:%.c=$(BUILD)/rel8/%.o)
	@rm -f $@
	$(AR) rcs $@ $^
$(BUILD)/rel8/host/%.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(HOST_WARN) -O2 -g $(INC) $(MEMORY8_FLAGS) -MMD -MP -c $< -o $@
$(BUILD)/rel8/host/%.o: %.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(CXXWARN) -O2 -g $(INC) $(MEMORY8_FLAGS) -MMD -MP -c $< -o $@
$(BENCH_MEMORY8_BIN): $(BUILD)/rel8/host/bench/memory.o $(BUILD)/rel8/host/port/posix/scan_xyz.o $(BUILD)/rel8/libocc.a
	@mkdir -p $(dir $@)
	$(CXX) -o $@ $^ -loctomap -loctomath -lm

bench-memory: $(BENCH_MEMORY_BIN) $(BENCH_MEMORY8_BIN) $(BUILD)/data/foundation/scan.dat
	@mkdir -p $(BUILD)/bench/rows
	$(BENCH_MEMORY_BIN) $(BUILD)/data/foundation/scan.dat $(BUILD)/bench/memory.json $(BUILD)/bench/rows/memory.json
	$(BENCH_MEMORY8_BIN) $(BUILD)/data/foundation/scan.dat $(BUILD)/bench/memory8.json $(BUILD)/bench/rows/memory8.json

-include $(wildcard $(BUILD)/rel8/*.d $(BUILD)/rel8/*/*.d $(BUILD)/rel8/*/*/*.d $(BUILD)/rel8/*/*/*/*.d)
BENCH_STEPS += bench-memory
.PHONY: bench-memory
