# SPDX-License-Identifier: BSD-3-Clause
# insert.mk - `make bench` step: point-cloud integration against OctoMap (bench/insert.cpp).
BENCH_INSERT_PORT := port/posix/scan_xyz.c port/posix/scan_graph.c port/posix/depth_png.c
$(BUILD)/bench/insert: bench/insert.cpp $(BENCH_INSERT_PORT:%.c=$(BUILD)/relhost/%.o) $(BUILD)/libocc.a
	@mkdir -p $(dir $@)
	$(CXX) -std=c++14 -O2 -g -Wall -Wextra -Werror $(INC) -I/usr/include/eigen3 -o $@ $^ \
	  -loctomap -loctomath -lpng -lm
bench-insert: $(BUILD)/bench/insert $(BUILD)/data/scan.dat
	@mkdir -p $(BENCH_ROWS_DIR)
	./$(BUILD)/bench/insert --rows $(BENCH_ROWS_DIR)/insert.json
BENCH_STEPS += bench-insert
.PHONY: bench-insert
