# SPDX-License-Identifier: BSD-3-Clause
# projective.mk - `make bench` step: OCC_INSERT_PROJECTIVE against OctoMap and SUPER_RAYS on the
# TUM depth frames (bench/projective.cpp, issue 19), with the issue-22 rows in
# build/bench/rows/projective.json. Skips (prints SKIP) without ../shared.
BENCH_PROJ_PORT := port/posix/scan_xyz.c port/posix/scan_graph.c port/posix/depth_png.c \
                   port/posix/tum_sequence.c
$(BUILD)/bench/projective: bench/projective.cpp $(BENCH_PROJ_PORT:%.c=$(BUILD)/relhost/%.o) $(BUILD)/libocc.a
	@mkdir -p $(dir $@)
	$(CXX) -std=c++14 -O2 -g -Wall -Wextra -Werror $(INC) -o $@ $^ -loctomap -loctomath -lpng -lm
bench-projective: $(BUILD)/bench/projective
	@mkdir -p $(BENCH_ROWS_DIR)
	./$(BUILD)/bench/projective --rows $(BENCH_ROWS_DIR)/projective.json
BENCH_STEPS += bench-projective
.PHONY: bench-projective
