# SPDX-License-Identifier: BSD-3-Clause
# bench/lookup_index.mk - `make bench` step (issue 22): random and trajectory point lookups through
# the lookup index against OctoMap's search() and occ_map_state_at in the same run
# (bench/lookup_index.cpp) on geb079.bt and fr_079 (../shared/data/maps, when present).
# Writes build/bench/rows/lookup_index.json.
BENCH_LOOKUP_INDEX_MAPS := /usr/share/doc/liboctomap-dev/examples/data/geb079.bt \
  $(wildcard ../shared/data/maps/fr_079*.bt ../shared/data/maps/fr_079*.ot)
$(BUILD)/bench/lookup_index: bench/lookup_index.cpp bench/bench_rows.hpp bench/octo_load.hpp $(BUILD)/relhost/port/posix/file_io.o $(BUILD)/libocc.a
	@mkdir -p $(dir $@)
	$(CXX) -std=c++14 -O2 -g -Wall -Wextra -Werror $(INC) -o $@ $(filter-out %.hpp,$^) -loctomap -loctomath -lm
bench-lookup-index: $(BUILD)/bench/lookup_index
	@mkdir -p $(BUILD)/bench/rows
	./$(BUILD)/bench/lookup_index --rows $(BUILD)/bench/rows/lookup_index.json $(BENCH_LOOKUP_INDEX_MAPS)
BENCH_STEPS += bench-lookup-index
.PHONY: bench-lookup-index
