# SPDX-License-Identifier: BSD-3-Clause
# scratch.mk - `make bench` step: scan.dat 0.05 m exact in 8 MB of scratch vs unbounded, and the
# peak RSS of that integration (bench/scratch.cpp, issue 22).
BENCH_SCRATCH_PORT := port/posix/scan_xyz.c
$(BUILD)/bench/scratch: bench/scratch.cpp bench/bench_rows.hpp $(BENCH_SCRATCH_PORT:%.c=$(BUILD)/relhost/%.o) $(BUILD)/libocc.a
	@mkdir -p $(dir $@)
	$(CXX) -std=c++14 -O2 -g -Wall -Wextra -Werror $(INC) -o $@ $(filter-out %.hpp,$^) \
	  -loctomap -loctomath -lm
bench-scratch: $(BUILD)/bench/scratch $(BUILD)/data/scan.dat
	@mkdir -p $(BENCH_ROWS_DIR)
	./$(BUILD)/bench/scratch
BENCH_STEPS += bench-scratch
.PHONY: bench-scratch
