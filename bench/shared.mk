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

# bench-shared-cost: what the mode costs a map that is never shared. The library once more with
# -DOCC_SHARED=0 (build/relnoshared) linked with the default build's `occmap` objects (they do not
# use the knob; it changes no struct), then callgrind's instruction count per scan inside
# occ_map_insert_cloud for both tools (bench/shared_cost.sh).
$(BUILD)/relnoshared/%.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(REL_CFLAGS) -DOCC_SHARED=0 $(EXTRA_CFLAGS) -MMD -MP -c $< -o $@
$(BUILD)/relnoshared/libocc.a: $(patsubst %.c,$(BUILD)/relnoshared/%.o,$(OCC_CORE_SRC) $(OCC_FEED_SRC) $(OCC_CCD_SRC))
	@rm -f $@
	$(AR) rcs $@ $^
# The feed's objects wait for the generated MAVLink headers (tests/mavlink.mk, read after this).
.SECONDEXPANSION:
$(OCC_FEED_SRC:%.c=$(BUILD)/relnoshared/%.o): $$(MAVGEN_STAMP)
$(BUILD)/relnoshared/occmap: $(TOOL_SRC:%.c=$(BUILD)/relhost/%.o) $(PORT_SRC:%.c=$(BUILD)/relhost/%.o) \
                             $(BUILD)/relnoshared/libocc.a
	$(CXX) -o $@ $^ $(HOST_LIBS)
bench-shared-cost: $(BUILD)/occmap $(BUILD)/relnoshared/occmap $(BUILD)/data/scan.dat
	bash bench/shared_cost.sh $(BUILD)/occmap $(BUILD)/relnoshared/occmap $(BUILD)/bench/shared_cost \
	  ../shared/data/depth/tum_fr2_pioneer_slam2
BENCH_STEPS += bench-shared-cost
.PHONY: bench-shared-cost
