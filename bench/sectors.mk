# SPDX-License-Identifier: BSD-3-Clause
# sectors.mk - cost of one 72-sector update (src/sectors/sectors.c) on OctoMap's geb079.bt:
# wall-clock median over corridor poses, and callgrind instructions per update.
SECT_BENCH := $(BUILD)/bench/sectors_bench
SECT_BENCH_MAP := /usr/share/doc/liboctomap-dev/examples/data/geb079.bt
$(SECT_BENCH): $(BUILD)/relhost/bench/sectors_bench.o $(PORT_SRC:%.c=$(BUILD)/relhost/%.o) $(BUILD)/libocc.a
	@mkdir -p $(dir $@)
	$(CXX) -o $@ $^ $(HOST_LIBS)
bench-sectors: $(SECT_BENCH)
	@$(SECT_BENCH) $(SECT_BENCH_MAP)
	@valgrind --tool=callgrind --toggle-collect=occ_sectors_compute \
	  --callgrind-out-file=$(BUILD)/bench/callgrind.sectors.out $(SECT_BENCH) $(SECT_BENCH_MAP) --callgrind \
	  > $(BUILD)/bench/callgrind.sectors.log 2>&1; \
	  n=$$(grep -o 'callgrind: [0-9]* updates' $(BUILD)/bench/callgrind.sectors.log | awk '{print $$2}'); \
	  ir=$$(grep -E '^(summary|totals):' $(BUILD)/bench/callgrind.sectors.out | tail -1 | awk '{print $$2}'); \
	  echo "sectors callgrind: $$n updates (default config), $$ir instructions in occ_sectors_compute," \
	       "$$(( ir / n )) per update"
BENCH_STEPS += bench-sectors
.PHONY: bench-sectors
