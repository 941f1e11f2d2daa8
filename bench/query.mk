# SPDX-License-Identifier: BSD-3-Clause
# query.mk - `make bench` step: collision checks, ray casts, line of sight and information gain
# against OctoMap in the same run (bench/query.cpp) on geb079.bt, ../shared/data/maps/* and maps
# built from the real scans by `occmap build` (5 cm, written as .bt so that OctoMap reads the same
# tree). Writes build/bench/query.json and the issue-22 rows build/bench/rows/query.json.
TUM_DIR := ../shared/data/depth/tum_fr2_pioneer_slam2
BENCH_QUERY_BUILT := $(BUILD)/bench/maps/scan_dat_5cm.bt $(BUILD)/bench/maps/spherical_scan_5cm.bt \
  $(if $(wildcard $(TUM_DIR)/my_association.txt),$(BUILD)/bench/maps/tum_fr2_pioneer_5cm.bt)
BENCH_QUERY_MAPS := /usr/share/doc/liboctomap-dev/examples/data/geb079.bt \
  $(wildcard ../shared/data/maps/*.bt ../shared/data/maps/*.ot) $(BENCH_QUERY_BUILT)
$(BUILD)/bench/maps/scan_dat_5cm.bt: $(BUILD)/occmap $(BUILD)/data/scan.dat
	@mkdir -p $(dir $@)
	./$(BUILD)/occmap build --scan $(BUILD)/data/scan.dat --res 0.05 -o $@ > /dev/null
$(BUILD)/bench/maps/spherical_scan_5cm.bt: $(BUILD)/occmap
	@mkdir -p $(dir $@)
	./$(BUILD)/occmap build --graph /usr/share/doc/liboctomap-dev/examples/data/spherical_scan.graph --res 0.05 -o $@ > /dev/null
$(BUILD)/bench/maps/tum_fr2_pioneer_5cm.bt: $(BUILD)/occmap
	@mkdir -p $(dir $@)
	./$(BUILD)/occmap build --depth-dir $(TUM_DIR) --res 0.05 -o $@ > /dev/null
$(BUILD)/bench/query: bench/query.cpp $(BUILD)/relhost/port/posix/file_io.o $(BUILD)/libocc.a
	@mkdir -p $(dir $@)
	$(CXX) -std=c++14 -O2 -g -Wall -Wextra -Werror $(INC) -o $@ $^ -loctomap -loctomath -lm
bench-query: $(BUILD)/bench/query $(BENCH_QUERY_BUILT)
	@mkdir -p $(BENCH_ROWS_DIR)
	./$(BUILD)/bench/query --json $(BUILD)/bench/query.json --rows $(BENCH_ROWS_DIR)/query.json $(BENCH_QUERY_MAPS)
BENCH_STEPS += bench-query
.PHONY: bench-query
