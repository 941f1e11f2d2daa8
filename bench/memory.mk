# SPDX-License-Identifier: BSD-3-Clause
# bench/memory.mk - bytes per stored voxel, occmap vs OctoMap's memoryUsage(), on the real scan.
BENCH_MEMORY_BIN := $(BUILD)/bench/memory

$(BENCH_MEMORY_BIN): $(BUILD)/relhost/bench/memory.o $(BUILD)/relhost/port/posix/scan_xyz.o $(BUILD)/libocc.a
	@mkdir -p $(dir $@)
	$(CXX) -o $@ $^ -loctomap -loctomath -lm

bench-memory: $(BENCH_MEMORY_BIN) $(BUILD)/data/foundation/scan.dat
	@mkdir -p $(BUILD)/bench
	$(BENCH_MEMORY_BIN) $(BUILD)/data/foundation/scan.dat $(BUILD)/bench/memory.json

BENCH_STEPS += bench-memory
.PHONY: bench-memory
