# SPDX-License-Identifier: BSD-3-Clause
# shared.mk - `make bench` step for the shared map (issue 20): writer throughput plain / shared /
# shared with 4 readers, interleaved, and reader latency (bench/shared.c).
SHARED_BENCH := $(BUILD)/bench/shared
SHARED_BENCH_PORT := port/posix/scan_xyz.c port/posix/scan_graph.c port/posix/depth_png.c
$(SHARED_BENCH): $(BUILD)/relhost/bench/shared.o $(BUILD)/relhost/tests/support/shared_replay.o \
                 $(SHARED_BENCH_PORT:%.c=$(BUILD)/relhost/%.o) $(BUILD)/libocc.a
	@mkdir -p $(dir $@)
	$(CC) -o $@ $^ -lpng -lm -lpthread
$(BUILD)/relhost/bench/shared.o: EXTRA_CFLAGS += -Itests
bench-shared: $(SHARED_BENCH) $(BUILD)/data/scan.dat
	./$(SHARED_BENCH)
BENCH_STEPS += bench-shared
.PHONY: bench-shared
