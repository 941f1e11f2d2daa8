# SPDX-License-Identifier: BSD-3-Clause
# shared.mk - `make bench` step for the shared map (issue 20): the writer's thread CPU time per
# scan plain / shared / shared with 4 readers, interleaved, and the readers' latency
# (bench/shared.cpp); rows to build/bench/rows/shared.json.
SHARED_BENCH := $(BUILD)/bench/shared
SHARED_BENCH_PORT := port/posix/scan_xyz.c port/posix/scan_graph.c port/posix/depth_png.c
$(SHARED_BENCH): bench/shared.cpp bench/bench_rows.hpp $(BUILD)/relhost/tests/support/shared_replay.o \
                 $(SHARED_BENCH_PORT:%.c=$(BUILD)/relhost/%.o) $(BUILD)/libocc.a
	@mkdir -p $(dir $@)
	$(CXX) -std=c++14 -O2 -g -Wall -Wextra -Werror $(INC) -Itests -o $@ $(filter-out %.hpp,$^) \
	  -lpng -lm -lpthread
bench-shared: $(SHARED_BENCH) $(BUILD)/data/scan.dat
	@mkdir -p $(BENCH_ROWS_DIR)
	./$(SHARED_BENCH) --rows $(BENCH_ROWS_DIR)/shared.json
BENCH_STEPS += bench-shared
.PHONY: bench-shared
